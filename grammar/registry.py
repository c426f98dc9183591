"""Every shape operation and built-in function, declared once.

The checker reads the signatures to validate calls, ``docs/operations.md`` is generated from the
docs here (``python -m bgr.grammar.reference > docs/operations.md``), and the interpreter looks up
the implementation of each operation by its name.  Adding an operation means adding one
:class:`Op` entry here and one function in the interpreter family that ``family`` names.
"""

from __future__ import annotations

from dataclasses import dataclass

# Argument kinds.  A "symbol" kind takes a bare word from a fixed set (``split(x)``,
# ``roof(hip, 30)``), which the checker validates; the other kinds take expressions.
NUMBER = "number"  # any numeric expression
SIZE = "size"  # numeric expression, or 'expr relative to the current scope size
STRING = "string"  # string expression
COLOR = "color"  # "#rrggbb" string expression
VALUE = "value"  # a number, a string or true/false (report's value)
ATTR_NAME = "attr name"  # a bare word naming an attr of the file (set's first argument)
AXIS = "axis"  # x | y | z
AXES = "axes"  # a non-empty combination of x, y, z: xz, xyz ...
COMP_KIND = "comp kind"  # f (faces) | e (edges) | v (vertices)
ROOF_KIND = "roof kind"  # flat | gable | ...
FOOTPRINT_KIND = "footprint kind"  # rect | L | U | T | cross | circle
EXTRUDE_KIND = "extrusion direction"  # face.normal | world.up
GEOMETRY = "geometry"  # a primitive or a declared asset
TEX_SIZE = "texture size"  # numeric expression, 'f (a fraction of the scope) or ~w (floating)
PROJECTION_AXES = "projection axes"  # scope.xy, world.xz ... (setupProjection)
NORMALIZE_MODE = "normalize mode"  # uv | uvUniform | u | v
NORMALIZE_TYPE = "normalize type"  # separatePerFace | collectiveAllFaces
UP_AXIS = "up axis"  # yUp | zUp (alignScopeToGeometry)
CLEANUP_KIND = "components"  # all | faces | edges | vertices (cleanupGeometry)
INNER_ALIGNMENT = "alignment"  # scope | edge (innerRectangle)
SPLIT_ADJUST = "adjustment"  # noAdjust | adjust (split)
# a number, or one of a few bare words (alignScopeToGeometry's face and edge)
FACE_PICK = "face index or selector"  # a number | largest | world.lowest | any
EDGE_PICK = "edge index or selector"  # a number | longest | world.lowest

