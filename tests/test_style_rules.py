"""Splitting rules of style sheets (inverse/style/rules.py): detection (section 4.3.4 of Zhang et
al.) and the splitting functions of section 5.2.3 (equations 8 and 9)."""

from __future__ import annotations

import itertools
import math
import time

import numpy as np
import pytest
from conftest import SHARED

from bgr.inverse.style.rules import (
    Rule,
    default_window,
    detect_rule,
    edge_signal,
    kmeans_1d,
    label_signal,
    layout,
    merge_fragments,
    rule_from_labels,
    split_h,
    split_v,
    variance_signal,
)

WINDOW_TILES = SHARED / "data" / "textured" / "candler" / "windowTiles_2000x256.jpg"

# --- split_h / split_v: equations 8 and 9 by hand ----------------------------------------------
# The rule A = [1, 2, 1], B = [3, 3]: sum A = 4, sum B = 6, one pattern a1 b1 a2 b2 a3 = 10.


def test_split_h_tail_with_some_insertables() -> None:
    # W = 25: x = floor(25 / 10) = 2; rest = 25 - 2 * 10 = 5; b1 = 3 <= 5, b1 + b2 = 6 > 5: y = 1
    # (0 < y < m = 2); Sn = x m + y = 2 * 2 + 1 = 5.
    # The scalables of 2 patterns plus the tail a1 a2: 2 * 4 + (1 + 2) = 11; they must cover
    # W - x sum B - b1 = 25 - 12 - 3 = 10: Sr = 10 / 11.  (Equation 9 as printed,
    # (25 - 20 - 3) / 11 = 2 / 11, would leave 2 * 6 + 3 + 11 * 2 / 11 = 17 of the 25 covered.)
    sn, sr = split_h([1, 2, 1], [3, 3], 25)
    assert sn == 5
    assert sr == pytest.approx(10 / 11)


def test_split_h_tail_without_insertables() -> None:
    # W = 22: x = 2; rest = 2 < b1 = 3: y = 0; Sn = 4; Sr = (22 - 12 - 0) / (8 + a1) = 10 / 9
    assert split_h([1, 2, 1], [3, 3], 22) == (4, pytest.approx(10 / 9))


def test_split_h_face_narrower_than_one_pattern() -> None:
    # W = 7: x = floor(7 / 10) = 0; rest 7 holds b1 + b2 = 6: y = 2 = m; Sn = 2;
    # Sr = (7 - 6) / (a1 + a2 + a3) = 1 / 4 (here equation 9 as printed agrees: x = 0)
    assert split_h([1, 2, 1], [3, 3], 7) == (2, pytest.approx(0.25))
    # W = 4: x = 0; b1 = 3 <= 4 < 6: y = 1; Sr = (4 - 3) / (a1 + a2) = 1 / 3
    assert split_h([1, 2, 1], [3, 3], 4) == (1, pytest.approx(1 / 3))


def test_split_h_exact_repeats() -> None:
    # W = 30 = 3 patterns: x = 3 (not 2 by rounding); rest 0: y = 0; Sn = 6;
    # Sr = (30 - 18) / (12 + a1) = 12 / 13: the tail's a1 takes its share.  The tie-break
    # (split_h's docstring): x = 2 repeats and the full tail y = m = 2 hold the same Sn = 6
    # windows with Sr = (30 - 3 * 6) / (3 * 4) = 1, nearer 1 than 12 / 13: that is taken
    assert split_h([1, 2, 1], [3, 3], 30) == (6, pytest.approx(1.0))
    sizes = [size for _, _, size in layout([1, 2, 1], [3, 3], 30)]
    assert sizes == pytest.approx([1, 3, 2, 3, 1] * 3)  # the texture three times, unstretched
    assert split_h([0.1, 0.1], [0.1], 0.3)[0] == 1  # 0.3 / 0.2 = 1.4999.. in floats: x = 1


def test_split_h_without_insertables_stretches_one_scalable() -> None:
    assert split_h([4.0], [], 10.0) == (0, 2.5)
    assert layout([4.0], [], 10.0) == [("scalable", 0, 10.0)]


