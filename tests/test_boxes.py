"""bgr.inverse.boxes: structure-preserving retargeting of box hierarchies (Lin et al. 2011) —
fixed boxes, the cascade of section 6, alignments, validity of results, the order of the axes,
the grammar ``bgr infer --kind boxes`` writes, and ``bgr retarget`` on good and bad input
(issue 14).

The numbers asserted below are worked out by hand from the paper's rule: the change goes to the
R boxes first, taller first (ties: lower first), each getting ``change * len / total_R`` plus
what the previous one left unused, repeated ``floor(share / len)`` times (toward zero; a
contraction deletes); the rest goes to the S boxes in proportion to their lengths; with no S box
left the R boxes are scaled in proportion.
"""

from __future__ import annotations

import itertools
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import test_gltf_validator as gltf
from conftest import ROOT
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import bgr
from bgr.cli import main
from bgr.grammar.errors import BgrError
from bgr.inverse.boxes import model
from bgr.inverse.boxes.analysis import Unit, min_length
from bgr.inverse.boxes.model import AXES
from bgr.inverse.boxes.retarget import alignments, cascade, retarget, retarget_axis

EXAMPLES = ROOT / "examples" / "boxes"
NAMES = ("regular_facade", "irregular_facade", "building")
ATTRS = ("width", "height", "length")

# the Khronos glTF validator of tests/test_gltf_validator.py (skips where Node is absent)
validator = gltf.validator


# ---- helpers ------------------------------------------------------------------------------


def box(id, lo, hi, tags="SSS", children=()) -> dict:
    """A box as the JSON has it; ``tags`` is the behaviour along x, y, z."""
    return {
        "id": id,
        "min": list(lo),
        "max": list(hi),
        "behavior": dict(zip("xyz", tags, strict=True)),
        "children": list(children),
    }


def text(root: dict) -> str:
    return json.dumps({"root": root})


def parse(root: dict) -> model.Box:
    return model.parse(text(root), "test")


def row(*parts, height=10.0, depth=1.0) -> model.Box:
    """Boxes b0, b1, ... side by side along x, each ``(width, tag along x)``, in a root S box."""
    x, kids = 0.0, []
    for i, (width, tag) in enumerate(parts):
        kids.append(box(f"b{i}", (x, 0, 0), (x + width, height, depth), tag + "SS"))
        x += width
    return parse(box("root", (0, 0, 0), (x, height, depth), "SSS", kids))


def layout(node: model.Box, axis: int = 0) -> list[tuple[str, float, float]]:
    """A node's children as (id, lo, hi) along ``axis``, in order."""
    return [(c.id, round(float(c.lo[axis]), 9), round(float(c.hi[axis]), 9)) for c in node.children]


def rows(boxes) -> np.ndarray:
    """Sorted (lo, hi) rows of boxes, for comparing two sets of boxes."""
    return np.array(sorted(np.round([(*b.lo, *b.hi) for b in boxes], 9).tolist()))


def parts(root: model.Box) -> np.ndarray:
    """The boxes a model shows: leaves, and boxes with a mesh fitted."""
    return rows(b for b in root.walk() if not b.children or b.mesh)


def assert_valid(result: model.Box, size) -> None:
    assert model.check(result) == []
    assert min(float(b.size.min()) for b in result.walk()) >= -1e-9
    assert np.allclose(result.size, size, atol=1e-6), (result.size, size)
    ids = [b.id for b in result.walk()]
    assert len(ids) == len(set(ids))


def assert_fixed_kept(source: model.Box, result: model.Box) -> int:
    """Every box fixed along an axis has its input length along it; returns how many checked."""
    original = {b.id: b for b in source.walk()}
    checked = 0
    for b in result.walk():
        was = original[b.source]
        for a in range(3):
            if was.tags[a] == "F":
                assert b.size[a] == pytest.approx(was.size[a], abs=1e-9), (b.id, AXES[a])
                checked += 1
    return checked


def scaled(root: model.Box, factors) -> tuple[float, float, float]:
    """``root``'s size times ``factors`` on the axes it is not fixed along."""
    return tuple(
        float(v * f) if t != "F" else float(v)
        for v, f, t in zip(root.size, factors, root.tags, strict=True)
    )


# ---- 1. fixed boxes -----------------------------------------------------------------------


def facade() -> model.Box:
    """Piers (S), two R bays each holding a window fixed along x and y (its panes fixed too,
    by inheritance), and a bay with a door fixed along x and y."""

    def bay(name, x0, x1):
        window = box(
            f"{name}-window",
            (x0 + 0.5, 3, 0),
            (x1 - 0.5, 5, 1),
            "FFS",
            [
                box(f"{name}-pane-l", (x0 + 0.5, 3, 0), (x0 + 1.5, 5, 1)),
                box(f"{name}-pane-r", (x0 + 1.5, 3, 0), (x1 - 0.5, 5, 1)),
            ],
        )
        return box(
            name,
            (x0, 0, 0),
            (x1, 10, 1),
            "RSS",
            [
                box(f"{name}-below", (x0, 0, 0), (x1, 3, 1)),
                window,
                box(f"{name}-above", (x0, 5, 0), (x1, 10, 1)),
            ],
        )

    door = box("door", (7, 0, 0), (9, 2.5, 1), "FFS")
    kids = [
        box("pier-l", (0, 0, 0), (1, 10, 1)),
        bay("bay-1", 1, 4),
        bay("bay-2", 4, 7),
        box("door-bay", (7, 0, 0), (9, 10, 1), "SSS", [door, box("over", (7, 2.5, 0), (9, 10, 1))]),
        box("pier-r", (9, 0, 0), (12, 10, 1)),
    ]
    return parse(box("facade", (0, 0, 0), (12, 10, 1), "SSS", kids))


def test_an_f_box_makes_its_descendants_f_on_that_axis():
    root = facade()
    tags = {b.id: b.tags for b in root.walk()}
    assert tags["bay-1-window"] == ("F", "F", "S")
    # the panes say SSS; inside a window fixed along x and y they are fixed there too
    assert tags["bay-1-pane-l"] == ("F", "F", "S")
    assert tags["bay-2-pane-r"] == ("F", "F", "S")
    assert tags["bay-1-below"] == ("S", "S", "S")