AXIS_NAMES = ("x", "y", "z")
COMP_KINDS = ("f", "e", "v")
ROOF_KINDS = ("flat", "gable", "hip", "pyramid", "shed", "mansard", "gambrel")
FOOTPRINT_KINDS = ("rect", "L", "U", "T", "cross", "circle")
EXTRUDE_KINDS = ("face.normal", "world.up")
PRIMITIVES = ("cube", "cylinder", "sphere", "quad", "wedge")
COMP_SELECTORS = (
    "front",
    "back",
    "left",
    "right",
    "side",
    "top",
    "bottom",
    "vertical",
    "horizontal",
    "aslant",
    "nutant",
    "all",
)
# edges also take CGA's roof selectors and border/inside; an index selector is face(i),
# edge(i) or vertex(i) by the comp's kind
EDGE_SELECTORS = (*COMP_SELECTORS, "border", "inside", "eave", "ridge", "hip", "valley")
VERTEX_SELECTORS = (*COMP_SELECTORS, "border", "inside")
COMP_INDEX_CALLS = {"f": "face", "e": "edge", "v": "vertex"}
OFFSET_SELECTORS = ("inside", "border")
INNER_SELECTORS = ("shape", "remainder")
SETBACK_SELECTORS = ("front", "back", "left", "right", "top", "bottom", "side", "all", "remainder")
PROJECTION_AXES_NAMES = tuple(
    f"{frame}.{a}{b}" for frame in ("scope", "world") for a in "xyz" for b in "xyz" if a != b
)
NORMALIZE_MODES = ("uv", "uvUniform", "u", "v")
NORMALIZE_TYPES = ("separatePerFace", "collectiveAllFaces")
UP_AXES = ("yUp", "zUp")
CLEANUP_KINDS = ("all", "faces", "edges", "vertices")
INNER_ALIGNMENTS = ("scope", "edge")
SPLIT_ADJUSTS = ("noAdjust", "adjust")
# CGA's shape attributes set() may change besides a file's attrs: whether vertical and
# horizontal trim planes cut (operations/trims.py), and the material's
# opacity, metallic and roughness (0..1: interpreter/surfaces.py)
SHAPE_ATTRIBUTES = (
    "trim.vertical",
    "trim.horizontal",
    "material.opacity",
    "material.metallic",
    "material.roughness",
)
# kinds that take a number or one of these words
NUMBER_OR_WORD = {
    FACE_PICK: ("largest", "world.lowest", "any"),
    EDGE_PICK: ("longest", "world.lowest"),
}
ANGLE_KINDS = ("maxSlope", "azimuth", "zenith")  # geometry.angle's bare word
OCCLUSION_TARGETS = ("all", "intra", "inter")  # inside/overlaps/touches' bare word
OCCLUSION = ("inside", "overlaps", "touches")
UV_SETS = 10  # uv-sets 0..9, as CGA's texture layers (material.colormap is 0, normalmap 5)

REQUIRED = object()
MANY = 1 << 20  # "any number of arguments": an operation whose last parameters repeat


@dataclass(frozen=True)
class Param:
    name: str
    kind: str
    default: object = REQUIRED


@dataclass(frozen=True)
class Op:
    name: str
    # transforms | splits | components | roofs | inserts | appearance | attributes | reports
    # | texturing
    family: str
    signatures: tuple[tuple[Param, ...], ...]
    doc: str
    example: str
    block: str | None = None  # None, or the kind of block: split | comp | offset | setback
    more: Param | None = None  # what any number of further arguments are (polygon's corners)

    def arities(self) -> list[tuple[int, int]]:
        """(least, most) argument counts of each signature."""
        out = []
        for sig in self.signatures:
            least = sum(1 for p in sig if p.default is REQUIRED)
            out.append((least, MANY if self.more else len(sig)))
        return out

    def param(self, sig: tuple[Param, ...], index: int) -> Param:
        """The parameter that argument ``index`` of a call matching ``sig`` fills."""
        return sig[index] if index < len(sig) or self.more is None else self.more

    def usage(self) -> str:
        tail = f", {self.more.name}" if self.more else ""
        return " or ".join(
            f"{self.name}({', '.join(p.name for p in sig)}{tail})" for sig in self.signatures
        )


def _sig(*params: Param) -> tuple[tuple[Param, ...], ...]:
    return (params,)


_MATRIX = tuple(Param(f"m{r}{c}", NUMBER) for r in range(3) for c in range(4))

