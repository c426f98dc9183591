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

from .tree import Placement, Rule

DEFAULT_LOT = 20.0  # the interpreter's default lot is a 20 m square (LANGUAGE.md section 4)


@dataclass
class Terminal:
    """A component type as written: its rule name, asset name and file, colour, comment."""

    name: str
    asset: str
    path: str  # relative to the grammar
    color: str | None
    comment: str


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


def matrix(angle: float, offset: np.ndarray) -> n.Operation:
    """``matrix(...)``: a turn about the vertical by ``angle`` degrees and a translation, as the
    3x4 row-major matrix whose columns are the child's axes in the parent's frame."""
    a = np.radians(angle)
    return _matrix(float(np.cos(a)), float(np.sin(a)), [float(v) for v in offset[:3]])


def _matrix(c: float, s: float, offset: list[float]) -> n.Operation:
    """:func:`matrix` from the turn's cosine and sine and the offset, as Python floats."""
    cos, sin, minus_sin = _num(c, 9), _num(s, 9), _num(-s, 9)
    args = [cos, n.Number(0.0), sin, _num(offset[0], 6)]
    args += [n.Number(0.0), n.Number(1.0), n.Number(0.0), _num(offset[1], 6)]
    args += [minus_sin, n.Number(0.0), _num(c, 9), _num(offset[2], 6)]
    return n.Operation("matrix", args)


def _num(value: float, digits: int) -> n.Expr:
    """:func:`num` of a Python float."""
    value = round(value, digits)
    if value < 0:
        return n.Unary("-", n.Number(-value))
    return n.Number(value if value else 0.0)  # -0.0 prints as 0


def placement(p: Placement) -> n.Push:
    return placements([p])[0]


def placements(found: list[Placement]) -> list[n.Push]:
    """``[ matrix(...) s(...) Rule ]`` of each placement: the turns' sines and cosines of all
    at once (a city's axiom places every building: 100,000 of them is ordinary)."""
    if not found:
        return []
    a = np.radians(np.array([p.angle for p in found], dtype=np.float64))
    cos, sin = np.cos(a).tolist(), np.sin(a).tolist()
    offsets = np.array([p.offset[:3] for p in found], dtype=np.float64).reshape(-1, 3).tolist()
    out = []
    for p, c, s, offset in zip(found, cos, sin, offsets, strict=True):
        steps: list = [_matrix(c, s, offset)]
        if p.size is not None:
            steps.append(n.Operation("s", [num(v) for v in p.size]))
        steps.append(n.Successor(p.rule))
        out.append(n.Push(steps))
    return out


def rule(name: str, found: list[Placement]) -> n.Rule:
    return n.Rule(name, [], n.Sequence(placements(found) or [n.Nil()]))


def module(
    header: list[str],
    terminals: list[Terminal],
    rules: list[Rule],
    city: list[Placement],
    units: list[Unit],
    carried: list[tuple[Terminal, Placement]],
    site: n.Site | None = None,
) -> n.Module:
    """The whole grammar, laid out in groups with comments (see :func:`_laid_out`); ``site``
    first, where the input has one (its CRS, up axis and the offset of its coordinates)."""
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
    placed: list[tuple[list[str], n.Item]] = [] if site is None else [([], site)]
    groups: list[list[tuple[list[str], n.Item]]] = [
        placed,
        [([], n.Asset(t.asset, t.path)) for t in terminals + [c for c, _ in carried]],
        [
            (
                [
                    "# On the default lot the axiom rebuilds the input city; on any other lot",
                    "# (--lot W,D or a GeoJSON of footprints) it fills the lot with the city's",
                    "# buildings and groups, chosen as often as the city has them.",
                ],
                axiom,
            ),
            ([], rule("City", city + [p for _, p in carried])),
        ],
        _synthesis(units),
        [([f"# {r.comment}"] if r.comment else [], rule(r.name, r.children)) for r in rules],
        [([f"# {t.comment}"], _terminal_rule(t)) for t in terminals],
        [([f"# {t.comment}"], _terminal_rule(t)) for t, _ in carried],
    ]
    return _laid_out(header, groups)


def _terminal_rule(t: Terminal) -> n.Rule:
    steps: list = [n.Operation("i", [n.Name(t.asset)])]
    if t.color:
        steps.insert(0, n.Operation("color", [n.String(t.color)]))
    return n.Rule(t.name, [], n.Sequence(steps))


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
