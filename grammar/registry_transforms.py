"""The transform operations of the registry: moving, turning, scaling and aligning the scope
(``t``, ``r``, ``s``, ``rotateScope``, ``alignScopeToGeometry`` ...), mirroring, cleanup and
``matrix``.  :mod:`registry` gathers them into ``OPERATIONS`` in the order given here.
"""

from __future__ import annotations

from .registry_kinds import (
    AXES,
    AXIS,
    CLEANUP_KIND,
    COORD_SYSTEM,
    EDGE_PICK,
    FACE_PICK,
    NUMBER,
    ROTATION_PIVOT,
    SIZE,
    TRANSFORM_MODE,
    UP_AXIS,
    VALUE,
    Op,
    Param,
    _sig,
)

_MATRIX = tuple(Param(f"m{r}{c}", NUMBER) for r in range(3) for c in range(4))

# rotate's and translate's arguments: a mode, a coordinate system and three numbers
_IN_SYSTEM = _sig(
    Param("mode", TRANSFORM_MODE),
    Param("coordSystem", COORD_SYSTEM),
    Param("x", NUMBER),
    Param("y", NUMBER),
    Param("z", NUMBER),
)

TRANSFORMS: list[Op] = [
    # -- transforms --------------------------------------------------------------------
    Op(
        "t",
        "transforms",
        _sig(Param("x", SIZE), Param("y", SIZE), Param("z", SIZE)),
        "Translate the scope along its own axes; `'f` is a fraction of the scope size.",
        "t(0, 0, '0.5)",
    ),
    Op(
        "r",
        "transforms",
        (
            (Param("x", NUMBER), Param("y", NUMBER), Param("z", NUMBER)),
            (
                Param("pivot", ROTATION_PIVOT),
                Param("x", NUMBER),
                Param("y", NUMBER),
                Param("z", NUMBER),
            ),
        ),
        "Rotate about the scope origin, in degrees, x then y then z, in scope coordinates; "
        "`r(scopeCenter, x, y, z)` about the scope's centre (`scopeOrigin`: its origin), as CGA's.",
        "r(0, 90, 0)",
    ),
    Op(
        "translate",
        "transforms",
        _IN_SYSTEM,
        "CGA's translate: `rel` moves the scope by (x, y, z) metres along the axes of "
        "`coordSystem`, `abs` puts its origin at the point (x, y, z) of that system. `scope` is "
        "the shape's own scope (`translate(rel, scope, ...)` is `t`), `world` the axes the "
        "output is written in (x east, y up, z south) with the site's origin, `object` (and "
        "`pivot`, the same in bgr) the lot's scope as its start rule received it.",
        "translate(rel, world, 2, 0, 0)",
    ),
    Op(
        "rotate",
        "transforms",
        _IN_SYSTEM,
        "CGA's rotate, about the scope origin, in degrees, x then y then z: `rel` turns the "
        "scope by those angles about the axes of `coordSystem` (`rotate(rel, scope, ...)` is "
        "`r`), `abs` sets its orientation to those angles from that system's (`rotate(abs, "
        "world, 0, 0, 0)` lines the scope up with the world). The systems are translate's.",
        "rotate(abs, world, 0, 90, 0)",
    ),
    Op(
        "s",
        "transforms",
        _sig(Param("x", SIZE), Param("y", SIZE), Param("z", SIZE)),
        "Set the scope size; the geometry is scaled with it. `'f` is relative to the current size.",
        "s('0.5, '1, 2)",
    ),
    Op(
        "center",
        "transforms",
        _sig(Param("axes", AXES)),
        "Centre the scope along the given axes on the previous scope (the one saved by the "
        "last "
        "`[`, or the shape the rule received).",
        "center(xz)",
    ),
    Op(
        "reverseNormals",
        "transforms",
        _sig(),
        "Turn a 2D shape over so that it faces the other way (as CGA's operation of that "
        "name): a face's scope turns 180 degrees about its own y axis, so x and z reverse "
        "and the outline stays where it is (a lot's turns about its z); a solid's "
        "triangles are each turned over in place.",
        "reverseNormals()",
    ),
    Op(
        "rotateScope",
        "transforms",
        _sig(Param("x", NUMBER), Param("y", NUMBER), Param("z", NUMBER)),
        "Turn the scope about its own axes by the given degrees (x, then y, then z) while the "
        "geometry stays where it is, as CGA's rotateScope: the new scope is the geometry's "
        "bounding box along the turned axes.",
        "rotateScope(0, 90, 0)",
    ),
    Op(
        "alignScopeToAxes",
        "transforms",
        ((), (Param("axis", AXIS),)),
        "Turn the scope to the world's axes, the geometry staying where it is, as CGA's "
        "alignScopeToAxes: all three, or only the one given (`y`: the scope's y becomes the "
        "world's up and its x is laid level); the new scope is the geometry's bounding box.",
        "alignScopeToAxes(y)",
    ),
    Op(
        "alignScopeToGeometry",
        "transforms",
        _sig(Param("upAxis", UP_AXIS), Param("face", FACE_PICK), Param("edge", EDGE_PICK)),
        "Turn the scope to an edge of one of the shape's faces (a 2D shape's own, a solid's "
        "as comp(f) takes them), as CGA's alignScopeToGeometry: x "
        "along the edge (an index of the face's outline, `longest` or `world.lowest`), the "
        "face's normal as y (`yUp`) or z (`zUp`); the face is an index, `largest`, "
        "`world.lowest` or `any` (the face holding the edge chosen). The geometry stays "
        "where it is.",
        "alignScopeToGeometry(yUp, 0, longest)",
    ),
    Op(
        "mirror",
        "transforms",
        _sig(Param("x", VALUE), Param("y", VALUE), Param("z", VALUE)),
        "Mirror the geometry inside its scope along each axis given true (the scope stays), "
        "as CGA's mirror: `mirror(true, false, false)` flips it left to right.",
        "mirror(true, false, false)",
    ),
    Op(
        "cleanupGeometry",
        "transforms",
        _sig(Param("components", CLEANUP_KIND), Param("tolerance", NUMBER)),
        "Merge points closer than `tolerance` metres and drop faces left without area, as "
        "CGA's cleanupGeometry (`all`, `faces`, `edges` or `vertices`: each is read as all); "
        "bgr's own shapes are exact, so it changes inserted meshes and outlines from files.",
        "cleanupGeometry(all, 0.01)",
    ),
    Op(
        "deleteHoles",
        "transforms",
        _sig(),
        "Fill the holes of a 2D shape's polygons (a courtyard, a window cut), as CGA's "
        "deleteHoles; a solid's faces have none, except an extrusion of a footprint with a "
        "courtyard, which is not in bgr yet (a runtime error).",
        "deleteHoles()",
    ),
    Op(
        "convexify",
        "transforms",
        ((), (Param("maxLength", NUMBER),)),
        "Cut a 2D shape's polygons into convex parts (its comp(f) then gives each as a "
        "face), as CGA's convexify; a solid keeps its geometry and its comp(f) cuts each "
        "concave face so; cuts longer than `maxLength` metres are not made, so a part may "
        "stay concave.",
        "convexify() comp(f) { all: Part }",
    ),
    Op(
        "matrix",
        "transforms",
        (_MATRIX,),
        "Apply a 3x4 affine transform, given row by row, to the scope.",
        "matrix(1, 0, 0, 2, 0, 1, 0, 0, 0, 0, 1, 0)",
    ),
]