OPERATIONS: dict[str, Op] = {
    op.name: op
    for op in [
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
            _sig(Param("x", NUMBER), Param("y", NUMBER), Param("z", NUMBER)),
            "Rotate about the scope origin, in degrees, x then y then z, in scope coordinates.",
            "r(0, 90, 0)",
        ),
        Op(
            "s",
            "transforms",
            _sig(Param("x", SIZE), Param("y", SIZE), Param("z", SIZE)),
            "Set the scope size; the geometry is scaled with it. `'f` is relative to the current "
            "size.",
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
            "convexify",
            "transforms",
            ((), (Param("maxLength", NUMBER),)),
            "Cut a 2D shape's polygons into convex parts (its comp(f) then gives each as a "
            "face), as CGA's convexify; cuts longer than `maxLength` metres are not made, so a "
            "part may stay concave.",
            "convexify() comp(f) { all: Part }",
        ),
        Op(
            "matrix",
            "transforms",
            (_MATRIX,),
            "Apply a 3x4 affine transform, given row by row, to the scope.",
            "matrix(1, 0, 0, 2, 0, 1, 0, 0, 0, 0, 1, 0)",
        ),
        # -- splits ------------------------------------------------------------------------
        Op(
            "split",
            "splits",
            _sig(Param("axis", AXIS), Param("adjustment", SPLIT_ADJUST, "noAdjust")),
            "Cut the scope along an axis into pieces of absolute (`3`), relative (`'0.25`) and "
            "floating (`~3`) sizes; `{ ... }*` repeats. Each piece keeps the slab's scope "
            "(`noAdjust`, the default), or with `adjust` (CGA's default) a scope fitted to the "
            "part of the geometry it holds.",
            "split(x) { 1: Edge | { ~2: Window }* | 1: Edge }",
            block="split",
        ),
        # -- components --------------------------------------------------------------------
        Op(
            "comp",
            "components",
            _sig(Param("kind", COMP_KIND)),
            "Split a shape into its faces (`f`), each a 2D shape with x along its bottom edge, "
            "y up and z out; into its edges (`e`), each a bare shape of zero height and depth "
            "with x along the edge and y the mean of its faces' normals (`eave`, `ridge`, `hip`, "
            "`valley`, `border`, `inside` select them too); or into its vertices (`v`), each a "
            "bare point with y its faces' mean normal.  Bare shapes make no terminals: give "
            "them a size and an `i()`.",
            "comp(f) { top: Roof | side: Facade }",
            block="comp",
        ),
        Op(
            "offset",
            "components",
            _sig(Param("distance", NUMBER)),
            "Inset a 2D face by a distance (a negative one grows it) into an inside and a border; "
            "a solid, each of its faces.",
            "offset(0.2) { inside: Glass | border: Frame }",
            block="offset",
        ),
        Op(
            "setback",
            "components",
            _sig(Param("distance", NUMBER)),
            "Set some edges of a 2D shape in by a distance, as CGA's setback: each selected "
            "edge's strip (`front`, `back`, `left`, `right`, `top`, `bottom`: by its outward "
            "normal in the scope's quadrants; `side`, `all`) is a piece, `remainder` the rest.",
            "setback(3) { front: Yard | remainder: Building }",
            block="setback",
        ),
        Op(
            "innerRectangle",
            "components",
            _sig(Param("alignment", INNER_ALIGNMENT)),
            "The largest rectangle inside a 2D shape (`shape`) and the rest (`remainder`), as "
            "CGA's innerRectangle: `scope`, its sides along the scope's axes (exact for outlines "
            "whose sides run along the scope, to 1/64 of it for others); `edge`, a side along "
            "one of the outline's edges (those longer than a quarter of their ring's longest), "
            "the scope kept.",
            "innerRectangle(scope) { shape: Building | remainder: Yard }",
            block="innerRectangle",
        ),
        Op(
            "footprint",
            "components",
            _sig(Param("kind", FOOTPRINT_KIND), Param("a", NUMBER, 0.4), Param("b", NUMBER, -1.0)),
            "Replace a 2D shape's outline by a building footprint filling its scope: `rect`, `L`, "
            "`U`, "
            "`T`, `cross` (wing widths `a`, `b` as fractions of the scope; `b` defaults to `a`), "
            "`circle` (`a` sides, at least 3 when given).",
            "footprint(L, 0.4, 0.5)",
        ),
        Op(
            "polygon",
            "components",
            _sig(*(Param(f"{a}{i}", NUMBER) for i in (1, 2, 3) for a in "xz")),
            "Replace a horizontal 2D shape (a lot, or a piece of one) by the polygon through the "
            "corners given as x, z pairs, in metres in the scope's frame (three corners or more, "
            "not crossing; either way round). The scope keeps its axes and becomes the "
            "polygon's bounding box. `bgr infer --kind city` writes footprints with it.",
            "polygon(0, 0, 12, 0, 12, 8, 5, 8, 5, 14, 0, 14)",
            more=Param("...", NUMBER),
        ),
        Op(
            "extrude",
            "components",
            (
                (Param("height", NUMBER),),
                (Param("direction", EXTRUDE_KIND), Param("height", NUMBER)),
            ),
            "Turn a 2D shape into a prism of the given height along its normal (a negative "
            "height extrudes against it), or along world y with `world.up`; a solid, each of "
            "its faces along its own normal. As in CGA, the "
            "new scope's y points along the extrusion, x keeps its direction as far as it "
            "can, and z completes a right-handed frame.",
            "extrude(12)",
        ),
        Op(
            "envelope",
            "components",
            tuple(
                (
                    Param("direction", EXTRUDE_KIND),
                    Param("maxHeight", NUMBER),
                    *(
                        Param(f"{side}{what}", NUMBER)
                        for side in sides
                        for what in ("BaseHeight", "Angle")
                    ),
                )
                for sides in (
                    ("front",),
                    ("front", "back"),
                    ("front", "back", "side"),
                    ("front", "back", "right", "left"),
                )
            ),
            "CGA's building envelope: the 2D shape erected to `maxHeight`, each side of its "
            "outline (front, back, right, left by its outward normal, as setback's; `side` both "
            "of the last two; missing ones as the one before) cut by a plane through the edge at "
            "its base height, rising inward at its angle from the horizontal (90: a plain wall).",
            "envelope(world.up, 30, 12, 45, 8, 60)",
        ),
        *(
            Op(
                name,
                "components",
                _sig(*(Param(side, NUMBER) for side in sides)),
                f"CGA's {name}: the strips of the given widths along the scope's "
                f"{', '.join(sides)} sides of a 2D shape (front: low z, or low y on a face; "
                "left: low x), joined and cut to its outline, are `shape`; the rest is "
                "`remainder`.",
                f"{name}({', '.join(['4'] * len(sides))}) {{ shape: Building | remainder: Yard }}",
                block="innerRectangle",
            )
            for name, sides in (
                ("shapeL", ("front", "left")),
                ("shapeU", ("front", "right", "left")),
                ("shapeO", ("front", "right", "back", "left")),
            )
        ),
        Op(
            "taper",
            "components",
            _sig(Param("height", NUMBER), Param("ratio", NUMBER)),
            "Extrude to a height while scaling the top by a ratio.",
            "taper(30, 0.6)",
        ),
        # -- roofs -------------------------------------------------------------------------
        Op(
            "roof",
            "roofs",
            _sig(
                Param("kind", ROOF_KIND),
                Param("pitch", NUMBER, 30.0),
                Param("overhang", NUMBER, 0.0),
            ),
            "Build a roof of the given kind on a 2D footprint: pitch in degrees, overhang in "
            "metres.",
            "roof(hip, 30, 0.5)",
        ),
        # -- inserts -----------------------------------------------------------------------
        Op(
            "i",
            "inserts",
            _sig(Param("geometry", GEOMETRY)),
            "Insert a primitive (cube, cylinder, sphere, quad, wedge) or a declared asset, fitted "
            "to "
            "the scope.",
            "i(cube)",
        ),
        Op(
            "trim",
            "inserts",
            _sig(),
            "Cut the shape's geometry by its trim planes now, as CGA's trim() (`i()` cuts what "
            "it inserts by itself); nothing happens while trimming is off or no plane crosses "
            "the shape, and a shape wholly cut away is gone.",
            "trim()",
        ),
        # -- appearance --------------------------------------------------------------------
        Op(
            "color",
            "appearance",
            (
                (Param("color", COLOR),),
                (Param("r", NUMBER), Param("g", NUMBER), Param("b", NUMBER)),
            ),
            'Set the colour of the shape and its descendants: a "#rrggbb" string '
            "or r, g, b in 0..1.",
            'color("#c8b89a")',
        ),
        Op(
            "material",
            "appearance",
            _sig(Param("name", STRING)),
            "Set a named material; the name reaches the output file.",
            'material("brick")',
        ),
        Op(
            "label",
            "appearance",
            _sig(Param("name", STRING)),
            "Set the semantic label written to outputs (default: the terminal rule's name).",
            'label("Window")',
        ),
        # -- attributes ----------------------------------------------------------------------
        Op(
            "set",
            "attributes",
            _sig(Param("attribute", ATTR_NAME), Param("value", VALUE)),
            "Set an attr of this file (or `alias.attr` of an imported one) for the shape and "
            "every shape derived from it, as CGA's "
            "set(): rules below read the new value, the rest of the lot the old one (attrs "
            "computed from it keep theirs). `set(trim.vertical, true)` turns CGA's trim planes "
            "on for the shape's subtree (`false` off).",
            "set(floors, floors - 1)",
        ),
        # -- reports -------------------------------------------------------------------------
        Op(
            "report",
            "reports",
            _sig(Param("key", STRING), Param("value", VALUE)),
            "Report a value (a number, a string or true/false) under a key, as CGA's report(): "
            "the shape is unchanged; each lot's reports, summed, counted and averaged per key, "
            "are in the derive result and in `bgr derive --reports FILE.json`.",
            'report("floor area", geometry.area())',
        ),
        Op(
            "print",
            "reports",
            _sig(Param("value", VALUE)),
            "Print a value (as str() writes it) on the console, as CGA's print(): `bgr derive` "
            "writes each lot's prints on standard error, in derivation order; the shape is "
            "unchanged.",
            'print("floors: " + floors)',
        ),
        # -- texturing (CGA's texturing operations; docs/language.md "Textures") -------------
        Op(
            "setupProjection",
            "texturing",
            _sig(
                Param("uvSet", NUMBER),
                Param("axes", PROJECTION_AXES),
                Param("w", TEX_SIZE),
                Param("h", TEX_SIZE),
                Param("uOffset", NUMBER, 0.0),
                Param("vOffset", NUMBER, 0.0),
                Param("uwFactor", NUMBER, 0.0),
            ),
            "Set up the texture projection of uv-set 0..9 on the scope (`scope.xy`, `scope.xz`, "
            "...) or the world (`world.xy`, ...) axes: a tile `w` by `h` metres (`~w` about w so "
            "that whole tiles span the scope, `'f` a fraction of it, negative mirrors), offsets "
            "in metres, `uwFactor` how much the third axis adds to u. The projection stays where "
            "it was set up: split pieces, faces and moved shapes keep it, so tiles line up across "
            "every cut.",
            "setupProjection(0, scope.xy, ~1.5, 1)",
        ),
        Op(
            "projectUV",
            "texturing",
            _sig(Param("uvSet", NUMBER)),
            "Give the shape the texture coordinates of uv-set `uvSet` from its projection.",
            "projectUV(0)",
        ),
        Op(
            "texture",
            "texturing",
            _sig(Param("path", STRING)),
            "Set the colour map (uv-set 0): a PNG or JPEG file, found like assets (the grammar's "
            "folder, the stdlib, --allow-path); its alpha channel is the opacity. "
            '`texture("")` removes it, so that an inserted asset shows its own texture.',
            'texture("bricks.png")',
        ),
        Op(
            "normalMap",
            "texturing",
            _sig(Param("path", STRING)),
            "Set the normal map (CGA's material.normalmap, uv-set 5): a PNG or JPEG file, found "
            "like texture().",
            'normalMap("bricks_normal.png")',
        ),
        Op(
            "tileUV",
            "texturing",
            _sig(Param("uvSet", NUMBER), Param("w", TEX_SIZE), Param("h", TEX_SIZE)),
            "Rescale the texture coordinates so that one tile is `w` by `h` metres (`~w`, `'f` "
            "and negative as in setupProjection; 0 leaves that direction as it is).",
            "tileUV(0, ~2, '0.5)",
        ),
        Op(
            "scaleUV",
            "texturing",
            _sig(Param("uvSet", NUMBER), Param("u", NUMBER), Param("v", NUMBER)),
            "Multiply the texture coordinates by `u` and `v`.",
            "scaleUV(0, 2, 2)",
        ),
        Op(
            "translateUV",
            "texturing",
            _sig(Param("uvSet", NUMBER), Param("u", NUMBER), Param("v", NUMBER)),
            "Add `u` and `v` to the texture coordinates (0.5 moves the texture half a tile).",
            "translateUV(0, 0.5, 0)",
        ),
        Op(
            "rotateUV",
            "texturing",
            _sig(Param("uvSet", NUMBER), Param("angle", NUMBER)),
            "Rotate the texture coordinates about u = v = 0 by `angle` degrees "
            "(counter-clockwise).",
            "rotateUV(0, 90)",
        ),
        Op(
            "normalizeUV",
            "texturing",
            _sig(
                Param("uvSet", NUMBER),
                Param("mode", NORMALIZE_MODE),
                Param("type", NORMALIZE_TYPE, "collectiveAllFaces"),
            ),
            "Map the texture coordinates of the shape's scope onto 0..1: `uv` both, `u` or `v` "
            "one, `uvUniform` both by one factor.",
            "normalizeUV(0, uv, collectiveAllFaces)",
        ),
        Op(
            "deleteUV",
            "texturing",
            _sig(Param("uvSet", NUMBER)),
            "Remove the texture coordinates of uv-set `uvSet` (its projection stays).",
            "deleteUV(0)",
        ),
    ]
}