@pytest.mark.parametrize(
    "factors",
    [(0.6, 0.6, 0.6), (2.5, 2.5, 2.5), (0.6, 2.5, 1.0), (2.5, 0.6, 2.5), (1.37, 0.8, 1.9)],
    ids=["60%", "250%", "narrow-tall", "wide-low", "odd"],
)
def test_fixed_boxes_and_their_descendants_keep_their_size(factors):
    root = facade()
    size = scaled(root, factors)
    result = retarget(root, size)
    assert_valid(result, size)
    sources = [b.source for b in result.walk()]
    # the door is never deleted; the windows come and go with their bays
    assert sources.count("door") == 1
    assert sources.count("bay-1-pane-l") + sources.count("bay-2-pane-l") >= 1
    assert assert_fixed_kept(root, result) >= 3 * 2  # door, a window and its panes, x and y
    for b in result.walk():
        if b.source.endswith("-window"):
            assert b.size[:2] == pytest.approx([2.0, 2.0])
        if b.source.endswith("-pane-l"):
            assert b.size[:2] == pytest.approx([1.0, 2.0])
        if b.source == "door":
            assert b.size[:2] == pytest.approx([2.0, 2.5])


# ---- 2. the cascade over R boxes ----------------------------------------------------------


def test_stretching_replicates_the_second_and_fourth_bay():
    # piers of 1.5, four R bays of 3 (width 15) to 21: change 6, a share of 6 * 3/12 = 1.5 each;
    # bay 1: floor(1.5 / 3) = 0; bay 2: floor((3 - 0) / 3) = 1 (used 3); bay 3:
    # floor((4.5 - 3) / 3) = 0; bay 4: floor((6 - 3) / 3) = 1 (used 6): counts 1, 2, 1, 2
    root = row((1.5, "S"), (3, "R"), (3, "R"), (3, "R"), (3, "R"), (1.5, "S"))
    result = retarget(root, (21, 10, 1))
    assert layout(result) == [
        ("b0", 0, 1.5),
        ("b1", 1.5, 4.5),
        ("b2", 4.5, 7.5),
        ("b2~1", 7.5, 10.5),
        ("b3", 10.5, 13.5),
        ("b4", 13.5, 16.5),
        ("b4~1", 16.5, 19.5),
        ("b5", 19.5, 21),
    ]
    copies = [b for b in result.children if b.replica]
    assert [(b.source, b.replica) for b in copies] == [("b2", 1), ("b4", 1)]
    assert_valid(result, (21, 10, 1))


def test_contraction_deletes_the_second_and_fourth_bay():
    # to 9: change -6, shares -1.5: bay 1 -0.5 -> 0; bay 2 -3/3 = -1 (deleted, used -3);
    # bay 3 (-4.5 + 3)/3 = -0.5 -> 0; bay 4 (-6 + 3)/3 = -1 (deleted): the piers keep 1.5
    root = row((1.5, "S"), (3, "R"), (3, "R"), (3, "R"), (3, "R"), (1.5, "S"))
    result = retarget(root, (9, 10, 1))
    assert layout(result) == [("b0", 0, 1.5), ("b1", 1.5, 4.5), ("b3", 4.5, 7.5), ("b5", 7.5, 9)]
    assert_valid(result, (9, 10, 1))


@pytest.mark.parametrize(
    "width, expected",
    [
        # 8 to 10: shares 1, 1; floor(1/4) = floor(2/4) = 0 copies; no S box: the 2 left
        # scales both R boxes in proportion, 4 + 1 each
        (10, [("b0", 0, 5), ("b1", 5, 10)]),
        # 8 to 13: shares 2.5, 5: b0 floor(2.5/4) = 0, b1 floor(5/4) = 1 (used 4): the 1 left
        # scales b0 (4) and b1's run (8) in proportion: 4 + 1/3 and 8 + 2/3, two copies of 13/3
        (13, [("b0", 0, 13 / 3), ("b1", 13 / 3, 26 / 3), ("b1~1", 26 / 3, 13)]),
        # 8 to 5: shares -1.5, -3: floor toward zero, no deletion; -3 scales both to 2.5
        (5, [("b0", 0, 2.5), ("b1", 2.5, 5)]),
    ],
)
def test_with_no_s_box_the_r_boxes_are_scaled(width, expected):
    result = retarget(row((4, "R"), (4, "R")), (width, 10, 1))
    got = layout(result)
    assert [g[0] for g in got] == [e[0] for e in expected]
    assert np.allclose([g[1:] for g in got], [e[1:] for e in expected], atol=1e-9)
    assert_valid(result, (width, 10, 1))


def test_taller_r_boxes_come_first():
    # S 1, R 2, R 4, S 1 (width 8) to 11: change 3 over R lengths 6.  The 4 goes first:
    # share 3 * 4/6 = 2, floor(2/4) = 0; then the 2: share 3 - 0 = 3, floor(3/2) = 1 (used 2);
    # the 1 left goes to the piers, 0.5 each.  (Lower first would copy nothing: piers 2.5.)
    result = retarget(row((1, "S"), (2, "R"), (4, "R"), (1, "S")), (11, 10, 1))
    assert layout(result) == [
        ("b0", 0, 1.5),
        ("b1", 1.5, 3.5),
        ("b1~1", 3.5, 5.5),
        ("b2", 5.5, 9.5),
        ("b3", 9.5, 11),
    ]


