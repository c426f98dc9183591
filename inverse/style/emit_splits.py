"""Equations 8 and 9 (section 5.2.3) as ``.bgr`` rules, written once per number m of insertable
pieces, the sizes and the pieces being parameters (the style sheet itself is emit.py's):

    SplitX2(a0, a1, a2, b0, b1, p, c1, c2, d0, d1, d2, s0, s1, s2, i0, i1, w) -->
        SplitX2Fit(.., floor(scope.sx / p))                 x whole patterns of length p
    SplitX2Fit(.., x) --> SplitX2Y(.., x, (scope.sx - x * p >= c1 ? 1 : 0) + (.. >= c2 ? 1 : 0))
    SplitX2Y(.., x, y) --> case (a tie, y = 0): .. | case (x = 0, y = 0): SplitX2Scaled(..)
                         | else: SplitX2Run(a.., b.., s.., i.., w, x, y, Sr)
    SplitX2Run(.., x, y, sr) --> case (Sr beyond MAX_SR): SplitX2Scaled(..)
        | case x > 0: split(x) { a0 * sr: Wall(s0) | b0: Bay(w, i0) | ..
                                 | ~1: SplitX2Run(.., x - 1, y, sr) }
        | else: split(x) { ~a0: Wall(s0) | (y > 0 ? b0 : 0): Bay(w, i0) | .. }   the tail

(c_y and d_y the sums of b0 .. b(y-1) and a0 .. ay).  A group's rule is one line of its
numbers (``Bays3(w, s0, s1, i0) --> SplitX1(0.8, 0.8, 1.2, 2.8, 1.2, 0.8, 1.6, s0, s1, i0,
w)``), and a face one line of its crops per row.  So the text grows with the crops, not with
faces x pieces x tail cases: PLATEAU's 10 buildings take 5,512 lines where a case per y and a
rule per face took 22,567 (parsing and formatting them was most of a capture's time), deriving
the same meshes (bench/style.py, docs/benchmarks.md).

Along x the pieces are crops: ``Wall(s)`` stretched, ``Bay(w, i)`` a window (``w`` = 1) or, in
a wall band between window rows cut at the same columns, a wall (``w`` = 0).  Along y they are
the face's rows, rules that call its stack group's rule with their crops.

Two deviations, both for the texture's sake where the equations leave a piece stretched far
beyond the density it was photographed at (PLATEAU: a crop of 2 pixels over 8 m).  When not one
insertable fits (x = 0 and y = 0) equation 8 leaves a0 alone stretched over the whole face, and
when equation 9's Sr is above MAX_SR or below 1 / MAX_SR (a pattern of a 12.45 m "window" and
0.45 m of wall on a 24 m face: Sr = 12.7) the walls between windows swell or vanish; in both
cases the face takes the nearest whole number of patterns (at least one), every piece scaled
alike (``..Scaled``: a floating repeat of a0 b0 .. am), so it shows the source's pieces in their
order and proportions.  And a rule with no insertable (m = 0) repeats its one scalable piece,
each about a0 long (MIN_REPEAT at least), rather than stretching it once over the scope.
"""

from __future__ import annotations

from collections.abc import Sequence

from bgr.grammar import nodes as n
from bgr.grammar.formatter import format_module, format_number

MIN_PIECE = 0.001  # metres: a scalable piece this short still takes its share (no 0 / 0)
MAX_SR = 2.0  # walls between windows stretch at most this much (or shrink to 1 / MAX_SR)
MIN_REPEAT = 0.5  # metres: a repeated plain piece (a rule with no insertable) is at least this


def num(x: float, digits: int = 4) -> str:
    """A .bgr number rounded to ``digits`` decimals (millimetres for metres)."""
    return format_number(round(float(x), digits) + 0.0)


def split_sizes(scalable: Sequence[float], insertable: Sequence[float]) -> list[str]:
    """The numbers a group hands its Split rule: A (a0 .. am, each at least MIN_PIECE), B (b0 ..
    b(m-1)), the pattern's length P, the sums c1 .. cm of b0 .. b(y-1) and d0 .. dm of a0 ..
    ay.  The sums are rounded here, once, like the sizes: summed by the grammar they would
    carry float error, and a target exactly as wide as a sum (the source's own mass) would
    fall on either side of an equation 8 comparison."""
    a = [max(MIN_PIECE, v) for v in scalable]
    b = list(insertable)
    sums = [sum(a) + sum(b)] + [sum(b[:y]) for y in range(1, len(b) + 1)]
    sums += [sum(a[: y + 1]) for y in range(len(a))]
    return [num(v) for v in a + b + sums]