def test_split_h_window_at_the_edge() -> None:
    # A = [0, 2, 0] (windows touch both edges), B = [3, 3]: pattern 8.  W = 17: x = 2, rest 1,
    # y = 0; Sr = (17 - 12) / (2 * 2 + a1 = 0) = 5 / 4
    assert split_h([0, 2, 0], [3, 3], 17) == (4, pytest.approx(1.25))
    # W = 2 is narrower than b1 and the only scalable it could hold, a1, is 0 wide
    with pytest.raises(ValueError, match="cannot be filled"):
        split_h([0, 2, 0], [3, 3], 2)
    assert split_h([0, 2, 0], [3, 3], 0) == (0, 1.0)  # nothing to fill


@pytest.mark.parametrize(
    ("a", "b", "w"),
    [
        ([1, 2, 1], [3, 3], math.nan),
        ([1, 2, 1], [3, 3], math.inf),
        ([1, 2, 1], [3, 3], -1.0),
        ([1, -2, 1], [3, 3], 10.0),
        ([1, 2, 1], [3, math.inf], 10.0),
        ([1, 2], [3, 3], 10.0),  # m + 1 scalables for m insertables
        ([0, 0], [0], 10.0),  # a rule of no width
        ([0.0], [], 10.0),  # a plain wall of no width
    ],
)
def test_split_refuses_bad_input(a: list[float], b: list[float], w: float) -> None:
    with pytest.raises(ValueError):
        split_h(a, b, w)
    with pytest.raises(ValueError):
        layout(a, b, w)


def test_split_v_is_split_h_along_the_height() -> None:
    # C bottom to top: base 0.5, between the floors' windows 0.2, cornice 0.3; D = [1, 1]:
    # pattern 3.0; H = 4.5: x = 1, rest 1.5 holds d1 = 1 only: y = 1; Sn = 1 * 2 + 1 = 3;
    # Sr = (4.5 - 2 - 1) / (1.0 + 0.5 + 0.2) = 1.5 / 1.7
    assert split_v([0.5, 0.2, 0.3], [1.0, 1.0], 4.5) == (3, pytest.approx(1.5 / 1.7))


def test_layout_order_and_sizes() -> None:
    s = 10 / 11  # Sr of W = 25 above
    expected = [
        ("scalable", 0, 1 * s),
        ("insertable", 0, 3),
        ("scalable", 1, 2 * s),
        ("insertable", 1, 3),
        ("scalable", 2, 1 * s),
    ] * 2 + [("scalable", 0, 1 * s), ("insertable", 0, 3), ("scalable", 1, 2 * s)]
    got = layout([1, 2, 1], [3, 3], 25)
    assert [(k, i) for k, i, _ in got] == [(k, i) for k, i, _ in expected]
    assert [v for _, _, v in got] == pytest.approx([v for _, _, v in expected])
    assert sum(v for _, _, v in got) == pytest.approx(25)
    assert sum(k == "insertable" for k, _, _ in got) == split_h([1, 2, 1], [3, 3], 25)[0]


@pytest.mark.parametrize("w", [0.5, 4, 7, 9.99, 10, 17, 22, 25, 30, 123.4])
def test_layout_fills_the_face(w: float) -> None:
    for a, b in (([1, 2, 1], [3, 3]), ([0, 2, 0], [3, 3]), ([0.7, 0.1, 0.2, 0.05], [1, 2, 0.5])):
        try:
            got = layout(a, b, w)
        except ValueError:
            assert a[0] == 0 and w < b[0]  # only the unfillable case of a window at the edge
            continue
        assert sum(v for _, _, v in got) == pytest.approx(w)
        assert all(v >= 0 for _, _, v in got)
        kinds = [k for k, _, _ in got]
        assert kinds[0] == kinds[-1] == "scalable"
        assert all(p != q for p, q in itertools.pairwise(kinds) if "insertable" in (p, q))


# --- labelling: k-means and the dynamic programme ------------------------------------------------


def test_kmeans_centres_by_hand() -> None:
    # start at min 0 and max 1: {0, 0.1} and {0.8, 0.9, 1}: centres 0.05 and 0.9; stable
    assert kmeans_1d(np.array([0.0, 0.9, 0.1, 1.0, 0.8])) == pytest.approx((0.05, 0.9))