def test_cascade_counts_and_lengths():
    def units(*spec):
        out, x = [], 0.0
        for length, tag in spec:
            out.append(Unit([], x, x + length, tag))
            x += length
        return out

    us = units((1.5, "S"), (3, "R"), (3, "R"), (3, "R"), (3, "R"), (1.5, "S"))
    counts, lengths = cascade(us, [0.0] * 6, 21)
    assert counts == [1, 1, 2, 1, 2, 1]
    assert lengths == pytest.approx([1.5, 3, 6, 3, 6, 1.5])
    counts, lengths = cascade(us, [0.0] * 6, 9)
    assert counts == [1, 1, 0, 1, 0, 1]
    assert lengths == pytest.approx([1.5, 3, 0, 3, 0, 1.5])
    # F units never change; the change to R 5 and R 2 (7): the 5 first, share 8 * 5/7 = 5.71
    # -> 1 copy (used 5); the 2: 8 - 5 = 3 -> 1 copy (used 7); 1 left to the S (2 -> 3)
    us = units((2, "F"), (5, "R"), (2, "R"), (2, "S"))
    counts, lengths = cascade(us, [2.0, 0, 0, 0], 19)
    assert counts == [1, 2, 2, 1]
    assert lengths == pytest.approx([2, 10, 4, 3])


# ---- 3. S boxes take the rest in proportion -----------------------------------------------


def test_s_boxes_absorb_the_rest_in_proportion_to_their_lengths():
    # S 1, R 4, S 3 (width 8) to 10: the R share 2 buys no copy of 4; the S boxes take 2 as
    # 1:3, 0.5 and 1.5
    result = retarget(row((1, "S"), (4, "R"), (3, "S")), (10, 10, 1))
    assert layout(result) == [("b0", 0, 1.5), ("b1", 1.5, 5.5), ("b2", 5.5, 10)]
    # and the same shrinking: to 6, share -2 deletes nothing, the S boxes give 0.5 and 1.5
    result = retarget(row((1, "S"), (4, "R"), (3, "S")), (6, 10, 1))
    assert layout(result) == [("b0", 0, 0.5), ("b1", 0.5, 4.5), ("b2", 4.5, 6)]
    # no R box: S 2, F 3, S 6 (11) to 19: the 8 goes 2:6 to the S boxes, the F box keeps 3
    result = retarget(row((2, "S"), (3, "F"), (6, "S")), (19, 10, 1))
    assert layout(result) == [("b0", 0, 4), ("b1", 4, 7), ("b2", 7, 19)]


# ---- 4. alignments ------------------------------------------------------------------------


def stack(prefix, x0, x1, spans) -> list[dict]:
    """Boxes stacked along y in x0..x1, each ``(y0, y1, tag along y)``."""
    return [
        box(f"{prefix}{i}", (x0, y0, 0), (x1, y1, 1), "S" + tag + "S")
        for i, (y0, y1, tag) in enumerate(spans)
    ]


def test_storey_lines_of_two_columns_stay_aligned():
    # column A: ground S 0-4, two R storeys 4-7, 7-10, a cornice F 10-11;
    # column B: ground S 0-4, one S box 4-10, cornice F 10-11.  Height 11 to 17: A copies each
    # storey once (shares 3 of 3): lines 4, 10, 16; B alone would put its line 4 at
    # 4 + 6 * 4/10 = 6.4 — the alignment with A keeps it at 4.
    a = stack("a", 0, 2, [(0, 4, "S"), (4, 7, "R"), (7, 10, "R"), (10, 11, "F")])
    b = stack("b", 2, 4, [(0, 4, "S"), (4, 10, "S"), (10, 11, "F")])
    column_b = parse(box("B", (2, 0, 0), (4, 11, 1), "SSS", b))
    alone = retarget(column_b, (2, 17, 1))
    assert layout(alone, 1) == [("b0", 0, 6.4), ("b1", 6.4, 16), ("b2", 16, 17)]

    root = parse(
        box(
            "root",
            (0, 0, 0),
            (4, 11, 1),
            "SSS",
            [box("A", (0, 0, 0), (2, 11, 1), "SSS", a), box("B", (2, 0, 0), (4, 11, 1), "SSS", b)],
        )
    )
    result = retarget(root, (4, 17, 1))
    col_a, col_b = result.children
    assert layout(col_a, 1) == [
        ("a0", 0, 4),
        ("a1", 4, 7),
        ("a1~1", 7, 10),
        ("a2", 10, 13),
        ("a2~1", 13, 16),
        ("a3", 16, 17),
    ]
    assert layout(col_b, 1) == [("b0", 0, 4), ("b1", 4, 16), ("b2", 16, 17)]
    # the boundaries at the same input height are at the same output height
    ends_a = {(round(c.lo[1], 9), round(c.hi[1], 9)) for c in col_a.children}
    assert {round(c.hi[1], 9) for c in col_b.children} <= {hi for _, hi in ends_a}
    kept, total = alignments(root, result, axis=1)
    assert 0 < kept <= total
    assert_valid(result, (4, 17, 1))


def test_a_secondary_sequence_snaps_to_the_alignment_set_by_the_primary():
    # left (the primary, from the bottom-left corner): S 0-4, R 4-7, R 7-10;
    # right (a secondary): S 0-2, S 2-4, S 4-10.  Height 10 to 16.  The primary copies both
    # storeys: its line 4 stays at 4.  The right column on its own would be 3.2, 6.4, 16; its
    # line at 4 is in an alignment group set by the primary at 4, so it goes there: 3.2, 4, 16.
    kids = stack("l", 0, 2, [(0, 4, "S"), (4, 7, "R"), (7, 10, "R")])
    kids += stack("r", 2, 4, [(0, 2, "S"), (2, 4, "S"), (4, 10, "S")])
    root = parse(box("root", (0, 0, 0), (4, 10, 1), "SSS", kids))
    result = retarget(root, (4, 16, 1))
    got = {c.id: (round(c.lo[1], 9), round(c.hi[1], 9)) for c in result.children}
    assert got == {
        "l0": (0, 4),
        "l1": (4, 7),
        "l1~1": (7, 10),
        "l2": (10, 13),
        "l2~1": (13, 16),
        "r0": (0, 3.2),
        "r1": (3.2, 4),
        "r2": (4, 16),
    }
    assert_valid(result, (4, 16, 1))


# ---- 5. validity --------------------------------------------------------------------------

BUG_F_UNDER_MOVED = (
    "bug: a box resting both on a box fixed along the axis and on a box of an earlier sequence "
    "that moved is placed on its own sequence's F box, overlapping the other (or, after x, "
    "gets a negative height); see test_box_on_a_fixed_and_a_moved_box_overlaps"
)


