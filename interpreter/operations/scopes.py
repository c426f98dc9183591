"""rotateScope, alignScopeToAxes, alignScopeToGeometry: the scope turns, the geometry stays.

CGA's scope operations change the frame a shape is measured in without moving what it is: after
``alignScopeToGeometry(yUp, 0, longest)`` a lot's x runs along its longest edge and its size is
its bounding box along that edge.  Geometry lives in unit scope coordinates here, so it is
re-expressed in the new frame (:func:`reframe`): a 2D shape whose plane is square to one of the
new axes stays a 2D shape (flat along that axis) and can be split, offset and extruded as
before; a prism turned about its own extrusion axis stays a prism; anything else becomes a mesh
(a solid, as an inserted asset is).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..expressions import runtime_error
from ..geometry.convex import convex_parts
from ..geometry.frames import _ccw, flat_points, reframe_flat
from ..geometry.meshes import PLANE_AXES, flat_mesh, prism_mesh
from ..geometry.polygons import RECT
from ..shapes import IDENTITY, Flat, Prism, Solid, cross, dot, normalise
from ..terminals import UnitMesh
from .transforms import _amounts, _mirror, _rotate_axes

Frame = tuple[tuple[float, float, float], ...]


def rotate_scope(app, shape, step, args) -> bool:
    angles = _amounts(app, step, shape, args[:3])
    axes = shape.axes
    for axis, deg in enumerate(angles):
        if deg:
            axes = _rotate_axes(axes, axis, deg)
    reframe(app, shape, axes)
    return False


def align_scope_to_axes(app, shape, step, args) -> bool:
    which = args[0] if len(args) > 1 else None
    if which is None:
        reframe(app, shape, IDENTITY)
        return False
    k = "xyz".index(which)
    keep = list(IDENTITY[k])
    # the axis laid level: x for y and z, z for x (CGA's choice), taken off the kept axis
    other = 2 if k == 0 else 0
    level = _without(shape.axes[other], keep)
    if level is None:  # that axis is along the kept one: the next axis round
        other = 3 - k - other if k != 1 else 2
        level = _without(shape.axes[other], keep) or list(IDENTITY[other])
    axes: list = [None, None, None]
    axes[k], axes[other] = tuple(keep), tuple(level)
    third = 3 - k - other
    # a right-handed frame: x = y × z, y = z × x, z = x × y
    i, j = (third + 1) % 3, (third + 2) % 3
    axes[third] = tuple(cross(axes[i], axes[j]))
    reframe(app, shape, tuple(axes))
    return False


def align_scope_to_geometry(app, shape, step, args) -> bool:
    up, face_pick, edge_pick = args[0], args[1], args[2]
    geom = shape.geom
    if isinstance(geom, Flat):
        faces = flat_points(shape.origin, shape.axes, shape.size, geom.k, geom.polys)
        rings = [ext for ext, _ in faces]
        normals = [tuple(shape.axes[geom.k])] * len(rings)
    else:  # a solid: its planar faces (as comp(f) takes them), in the world
        from .components import faces_of

        solid_faces = faces_of(app, step, shape)
        rings = [[shape.world(p) for p in face_rings[0]] for face_rings, _, _ in solid_faces]
        normals = [tuple(shape.direction(nrm)) for _, nrm, _ in solid_faces]
    start, end, face = _edge(app, step, rings, face_pick, edge_pick)
    along = [end[i] - start[i] for i in range(3)]
    if dot(along, along) < 1e-18:
        raise runtime_error(app.module, step.pos, "alignScopeToGeometry(): that edge has no length")
    x = tuple(normalise(along))
    normal = normals[face]
    if abs(dot(x, normal)) > 1e-6:  # an edge off the face's plane (a solid's, picked by any)
        raise runtime_error(app.module, step.pos, "alignScopeToGeometry(): that edge is not flat")
    if up == "yUp":
        frame = (x, normal, tuple(cross(x, normal)))
    else:
        frame = (x, tuple(cross(normal, x)), normal)
    reframe(app, shape, frame)
    return False


def _without(v, axis) -> list | None:
    """``v`` with its part along ``axis`` taken off, normalised; None when nothing is left."""
    d = dot(v, axis)
    rest = [v[i] - d * axis[i] for i in range(3)]
    return normalise(rest) if dot(rest, rest) > 1e-12 else None


def _edge(app, step, rings: list, face_pick, edge_pick):
    """The (start, end) world points of the edge alignScopeToGeometry's arguments choose, and
    the index of the face (ring) it belongs to."""

    def edges(ring):
        return [(ring[i], ring[(i + 1) % len(ring)]) for i in range(len(ring))]

    def length(e):
        return math.dist(e[0], e[1])

    def height(e):
        return (e[0][1] + e[1][1]) / 2

    if face_pick == "any":
        candidates = [(*e, k) for k, ring in enumerate(rings) for e in edges(ring)]
    else:
        if face_pick == "largest":
            k = max(range(len(rings)), key=lambda i: _area(rings[i]))
        elif face_pick == "world.lowest":
            k = min(range(len(rings)), key=lambda i: min(p[1] for p in rings[i]))
        else:
            k = _index(app, step, face_pick, len(rings), "face")
        candidates = [(*e, k) for e in edges(rings[k])]
        if edge_pick not in ("longest", "world.lowest"):
            return candidates[_index(app, step, edge_pick, len(candidates), "edge")]
    if edge_pick == "longest":
        return max(candidates, key=length)
    if edge_pick == "world.lowest":
        return min(candidates, key=height)
    raise runtime_error(
        app.module, step.pos, "alignScopeToGeometry(upAxis, any, ...) takes longest or world.lowest"
    )


def _index(app, step, value, count: int, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise runtime_error(app.module, step.pos, f"the {what} index must be a number")
    return int(math.floor(value)) % count  # negative indices count from the end, as CGA's


def _area(ring) -> float:
    a = np.asarray(ring, dtype=np.float64)
    return float(np.linalg.norm(np.cross(a, np.roll(a, -1, axis=0)).sum(axis=0)) / 2)


# ---- the geometry in the new frame -------------------------------------------------------------


def reframe(app, shape, frame: Frame) -> None:
    """Give ``shape`` the axes ``frame`` (right-handed, orthonormal), its geometry kept in place
    in the world; the scope becomes the geometry's bounding box along the new axes."""
    geom = shape.geom
    if isinstance(geom, Flat):
        # the face keeps facing the way it did: its normal must be one of the new axes, the same
        # way round (a 2D shape faces along its flat axis)
        normal = shape.axes[geom.k]
        t = next((k for k in range(3) if dot(frame[k], normal) > 1 - 1e-9), None)
        if t is not None:
            _flat(shape, frame, t, geom.k, geom.polys, geom.name)
            return
        verts, tris = flat_mesh(geom.polys, geom.k)
        name = geom.name
    elif isinstance(geom, Prism):
        k = geom.k
        if dot(frame[k], shape.axes[k]) > 1 - 1e-9:  # turned about its own extrusion axis
            height = shape.size[k]
            _flat(shape, frame, k, k, geom.polys, geom.name)
            shape.geom = Prism(k, shape.geom.polys, geom.name)
            shape.size[k] = height
            return
        verts, tris = prism_mesh(geom.polys, k)
        name = "extrusion"
    else:
        mesh = app.engine.table.library.meshes[geom.mesh]
        _solid(app, shape, frame, mesh.vertices, mesh.faces, geom.name, mesh.uv, mesh.image)
        return
    _solid(app, shape, frame, verts, tris, name, None, None)