def _energy(signal: np.ndarray, labels: np.ndarray, lam: float) -> float:
    """Equation 3 written out, with the centres of k-means (checked by hand above)."""
    mu = kmeans_1d(signal)
    data = sum(abs(v - mu[label]) for v, label in zip(signal, labels, strict=True))
    return data + lam * sum(p != q for p, q in itertools.pairwise(labels))


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("lam", [0.025, 0.2, 1.0])
def test_labelling_is_the_minimum(seed: int, lam: float) -> None:
    rng = np.random.default_rng(seed)
    signal = rng.random(12)
    if seed % 2:  # near-ties and a smaller spread, where lambda decides
        signal = np.round(signal * 4) / 40
    labels = label_signal(signal, lam)
    best = min(_energy(signal, np.array(c), lam) for c in itertools.product((0, 1), repeat=12))
    assert _energy(signal, labels, lam) == pytest.approx(best, abs=1e-12)
    assert np.array_equal(label_signal(signal.copy(), lam), labels)  # deterministic


def test_labelling_smooths_and_keeps_high_variance_as_windows() -> None:
    signal = np.array([0.0, 0.05, 0.0, 0.9, 1.0, 0.5, 1.0, 0.95, 0.0, 0.1])
    # with lambda = 0.6 one change costs more than relabelling the 0.5 dip (|0.5 - mu1| ~ 0.39)
    assert label_signal(signal, 0.6).tolist() == [0, 0, 0, 1, 1, 1, 1, 1, 0, 0]
    assert label_signal(signal, 0.0).tolist() == [0, 0, 0, 1, 1, 0, 1, 1, 0, 0]


def test_constant_signal_is_all_scalable() -> None:
    assert not label_signal(np.full(50, 0.3)).any()
    flat = np.full((20, 30, 3), 128, np.uint8)
    rule = detect_rule(flat, "x", 3.0)
    assert rule.scalable == pytest.approx((3.0,)) and rule.insertable == ()


# --- fragments and rules ------------------------------------------------------------------------


def test_merge_fragments() -> None:
    bay = [1] * 20 + [0, 0] + [1] * 5  # a 27-sample window cut by a 2-sample dip
    labels = np.array([0] * 10 + bay + [0] * 10 + [1] * 25 + [0] * 3 + [1] * 25 + [0] * 30)
    labels[115:118] = 1  # a 3-sample stain on the wall, 15 samples from the last window
    merged = merge_fragments(labels, window=25)
    # the 5-sample piece (< 12.5) joins its bay: 27 <= 1.25 * 25
    assert merged[10:37].all() and not merged[:10].any()
    # the 3-sample mullion between two whole bays stays; the stain becomes wall
    assert merged[47:72].all() and not merged[72:75].any() and merged[75:100].all()
    assert not merged[100:].any()
    # default window: insertable runs 20, 5, 25, 25, 3 hold 78 samples; the run holding the
    # 39th (sorted 3, 5, 20, 25, 25: cumulative 3, 8, 28, 53) is 25 long
    assert default_window(labels) == 25
    assert np.array_equal(merge_fragments(labels), merged)


def test_rule_from_labels_orders() -> None:
    labels = np.array([1, 1, 0, 0, 0, 1, 1, 1, 0, 0])  # 10 pixels of a 5 m face: 0.5 m each
    rule = rule_from_labels(labels, 5.0)
    assert rule.scalable == pytest.approx((0.0, 1.5, 1.0))  # a1 = 0: a window at the left edge
    assert rule.insertable == pytest.approx((1.0, 1.5))
    assert rule.sections == [
        ("scalable", 0, 0),
        ("insertable", 0, 2),
        ("scalable", 2, 5),
        ("insertable", 5, 8),
        ("scalable", 8, 10),
    ]
    up = rule_from_labels(labels, 5.0, axis="y")  # rows: C, D bottom to top
    assert up.scalable == pytest.approx((1.0, 1.5, 0.0))
    assert up.insertable == pytest.approx((1.5, 1.0))
    assert up.sections == rule.sections  # pixel sections stay in image order


# --- detection on images -------------------------------------------------------------------------