@pytest.mark.parametrize(
    "name, factors",
    [
        ("regular_facade", (0.6, 0.6, 1)),
        ("regular_facade", (2.5, 2.5, 1)),
        ("regular_facade", (0.6, 2.5, 1)),
        ("regular_facade", (2.5, 0.6, 1)),
        ("building", (0.6, 0.6, 0.6)),
        ("building", (2.5, 2.5, 2.5)),
        ("building", (0.6, 2.5, 1.0)),
        ("building", (2.5, 0.6, 2.5)),
        ("irregular_facade", (2.5, 2.5, 1)),
        ("irregular_facade", (0.6, 2.5, 1)),
        ("irregular_facade", (0.6, 1, 1)),
        ("irregular_facade", (2.5, 1, 1)),
        pytest.param(
            "irregular_facade",
            (1, 2.5, 1),
            marks=(),
        ),
        pytest.param(
            "irregular_facade",
            (1, 1.2, 1),
            marks=(),
        ),
        pytest.param(
            "irregular_facade",
            (0.6, 0.6, 1),
            marks=(),
        ),
    ],
)
def test_examples_retarget_to_valid_hierarchies(name, factors):
    root = model.read(EXAMPLES / f"{name}.json")
    size = scaled(root, factors)
    result = retarget(root, size)
    assert_valid(result, size)
    assert assert_fixed_kept(root, result) > 0


def test_irregular_facade_cannot_go_below_its_fixed_storeys():
    # along y the door and the shops are fixed, 4 m; the storeys above may shrink to nothing:
    # 3.5 m is refused, 4 m is the shortest façade (every upper storey gone)
    root = model.read(EXAMPLES / "irregular_facade.json")
    assert min_length(root, 1) == pytest.approx(4)
    with pytest.raises(BgrError) as e:
        retarget(root, (20, 3.5, 0.4), "y")
    assert "need at least 4 m" in e.value.message and "3.5" in e.value.message
    result = retarget(root, (20, 4, 0.4), "y")
    assert_valid(result, (20, 4, 0.4))
    assert all(b.hi[1] <= 4 + 1e-6 for b in result.walk())


def test_box_on_a_fixed_and_a_moved_box_overlaps():
    # a (S, 0-4) under b (x 0-1) and w (x 1-4); d (F along y, 0-4, x 2-4) under w as well.
    # Height 10 to 8: the primary a, b shrinks a to 3.2; the secondary d, w keeps d at 0-4
    # and w is attached to a at 3.2, so w (3.2-8) overlaps d (0-4) in x 2-4, y 3.2-4, though
    # a valid result exists (a 0-4, b 4-8, d 0-4, w 4-8; the fixed boxes need only 4).
    kids = [
        box("a", (0, 0, 0), (2, 4, 1)),
        box("b", (0, 4, 0), (1, 10, 1)),
        box("d", (2, 0, 0), (4, 4, 1), "SFS"),
        box("w", (1, 4, 0), (4, 10, 1)),
    ]
    root = parse(box("root", (0, 0, 0), (4, 10, 1), "SSS", kids))
    assert min_length(root, 1) == pytest.approx(4)
    result = retarget(root, (4, 8, 1), "y")
    assert model.check(result) == []


def test_box_on_a_fixed_and_a_moved_box_when_stretched():
    # the same hierarchy stretched to 12: d, fixed on the ground, holds the face at 4 (its
    # top), so a stays 4 and b and w take the 2 m. (The paper's greedy placement put a's top,
    # and w, at 4.8, leaving a hole over d: issue 24.)
    kids = [
        box("a", (0, 0, 0), (2, 4, 1)),
        box("b", (0, 4, 0), (1, 10, 1)),
        box("d", (2, 0, 0), (4, 4, 1), "SFS"),
        box("w", (1, 4, 0), (4, 10, 1)),
    ]
    root = parse(box("root", (0, 0, 0), (4, 10, 1), "SSS", kids))
    result = retarget(root, (4, 12, 1), "y")
    got = {c.id: (round(c.lo[1], 9), round(c.hi[1], 9)) for c in result.children}
    assert got == {"a": (0, 4), "b": (4, 12), "d": (0, 4), "w": (4, 12)}
    assert_valid(result, (4, 12, 1))


@st.composite
def guillotine(draw) -> dict:
    """A small hierarchy of nested splits: every inner box cut along one axis into 2-3 parts."""
    counter = itertools.count()

    def build(lo, hi, depth, tags):
        children = []
        if depth == 0 or (depth < 3 and draw(st.booleans())):
            axis = draw(st.integers(0, 2))
            weights = draw(st.lists(st.integers(1, 4), min_size=2, max_size=3))
            edges = np.cumsum([0, *weights]) / sum(weights)
            for a, b in itertools.pairwise(edges):
                clo, chi = list(lo), list(hi)
                clo[axis] = lo[axis] + a * (hi[axis] - lo[axis])
                chi[axis] = lo[axis] + b * (hi[axis] - lo[axis]) if b < 1 else hi[axis]
                tag = "".join(draw(st.sampled_from("SSRRF")) for _ in range(3))
                children.append(build(clo, chi, depth + 1, tag))
        return box(f"n{next(counter)}", lo, hi, tags, children)

    size = [float(draw(st.integers(2, 12))) for _ in range(3)]
    return build([0.0, 0.0, 0.0], size, 0, "SSS")


