"""The split solver and the split operation, against every example row of LANGUAGE.md section 6."""

import io
import json

import pytest

import bgr
from bgr.formats import write_json
from bgr.interpreter.split_solver import Piece, Repeat, solve


def pieces(block: str, length: float = 10.0):
    """(label, size) of the terminals of `split(x) <block>` on a lot `length` wide."""
    names = sorted(
        set(
            w
            for w in block.replace("{", " ").replace("}", " ").replace("|", " ").split()
            if w[:1].isupper()
        )
    )
    src = f"Lot --> split(x) {block}\n" + "".join(
        f'{name} --> color("#ffffff")\n' for name in names
    )
    result = bgr.derive(bgr.load(src), lot=(length, 5.0))
    return [(t["label"], round(t["size"][0], 6)) for t in terminal_list(result)]


def terminal_list(result) -> list[dict]:
    """The terminals as the .json writer prints them: what these tests read."""
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=result.seed, attrs=result.attrs)
    return json.loads(buffer.getvalue())["terminals"]


@pytest.mark.parametrize(
    "block, length, expected",
    [
        ("{ 3: A | ~1: B }", 10, [("A", 3), ("B", 7)]),
        ("{ '0.5: A | ~1: B | ~1: C }", 10, [("A", 5), ("B", 2.5), ("C", 2.5)]),
        ("{ ~2: A }*", 10, [("A", 2)] * 5),
        ("{ ~3: A }*", 10, [("A", round(10 / 3, 6))] * 3),
        ("{ 1: E | { ~2: W }* | 1: E }", 10, [("E", 1)] + [("W", 2)] * 4 + [("E", 1)]),
        ("{ 4: A | 4: B | 4: C }", 10, [("A", 4), ("B", 4), ("C", 2)]),
        ("{ 3: A }*", 10, [("A", 3), ("A", 3), ("A", 3), ("A", 1)]),
        (
            "{ 1: E | { ~1: B | 2: C }* | ~1: B | 1: E }",
            12,
            [("E", 1)] + [("B", 1), ("C", 2)] * 3 + [("B", 1), ("E", 1)],
        ),
        (
            "{ 1: E | { ~1: B | 2: C }* | ~1: B | 1: E }",
            10,
            [("E", 1)]
            + [("B", round(4 / 3, 6)), ("C", 2)] * 2
            + [("B", round(4 / 3, 6)), ("E", 1)],
        ),
        ("{ 2: A | 2: B }", 10, [("A", 2), ("B", 2)]),
    ],
)
def test_contract_examples(block, length, expected):
    assert pieces(block, length) == expected


def test_split_index_and_total_are_global_across_repetitions():
    src = (
        "Lot --> split(x) { '0.1: A(split.index, split.total) | '0.1: A(split.index, split.total) "
        "}*\n"
        "A(i, n) --> s(i + 1, n, 1)\n"
    )
    t = bgr.derive(bgr.load(src), lot=(10, 5)).terminals
    assert [int(s[0]) - 1 for s in t.size] == list(range(10))
    assert {int(s[1]) for s in t.size} == {10}


def test_pieces_tile_the_scope_in_order():
    t = bgr.derive(
        bgr.load(
            "Lot --> split(z) { 2: A | ~1: B | 3: C }\n"
            'A --> NIL B\nB --> color("#000000")\nC --> B\n'
        ),
        lot=(4, 10),
    ).terminals
    zs = [round(float(o[2]), 9) for o in t.origin]
    sizes = [round(float(s[2]), 9) for s in t.size]
    assert (zs, sizes) == ([2.0, 7.0], [5.0, 3.0])


def test_floating_scale_ties_prefer_more_repetitions():
    # L = 5, ~2: 2 reps give s = 1.25 (0.25 off), 3 reps s = 0.833 (0.167 off): 3 wins
    assert [p.size for p in solve([Repeat((Piece("float", 2.0, "A"),))], 5.0)] == pytest.approx(
        [5 / 3] * 3
    )
    # exact tie: L = 3 with ~2: 1 rep s = 1.5, 2 reps s = 0.75 -> |0.5| vs |0.25|; L = 2.4, ~1.6:
    # 1 rep s = 1.5 (0.5 off), 2 reps s = 0.75 (0.25 off)
    assert len(solve([Repeat((Piece("float", 1.0, "A"),))], 1.5)) == 2  # s = 1.5 vs 0.75 -> 2