def _facade() -> np.ndarray:
    """A 600 x 300 wall with a 4 x 2 grid of windows, irregular spacing, seeded noise."""
    rng = np.random.default_rng(27)
    img = np.empty((300, 600, 3), np.float64)
    img[:] = (205, 185, 160)  # plaster
    cols = [(50, 110), (190, 250), (330, 400), (480, 540)]
    rows = [(40, 120), (170, 250)]  # top to bottom
    for y0, y1 in rows:
        for x0, x1 in cols:
            img[y0:y1, x0:x1] = (45, 55, 75)  # glass
            img[y0 : y0 + 30, x0:x1] += 20  # a faint reflection in the top of the pane
    img += rng.normal(0, 8, img.shape)
    return np.clip(img, 0, 255).astype(np.uint8)


def test_synthetic_facade_rules_within_2_pixels() -> None:
    img = _facade()
    h_rule = detect_rule(img, "x", 600.0)  # one unit a pixel
    # A = gaps 50, 80, 80, 80, 60; B = widths 60, 60, 70, 60
    assert h_rule.scalable == pytest.approx((50, 80, 80, 80, 60), abs=2)
    assert h_rule.insertable == pytest.approx((60, 60, 70, 60), abs=2)
    v_rule = detect_rule(img, "y", 300.0)
    # rows top to bottom: wall 40, window 80, wall 50, window 80, wall 50; C, D bottom to top
    assert v_rule.scalable == pytest.approx((50, 50, 40), abs=2)
    assert v_rule.insertable == pytest.approx((80, 80), abs=2)
    assert [k for k, _, _ in v_rule.sections] == ["scalable", "insertable"] * 2 + ["scalable"]
    assert v_rule.sections[1][1] == pytest.approx(40, abs=2)  # image order: the top window first


def test_window_size_merges_a_window_cut_by_its_muntin() -> None:
    img = _facade()
    img[:, 368:371] = (205, 185, 160)  # a wall-coloured muntin down the third window (330-400)
    # the muntin's columns vary no more than the wall's: the labelling cuts that window in two
    # halves of 38 and 29 pixels; the objective window size (in the caller's unit: 600 px make
    # 6 m) decides whether they are fragments of one window (< 0.5 window) or windows
    whole = detect_rule(img, "x", 6.0, window=0.65)
    assert whole.insertable == pytest.approx((0.6, 0.6, 0.7, 0.6), abs=0.02)
    cut = detect_rule(img, "x", 6.0, window=0.2)
    assert cut.insertable == pytest.approx((0.6, 0.6, 0.38, 0.29, 0.6), abs=0.02)
    assert detect_rule(img, "x", 6.0).insertable == pytest.approx(whole.insertable)  # default
    with pytest.raises(ValueError):
        detect_rule(img, "x", 6.0, window=math.nan)


@pytest.mark.parametrize("axis", ["x", "y"])
def test_a_blank_wall_has_no_window(axis: str) -> None:
    # plaster with +-4 levels of grain: stretched to 0..1 its variance signal is all noise, and
    # k-means and the labelling would cut it into dozens of one-pixel "windows"
    rng = np.random.default_rng(5)
    img = np.clip(205 + rng.integers(-4, 5, (300, 600, 1)), 0, 255).astype(np.uint8)
    img = np.repeat(img, 3, axis=2)
    rule = detect_rule(img, axis, 6.0)
    assert rule.insertable == ()
    assert rule.scalable == pytest.approx((6.0,))
    # one faint window (glass 20 levels darker than the plaster) is still a window: a column
    # through it is 0.27 glass, its variance p (1 - p) 20^2 * 3 / 255^2 = 3.6e-3; a row 0.1
    # glass, 1.7e-3: both over PLAIN_VARIANCE (1e-3)
    img[40:120, 200:260] -= 20
    found = detect_rule(img, axis, 6.0)
    assert found.m == 1
    span = (2.0, 2.6) if axis == "x" else (3.6, 5.2)  # metres; y from the bottom (row 120)
    first = sum(found.scalable[:1])
    assert (first, first + found.insertable[0]) == pytest.approx(span, abs=0.03)


@pytest.mark.parametrize("axis", ["x", "y"])
def test_variance_signal_is_the_summed_channel_variance(axis: str) -> None:
    img = np.random.default_rng(3).integers(0, 256, (37, 53, 3), dtype=np.uint8)
    img[:, 5] = (10, 200, 30)  # one column of one colour
    img[7] = (90, 90, 90)  # one row of one colour
    down = 0 if axis == "x" else 1
    var = (img / 255.0).var(axis=down).sum(axis=-1)  # numpy's variance, 0..1 units
    expected = (var - var.min()) / (var.max() - var.min())
    assert variance_signal(img, axis) == pytest.approx(expected, abs=1e-9)
    assert variance_signal(img, axis).argmin() == (5 if axis == "x" else 7)


