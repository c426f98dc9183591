"""The inferred city as a .bgr syntax tree (paper, section V.C), printed by the one formatter.

Terminals are the component types, each a named rule that inserts its representative's mesh (an
asset beside the grammar) with a comment giving its instance count and size; non-terminals are
the building kinds and the neighbourhood groups; the axiom rebuilds the city on the default lot
and, on any other lot, fills it with the city's buildings and groups (synthesis, Figure 9).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bgr.grammar import nodes as n

from .houses import HouseFit
from .prisms import PrismFit
from .tree import Placement, Rule

# the faces of an extruded footprint that comp(f) keeps, as terminals named after CityGML's
# WallSurface, RoofSurface and GroundSurface
SURFACES = {"side": "Wall", "top": "Roof", "bottom": "Ground"}
DEFAULT_LOT = 20.0  # the interpreter's default lot is a 20 m square (LANGUAGE.md section 4)


@dataclass
class Terminal:
    """A component type as written: its rule name, asset name and file, colour, comment."""

    name: str
    asset: str
    path: str  # relative to the grammar
    color: str | None
    comment: str
    prism: PrismFit | None = None  # written as polygon() extrude(), with no asset
    house: HouseFit | None = None  # written as polygon() extrude() comp(f) { top: roof() }

    @property
    def operations(self) -> bool:
        """Whether the type is written as the operations that make it (no asset)."""
        return self.prism is not None or self.house is not None


@dataclass
class Unit:
    """Something synthesis can put on a lot: a building kind or a group, its width along its
    frame's x and the corner of its extent in that frame."""

    rule: str
    uses: int
    low: np.ndarray  # (3,) min corner of its boxes in its own frame
    high: np.ndarray


def num(x: float, digits: int = 6) -> n.Expr:
    """A number rounded for print (micrometres for lengths), negatives as unary minus, so that
    the formatter's text parses back to the same tree."""
    value = round(float(x), digits)
    if value == 0:
        value = 0.0
    if value < 0:
        return n.Unary("-", n.Number(-value))
    return n.Number(value)


def _num(value: float, digits: int) -> n.Expr:
    """:func:`num` of a Python float."""
    value = round(value, digits)
    if value < 0:
        return n.Unary("-", n.Number(-value))
    return n.Number(value if value else 0.0)  # -0.0 prints as 0


def placement(p: Placement) -> n.Push:
    return placements([p])[0]


@dataclass(frozen=True)
class Style:
    """How placements are written: lengths to ``digits`` decimals (millimetres for the default
    1 cm tolerance), and ``sizeless`` the rules that make their own size (a polygon(), or at
    level 0 a mesh inserted at its own size), whose placements carry no ``s()``."""

    digits: int = 6
    sizeless: frozenset[str] = frozenset()
    # decimals of the turns' degrees (None: one more than the lengths', as at level 0)
    angle_digits: int | None = None


def placements(found: list[Placement], style: Style = Style()) -> list[n.Push]:
    """``[ t(x, y, z) r(0, a, 0) s(...) Rule ]`` of each placement (a move or a turn left out
    where it is none, the size where the rule makes its own): the numbers of all at once (a
    city's axiom places every building: 100,000 is ordinary)."""
    if not found:
        return []
    digits = style.digits
    turns = digits + 1 if style.angle_digits is None else style.angle_digits
    angles = np.array([p.angle for p in found], dtype=np.float64)
    angles = np.round((angles + 180.0) % 360.0 - 180.0, turns)  # in [-180, 180)
    offsets = np.round(np.array([p.offset[:3] for p in found], dtype=np.float64), digits)
    out = []
    for p, angle, offset in zip(
        found, angles.tolist(), offsets.reshape(-1, 3).tolist(), strict=True
    ):
        steps: list = []
        if any(offset):
            steps.append(n.Operation("t", [_num(v, digits) for v in offset]))
        if angle:
            steps.append(n.Operation("r", [n.Number(0.0), _num(angle, turns), n.Number(0.0)]))
        if p.size is not None and p.rule not in style.sizeless:
            steps.append(n.Operation("s", [num(v, digits) for v in p.size]))
        steps.append(n.Successor(p.rule))
        out.append(n.Push(steps))
    return out


def rule(name: str, found: list[Placement], style: Style = Style()) -> n.Rule:
    return n.Rule(name, [], n.Sequence(placements(found, style) or [n.Nil()]))