@dataclass(frozen=True)
class Builtin:
    name: str
    least: int
    most: int | None  # None: any number
    usage: str
    doc: str


BUILTINS: dict[str, Builtin] = {
    b.name: b
    for b in [
        Builtin(
            "rand",
            0,
            2,
            "rand(a, b)",
            "a uniform draw from the shape's stream: rand() in [0, 1), "
            "rand(b) in [0, b), rand(a, b) in [a, b).",
        ),
        Builtin("randint", 2, 2, "randint(a, b)", "a whole number from a to b inclusive."),
        Builtin("floor", 1, 1, "floor(x)", "round down."),
        Builtin("ceil", 1, 1, "ceil(x)", "round up."),
        Builtin(
            "round", 1, 1, "round(x)", "round to the nearest whole number (halves away from zero)."
        ),
        Builtin("abs", 1, 1, "abs(x)", "absolute value."),
        Builtin("min", 2, None, "min(a, b, ...)", "the least of two or more numbers."),
        Builtin("max", 2, None, "max(a, b, ...)", "the greatest of two or more numbers."),
        Builtin("sqrt", 1, 1, "sqrt(x)", "square root."),
        Builtin("acos", 1, 1, "acos(x)", "inverse cosine, in degrees."),
        Builtin("asin", 1, 1, "asin(x)", "inverse sine, in degrees."),
        Builtin("atan", 1, 1, "atan(x)", "inverse tangent, in degrees."),
        Builtin("atan2", 2, 2, "atan2(y, x)", "the angle of the point (x, y), in degrees."),
        Builtin("exp", 1, 1, "exp(x)", "e to the power x."),
        Builtin("ln", 1, 1, "ln(x)", "natural logarithm."),
        Builtin("log10", 1, 1, "log10(x)", "logarithm to base 10."),
        Builtin("rint", 1, 1, "rint(x)", "the nearest whole number, halves to the even one."),
        Builtin("isinf", 1, 1, "isinf(x)", "true when x is infinite."),
        Builtin("isnan", 1, 1, "isnan(x)", "true when x is not a number."),
        Builtin(
            "p",
            1,
            1,
            "p(prob)",
            "true with probability prob (0..1), from the shape's random stream, as CGA's p().",
        ),
        Builtin(
            "float",
            1,
            1,
            "float(x)",
            'x as a number: a string that spells one ("1.5"), true 1, false 0; a string that '
            "spells none is an error (CGA gives NaN; bgr's numbers are finite).",
        ),
        Builtin(
            "bool",
            1,
            1,
            "bool(x)",
            'x as true or false: a number other than 0, the string "true" or "1".',
        ),
        Builtin("len", 1, 1, "len(s)", "the number of characters of the string s."),
        Builtin("count", 2, 2, "count(s, match)", "how many times match occurs in s."),
        Builtin(
            "find",
            3,
            3,
            "find(s, match, n)",
            "where the n-th (0-based) occurrence of match starts in s, or -1.",
        ),
        Builtin(
            "substring",
            3,
            3,
            "substring(s, start, end)",
            "the characters of s from start up to, not including, end.",
        ),
        Builtin("sin", 1, 1, "sin(deg)", "sine of an angle in degrees."),
        Builtin("cos", 1, 1, "cos(deg)", "cosine of an angle in degrees."),
        Builtin("tan", 1, 1, "tan(deg)", "tangent of an angle in degrees."),
        Builtin("clamp", 3, 3, "clamp(x, lo, hi)", "x limited to the range lo..hi."),
        Builtin(
            "str",
            1,
            1,
            "str(x)",
            'x as text, as CGA\'s str(): str(1.69) is "1.69", str(2) "2", str(true) "true" '
            "(numbers to 10 significant digits); a string joined with + to a number or a "
            'boolean converts it the same way ("Floor" + 2 is "Floor2").',
        ),
        Builtin(
            "geometry.isRectangular",
            0,
            1,
            "geometry.isRectangular(tolerance)",
            "true when the shape's outline (a 2D shape's, or an extruded prism's base) is one "
            "rectangle without holes, every corner within tolerance degrees of a right angle "
            "(default 1), as CGA's function of that name; false for other solids but cubes.",
        ),
        Builtin(
            "geometry.area",
            0,
            1,
            "geometry.area(selector)",
            "the sum of the areas of the faces of the shape's geometry, in square metres (a "
            "10 x 20 m lot: 200; that lot extruded 5 m: 700): all of them, or those a comp(f) "
            "selector written bare would take (`geometry.area(top)`: 200).",
        ),
        Builtin(
            "geometry.angle",
            1,
            1,
            "geometry.angle(kind)",
            "an angle of the shape's geometry in degrees, as CGA's: `maxSlope` the steepest of "
            "its faces against the world's horizontal plane (a lot: 0, a wall: 90), `zenith` "
            "90 minus that, `azimuth` the compass direction that steepest face looks to, "
            "clockwise from north (-z; east, +x, is 90).",
        ),
        *(
            Builtin(
                name,
                0,
                2,
                f"{name}(target, label)",
                f"CGA's occlusion query: true when the shape's geometry {what} the closed "
                "geometry of another shape of the same lot (`intra` or `all`, the default; "
                "`inter`, other lots, is not taken: false), or only of shapes that "
                "`label(label)` named; tested against the lot derived once with every query "
                "false (see language.md).",
            )
            for name, what in (
                ("inside", "lies wholly inside or on"),
                ("overlaps", "lies partly inside (or holds part of)"),
                ("touches", "overlaps or lies against"),
            )
        ),
        Builtin(
            "geometry.volume",
            0,
            0,
            "geometry.volume()",
            "the volume the shape's closed geometry encloses, in cubic metres; 0 for a 2D shape.",
        ),
        Builtin(
            "geometry.nVertices",
            0,
            0,
            "geometry.nVertices()",
            "the distinct corners of the shape's geometry (a box: 8).",
        ),
        Builtin(
            "geometry.nFaces",
            0,
            0,
            "geometry.nFaces()",
            "the faces of the shape's geometry, coplanar connected triangles counted as one "
            "polygon (a box: 6).",
        ),
        Builtin(
            "geometry.height",
            0,
            0,
            "geometry.height()",
            "the extent of the shape's geometry along the world's vertical, in metres.",
        ),
        Builtin("geometry.nEdges", 0, 0, "geometry.nEdges()", "the distinct edges (a box: 12)."),
        Builtin(
            "geometry.nHoles",
            0,
            0,
            "geometry.nHoles()",
            "the holes in the faces of the shape's geometry (a courtyard lot: 1).",
        ),
        Builtin(
            "geometry.boundaryLength",
            0,
            0,
            "geometry.boundaryLength()",
            "the length of the edges only one face has: a 2D shape's outline with its holes', "
            "0 for a closed solid.",
        ),
        Builtin(
            "geometry.isConcave",
            0,
            0,
            "geometry.isConcave()",
            "true when a face of the shape's geometry is concave or has a hole.",
        ),
        Builtin(
            "geometry.isPlanar",
            0,
            1,
            "geometry.isPlanar(tolerance)",
            "true when all the faces of the shape's geometry lie in one plane, within tolerance "
            "degrees (default 0).",
        ),
    ]
}