def test_signals_refuse_bad_images() -> None:
    with pytest.raises(ValueError):
        variance_signal(np.zeros((4, 4, 3), np.uint8), "z")
    with pytest.raises(ValueError):
        variance_signal(np.zeros((0, 4, 3), np.uint8), "x")
    with pytest.raises(ValueError):
        edge_signal(np.zeros((4, 4, 3), np.float32), "x")


def _window_tiles() -> np.ndarray:
    if not WINDOW_TILES.exists():
        pytest.skip(f"{WINDOW_TILES} is not here (shared data, never committed)")
    from PIL import Image

    with Image.open(WINDOW_TILES) as image:
        return np.asarray(image.convert("RGB"))


# The glass of each of the 10 bays of Candler's window tiles (2000 x 256), read by eye from 5x
# zoomed crops around each mullion (bright vertical lines at x = 0, 200, .., 2000): the dark
# frames around the glass are 12-26 pixels each side of a mullion.
BAYS_BY_EYE = [
    (15, 183),
    (215, 382),
    (416, 582),
    (626, 788),
    (821, 989),
    (1015, 1183),
    (1215, 1382),
    (1418, 1590),
    (1621, 1789),
    (1811, 1985),
]


def test_window_bays_of_a_real_texture() -> None:
    img = _window_tiles()
    rule = detect_rule(img, "x", 2000.0, signal="edges")
    bays = [(b, e) for kind, b, e in rule.sections if kind == "insertable"]
    assert len(bays) == 10
    for (b, e), (eye_b, eye_e) in zip(bays, BAYS_BY_EYE, strict=True):
        assert abs(b - eye_b) <= 40 and abs(e - eye_e) <= 40  # 2 % of the width
    assert sum(rule.scalable) + sum(rule.insertable) == pytest.approx(2000.0)


def test_paper_signal_misses_the_dark_bays() -> None:
    """Why ``edge_signal`` exists: bays 1 and 6 hold dark drawn blinds whose columns vary as
    little as the frames', so the paper's colour-variance labelling calls them wall."""
    img = _window_tiles()
    rule = detect_rule(img, "x", 2000.0)
    bays = [(b, e) for kind, b, e in rule.sections if kind == "insertable"]
    for middle in (100, 1100):  # the middle of bay 1 and of bay 6
        assert not any(b <= middle < e for b, e in bays)
    found = [eye for eye in BAYS_BY_EYE if any(b < eye[1] and eye[0] < e for b, e in bays)]
    assert len(found) == 8


def test_pane_rows_of_a_real_texture() -> None:
    """Along y the paper's signal works: two rows of panes in every bay.  By eye (bay 3, 3x
    zoom): the upper sash's glass spans rows 28-124, the lower's 145-242; the frame's grey bar
    and shadow between them (124-145), the top frame (0-28) and the sill (242-256) are wall.
    The detected upper pane runs to row 133, taking the thin grey bar (rows 124-130, lit like
    glass in the bays with bright blinds) with it: within 10 rows (4 % of the height)."""
    img = _window_tiles()
    rule = detect_rule(img, "y", 1.0)
    panes = [(b, e) for kind, b, e in rule.sections if kind == "insertable"]
    assert len(panes) == 2
    for (b, e), (eye_b, eye_e) in zip(panes, [(28, 124), (145, 242)], strict=True):
        assert abs(b - eye_b) <= 10 and abs(e - eye_e) <= 10
    assert rule.insertable[0] == pytest.approx((panes[1][1] - panes[1][0]) / 256)  # D: bottom up


def test_detection_is_fast() -> None:
    img = _window_tiles()
    detect_rule(img, "x", 20.0, signal="edges")
    for axis, signal in (("x", "edges"), ("x", "variance"), ("y", "variance")):
        best = math.inf
        for _ in range(5):
            start = time.perf_counter()
            rule = detect_rule(img, axis, 20.0, signal=signal)
            best = min(best, time.perf_counter() - start)
        assert isinstance(rule, Rule)
        assert best < 0.1, (axis, signal, best)
