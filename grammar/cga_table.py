"""CityEngine CGA's operations and functions beside bgr's: docs/cga.md, generated.

    python -m bgr.grammar.cga_table > docs/cga.md

:data:`CGA` lists what CGA's reference index names (operations, then functions and other
words), each with what bgr writes for it and a status: **same** (the same name and meaning),
**different** (another spelling, given), **partly** (some of its forms) or **not yet**.  Where
bgr has an operation or a function of the same name, its usage comes from the registry
(grammar/registry.py), so the table cannot drift from the language; a test keeps docs/cga.md
equal to this output and checks that every registry entry CGA also has is listed.
"""

from __future__ import annotations

from .registry import BUILTINS, OPERATIONS

SAME, DIFFERENT, PARTLY, NOT_YET = "same", "different", "partly", "not yet"

# (CGA name, status, what bgr writes where the registry cannot say it, a note)
CGA: list[tuple[str, str, str, str]] = [
    # ---- operations ------------------------------------------------------------------------
    ("alignScopeToAxes", SAME, "", ""),
    (
        "alignScopeToGeometry",
        SAME,
        "",
        "2D shapes, and solids by the planar faces comp(f) gives (not assets)",
    ),
    ("center", SAME, "", ""),
    ("cleanupGeometry", SAME, "", ""),
    ("color", SAME, "", ""),
    (
        "comp",
        PARTLY,
        "",
        "faces, edges and vertices (`f`, `e`, `v`) with their selectors, roof edges included, "
        "and comp(f)'s `=` (the faces as one shape); `fe`, `fv`, `g`, `m`, `h`, `=` in comp(e) "
        "and comp(v), street and object selectors not yet",
    ),
    ("convexify", SAME, "", ""),
    ("deleteHoles", PARTLY, "", "2D shapes and solids; an extrusion with a courtyard not yet"),
    ("deleteUV", SAME, "", ""),
    (
        "envelope",
        PARTLY,
        "",
        "the four forms by side; per-edge arrays and street edges (`streetWidth`) not yet",
    ),
    ("extrude", SAME, "", ""),
    ("i", SAME, "", 'a file path is declared first: `asset x = "x.obj"`, then `i(x)`'),
    (
        "innerRectangle",
        SAME,
        "",
        "`scope` and `edge` alignments; `innerRect` in older releases",
    ),
    ("insertAlongUV", NOT_YET, "", ""),
    ("label", SAME, "", ""),
    ("mirror", SAME, "", ""),
    ("mirrorScope", NOT_YET, "", ""),
    ("NIL", SAME, "NIL", ""),
    ("normalizeUV", SAME, "", ""),
    ("offset", DIFFERENT, "", "a positive distance shrinks (CGA's negative one)"),
    (
        "primitiveCube",
        DIFFERENT,
        "i(cube)",
        "also `cylinder`, `sphere`, `quad`, `wedge`; import-cga gives `primitiveCylinder(sides, "
        "radius, height)` its 2r x height x 2r scope in the xz centre, as CGA's",
    ),
    ("print", SAME, "", "on standard error, each lot's in derivation order"),
    ("projectUV", SAME, "", ""),
    ("r", SAME, "", "about the scope's origin, or its centre: `r(scopeCenter, x, y, z)`"),
    ("report", SAME, "", "each lot's values summed up per key; `bgr derive --reports`"),
    ("resetMaterial", SAME, "", "the colour a shape never coloured has (`#cccccc`)"),
    ("reverseNormals", SAME, "", ""),
    ("roofGable", DIFFERENT, "roof(gable, pitch, overhang)", ""),
    ("roofHip", DIFFERENT, "roof(hip, pitch, overhang)", ""),
    ("roofPyramid", DIFFERENT, "roof(pyramid, pitch, overhang)", ""),
    ("roofShed", DIFFERENT, "roof(shed, pitch, overhang)", ""),
    ("rotate", SAME, "", ""),
    ("rotateScope", SAME, "", ""),
    ("rotateUV", SAME, "", ""),
    ("s", SAME, "", ""),
    ("scaleUV", SAME, "", ""),
    ("scatter", NOT_YET, "", ""),
    (
        "set",
        PARTLY,
        "",
        "attrs; `trim.*`; `material.opacity`, `.metallic`, `.roughness`, `.specular.r/g/b`, "
        "`.shininess`, `.reflectivity`, `.color.r/g/b`; `set(material.name, v)` is "
        "`material(v)`; the other shape attributes (`material.bumpValue`, `pivot.*`...) not yet",
    ),  # fmt: skip
    (
        "setback",
        PARTLY,
        "",
        "one distance, the scope's edge selectors, side, all and remainder; a distance per "
        "edge from `comp(fe) { front = 5 | all = 2 }` (import-cga writes it as "
        "`setbackPerEdge` of comp.sel), `street.`/`object.` selectors read as the scope's; "
        "arrays and uv selectors not yet",
    ),
    ("setbackPerEdge", SAME, "", ""),
    ("setNormals", NOT_YET, "", ""),
    ("setPivot", NOT_YET, "", ""),
    ("setupProjection", SAME, "", ""),
    ("shapeL", SAME, "", "`footprint(L, a, b)` makes an L of wing fractions instead"),
    ("shapeO", SAME, "", ""),
    ("shapeU", SAME, "", ""),
    ("softenNormals", NOT_YET, "", ""),
    (
        "split",
        PARTLY,
        "",
        "absolute, `'` relative and `~` floating sizes, `{ ... }*` repeats, `adjust` and "
        "`noAdjust`: bgr's default is `noAdjust` (import-cga writes CGA's default, `adjust`); "
        "`unitSpace`/`uvSpace` not yet",
    ),
    ("splitArea", NOT_YET, "", ""),
    ("t", SAME, "", ""),
    ("taper", SAME, "", ""),
    ("texture", SAME, "", ""),
    ("tileUV", SAME, "", ""),
    ("translate", SAME, "", ""),
    ("translateUV", SAME, "", ""),
    (
        "trim",
        SAME,
        "set(trim.vertical, true)",
        "vertical and horizontal trim planes from comp(f) cut what i() inserts and what the "
        "trim() operation cuts, once turned on (import-cga turns vertical ones on)",
    ),
    # ---- functions -------------------------------------------------------------------------
    ("abs", SAME, "", ""),
    ("acos", SAME, "", ""),
    ("asin", SAME, "", ""),
    ("atan", SAME, "", ""),
    ("atan2", SAME, "", ""),
    ("bool", SAME, "", ""),
    ("ceil", SAME, "", ""),
    ("cos", SAME, "", ""),
    ("count", SAME, "", ""),
    ("exp", SAME, "", ""),
    ("fileExists", NOT_YET, "", ""),
    ("find", SAME, "", ""),
    ("float", SAME, "", ""),
    ("floor", SAME, "", ""),
    ("geometry.angle", SAME, "", "maxSlope, azimuth and zenith; north is -z, as in CityEngine"),
    ("geometry.area", SAME, "", "with or without brackets; the comp(f) face selectors"),
    ("geometry.boundaryLength", SAME, "", "with or without brackets"),
    ("geometry.height", SAME, "", "with or without brackets"),
    ("geometry.isConcave", SAME, "", "with or without brackets"),
    ("geometry.isPlanar", SAME, "", ""),
    ("geometry.isRectangular", SAME, "", ""),
    ("geometry.nEdges", SAME, "", "with or without brackets"),
    ("geometry.nFaces", SAME, "", "with or without brackets"),
    ("geometry.nHoles", SAME, "", "with or without brackets"),
    ("geometry.nVertices", SAME, "", "with or without brackets"),
    ("geometry.volume", SAME, "", "with or without brackets"),
    ("inside", SAME, "", ""),
    ("isinf", SAME, "", ""),
    ("isnan", SAME, "", ""),
    ("len", SAME, "", ""),
    ("listAdd", SAME, "", ""),
    ("listCount", SAME, "", ""),
    ("listFirst", SAME, "", ""),
    ("listIndex", SAME, "", ""),
    ("listItem", SAME, "", ""),
    ("listLast", SAME, "", ""),
    ("listRandom", SAME, "", ""),
    ("listRange", SAME, "", ""),
    ("listSize", SAME, "", ""),
    ("listTerminate", SAME, "", ""),
    ("ln", SAME, "", ""),
    ("log10", SAME, "", ""),
    ("max", SAME, "", ""),
    ("min", SAME, "", ""),
    ("overlaps", SAME, "", ""),
    ("p", SAME, "", "or a stochastic rule: `30%: A | else: B`"),
    ("pow", DIFFERENT, "a ** b", ""),
    ("rand", SAME, "", ""),
    ("rint", SAME, "", "halves to the even number; `round(x)` rounds them away from zero"),
    ("sin", SAME, "", ""),
    (
        "splitString",
        SAME,
        "",
        "arrays: `[1, 2, 3]`, `a[i]`, `size(a)`, `index(a, v)`; two dimensions not yet",
    ),
    ("size", SAME, "", ""),
    ("index", SAME, "", ""),
    ("sqrt", SAME, "", ""),
    ("str", SAME, "", "and `+` joining a string with a number"),
    ("substring", SAME, "", ""),
    ("tan", SAME, "", ""),
    ("touches", SAME, "", ""),
    # ---- other words -----------------------------------------------------------------------
    (
        "@Range, @Enum, @Group, ... (annotations)",
        SAME,
        "@Range(min = 1, max = 20)",
        "metadata, checked; `bgr.attr_metadata`",
    ),  # fmt: skip
    ("attr", SAME, "attr name = value", ""),
    ("case / else", DIFFERENT, "case c: A | else: B", "branches separated by `|`"),
    ("const", SAME, "const name = value", ""),
    (
        "import",
        DIFFERENT,
        'import "file.bgr" as name',
        "then `name.Rule`; a binding `(attr = v)` is `set(name.attr, v)`, an attr of the same "
        "name in both files propagates as CGA's (import-cga); "
        "`name.Rule --> ...` overrides the imported rule, as CGA's",
    ),
    ("scope.sx, scope.sy, scope.sz", SAME, "scope.sx, scope.sy, scope.sz", ""),
    ("scope.tx, scope.ty, scope.tz", DIFFERENT, "scope.x, scope.y, scope.z", ""),
    (
        "split.index, split.total, comp.index, comp.total, comp.sel",
        SAME,
        "split.index",
        "and the others",
    ),
    ("@StartRule", DIFFERENT, "start Name", "or the first rule; the annotation is kept too"),
    (
        "style",
        DIFFERENT,
        'import "file.bgr" as base',
        "import-cga writes each style as a grammar that sets the attrs it redefines "
        "(`set(base.attr, v)`), overrides the rules it redefines (`base.Rule --> ...`) and "
        "runs the file's start rule",
    ),
]
# CGA's operations (the first part of the list), and those its reference has beyond the
# index above: a call of any other name in a CGA file is a rule's (bgr import-cga)
OPERATION_NAMES = frozenset(
    [name for name, *_ in CGA[: [e[0] for e in CGA].index("abs")]]
    + [
        "alignScopeToGeometryBBox",
        "copyUV",
        "deleteTags",
        "inline",
        "insertAlongUV",
        "intersect",
        "modify",
        "mirrorScope",
        "primitiveCone",
        "primitiveDisk",
        "primitiveTorus",
        "rectify",
        "reduceGeometry",
        "resetGeometry",
        "roofRidge",
        "roofRamp",
        "scatter",
        "setbackPerEdge",
        "setbackToArea",
        "setNormals",
        "setPivot",
        "setTagsFromEdgeAttrs",
        "shapeL",
        "shapeO",
        "shapeU",
        "softenNormals",
        "splitAndSetbackPerimeter",
        "splitArea",
        "subtract",
        "tag",
        "texture3D",
        "tileUV3D",
        "translate",
        "rotate",
        "union",
        "deleteHoles",
        "alignScopeToAxes3D",
        "setMaterial",
    ]
)