def _flat(shape, frame: Frame, t: int, k: int, polys, name: str) -> None:
    """A flat outline (flat along scope axis ``k``) in ``frame``, flat along its axis ``t``."""
    if t == 1:
        origin, size, unit, _ = reframe_flat(shape.origin, shape.axes, shape.size, k, polys, frame)
        shape.origin, shape.axes, shape.size = origin, frame, [size[0], 0.0, size[2]]
        shape.geom = Flat(1, unit, name)
        return
    # reframe_flat lays a shape flat along a frame's y: hand it the frame whose y is axis t and
    # whose x is the next axis round (PLANE_AXES[t]'s first); its z is then minus the axis
    # after that, so the second plane coordinate comes back reversed
    nxt, back = (t + 1) % 3, frame[(t + 2) % 3]
    local = (frame[nxt], frame[t], tuple(cross(frame[nxt], frame[t])))
    origin, size, unit, _ = reframe_flat(shape.origin, shape.axes, shape.size, k, polys, local)
    depth = size[2]
    shape.origin = [origin[i] - depth * back[i] for i in range(3)]
    shape.axes = frame
    new_size = [0.0, 0.0, 0.0]
    new_size[nxt], new_size[(t + 2) % 3] = size[0], depth
    shape.size = new_size
    if unit == RECT:
        shape.geom = Flat(t, RECT, name)
        return
    assert PLANE_AXES[t][0] == nxt  # (1, 2) for t = 0, (0, 1) for t = 2

    def move(ring, outer):
        return _ccw([(u, 1.0 - v) for u, v in ring], outer)

    shape.geom = Flat(
        t, [(move(ext, True), tuple(move(h, False) for h in holes)) for ext, holes in unit], name
    )


