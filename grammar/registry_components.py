"""The split and component operations of the registry: ``split`` and what cuts a shape into
pieces or remakes its outline or volume (``comp``, ``offset``, ``setback``, ``innerRectangle``,
``footprint``, ``polygon``, ``extrude``, ``envelope``, ``shapeL/U/O``, ``taper``).
:mod:`registry` gathers them into ``OPERATIONS`` in the order given here.
"""

from __future__ import annotations

from .registry_kinds import (
    AXIS,
    COMP_KIND,
    EXTRUDE_KIND,
    FOOTPRINT_KIND,
    INNER_ALIGNMENT,
    NUMBER,
    PER_EDGE,
    SPLIT_ADJUST,
    Op,
    Param,
    _sig,
)

SPLITS_AND_COMPONENTS: list[Op] = [
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
        "setbackPerEdge",
        "components",
        _sig(Param("distance", PER_EDGE)),
        "setback with a distance for each edge, as CGA's: `distance` is evaluated once per "
        "edge of the outline with the edge as the current shape (its `scope.sx` the edge's "
        "length, `comp.sel` its selector word, `comp.index` its number round the outline); "
        "the selectors are setback's.",
        'setbackPerEdge(comp.sel == "front" ? 5 : 2) { all: Yard | remainder: Building }',
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
]