def test_several_repeat_groups_share_a_multiplier():
    # A { B | C }* B { D }* A: counts differ by at most one
    items = [
        Piece("abs", 1, "A"),
        Repeat((Piece("float", 1, "B"), Piece("abs", 1, "C"))),
        Piece("float", 1, "B"),
        Repeat((Piece("float", 2, "D"),)),
        Piece("abs", 1, "A"),
    ]
    for length in (8, 13, 21, 34):
        placed = solve(items, length)
        c_count = sum(p.payload == "C" for p in placed)
        d_count = sum(p.payload == "D" for p in placed)
        assert abs(c_count - d_count) <= 1
        assert sum(p.size for p in placed) == pytest.approx(length)


def test_absolute_sizes_overflowing_leave_floats_nothing():
    assert [
        (p.payload, p.size) for p in solve([Piece("abs", 12, "A"), Piece("float", 1, "B")], 10)
    ] == [("A", 10)]


@pytest.mark.parametrize(
    "src, lot, expected",
    [
        # a repeat tile longer than its scope: one repetition, cut to the scope (rule 4)
        ("Lot --> split(x) { 30: T }*\nterminal T\n", (20, 20), [("T", 20.0, 0.0)]),
        (
            "Lot --> split(x) { 1: A | { 30: T }* | 2: B }\nterminal T, A, B\n",
            (20, 20),
            [("A", 1.0, 0.0), ("T", 17.0, 1.0), ("B", 2.0, 18.0)],
        ),
    ],
)
def test_a_repeat_tile_longer_than_its_scope_is_cut_not_a_crash(src, lot, expected):
    t = bgr.derive(bgr.load(src), lot=lot).terminals
    got = [
        (lab, float(s[0]), float(o[0])) for lab, s, o in zip(t.label, t.size, t.origin, strict=True)
    ]
    assert got == [(lab, pytest.approx(s), pytest.approx(o)) for lab, s, o in expected]


def test_a_repeat_tile_longer_than_a_face_is_cut():
    src = (
        "Lot --> s(2, 0, 2) extrude(3) comp(f) { side: split(x) { 3: T }* | all: NIL }\n"
        "terminal T\n"
    )
    t = bgr.derive(bgr.load(src)).terminals
    assert len(t) == 4 and all(s[0] == pytest.approx(2.0) for s in t.size)


@pytest.mark.parametrize("size", ["0.001", "~0.001", "'0.0000001"])
def test_a_runaway_repeat_is_counted_before_it_is_built(size):
    """10 million pieces asked of a budget of 1,000: refused at once, before any is made."""
    import time

    src = f"Lot --> split(x) {{ {size}: T }}*\nterminal T\n"
    start = time.perf_counter()
    with pytest.raises(bgr.BgrError, match="would make 10,000,000 pieces") as e:
        bgr.derive(bgr.load(src), lot=(10000, 10), max_shapes=1000)
    assert time.perf_counter() - start < 2.0
    assert (e.value.line, e.value.column) == (1, 9)


def test_nested_repeats_are_counted_too():
    src = "Lot --> split(x) { { 1: split(z) { 0.01: T }* }* }\nterminal T\n"
    with pytest.raises(bgr.BgrError, match="would make"):
        bgr.derive(bgr.load(src), lot=(1000, 1000), max_shapes=5000)


def test_split_adjust_fits_each_piece_to_its_geometry():
    # CGA's default split adjusts each piece's scope to the geometry it holds: the upper half
    # of a triangle is as wide as the triangle is there; noAdjust (bgr's default) keeps the slab
    src = "terminal P\nLot --> polygon(0, 0, 10, 0, 5, 10) split(z MODE) { ~5: P }*\n"
    fitted = bgr.derive(bgr.load(src.replace(" MODE", ", adjust")), lot=(10, 10)).terminals
    plain = bgr.derive(bgr.load(src.replace(" MODE", "")), lot=(10, 10)).terminals
    assert [list(map(float, o)) for o in fitted.origin] == [[0, 0, 0], [2.5, 0, 5]]
    assert [list(map(float, s)) for s in fitted.size] == [[10, 0, 5], [5, 0, 5]]
    assert [list(map(float, s)) for s in plain.size] == [[10, 0, 5], [10, 0, 5]]
    # a roof's slabs too: the hip roof's end slab is fitted to what it holds of the roof
    roof = "terminal R\nLot --> roof(hip, 45) split(x, adjust) { ~2: R }*\n"
    slabs = bgr.derive(bgr.load(roof), lot=(12, 8)).terminals
    heights = [round(float(s[1]), 6) for s in slabs.size]
    assert heights[0] == pytest.approx(2.0) and max(heights) == pytest.approx(4.0)