def _solid(app, shape, frame: Frame, verts, tris, name: str, uv, image) -> None:
    """A mesh in unit coordinates of the old scope, as a solid in ``frame``."""
    v = np.asarray(verts, dtype=np.float64)
    world = np.asarray(shape.origin) + (v * np.asarray(shape.size)) @ np.asarray(
        shape.axes, dtype=np.float64
    )
    axes = np.asarray(frame, dtype=np.float64)
    local = world @ axes.T
    low, high = local.min(axis=0), local.max(axis=0)
    size = high - low
    size[size < 1e-9] = 0.0  # a face seen edge-on: no thickness, not rounding noise
    unit = np.divide(local - low, size, out=np.zeros_like(local), where=size > 1e-12)
    mesh_id = app.engine.table.library.add(UnitMesh(name, unit, tris, uv, image))
    shape.origin = list(low @ axes)
    shape.axes = tuple(tuple(float(c) for c in a) for a in frame)
    shape.size = [float(s) for s in size]
    shape.geom = Solid(mesh_id, name)


def mirror(app, shape, step, args) -> bool:
    """CGA's mirror(xFlip, yFlip, zFlip): the geometry mirrored inside its scope, which stays.

    A flip along a 2D shape's flat axis, or along a prism's extrusion, changes nothing (the shape
    is symmetric that way); a mesh mirrored an odd number of times turns its triangles round so
    that they keep facing out."""
    flips = args[:3]
    for value in flips:
        if not isinstance(value, bool):
            raise runtime_error(app.module, step.pos, "mirror() takes true or false for each axis")
    geom = shape.geom
    if isinstance(geom, (Flat, Prism)):
        polys = geom.polys
        if polys == RECT:
            return False
        for which, axis in enumerate(PLANE_AXES[geom.k]):
            if flips[axis]:
                polys = [
                    (_mirror(ext, which), tuple(_mirror(h, which) for h in holes))
                    for ext, holes in polys
                ]
        shape.geom = type(geom)(geom.k, polys, geom.name)
        return False
    if not any(flips):
        return False
    library = app.engine.table.library
    mesh = library.meshes[geom.mesh]
    verts = mesh.vertices.copy()
    faces, uv = mesh.faces, mesh.uv
    for axis in range(3):
        if flips[axis]:
            verts[:, axis] = 1.0 - verts[:, axis]
    if sum(flips) % 2:
        faces = faces[:, ::-1].copy()
        uv = uv[:, ::-1].copy() if uv is not None else None
    shape.geom = Solid(library.add(UnitMesh(mesh.name, verts, faces, uv, mesh.image)), geom.name)
    return False


