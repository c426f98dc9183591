"""The face schema of Build-by-Number (section 3.2.1): the paper's derivations, properties of the
rewrite, and the application rule checked against the split solver of LANGUAGE.md section 6."""

from __future__ import annotations

import itertools

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from bgr.interpreter.split_solver import Piece, Repeat, solve
from bgr.inverse.schema.faces import (
    Star,
    Sym,
    counts_expressible,
    expand,
    retarget,
    rewrite,
    stars,
    symbols,
    to_text,
    unroll,
)

# ---- the symbolic rule ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "face, rule",
    [
        ("ABABABA", "(AB)*A"),
        ("AABAABAA", "A(AB)*A(AB)*AA"),
        ("ACABABA", "AC(AB)*A"),
        ("ABCBCBCBA", "A(BC)*BA"),  # Figure 4
    ],
)
def test_paper_derivations(face, rule):
    assert to_text(rewrite(list(face)), list(face)) == rule


def test_figure_4_counts():
    assert rewrite(list("ABCBCBCBA")) == [Sym(0), Star(1, 2, 3), Sym(7), Sym(8)]


def test_symbols_follow_first_appearance():
    keys = [("brick",), ("window", "brick"), ("brick",), ("door",), ("window", "brick")]
    assert symbols(keys) == ["A", "B", "A", "C", "B"]
    assert symbols(range(28))[24:] == ["Y", "Z", "A1", "B1"]


def test_symbols_feed_rewrite():
    columns = ["wall", "win", "wall", "win", "wall", "door"]
    assert to_text(rewrite(symbols(columns)), symbols(columns)) == "(AB)*AC"


# A face string built from pieces that repeat (pairs of different symbols) and single columns, so
# that stars are common.
segment = st.one_of(
    st.sampled_from("ABCD").map(lambda c: c),
    st.tuples(st.sampled_from("ABCD"), st.sampled_from("ABCD"), st.integers(1, 5))
    .filter(lambda t: t[0] != t[1])
    .map(lambda t: (t[0] + t[1]) * t[2]),
)
faces = st.lists(segment, max_size=8).map(lambda parts: list("".join(parts)))


@given(faces)
def test_rewrite_expands_back(face):
    items = rewrite(face)
    assert [face[i] for i in expand(items)] == face


@given(faces)
def test_rewrite_never_stars_aa_nor_adjacent_equal_stars(face):
    items = rewrite(face)
    pairs = [(face[s.first_index], face[s.second_index]) for s in stars(items)]
    assert all(a != b for a, b in pairs)
    for left, right in itertools.pairwise(items):
        if isinstance(left, Star) and isinstance(right, Star):
            assert (face[left.first_index], face[left.second_index]) != (
                face[right.first_index],
                face[right.second_index],
            )


@given(faces)
def test_rewrite_marks_exactly_the_reoccurring_pairs(face):
    def occurs(a, b):
        return sum(face[i] == a and face[i + 1] == b for i in range(len(face) - 1))

    items = rewrite(face)
    for s in stars(items):
        assert occurs(face[s.first_index], face[s.second_index]) >= 2
    for left, right in itertools.pairwise(items):  # two plain columns never form a reoccurring pair
        if (
            isinstance(left, Sym)
            and isinstance(right, Sym)
            and face[left.index] != face[right.index]
        ):
            assert occurs(face[left.index], face[right.index]) < 2


# ---- unroll ------------------------------------------------------------------------------------


def test_unroll_four_and_two():
    face = list("ABABABABCABAB")
    items = rewrite(face)
    assert to_text(items, face) == "(AB)*C(AB)*" and [s.count for s in stars(items)] == [4, 2]
    assert not counts_expressible([4, 2])
    out = unroll(items)
    assert to_text(out, face) == "(AB)*ABC(AB)*" and [s.count for s in stars(out)] == [3, 2]
    assert expand(out) == expand(items)


@given(faces)
def test_unroll_keeps_the_face_and_makes_counts_expressible(face):
    items = rewrite(face)
    out = unroll(items)
    assert expand(out) == expand(items)
    assert counts_expressible([s.count for s in stars(out)])
    assert len(stars(out)) == len(stars(items))  # every group can still grow
    if counts_expressible([s.count for s in stars(items)]):
        assert out == items


def test_counts_expressible():
    assert counts_expressible([]) and counts_expressible([3]) and counts_expressible([3, 2, 3])
    assert not counts_expressible([1, 3])


# ---- the application rule against the split solver ---------------------------------------------