def group_body(
    axis: str, scalable: Sequence[float], insertable: Sequence[float], args: Sequence[str]
) -> str:
    """The successor of a group's rule: its Split rule called with its sizes and ``args`` (s0 ..
    sm, i0 .. i(m-1), then ``w`` along x); with no insertable piece (m = 0), its one scalable
    piece repeated (see the module's docstring)."""
    if insertable:
        sizes = split_sizes(scalable, insertable)
        return f"Split{axis.upper()}{len(insertable)}({', '.join(sizes + list(args))})"
    piece = f"Wall({args[0]})" if axis == "x" else args[0]
    return f"split({axis}) {{ ~{num(max(scalable[0], MIN_REPEAT))}: {piece} }}*"


def split_rules(axis: str, m: int) -> list[str]:
    """Equations 8-9 (split_h along x, split_v along y) once for every rule of ``m >= 1``
    insertable pieces: ``SplitX<m>(a0 .. am, b0 .. b(m-1), p, c1 .. cm, d0 .. dm, s0 .. sm,
    i0 .. i(m-1), w)`` takes the sizes of A (scalable, metres) and B (insertable) and their
    sums (:func:`split_sizes`), then the pieces (see the module's docstring).

    ``..Fit`` takes x = floor(W / P) whole patterns; ``..Y`` the largest tail y whose insertable
    pieces b0 .. b(y-1) fit what is left (the count of the sums c_k the rest holds: they grow
    with k), Sr filling the scope, and a tie in the window count when no tail fits goes to the
    layout whose walls stretch least; ``..Run`` lays the whole patterns one by one, then the
    tail [a0 b0 .. a(y-1) b(y-1) ay] as one split whose pieces beyond y have size 0 (a split
    makes no shape of size 0).  Every choice is one expression rather than a case per y, so the
    text grows with m, not m^2 (the rules pass every parameter on: a case per y made a rule
    of 74 windows 70,000 tokens long).  ``..Scaled`` is the deviation of the module's
    docstring."""
    return [format_module(n.Module([rule])).rstrip("\n") for rule in split_rule_nodes(axis, m)]


# The rules are built as syntax trees and printed by the formatter: parsing their text back
# (about 9,000 tokens for a rule of 70 windows) was a third of a capture's time.
def _v(name: str) -> n.Name:
    return n.Name(name)


def _k(value: float) -> n.Number:
    return n.Number(float(value))


def _op(op: str, left: n.Expr, right: n.Expr) -> n.Binary:
    return n.Binary(op, left, right)


def _if(cond: n.Expr, then: n.Expr, otherwise: n.Expr) -> n.Ternary:
    return n.Ternary(cond, then, otherwise)


def _call(name: str, *args: n.Expr) -> n.Sequence:
    """A body of one successor ``name(args)``."""
    return n.Sequence([n.Successor(name, list(args))])


def _split(axis: str, entries: list[tuple[str, n.Expr, n.Sequence]], repeat: bool = False):
    """A body ``split(axis) { key: body | .. }``, each entry (kind, key, body)."""
    block = n.Block([n.Entry(kind, key, body) for kind, key, body in entries], repeat)
    return n.Sequence([n.Operation("split", [_v(axis)], block=block)])


def _sum(terms: list[n.Expr]) -> n.Expr:
    """A sum of terms nested log2(n) deep: the checker limits an expression's depth."""
    if len(terms) == 1:
        return terms[0]
    half = len(terms) // 2
    return _op("+", _sum(terms[:half]), _sum(terms[half:]))