# registry entries CGA has no word for: bgr's own
BGR_ONLY = {"matrix", "footprint", "polygon", "normalMap", "material", "roof", "clamp",
            "randint", "round"}  # fmt: skip


def usage(name: str) -> str:
    """bgr's usage of a name the registry knows ('' when it does not)."""
    if name in OPERATIONS:
        return OPERATIONS[name].usage()
    if name in BUILTINS:
        return BUILTINS[name].usage
    return ""


def table() -> str:
    """docs/cga.md."""
    counts = {s: sum(1 for _, status, _, _ in CGA if status == s) for s in (SAME, DIFFERENT,
              PARTLY, NOT_YET)}  # fmt: skip
    lines = [
        "# CGA and bgr",
        "",
        "<!-- generated by `python -m bgr.grammar.cga_table > docs/cga.md`; edit "
        "grammar/cga_table.py -->",
        "",
        "CityEngine CGA's operations, functions and other words (its reference index) with "
        "what bgr writes for each. **same**: the same name and meaning; **different**: "
        "another spelling; **partly**: some of its forms; **not yet**. Where bgr has the "
        "same name, its usage comes from bgr's operation registry. The semantics of each "
        "are in [language.md](language.md); section 14 there is the short version. "
        "`bgr import-cga` translates a CGA file with these equivalents and reports each "
        "*not yet* it meets, at its line and column, leaving it out "
        "([cli.md](cli.md#bgr-import-cga)).",
        "",
        f"{counts[SAME]} same, {counts[DIFFERENT]} different, {counts[PARTLY]} partly, "
        f"{counts[NOT_YET]} not yet, of {len(CGA)}.",
        "",
        "| CGA | status | bgr | note |",
        "|---|---|---|---|",
    ]
    for name, status, written, note in CGA:
        bgr = (written or usage(name)).replace("|", "\\|")  # a cell's | would end it
        note = note.replace("|", "\\|")
        lines.append(
            f"| `{name}` | {status} | {f'`{bgr}`' if bgr else ''} | {note} |"
            if "(" not in name and "," not in name and "/" not in name
            else f"| {name} | {status} | {f'`{bgr}`' if bgr else ''} | {note} |"
        )
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    print(table(), end="")