def via_solver(items, widths, fixed, length):
    """The equivalent split solved by LANGUAGE.md section 6: (counts per star, scale)."""

    def kind(c):
        return "abs" if fixed[c] else "float"

    split, groups = [], stars(items)
    for item in items:
        if isinstance(item, Sym):
            split.append(Piece(kind(item.index), widths[item.index], ("sym", item.index)))
        else:
            g = groups.index(item)
            split.append(
                Repeat(
                    (
                        Piece(kind(item.first_index), widths[item.first_index], ("star", g, 0)),
                        Piece(kind(item.second_index), widths[item.second_index], ("star", g, 1)),
                    )
                )
            )
    placed = solve(split, length)
    counts = tuple(sum(p.payload == ("star", g, 0) for p in placed) for g in range(len(groups)))

    def column(p):
        return (
            p.payload[1]
            if p.payload[0] == "sym"
            else (
                groups[p.payload[1]].first_index
                if p.payload[2] == 0
                else groups[p.payload[1]].second_index
            )
        )

    scales = [p.size / widths[column(p)] for p in placed if not fixed[column(p)]]
    assert not scales or max(scales) - min(scales) < 1e-9
    return counts, scales[0] if scales else 0.0  # pieces of no size are not placed


def nominal(items, widths, fixed, counts):
    """(fixed, variable) width the rule lays out with these counts."""
    cols = expand(items, counts)
    return sum(widths[c] for c in cols if fixed[c]), sum(widths[c] for c in cols if not fixed[c])


def is_tie(items, widths, fixed, length, a, b):
    """Two count tuples whose scales are equally close to 1, to rounding: where LANGUAGE.md's
    tie rule (more repetitions) applies, or, for equal totals, the order of the search.  The
    solver compares exact floats, so there rounding may pick either."""

    def distance(counts):
        fixed_width, var_width = nominal(items, widths, fixed, counts)
        return abs((length - fixed_width) / var_width - 1.0)

    return abs(distance(a) - distance(b)) < 1e-9


@st.composite
def schemas(draw):
    """A rule with 1-3 stars from a random face, and per-column widths with at least one stretch
    column (without one, the paper's scale means nothing; see test_all_fixed_columns)."""
    face = draw(faces)
    items = rewrite(face)
    assume(1 <= len(stars(items)) <= 3)
    n = len(face)
    widths = draw(st.lists(st.floats(0.2, 3.0), min_size=n, max_size=n))
    fixed = draw(st.lists(st.booleans(), min_size=n, max_size=n))
    assume(not all(fixed[c] for c in expand(items)))
    return unroll(items, widths=widths), widths, fixed


@settings(max_examples=300)
@given(schemas(), st.one_of(st.sampled_from([0.7, 1.0, 1.5]), st.floats(0.3, 3.0)))
def test_retarget_agrees_with_split_solver(schema, factor):
    items, widths, fixed = schema
    length = factor * sum(nominal(items, widths, fixed, None))
    counts, scale = retarget(items, widths, fixed, length)
    assume(scale > 0)  # fixed columns alone overflow: both rules are off their map
    theirs, their_scale = via_solver(items, widths, fixed, length)
    if 0 in counts:  # the paper's k = 0; LANGUAGE.md keeps one repetition (test_paper_allows_zero)
        assert all(
            t <= 1 for t in theirs
        )  # one each (a repetition squeezed to nothing is not placed)
        return
    if counts != theirs:
        assert is_tie(items, widths, fixed, length, counts, theirs)
        return
    assert scale == pytest.approx(their_scale, abs=1e-9)


@given(schemas())
def test_retarget_at_the_original_length_gives_the_original(schema):
    items, widths, fixed = schema
    original = tuple(s.count for s in stars(items))
    length = sum(nominal(items, widths, fixed, None))
    counts, scale = retarget(items, widths, fixed, length)
    assert counts == original and scale == pytest.approx(1.0, abs=1e-9)
    assert via_solver(items, widths, fixed, length)[0] == original


def test_retarget_grows_symmetrically():
    face = list("ABCBCBCBA")  # A(BC)*BA, A and C fixed (windows), B stretches (wall)
    items = rewrite(face)
    widths = [1.0, 2.0, 1.0, 2.0, 1.0, 2.0, 1.0, 2.0, 1.0]
    fixed = [f == "A" or f == "C" for f in face]
    assert retarget(items, widths, fixed, 13.0) == ((3,), 1.0)  # the face itself
    assert retarget(items, widths, fixed, 19.0) == ((5,), 1.0)
    counts, scale = retarget(items, widths, fixed, 14.0)  # 3 reps: s = 9/8; 4 reps: s = 8/10
    assert counts == (3,) and scale == pytest.approx(1.125)
    counts, scale = retarget(items, widths, fixed, 15.0)  # 3 reps: s = 10/8; 4 reps: s = 9/10
    assert counts == (4,) and scale == pytest.approx(0.9)


