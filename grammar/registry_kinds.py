"""The vocabulary of operation signatures: argument kinds, the bare words each kind takes, and
the :class:`Param` and :class:`Op` records that the operation families declare.

Apart from :mod:`registry` so that the family modules, which :mod:`registry` gathers, can use it
without importing the registry back; :mod:`registry` re-exports all of it.
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
TRANSFORM_MODE = "mode"  # abs | rel (rotate, translate)
# a number evaluated once per edge, the edge as the current shape (setbackPerEdge)
PER_EDGE = "distance per edge"
ROTATION_PIVOT = "pivot"  # scopeOrigin | scopeCenter (r)
COORD_SYSTEM = "coordinate system"  # scope | pivot | object | world (rotate, translate)
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
TRANSFORM_MODES = ("abs", "rel")
ROTATION_PIVOTS = ("scopeOrigin", "scopeCenter")
COORD_SYSTEMS = ("scope", "pivot", "object", "world")
# CGA's shape attributes set() may change besides a file's attrs: whether vertical and
# horizontal trim planes cut (operations/trims.py), and the material's opacity, metallic,
# roughness, specular colour and reflectivity (0..1) and shininess (0..128:
# interpreter/surfaces.py), and one channel of the shape's colour (0..1, as color()'s)
SHAPE_ATTRIBUTES = (
    "trim.vertical",
    "trim.horizontal",
    "material.opacity",
    "material.metallic",
    "material.roughness",
    "material.specular.r",
    "material.specular.g",
    "material.specular.b",
    "material.shininess",
    "material.reflectivity",
    "material.color.r",
    "material.color.g",
    "material.color.b",
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