@settings(
    max_examples=40,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(
    guillotine(),
    st.tuples(*[st.sampled_from([0.6, 2.5, 1.0]) for _ in range(3)]),
    st.sampled_from(["".join(p) for p in itertools.permutations("xyz")]),
)
def test_random_guillotine_hierarchies_retarget_to_valid_hierarchies(doc, factors, order):
    root = parse(doc)
    # the sizes asked for, raised to what the fixed boxes need (a shorter size is refused)
    size = [float(v) for v in root.size]
    probe = root.copy()
    for name in order:
        a = AXES.index(name)
        need = min_length(probe, a)
        want = float(root.size[a]) * factors[a]
        if want < need - 1e-9:
            with pytest.raises(BgrError, match="fixed boxes"):
                retarget_axis(probe.copy(), a, want)
        size[a] = max(want, need)
        probe = retarget_axis(probe, a, size[a])
    result = retarget(root, size, order)
    assert_valid(result, size)
    assert_fixed_kept(root, result)
    assert np.array_equal(parts(result), parts(probe))  # retargeting is deterministic
    assert np.array_equal(parts(root), parts(parse(doc)))  # the input is left alone


def test_an_r_box_holding_a_fixed_box_is_deleted_when_it_cannot_shrink():
    # bay (R, 0-5) holding a window fixed along x (1-4), then a pier (S, 5-7); width 7 to 2.5.
    # The bay may go (the minimum is 0) but the cascade's share (-4.5 of 5) buys no deletion
    # and the bay cannot be scaled below its window (3): the placement does not fit, and the
    # fitting deletes the bay and gives the pier the whole width
    kids = [
        box("bay", (0, 0, 0), (5, 4, 1), "RSS", [box("window", (1, 0, 0), (4, 4, 1), "FSS")]),
        box("pier", (5, 0, 0), (7, 4, 1)),
    ]
    root = parse(box("root", (0, 0, 0), (7, 4, 1), "SSS", kids))
    assert min_length(root, 0) == 0
    result = retarget(root, (2.5, 4, 1), "x")
    assert_valid(result, (2.5, 4, 1))
    assert layout(result) == [("pier", 0, 2.5)]
    # to 4 the paper's cascade fits: the pier gives its 2 m, the bay is scaled to 4 (>= 3)
    assert layout(retarget(root, (4, 4, 1), "x")) == [("bay", 0, 4)]


def test_an_r_box_that_cannot_shrink_beside_a_fixed_one_leaves_a_gap():
    # bay (R, 0-5, all window fixed along x), pier F 5-10: to 6 only the pier fits; nothing
    # can take the 1 m left, so a gap stays below the pier rather than an overlap
    kids = [
        box("bay", (0, 0, 0), (5, 4, 1), "RSS", [box("window", (0, 0, 0), (5, 4, 1), "FSS")]),
        box("pier", (5, 0, 0), (10, 4, 1), "FSS"),
    ]
    root = parse(box("root", (0, 0, 0), (10, 4, 1), "SSS", kids))
    assert min_length(root, 0) == 5
    result = retarget(root, (6, 4, 1), "x")
    assert_valid(result, (6, 4, 1))
    assert [c.id for c in result.children] == ["pier"]
    assert result.children[0].size[0] == pytest.approx(5)


def test_boxes_squeezed_to_nothing_are_deleted_and_the_next_axis_goes_on():
    # S 2, S 2, F 3 to width 3 (the minimum): both S boxes are deleted; y is retargeted next
    # (zero-length boxes once made the compatibility graph cyclic and the analysis hang)
    root = row((2, "S"), (2, "S"), (3, "F"))
    first = retarget(root, (3, 10, 1), "x")
    assert layout(first) == [("b2", 0, 3)]
    result = retarget(first, (3, 12, 1), "y")
    assert_valid(result, (3, 12, 1))


def test_fixed_columns_side_by_side_need_only_the_taller():
    # two columns: a fixed 4 m box under an S box, and an S box under a fixed 4 m box. Their
    # fixed boxes are in different columns, so 4 m is enough: each column squeezes its S box
    kids = [
        box("a", (0, 0, 0), (1, 4, 1), "SFS"),
        box("a2", (0, 4, 0), (1, 8, 1)),
        box("b", (1, 0, 0), (2, 4, 1)),
        box("b2", (1, 4, 0), (2, 8, 1), "SFS"),
    ]
    root = parse(box("root", (0, 0, 0), (2, 8, 1), "SSS", kids))
    assert min_length(root, 1) == pytest.approx(4)
    for height in (4, 5, 6.5):
        result = retarget(root, (2, height, 1), "y")
        assert_valid(result, (2, height, 1))
        assert assert_fixed_kept(root, result) == 2


def test_empty_space_between_children_scales_like_an_s_box():
    # a (F, 1-3), b (R, 4-6), c (S, 7-9) with gaps between them and the parent's ends, to 20:
    # one sequence a, b, c with the gaps as S units; the R box takes the change first and is
    # repeated at its own size (5 copies), its copies numbered from 1
    kids = [
        box("a", (1, 1, 0), (3, 4, 2), "FFS"),
        box("b", (4, 1, 0), (6, 4, 2), "RSS"),
        box("c", (7, 0, 0), (9, 5, 2)),
    ]
    root = parse(box("g", (0, 0, 0), (10, 5, 2), "SSS", kids))
    result = retarget(root, (20, 5, 2), "x")
    assert_valid(result, (20, 5, 2))
    assert layout(result) == [
        ("a", 1, 3),
        ("b", 4, 6),
        *[(f"b~{k}", 4 + 2 * k, 6 + 2 * k) for k in range(1, 6)],
        ("c", 17, 19),
    ]


def test_a_fitted_node_gives_the_placement_back_when_it_was_valid(monkeypatch):
    # force the fitting on every node: the placement's copies are undone, and the fitting of a
    # valid tessellation is that tessellation (no gap, no move), with the copies numbered anew
    # from 1 (the undone ones leave no holes)
    from bgr.inverse.boxes import retarget as retargeting

    root = model.read(EXAMPLES / "regular_facade.json")
    size = (30, 20, 0.5)
    plain = retarget(root, size)
    monkeypatch.setattr(retargeting, "valid", lambda layout, placed: False)
    forced = retarget(root, size)
    assert_valid(forced, size)
    assert np.allclose(parts(forced), parts(plain), atol=1e-6)
    assert sorted(b.id for b in forced.walk()) == sorted(b.id for b in plain.walk())


def test_too_many_boxes_are_refused_quickly(tmp_path, capsys):
    content = text(
        box(
            "r",
            (0, 0, 0),
            (1, 1, 1),
            "SSS",
            [box("a", (0, 0, 0), (0.001, 1, 1), "RSS"), box("b", (0.001, 0, 0), (1, 1, 1))],
        )
    )
    code, err, out = retarget_cli(tmp_path, capsys, content, "--size", "1000,1,1")
    assert code == 1 and "more than 200,000 boxes" in err and "--max-boxes" in err
    assert not out.exists()
    code, err, out = retarget_cli(
        tmp_path, capsys, content, "--size", "10,1,1", "--max-boxes", "20000"
    )
    assert code == 0 and len(list(model.read(out).walk())) == 9_003


def test_a_result_over_max_boxes_is_refused_before_any_copy_is_made(monkeypatch):
    # forty storeys each repeated 30 times: no one repeat passes the limit, all of them do; the
    # walk is counted first, so the refusal comes before the first copy (4 s of copies before)
    storeys = [
        box(f"s{k}", (0, k, 0), (1, k + 1, 1), "RSS", [box(f"w{k}", (0.2, k, 0), (0.8, k + 1, 1))])
        for k in range(40)
    ]
    from bgr.inverse.boxes import retarget as retargeting

    root = parse(box("r", (0, 0, 0), (1, 40, 1), "SSS", storeys))
    made = []
    real = retargeting.Retargeter.replicate
    monkeypatch.setattr(
        retargeting.Retargeter, "replicate", lambda self, *a: made.append(1) or real(self, *a)
    )
    with pytest.raises(BgrError, match="more than 2,000 boxes"):
        retarget_axis(root, 0, 30.0, max_boxes=2_000)
    assert made == []
    assert len(list(root.walk())) == 81  # the counting walk was undone
    assert len(list(retarget_axis(root, 0, 30.0, max_boxes=3_000).walk())) == 1 + 40 * 2 * 30
    assert len(made) == 40 * 29


def test_ids_with_a_tilde_count_their_alignments():
    # the input may use "~" in its ids: its boxes are not taken for copies
    kids = [box("w~1", (0, 0, 0), (2, 4, 1)), box("door~a", (2, 0, 0), (4, 4, 1), "FSS")]
    plain = [box("w", (0, 0, 0), (2, 4, 1)), box("door", (2, 0, 0), (4, 4, 1), "FSS")]
    tilde = parse(box("root", (0, 0, 0), (4, 4, 1), "SSS", kids))
    root = parse(box("root", (0, 0, 0), (4, 4, 1), "SSS", plain))
    size = (6, 5, 1)
    assert alignments(tilde, retarget(tilde, size)) == alignments(root, retarget(root, size))
    assert alignments(root, retarget(root, size))[0] > 0


# ---- 6. the order of the axes -------------------------------------------------------------


def bench_facade(storeys: int, seed: int) -> model.Box:
    """The random irregular façade of bench/boxes.py (bays in offset columns, no storey boxes)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("bench_boxes", ROOT / "bench" / "boxes.py")
    assert spec is not None and spec.loader is not None
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    return model.parse(json.dumps(bench.facade(storeys, seed)), "bench")


def test_xy_and_yx_give_different_valid_results():
    # the paper's Figure 12. (The examples' storeys have nothing R along y: there x and y
    # commute. On the bench's façades the alignment groups y finds depend on the widths x gave.)
    root = bench_facade(3, 1)
    size = (root.size[0] * 1.5, root.size[1] * 1.5, root.size[2])
    before = parts(root)
    xy = retarget(root, size, "xy")
    yx = retarget(root, size, "yx")
    for result in (xy, yx):
        assert_valid(result, size)
        assert model.holes(root, result) == []
    a, b = parts(xy), parts(yx)
    assert len(a) != len(b)
    assert alignments(root, xy) != alignments(root, yx)
    # the input is not changed by either
    assert np.array_equal(parts(root), before)


# ---- 7. the grammar bgr infer writes ------------------------------------------------------


@pytest.fixture(scope="module")
def inferred(tmp_path_factory) -> dict[str, Path]:
    """Each example's grammar written by ``bgr infer`` next to a copy of the example (its
    parts then resolve inside the grammar's folder)."""
    where = tmp_path_factory.mktemp("boxes")
    shutil.copytree(EXAMPLES / "parts", where / "parts")
    out = {}
    for name in NAMES:
        shutil.copy(EXAMPLES / f"{name}.json", where / f"{name}.json")
        path = where / f"{name}.bgr"
        # the default kind for a .json whose first key is "root"
        assert main(["infer", str(where / f"{name}.json"), "-o", str(path)]) == 0
        out[name] = path
    return out


def derived(path: Path, size) -> np.ndarray:
    result = bgr.derive(bgr.load(path), attrs=dict(zip(ATTRS, map(float, size), strict=True)))
    t = result.terminals.freeze()
    return np.array(sorted(np.round(np.hstack([t.origin, t.origin + t.size]), 9).tolist()))


@pytest.mark.parametrize("name", NAMES)
def test_inferred_grammar_gives_the_input_back(inferred, name):
    root = model.read(EXAMPLES / f"{name}.json")
    want, got = parts(root), derived(inferred[name], root.size)
    assert want.shape == got.shape
    assert np.allclose(want, got, atol=1e-6)


def test_the_grammar_says_the_least_size_its_fixed_boxes_need(inferred):
    # building.json: the porch (fixed) and the wall around it need 4 x 4 x 2 m
    header = inferred["building"].read_text().splitlines()[:8]
    assert any("need at least 4 x 4 x 2 m" in line for line in header)


def test_infer_matches_the_shipped_grammars(inferred):
    for name in ("regular_facade", "building"):
        shipped = (EXAMPLES / f"{name}.bgr").read_text().splitlines()
        written = inferred[name].read_text().splitlines()
        assert written[1:] == shipped[1:]  # the first line names the input's path


@pytest.mark.parametrize("name", ["regular_facade", "building"])
@pytest.mark.parametrize("factors", [(0.7, 0.7, 0.7), (1.37, 2.1, 1.0), (2.5, 0.8, 1.6)])
def test_inferred_grammar_replicates_as_retarget_does(inferred, name, factors):
    root = model.read(EXAMPLES / f"{name}.json")
    size = scaled(root, factors)
    want, got = parts(retarget(root, size)), derived(inferred[name], size)
    assert len(want) != len(parts(root))  # something was replicated or deleted
    assert want.shape == got.shape
    assert np.allclose(want, got, atol=1e-6)


# ---- 8. bad input -------------------------------------------------------------------------

BAD = {
    "a key beside root": (
        '{"root": {"id": "r", "min": [0, 0, 0], "max": [1, 1, 1]}, "extra": 1}',
        ["'extra'", "root"],
    ),  # fmt: skip
    "overlap": (
        text(
            box(
                "root",
                (0, 0, 0),
                (4, 4, 1),
                "SSS",
                [box("left", (0, 0, 0), (3, 4, 1)), box("right", (2, 0, 0), (4, 4, 1))],
            )
        ),
        ["'left'", "'right'", "overlap"],
    ),
    "outside": (
        text(box("root", (0, 0, 0), (4, 4, 1), "SSS", [box("kid", (0, 0, 0), (5, 4, 1))])),
        ["'kid'", "'root'", "not inside"],
    ),
    "tag": (
        text(box("root", (0, 0, 0), (4, 4, 1), "SSS", [box("odd", (0, 0, 0), (4, 4, 1), "QSS")])),
        ["'odd'", '"Q"'],
    ),
    "infinite": (
        '{"root": {"id": "root", "min": [0, 0, 0], "max": [4, 4, 1], "children": ['
        '{"id": "huge", "min": [0, 0, 0], "max": [1e999, 4, 1]}]}}',
        ["'huge'", "not finite"],
    ),
    "duplicate": (
        text(
            box(
                "root",
                (0, 0, 0),
                (4, 4, 1),
                "SSS",
                [box("twin", (0, 0, 0), (2, 4, 1)), box("twin", (2, 0, 0), (4, 4, 1))],
            )
        ),
        ["'twin'"],
    ),
    "flat": (
        text(box("root", (0, 0, 0), (4, 4, 1), "SSS", [box("flat", (0, 0, 0), (4, 0, 1))])),
        ["'flat'", "max must exceed min"],
    ),
    "no-root": (json.dumps({"boxes": []}), ['"root"']),
    "not-json": ("{root: ", ["bad.json:1:2", "not JSON"]),
    "fixed-root": (text(box("root", (0, 0, 0), (4, 4, 1), "FSS")), ["'root'", "fixed (F) along x"]),
    "too-small": (
        text(
            box(
                "root",
                (0, 0, 0),
                (10, 4, 1),
                "SSS",
                [box("a", (0, 0, 0), (6, 4, 1), "FSS"), box("b", (6, 0, 0), (10, 4, 1))],
            )
        ),
        ["fixed boxes along x need at least 6 m", "5 m"],
    ),
}


def retarget_cli(tmp_path, capsys, content: str, *args: str) -> tuple[int, str, Path]:
    source = tmp_path / "bad.json"
    source.write_text(content)
    out = tmp_path / "out.json"
    code = main(["retarget", str(source), *args, "-o", str(out)])
    return code, capsys.readouterr().err, out


@pytest.mark.parametrize("case", list(BAD))
def test_bad_input_exits_1_naming_the_boxes(tmp_path, capsys, case):
    content, words = BAD[case]
    code, err, out = retarget_cli(tmp_path, capsys, content, "--size", "5,4,1")
    assert code == 1
    for word in words:
        assert word in err, err
    # as every command prints an error: FILE[:LINE:COL]: error: MESSAGE, then hint: (issue 24)
    first = err.splitlines()[0]
    assert first.startswith(str(tmp_path / "bad.json")) and ": error: " in first, err
    assert all(line.startswith(("hint: ", "    ")) for line in err.splitlines()[1:]), err
    assert "Traceback" not in err and "internal error" not in err
    assert not out.exists()
    assert list(tmp_path.iterdir()) == [tmp_path / "bad.json"]  # no temporary left either


@pytest.mark.parametrize(
    "name, content, message",
    [
        ("building.bgr", "Lot --> extrude(10) Mass\n", "a grammar (.bgr), not a box hierarchy"),
        ("photo.jpg", b"\xff\xd8\xff\xe0\x00\x10JFIF\x00", "a JPEG image, not a box hierarchy"),
        ("boxes.json", '{"boxes": []}', 'a boxes file is an object with a "root" box'),
        ("missing.json", None, "no such file"),
    ],
)
def test_retarget_errors_print_as_every_command_does(tmp_path, capsys, name, content, message):
    """`bgr retarget building.bgr` printed "error: building.bgr:1:1: not JSON" (issue 24): now
    `file: error: message` and a hint saying what retarget reads, like `bgr derive` and `infer`."""
    path = tmp_path / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    elif content is not None:
        path.write_text(content)
    assert main(["retarget", str(path), "--size", "5,4,1", "-o", str(tmp_path / "o.json")]) == 1
    lines = capsys.readouterr().err.splitlines()
    assert lines[0] == f"{path}: error: {message}"
    assert len(lines) == 2 and lines[1].startswith("hint: ")
    if content is not None:
        assert '{"root": {"id": ...' in lines[1]
    # an error found while retargeting names the file too
    fixed = tmp_path / "fixed.json"
    fixed.write_text(text(box("root", (0, 0, 0), (4, 4, 1), "FSS")))
    assert main(["retarget", str(fixed), "--size", "5,4,1"]) == 1
    lines = capsys.readouterr().err.splitlines()
    assert lines == [
        f"{fixed}: error: box 'root' is fixed (F) along x: it stays 4 m",
        "hint: give --size with 4 for x, or tag the root S",
    ]


@pytest.mark.parametrize("word", ["NaN", "Infinity"])
def test_nan_is_refused_naming_the_box(tmp_path, capsys, word):
    content = (
        '{"root": {"id": "root", "min": [0, 0, 0], "max": [4, 4, 1], "children": ['
        f'{{"id": "bad-box", "min": [{word}, 0, 0], "max": [4, 4, 1]}}]}}}}'
    )
    code, err, out = retarget_cli(tmp_path, capsys, content, "--size", "5,4,1")
    assert code == 1 and not out.exists() and "Traceback" not in err
    assert word in err
    assert "'bad-box'" in err, err


def test_nan_is_refused(tmp_path, capsys):
    content = '{"root": {"id": "root", "min": [NaN, 0, 0], "max": [4, 4, 1]}}'
    code, err, out = retarget_cli(tmp_path, capsys, content, "--size", "5,4,1")
    assert code == 1 and "NaN" in err and not out.exists() and "Traceback" not in err


@pytest.mark.parametrize(
    "args",
    [
        ["--size", "3,4"],
        ["--size", "a,b,c"],
        ["--size", "1_0,4,1"],
        ["--size", "0,4,1"],
        ["--size", "5,4,1", "--order", "xx"],
        ["--size", "5,4,1", "--order", "xw"],
    ],
)
def test_bad_usage_exits_2(tmp_path, capsys, args):
    good = text(box("root", (0, 0, 0), (4, 4, 1)))
    code, err, out = retarget_cli(tmp_path, capsys, good, *args)
    assert code == 2
    assert "bgr retarget" in err and ("--size" in err or "--order" in err)
    assert "Traceback" not in err and not out.exists()


def test_a_missing_size_is_a_usage_error(tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        main(["retarget", str(EXAMPLES / "building.json")])
    assert e.value.code == 2


def test_the_irregular_facade_below_its_fixed_storeys_exits_1(tmp_path, capsys):
    out = tmp_path / "out.json"
    source = str(EXAMPLES / "irregular_facade.json")
    code = main(["retarget", source, "--size", "20,3.5,0.4", "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 1 and "need at least 4 m" in err and not out.exists()


json_values = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-5, 20)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.sampled_from(["S", "R", "F", "x", "", "root", "a"]),
    lambda inner: (
        st.lists(inner, max_size=4)
        | st.dictionaries(
            st.sampled_from(
                ["id", "min", "max", "behavior", "children", "mesh", "x", "y", "source"]
            ),
            inner,
            max_size=6,
        )
    ),
    max_leaves=30,
)


@settings(max_examples=300, deadline=None, derandomize=True)
@given(json_values)
def test_any_json_under_root_is_read_or_refused_cleanly(value):
    # whatever the "root" holds, reading gives a hierarchy or a BgrError, never another exception
    text = json.dumps({"root": value}, allow_nan=True)
    try:
        model.parse(text)
    except BgrError as e:
        assert e.message


@settings(max_examples=300, deadline=None, derandomize=True)
@given(st.data())
def test_a_valid_file_cut_or_changed_anywhere_is_read_or_refused_cleanly(data):
    text = (EXAMPLES / "building.json").read_text()
    at = data.draw(st.integers(0, len(text)))
    cut = data.draw(st.integers(0, 12))
    junk = data.draw(st.text(alphabet='{}[]",:0123456789.-eENaIfity xyzSRF', max_size=8))
    try:
        root = model.parse(text[:at] + junk + text[at + cut :])
    except BgrError as e:
        assert e.message
    else:
        assert model.check(root) == []


# ---- 9. output files ----------------------------------------------------------------------


def test_json_output_reads_back_and_retargets_again(tmp_path, capsys):
    out = tmp_path / "out.json"
    args = ["retarget", str(EXAMPLES / "regular_facade.json"), "--size", "30,20,0.5"]
    assert main([*args, "--order", "yx", "-o", str(out)]) == 0
    assert "30 x 20 x 0.5 m" in capsys.readouterr().err
    first = model.read(out)
    assert_valid(first, (30, 20, 0.5))
    expected = retarget(model.read(EXAMPLES / "regular_facade.json"), (30, 20, 0.5), "yx")
    assert np.allclose(parts(first), parts(expected), atol=1e-9)
    # the copies read back with their source and replica number, under fresh ids
    copies = [b for b in first.walk() if b.replica]
    assert copies and all(b.id.startswith(b.source + "~") for b in copies)
    assert {b.id for b in copies} == {b.id for b in expected.walk() if b.replica}
    # and again, from the written file, back to a smaller size
    again = tmp_path / "again.json"
    assert main(["retarget", str(out), "--size", "12,9,0.5", "-o", str(again)]) == 0
    second = model.read(again)
    assert_valid(second, (12, 9, 0.5))
    assert assert_fixed_kept(first, second) > 0


def test_a_mesh_outside_the_boxes_folder_needs_allow_path(tmp_path, capsys):
    outside = tmp_path / "parts"
    outside.mkdir()
    shutil.copy(EXAMPLES / "parts" / "door.obj", outside / "door.obj")
    here = tmp_path / "boxes"
    here.mkdir()
    doc = box("root", (0, 0, 0), (4, 4, 1))
    doc["mesh"] = "../parts/door.obj"
    (here / "b.json").write_text(text(doc))
    out = here / "b.obj"
    assert main(["retarget", str(here / "b.json"), "--size", "5,4,1", "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "outside the boxes file's folder" in err and "--allow-path" in err
    assert not out.exists()
    args = ["retarget", str(here / "b.json"), "--size", "5,4,1", "-o", str(out)]
    assert main([*args, "--allow-path", str(outside)]) == 0 and out.exists()


def test_a_byte_order_mark_is_read(tmp_path):
    path = tmp_path / "bom.json"
    path.write_bytes(b"\xef\xbb\xbf" + text(box("r", (0, 0, 0), (1, 1, 1))).encode())
    assert model.read(path).id == "r"


def test_glb_output_passes_the_khronos_validator(tmp_path, capsys, validator):
    out = tmp_path / "building.glb"
    args = ["retarget", str(EXAMPLES / "building.json"), "--size", "30,20,10", "-o", str(out)]
    assert main(args) == 0
    assert out.stat().st_size > 0
    report = gltf.validate(validator, [out])[str(out)]
    assert report["errors"] == 0 and report["warnings"] == 0, gltf.clean(report)
    assert report["totalTriangleCount"] > 0