def test_ties_go_to_more_repetitions():
    items = rewrite(list("ABABC"))  # (AB)*C, all stretch, widths 1: 1 rep s = 4/3, 2 reps s = 4/5
    widths, fixed = [1.0] * 5, [False] * 5
    # at 4 the two are 1/3 and 1/5 off; find the length where both are equally far: L/3 - 1 = 1 -
    # L/5
    length = 2 / (1 / 3 + 1 / 5)
    assert retarget(items, widths, fixed, length)[0] == (2,)
    assert via_solver(items, widths, fixed, length)[0] == (2,)


def test_non_expressible_counts_need_unroll():
    face = list("ABABABABCABAB")  # (AB)*C(AB)* with 4 and 2
    widths, fixed = [1.0, 2.0] * 4 + [5.0] + [1.0, 2.0] * 2, [False] * 13
    items, length = rewrite(face), sum(widths)
    assert retarget(items, widths, fixed, length) == ((3, 3), 1.0)  # not the face we had
    out = unroll(items)  # (3, 2): expressible, but the two stars tie at this length
    assert to_text(out, face) == "(AB)*ABC(AB)*"
    assert retarget(out, widths, fixed, length) == ((2, 3), 1.0)
    out = unroll(items, widths=widths)  # the tie seen: down to (2, 2)
    assert to_text(out, face) == "(AB)*ABABC(AB)*" and expand(out) == expand(items)
    assert retarget(out, widths, fixed, length) == ((2, 2), 1.0)
    assert via_solver(out, widths, fixed, length)[0] == (2, 2)


def test_unroll_keeps_k_plus_one_when_nothing_ties():
    face = list("ABABABABCDEDE")  # (AB)*C(DE)* with 4 and 2, repetitions 3 and 2.5 wide
    widths, fixed = [1.0, 2.0] * 4 + [5.0] + [1.0, 1.5] * 2, [False] * 13
    out = unroll(rewrite(face), widths=widths)
    assert to_text(out, face) == "(AB)*ABC(DE)*"
    assert retarget(out, widths, fixed, sum(widths)) == ((3, 2), 1.0)


# ---- where the paper and split_solver part ------------------------------------------------------


def test_paper_and_solver_allow_zero_repetitions():
    """The paper's k may be 0 when one repetition does not fit, and so may the split solver's
    where a floating piece outside the group takes the length (as CGA: issue 31).  (AB)*C, all
    stretch, A = B = 1, C = 10 (14 long), at 10.5: no (AB) gives s = 1.05, one gives s = 0.875."""
    items = rewrite(list("ABABC"))
    widths, fixed = [1.0, 1.0, 1.0, 1.0, 10.0], [False] * 5
    counts, scale = retarget(items, widths, fixed, 10.5)
    assert counts == (0,) and scale == pytest.approx(1.05)
    theirs, their_scale = via_solver(items, widths, fixed, 10.5)
    assert theirs == (0,) and their_scale == pytest.approx(1.05)


def test_equal_groups_tie_at_the_original_length():
    """Counts 3 and 2 on two stars of the same pair are expressible, but at the original length
    (2, 3) fits as exactly as (3, 2): both rules then take the extra on the later star."""
    face = list("A" + "AB" * 3 + "A" + "AB" * 2 + "AA")
    items = rewrite(face)
    assert to_text(items, face) == "A(AB)*A(AB)*AA" and [s.count for s in stars(items)] == [3, 2]
    widths, fixed = [1.0] * len(face), [False] * len(face)
    assert retarget(items, widths, fixed, len(face)) == ((2, 3), 1.0)
    assert via_solver(items, widths, fixed, len(face))[0] == (2, 3)


def test_all_fixed_columns():
    """With no variable column the paper's scale means nothing; we fill as much as fits.  The
    solver instead gives every absolute repeat k whole repetitions and cuts one more (rule 4).
    (AB)*(CD)* with repetitions of 2 and 3, in 7.5: (2, 1) fills 7."""
    items = rewrite(list("ABABCDCD"))
    widths, fixed = [1.0, 1.0, 1.0, 1.0, 1.5, 1.5, 1.5, 1.5], [True] * 8
    assert retarget(items, widths, fixed, 7.5) == ((2, 1), 1.0)
