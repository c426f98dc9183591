"""The built-in functions of expressions (``rand``, ``min``, ``geometry.area`` ...), the bare
words some of them take, and the names the interpreter provides while deriving a shape
(``scope.sx``, ``split.index`` ...).  :mod:`registry` re-exports them with the operations.
"""

from __future__ import annotations

from dataclasses import dataclass

from .registry_kinds import (
    ANGLE_KINDS,
    COMP_SELECTORS,
    OCCLUSION,
    OCCLUSION_TARGETS,
)


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
        # CGA's arrays: [1, 2, 3], a[i]
        Builtin(
            "size", 1, 1, "size(a)", "the number of items of an array (of a string: its length)."
        ),
        Builtin("index", 2, 2, "index(a, v)", "where v first stands in the array a, or -1."),
        Builtin(
            "splitString",
            2,
            2,
            "splitString(s, separator)",
            "the pieces of s between the separators, as an array of strings.",
        ),
        # CGA's string lists: items each followed by a semicolon, "a;b;c;"
        Builtin("listSize", 1, 1, "listSize(list)", "the number of items of a string list."),
        Builtin("listItem", 2, 2, "listItem(list, i)", 'the i-th item (0-based); "" past the end.'),
        Builtin("listIndex", 2, 2, "listIndex(list, item)", "where item first stands, or -1."),
        Builtin("listCount", 2, 2, "listCount(list, item)", "how many times item stands in it."),
        Builtin("listFirst", 1, 1, "listFirst(list)", "the first item."),
        Builtin("listLast", 1, 1, "listLast(list)", "the last item."),
        Builtin("listAdd", 2, 2, "listAdd(list, item)", "the list with item added at its end."),
        Builtin(
            "listRange",
            3,
            3,
            "listRange(list, start, end)",
            "the items from start up to, not including, end, as a list.",
        ),
        Builtin("listTerminate", 1, 1, "listTerminate(list)", "the list with its last semicolon."),
        Builtin(
            "listRandom",
            1,
            1,
            "listRandom(list)",
            "an item drawn at random from the shape's stream.",
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
                "geometry of another shape: of the same lot (`intra`), of the lots within "
                "1 m of it (`inter`) or both (`all`, the default); or only of shapes that "
                "`label(label)` named; tested against the lots derived once with every query "
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