def module(
    header: list[str],
    terminals: list[Terminal],
    rules: list[Rule],
    city: list[Placement],
    units: list[Unit],
    carried: list[tuple[Terminal, Placement]],
    site: n.Site | None = None,
    *,
    exact: bool = False,
    digits: int = 6,
) -> n.Module:
    """The whole grammar, laid out in groups with comments (see :func:`_laid_out`); ``site``
    first, where the input has one (its CRS, up axis and the offset of its coordinates).
    ``exact`` (level 0): every instance of a type has its size, so a mesh is inserted at its
    own size (``s(0, 0, 0)``) and no placement says it again."""
    axiom = n.Rule(
        "Lot",
        [],
        n.Conditional(
            [
                n.Case(
                    n.Binary(
                        "and",
                        n.Binary("==", n.Name("scope.sx"), n.Number(DEFAULT_LOT)),
                        n.Binary("==", n.Name("scope.sz"), n.Number(DEFAULT_LOT)),
                    ),
                    n.Sequence([n.Successor("City")]),
                ),
                n.Case(None, n.Sequence([n.Successor("Synthesis")])),
            ]
        ),
    )
    own = terminals + [c for c, _ in carried]
    # a lossy level's turns as coarse as its lengths: a tenth of a degree moves a point 20 m
    # off by 1.7 cm, under what its decimetres already move it
    style = Style(
        digits,
        frozenset(t.name for t in own if exact or t.operations),
        None if exact else digits,
    )
    placed: list[tuple[list[str], n.Item]] = [] if site is None else [([], site)]
    if any(t.house is not None for t in terminals) or any(
        _split_faces(t.prism) for t in terminals if t.prism is not None
    ):
        placed.append(([], n.TerminalDecl(list(SURFACES.values()))))
    groups: list[list[tuple[list[str], n.Item]]] = [
        placed,
        [
            ([], n.Asset(t.asset, t.path))
            for t in terminals + [c for c, _ in carried]
            if not t.operations
        ],
        [
            (
                [
                    "# On the default lot the axiom rebuilds the input city; on any other lot",
                    "# (--lot W,D or a GeoJSON of footprints) it fills the lot with the city's",
                    "# buildings and groups, chosen as often as the city has them.",
                ],
                axiom,
            ),
            ([], rule("City", city + [p for _, p in carried], style)),
        ],
        _synthesis(units),
        [([f"# {r.comment}"] if r.comment else [], rule(r.name, r.children, style)) for r in rules],
        [
            ([f"# {t.comment}"] if t.comment else [], _terminal_rule(t, exact, digits))
            for t in terminals
        ],
        shared_extrusions(terminals),
        [([f"# {t.comment}"], _terminal_rule(t, exact, digits)) for t, _ in carried],
    ]
    return _laid_out(header, groups)


def _split_faces(prism: PrismFit) -> bool:
    """Whether a prism is written with comp(f): it lacks a cap, or its parts differ in colour."""
    parts = ["side"] + [p for p, has in (("bottom", prism.bottom), ("top", prism.top)) if has]
    return len(parts) < 3 or len({prism.colors.get(p) for p in parts}) > 1


def _terminal_rule(t: Terminal, own_size: bool = False, digits: int = 6) -> n.Rule:
    """``i(asset)`` (at the asset's own size where ``own_size``: ``s(0, 0, 0)`` first, as in
    CGA), or a footprint's ``polygon() extrude()``; its colour first where it has one."""
    if t.prism is not None:
        return n.Rule(t.name, [], n.Sequence(_prism_steps(t.prism, digits)))
    if t.house is not None:
        return n.Rule(t.name, [], n.Sequence(_house_steps(t.house, digits)))
    steps: list = [n.Operation("i", [n.Name(t.asset)])]
    if own_size:
        steps.insert(0, n.Operation("s", [n.Number(0.0)] * 3))
    if t.color:
        steps.insert(0, n.Operation("color", [n.String(t.color)]))
    return n.Rule(t.name, [], n.Sequence(steps))


def _prism_steps(prism: PrismFit, digits: int) -> list:
    """``polygon(...) extrude(h)``, with ``comp(f) { side: Wall | top: Roof }`` keeping only
    the faces the component has (named as CityGML names its surfaces), and its colours (one
    a part)."""
    corners = [num(c, digits) for corner in prism.ring for c in corner]
    height = num(prism.height, digits)
    steps: list = [n.Operation("polygon", corners), n.Operation("extrude", [height])]
    colors = prism.colors
    parts = _parts(prism)
    if not _split_faces(prism):  # the whole prism, in one colour or none
        if colors:
            steps.insert(0, n.Operation("color", [n.String(colors["side"])]))
        return steps
    if not any(colors.get(part) for part in parts):  # the rule all such prisms share
        return [steps[0], n.Successor(_shared_name(parts), [height])]
    entries = []
    for part in parts:
        paint = colors.get(part)
        body: list = [n.Successor(SURFACES[part])]
        if paint:
            body.insert(0, n.Operation("color", [n.String(paint)]))
        entries.append(n.Entry("abs", n.Name(part), n.Sequence(body)))
    steps.append(n.Operation("comp", [n.Name("f")], n.Block(entries)))
    return steps