def cleanup_geometry(app, shape, step, args) -> bool:
    """CGA's cleanupGeometry(components, tolerance): points closer than ``tolerance`` metres
    merged, faces left without area dropped.  bgr's own shapes are exact, so this changes
    imported meshes and outlines made of near-duplicate points; ``components`` (CGA's all,
    faces, edges, vertices) is read as all."""
    tolerance = args[1]
    if isinstance(tolerance, bool) or not isinstance(tolerance, (int, float)):
        raise runtime_error(app.module, step.pos, "cleanupGeometry()'s tolerance is a number")
    if tolerance <= 0:
        return False
    geom = shape.geom
    if isinstance(geom, (Flat, Prism)):
        if geom.polys == RECT:
            return False
        p, q = PLANE_AXES[geom.k]
        su, sv = shape.size[p], shape.size[q]
        polys = []
        for ext, holes in geom.polys:
            outer = _thinned(ext, su, sv, tolerance)
            if outer is None:
                continue
            kept_holes = [r for r in (_thinned(h, su, sv, tolerance) for h in holes) if r]
            polys.append((outer, tuple(kept_holes)))
        if polys:
            shape.geom = type(geom)(geom.k, polys, geom.name)
        return False
    library = app.engine.table.library
    mesh = library.meshes[geom.mesh]
    metres = mesh.vertices * np.asarray(shape.size)
    keys = np.round(metres / tolerance).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    faces = inverse.reshape(-1)[mesh.faces]
    good = (
        (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    )
    if good.all() and len(first) == len(mesh.vertices):
        return False
    uv = mesh.uv[good] if mesh.uv is not None else None
    cleaned = UnitMesh(mesh.name, mesh.vertices[first], faces[good], uv, mesh.image)
    shape.geom = Solid(library.add(cleaned), geom.name)
    return False


def _thinned(ring, su: float, sv: float, tolerance: float):
    """A unit ring without points closer than ``tolerance`` metres to the last one kept; None
    when fewer than three are left."""
    out: list = []
    for u, v in ring:
        if out and math.hypot((u - out[-1][0]) * su, (v - out[-1][1]) * sv) < tolerance:
            continue
        out.append((u, v))
    if (
        len(out) > 1
        and math.hypot((out[0][0] - out[-1][0]) * su, (out[0][1] - out[-1][1]) * sv) < tolerance
    ):
        out.pop()
    return tuple(out) if len(out) >= 3 else None


def delete_holes(app, shape, step, args) -> bool:
    """CGA's deleteHoles(): a 2D shape's polygons without their holes.  A solid keeps its
    faces, which have none (boxes, roofs, assets: an OBJ polygon has no holes), except an
    extrusion of a footprint with a courtyard, whose filled caps bgr cannot hold yet."""
    geom = shape.geom
    if isinstance(geom, Prism) and geom.polys != RECT and any(h for _, h in geom.polys):
        raise runtime_error(
            app.module,
            step.pos,
            "deleteHoles() of an extrusion with holes is not in bgr yet",
            "delete the holes before extruding: deleteHoles() extrude(h)",
        )
    if isinstance(geom, Flat) and geom.polys != RECT and any(h for _, h in geom.polys):
        shape.geom = Flat(geom.k, [(ext, ()) for ext, _ in geom.polys], geom.name)
    return False


def convexify(app, shape, step, args) -> bool:
    """CGA's convexify(maxLength): a 2D shape's polygons cut into convex parts (its comp(f)
    gives each as a face), or a solid's concave faces (its comp(f) then gives their parts);
    cuts longer than ``maxLength`` metres are not made."""
    geom = shape.geom
    limit = args[0] if len(args) > 1 else math.inf
    if isinstance(limit, bool) or not isinstance(limit, (int, float)):
        raise runtime_error(app.module, step.pos, "convexify()'s maxLength is a number")
    if limit <= 0:  # no cut is that short
        return False
    if not isinstance(geom, Flat):
        # the solid's own faces stay; comp(f) cuts them (components.faces_of)
        shape.geom = replace(geom, convex=float(limit))
        return False
    if geom.polys == RECT:
        return False
    p, q = PLANE_AXES[geom.k]
    parts = convex_parts(geom.polys, shape.size[p], shape.size[q], float(limit))
    if parts:
        shape.geom = Flat(geom.k, parts, geom.name)
    return False