def split_rule_nodes(axis: str, m: int) -> list[n.Rule]:
    """The five rules of :func:`split_rules` as syntax trees."""
    a = [_v(f"a{k}") for k in range(m + 1)]
    b = [_v(f"b{k}") for k in range(m)]
    c = [_v(f"c{k}") for k in range(1, m + 1)]  # c_y = b0 + .. + b(y-1)
    d = [_v(f"d{k}") for k in range(m + 1)]  # d_y = a0 + .. + ay
    s = [_v(f"s{k}") for k in range(m + 1)]
    i = [_v(f"i{k}") for k in range(m)]
    flag = [_v("w")] if axis == "x" else []
    x, y, p, sr_ = _v("x"), _v("y"), _v("p"), _v("sr")
    zero, one = _k(0), _k(1)

    def scalable(k: int) -> n.Sequence:
        return _call("Wall", s[k]) if axis == "x" else n.Sequence([n.Successor(s[k].name)])

    def inserted(k: int) -> n.Sequence:
        return _call("Bay", _v("w"), i[k]) if axis == "x" else n.Sequence([n.Successor(i[k].name)])

    name = f"Split{axis.upper()}{m}"
    every = a + b + [p] + c + d + s + i + flag
    pieces = a + b + s + i + flag  # what laying the pieces out needs
    names = [v.name for v in every]
    size = _v(f"scope.s{axis}")
    sum_a, sum_b = d[m], c[m - 1]
    rest = _op("-", size, _op("*", x, p))
    # y: how many of c1 <= c2 <= .. <= cm the rest holds, i.e. the largest y with c_y <= rest
    count = _sum([_if(_op(">=", rest, v), one, zero) for v in c])
    tail_b = _sum([_if(_op("==", y, _k(k)), v, zero) for k, v in enumerate(c, 1)])
    tail_a = _sum([_if(_op("==", y, _k(k)), v, zero) for k, v in enumerate(d)])
    left = _op("-", size, _op("*", x, sum_b))
    sr = _op("/", _op("-", left, tail_b), _op("+", _op("*", x, sum_a), tail_a))
    alt = _op("/", left, _op("*", x, sum_a))
    sr0 = _op("/", left, _op("+", _op("*", x, sum_a), d[0]))
    whole = [("abs", _op("*", a[0], sr_), scalable(0))]
    tail = [("float", a[0], scalable(0))]
    scaled = [("float", a[0], scalable(0))]
    for k in range(m):
        whole += [("abs", b[k], inserted(k)), ("abs", _op("*", a[k + 1], sr_), scalable(k + 1))]
        tail += [
            ("abs", _if(_op(">", y, _k(k)), b[k], zero), inserted(k)),
            ("float", _if(_op(">", y, _k(k)), a[k + 1], zero), scalable(k + 1)),
        ]
        scaled += [("float", b[k], inserted(k)), ("float", a[k + 1], scalable(k + 1))]
    whole.append(("float", one, _call(f"{name}Run", *pieces, _op("-", x, one), y, sr_)))

    def distance(e: n.Expr) -> n.Call:  # |e - 1|
        return n.Call("abs", [_op("-", e, one)])

    def case(cond: n.Expr | None, body: n.Sequence) -> n.Case:
        return n.Case(cond, body)

    run = [v.name for v in pieces] + ["x", "y", "sr"]
    rules = [
        n.Rule(name, names, _call(f"{name}Fit", *every, n.Call("floor", [_op("/", size, p)]))),
        n.Rule(f"{name}Fit", names + ["x"], _call(f"{name}Y", *every, x, count)),
        # a tie in the window count (no tail fits): the layout whose walls stretch least;
        # not one insertable fits: the whole pattern scaled
        n.Rule(
            f"{name}Y",
            names + ["x", "y"],
            n.Conditional(
                [
                    case(
                        _op(
                            "and",
                            _op("and", _op("==", y, zero), _op(">", x, zero)),
                            _op("<", distance(alt), distance(sr0)),
                        ),
                        _call(f"{name}Run", *pieces, _op("-", x, one), _k(m), alt),
                    ),
                    case(
                        _op("and", _op("==", y, zero), _op("==", x, zero)),
                        _call(f"{name}Scaled", *pieces),
                    ),
                    case(None, _call(f"{name}Run", *pieces, x, y, sr)),
                ]
            ),
        ),
        n.Rule(
            f"{name}Run",
            run,
            n.Conditional(
                [
                    case(
                        _op("or", _op(">", sr_, _k(MAX_SR)), _op("<", sr_, _k(1 / MAX_SR))),
                        _call(f"{name}Scaled", *pieces),
                    ),
                    case(_op(">", x, zero), _split(axis, whole)),
                    case(None, _split(axis, tail)),
                ]
            ),
        ),
        n.Rule(f"{name}Scaled", [v.name for v in pieces], _split(axis, scaled, repeat=True)),
    ]
    return rules