def _house_steps(house: HouseFit, digits: int) -> list:
    """``polygon(...) extrude(h) comp(f) { top: roof(kind, pitch, overhang) Roof | side: Wall
    | bottom: Ground }``, the floor where the building has one, each part in its colour."""
    corners = [num(c, digits) for corner in house.ring for c in corner]
    roof_args: list = [n.Name(house.kind), num(house.pitch, 3)]
    if house.overhang > 0:
        roof_args.append(num(house.overhang, digits))
    parts = [("top", "roof", [n.Operation("roof", roof_args)]), ("side", "side", [])]
    if house.bottom:
        parts.append(("bottom", "bottom", []))
    entries = []
    for face, part, steps in parts:
        paint = house.colors.get(part)
        body: list = steps + ([n.Operation("color", [n.String(paint)])] if paint else [])
        body.append(n.Successor(SURFACES[face]))
        entries.append(n.Entry("abs", n.Name(face), n.Sequence(body)))
    return [
        n.Operation("polygon", corners),
        n.Operation("extrude", [num(house.height, digits)]),
        n.Operation("comp", [n.Name("f")], n.Block(entries)),
    ]


def _parts(prism: PrismFit) -> list[str]:
    """The faces of an extruded footprint a component has: its walls, and its floor and cap
    where it has them."""
    return ["side"] + [p for p, has in (("bottom", prism.bottom), ("top", prism.top)) if has]


def _shared_name(parts: list[str]) -> str:
    """The rule that extrudes and keeps these faces: ``WallsAndRoof``, ``WallsAndGround``,
    ``WallsOnly``."""
    kept = [SURFACES[p] for p in parts if p != "side"]
    return "WallsAnd" + "And".join(kept) if kept else "WallsOnly"


def shared_extrusions(terminals: list[Terminal]) -> list[tuple[list[str], n.Item]]:
    """The rules the uncoloured prisms that lack a face share, ``WallsAndRoof(h) --> extrude(h)
    comp(f) { side: Wall | top: Roof }`` (one place to change how every such block is made,
    and ~40 bytes a block fewer), one for each set of faces used."""
    used: dict[str, list[str]] = {}
    for t in terminals:
        prism = t.prism
        if prism is None or not _split_faces(prism):
            continue
        parts = _parts(prism)
        if not any(prism.colors.get(part) for part in parts):
            used.setdefault(_shared_name(parts), parts)
    out: list[tuple[list[str], n.Item]] = []
    for name, parts in sorted(used.items()):
        entries = [
            n.Entry("abs", n.Name(part), n.Sequence([n.Successor(SURFACES[part])]))
            for part in parts
        ]
        body = [
            n.Operation("extrude", [n.Name("h")]),
            n.Operation("comp", [n.Name("f")], n.Block(entries)),
        ]
        kept = " and ".join(SURFACES[p] for p in parts)
        note = f"# a footprint extruded h metres, keeping its {kept}"
        out.append(([note], n.Rule(name, ["h"], n.Sequence(body))))
    return out


def _synthesis(units: list[Unit]) -> list[tuple[list[str], n.Item]]:
    """``Synthesis --> split(x) { ~w: Plot }*`` along the lot's front edge, and ``Plot`` a
    stochastic choice among the units, weighted by how often the city uses each, every unit put
    with the corner of its extent at the plot's corner."""
    if not units:
        return [([], n.Rule("Synthesis", [], n.Sequence([n.Nil()])))]
    uses = np.array([u.uses for u in units], dtype=float)
    widths = np.array([u.high[0] - u.low[0] for u in units])
    width = float(np.average(widths, weights=uses)) + 2.0  # a 2 m gap between neighbours
    split = n.Operation(
        "split",
        [n.Name("x")],
        n.Block(
            [n.Entry("float", num(max(width, 1.0), 3), n.Sequence([n.Successor("Plot")]))],
            repeat=True,
        ),
    )
    choices = []
    shares = uses / uses.sum() * 100
    for i, u in enumerate(units):
        move = n.Operation("t", [num(1.0 - u.low[0]), num(-u.low[1]), num(1.0 - u.low[2])])
        body = n.Sequence([n.Push([move, n.Successor(u.rule)])])
        last = i == len(units) - 1
        choices.append(n.Choice(None if last else num(shares[i], 2), body))
    comment = [
        "# Synthesis: plots along the lot's first edge, each given one of the city's buildings",
        "# or groups (percentages: how often the city has them).",
    ]
    plot = n.Rule("Plot", [], n.Stochastic(choices) if len(choices) > 1 else choices[0].body)
    return [(comment, n.Rule("Synthesis", [], n.Sequence([split]))), ([], plot)]


def _laid_out(header: list[str], groups: list[list[tuple[list[str], n.Item]]]) -> n.Module:
    """A module whose layout the formatter keeps: the header comment, then the groups of items
    with a blank line between groups, each item after its own comment lines (positions and a
    stand-in source tell the formatter where lines are)."""
    items, comments, lines = [], [], []
    for text in header:
        lines.append(text)
        comments.append(n.Comment(text, len(lines), 1, True))
    for group in groups:
        if not group:
            continue
        lines.append("")
        for notes, item in group:
            for text in notes:
                lines.append(text)
                comments.append(n.Comment(text, len(lines), 1, True))
            lines.append("x")
            item.pos = n.Pos(len(lines), 1, len(lines), 2)
            items.append(item)
    return n.Module(items, comments=comments, source="\n".join(lines) + "\n")