# Names the interpreter provides while deriving a shape (LANGUAGE.md section 8).
# functions whose argument is a bare word from a fixed set, not a value
WORD_ARGUMENTS: dict[str, tuple[str, ...]] = {
    "geometry.area": COMP_SELECTORS,
    "geometry.angle": ANGLE_KINDS,
    **{name: OCCLUSION_TARGETS for name in OCCLUSION},
}

BUILTIN_NAMES: dict[str, str] = {
    "scope.sx": "scope size along x",
    "scope.sy": "scope size along y",
    "scope.sz": "scope size along z",
    "scope.x": "scope origin x in the parent frame",
    "scope.y": "scope origin y",
    "scope.z": "scope origin z",
    "split.index": "0-based index of the piece in the enclosing split (global across repetitions)",
    "split.total": "number of pieces of the enclosing split",
    "comp.index": "0-based index of the face in the enclosing component split",
    "comp.total": "number of faces of the enclosing component split",
    "comp.left": (
        "the corner at the face's left edge, seen from outside: the angle the wall turns there in "
        "degrees (90 at a box's corners, -90 at an inner corner, 0 where the wall runs on or for "
        "a top or bottom face)"
    ),
    "comp.right": "the corner at the face's right edge, as comp.left",
    "comp.sel": (
        'the selector that took the face in the enclosing comp ("front", "side", "top"...; '
        '"face" for face(i)), as CGA\'s comp.sel'
    ),
    "depth": "derivation depth of the shape",
    # CGA writes its geometry functions without brackets too: `case geometry.area < 100`
    "geometry.area": "geometry.area(), written bare as CGA allows",
    "geometry.volume": "geometry.volume(), written bare",
    "geometry.nVertices": "geometry.nVertices(), written bare",
    "geometry.nFaces": "geometry.nFaces(), written bare",
    "geometry.height": "geometry.height(), written bare",
    "geometry.nEdges": "geometry.nEdges(), written bare",
    "geometry.nHoles": "geometry.nHoles(), written bare",
    "geometry.boundaryLength": "geometry.boundaryLength(), written bare",
    "geometry.isConcave": "geometry.isConcave(), written bare",
    "seed": "the global seed",
}

KEYWORDS = (
    "version",
    "import",
    "as",
    "attr",
    "const",
    "func",
    "start",
    "asset",
    "terminal",
    "site",
    "case",
    "else",
    "NIL",
    "true",
    "false",
    "and",
    "or",
    "not",
)
