"""Splitting rules of a style sheet (Zhang et al., section 4.3.4) and the splitting functions
that replay them on a face of another size (section 5.2.3, equations 8 and 9).

A texture map is cut, along one axis, into *insertable* sections (windows: label 1) and
*scalable* sections (the wall between them: label 0).  Detection (section 4.3.4): the colour
variance signal of the image's columns (or rows), two cluster centres by k-means (k = 2), the
binary labelling that minimises equation 3 by dynamic programming, the merge of fragments much
shorter than the objective window size, and the runs of labels as the vectors A (scalable
widths) and B (insertable widths), or C and D for a vertical rule.  Generation (section 5.2.3):
``split_h`` / ``split_v`` give the number of insertables Sn and the scaling factor Sr of the
scalables for a face of width W (height H), ``layout`` the sequence of pieces itself.  The
signals themselves are in inverse/style/signals.py.

Pure numpy: no I/O; images are (h, w, 3) uint8 arrays, row 0 the top (inverse/style/model.py).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from itertools import accumulate

import numpy as np

from .signals import AXES, SIGNALS, colour_variance, edge_signal, unit_range, variance_signal

__all__ = [
    "AXES",
    "LAMBDA",
    "PLAIN_VARIANCE",
    "SIGNALS",
    "Rule",
    "default_window",
    "detect_rule",
    "edge_signal",
    "kmeans_1d",
    "label_runs",
    "label_signal",
    "labelling_energy",
    "layout",
    "merge_fragments",
    "rule_from_labels",
    "split_h",
    "split_v",
    "variance_signal",
]

LAMBDA = 0.025
"""Weight of the smoothness term of equation 3 (section 4.3.4: lambda = 0.025)."""

PLAIN_VARIANCE = 1e-3
"""A texture whose colour-variance signal (``colour_variance``, 0..1 units) spans less than
this along the axis is a plain wall: no insertable section.  Deviation from section 4.3.4, whose
k-means and labelling always find two clusters: the signal is stretched to 0..1 before
labelling (so that lambda is scale-free), and on a blank wall that stretches its noise (a
photograph's grain, JPEG blocks) into dozens of one-pixel "windows".  1e-3 is a change of
standard deviation of about 5 grey levels a channel, a wall no one sees windows in; a blank
synthetic wall with +-4 levels of grain spans 1.5e-4, a row of windows 0.14 to 0.25 and the
Candler window tiles 0.17 to 0.19 (tests/test_style_rules.py, tests/test_style_roundtrip.py)."""

SCALABLE, INSERTABLE = 0, 1
"""Labels l(i) of section 4.3.4: 0 a scalable element (wall), 1 an insertable one (window)."""


# --- detection (section 4.3.4) ----------------------------------------------------------------


def kmeans_1d(signal: np.ndarray, iterations: int = 100) -> tuple[float, float]:
    """The two cluster centres mu0 <= mu1 of a 1D signal (k-means with k = 2, section 4.3.4).

    Deterministic: the centres start at the signal's minimum and maximum and Lloyd's iteration
    (assign each value to the nearer centre, ties to mu0; move each centre to its cluster's
    mean) runs until no assignment changes.  Starting at the extremes keeps mu0 <= mu1 all the
    way, so label 1 (insertable) is always the high-variance cluster."""
    values = np.asarray(signal, dtype=np.float64).ravel()
    if values.size == 0:
        raise ValueError("k-means of an empty signal")
    mu = np.array([values.min(), values.max()])
    assign = np.zeros(values.size, dtype=bool)
    for step in range(iterations):
        new = np.abs(values - mu[1]) < np.abs(values - mu[0])
        if step and np.array_equal(new, assign):
            break
        assign = new
        if assign.any():
            mu[1] = values[assign].mean()
        if (~assign).any():
            mu[0] = values[~assign].mean()
    return float(mu[0]), float(mu[1])


def data_costs(signal: np.ndarray, centres: tuple[float, float]) -> np.ndarray:
    """(n, 2) data term of equation 4: |var(i) - mu_l| for l = 0, 1."""
    values = np.asarray(signal, dtype=np.float64).ravel()
    return np.abs(values[:, None] - np.asarray(centres, dtype=np.float64)[None, :])


def labelling_energy(signal: np.ndarray, labels: np.ndarray, lam: float = LAMBDA) -> float:
    """Equation 3 for a given labelling: the data term (equation 4, centres by ``kmeans_1d``)
    summed over the signal plus lam times the number of label changes (equation 5)."""
    labels = np.asarray(labels, dtype=np.intp).ravel()
    costs = data_costs(signal, kmeans_1d(signal))
    data = costs[np.arange(labels.size), labels].sum()
    return float(data + lam * np.count_nonzero(np.diff(labels)))


def label_signal(signal: np.ndarray, lam: float = LAMBDA) -> np.ndarray:
    """The labelling l of equation 3 that minimises the data term (equation 4) plus lam times
    the smoothness term (equation 5), as (n,) int8, 1 insertable, 0 scalable.

    Dynamic programming as section 4.3.4 says (after [MWW12]): the minimum energy of a labelling
    of var(1..i) that ends in label l is accumulated stage by stage, with, for each stage and
    label, the previous label that achieved it; the minimum at the last stage is then followed
    back.  With two labels a stage updates both accumulated energies through their difference
    alone (below), so the forward pass is one scalar step a stage and the back pointers of all
    stages are two vectorised comparisons.  Ties keep the previous label (no change) and a
    final tie ends scalable, so the result is a function of the signal alone.  A constant
    signal (both centres equal) is all scalable."""
    values = np.asarray(signal, dtype=np.float64).ravel()
    n = values.size
    if n == 0:
        return np.zeros(0, dtype=np.int8)
    if not np.isfinite(values).all():
        raise ValueError("the variance signal holds a non-finite value")
    if lam < 0 or not math.isfinite(lam):
        raise ValueError(f"lambda must be a finite number >= 0, not {lam}")
    centres = kmeans_1d(values)
    if centres[1] - centres[0] <= 1e-12:
        return np.zeros(n, dtype=np.int8)
    data = data_costs(values, centres)
    # Two labels make the accumulated energies E0(i), E1(i) one number: d(i) = E1(i) - E0(i).
    # With Es = lam on a change, E_l(i) = min(E_l(i-1), E_(1-l)(i-1) + lam) + Ed_l(i), so
    # d(i) = clip(d(i-1), -lam, lam) + Ed_1(i) - Ed_0(i): each stage is one scalar step for
    # both labels at once (no per-label work), run by itertools.accumulate.
    delta = (data[:, 1] - data[:, 0]).tolist()
    d = np.fromiter(accumulate(delta, lambda prev, x: min(max(prev, -lam), lam) + x), np.float64, n)
    # back pointers of stage i: label 0 came from label 1 when E1 + lam < E0 (d < -lam), label
    # 1 from label 0 when d > lam; a tie keeps the label, so the result is unique
    from0 = np.r_[False, d[:-1] < -lam]
    from1 = np.r_[False, d[:-1] > lam]
    labels = np.empty(n, dtype=np.int8)
    label = INSERTABLE if d[-1] < 0 else SCALABLE
    switch = (from0.tolist(), from1.tolist())
    out = [0] * n
    for i in range(n - 1, -1, -1):  # backtrack the minimum path (one lookup a stage)
        out[i] = label
        if switch[label][i]:
            label = 1 - label
    labels[:] = out
    return labels


# --- runs and fragments -----------------------------------------------------------------------


def label_runs(labels: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(label, start, end) arrays of the maximal runs of equal labels, in order (end exclusive)."""
    labels = np.asarray(labels).ravel()
    if labels.size == 0:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty, empty
    cuts = np.flatnonzero(np.diff(labels)) + 1
    starts = np.r_[0, cuts]
    ends = np.r_[cuts, labels.size]
    return labels[starts].astype(np.intp), starts.astype(np.intp), ends.astype(np.intp)


FRAGMENT = 0.5
"""An insertable run shorter than this fraction of the window size is a fragment."""

JOIN_SPAN = 1.25
"""A fragment joins a neighbouring insertable run, across the scalable gap between them, only
if the joined run is at most this many window sizes long."""


def default_window(labels: np.ndarray) -> float:
    """The objective window size when the caller gives none: the length-weighted median of the
    insertable runs (the length of the run holding the median insertable pixel).  Weighting by
    length keeps many one-pixel fragments from pulling it down, as a plain median of the runs
    would.  0 when nothing is insertable."""
    kind, start, end = label_runs(labels)
    lengths = np.sort((end - start)[kind == INSERTABLE])
    if lengths.size == 0:
        return 0.0
    cumulative = np.cumsum(lengths)
    return float(lengths[np.searchsorted(cumulative, cumulative[-1] / 2.0)])


def merge_fragments(labels: np.ndarray, window: float | None = None) -> np.ndarray:
    """Section 4.3.4's fix for fragmented labels: insertable sections much shorter than the
    objective ``window`` size (in samples; default ``default_window``) are merged.

    The paper leaves the rule open; here, repeatedly, the shortest insertable run shorter than
    FRAGMENT (0.5) windows is taken.  If it can join the nearer neighbouring insertable run
    (the one giving the shorter union) across the scalable gap between them and the union is at
    most JOIN_SPAN (1.25) windows long, the gap becomes insertable: a window cut by its own
    mullion or by a reflection.  Otherwise the fragment becomes scalable: a stain on the wall.
    Runs that are not fragments, and the scalable gaps between them, are never changed, so a
    bay's mullion stays a scalable section.  Returns a new (n,) int8 array."""
    out = np.asarray(labels).astype(np.int8).ravel().copy()
    if window is None:
        window = default_window(out)
    if window <= 0:
        return out
    while True:
        kind, start, end = label_runs(out)
        ins = np.flatnonzero(kind == INSERTABLE)
        length = end[ins] - start[ins]
        short = ins[length < FRAGMENT * window]
        if short.size == 0:
            return out
        r = short[np.argmin(end[short] - start[short])]  # the shortest, leftmost on a tie
        spans = []
        if r >= 2:  # runs alternate, so the previous insertable run is r - 2
            spans.append((end[r] - start[r - 2], start[r - 1], end[r - 1]))
        if r + 2 < kind.size:
            spans.append((end[r + 2] - start[r], start[r + 1], end[r + 1]))
        spans = [s for s in spans if s[0] <= JOIN_SPAN * window]
        if spans:
            _, lo, hi = min(spans)
            out[lo:hi] = INSERTABLE
        else:
            out[start[r] : end[r]] = SCALABLE


# --- rules --------------------------------------------------------------------------------


@dataclass
class Rule:
    """A splitting rule: m insertable sections between m + 1 scalable ones.

    ``scalable`` is the paper's A = [a1 .. a_(m+1)] (C for a vertical rule) and ``insertable``
    B = [b1 .. bm] (D), in the caller's length unit; a1 or a_(m+1) is 0 where a window touches
    the edge.  A and B run left to right for axis "x" (the face's left seen from outside first)
    and **bottom to top** for axis "y", as heights are measured and as ``split_v`` / ``layout``
    stack them.  ``sections`` are the same pieces as pixel ranges of the texture, ("scalable" or
    "insertable", first pixel, end pixel exclusive), in *image* order: left to right, or top
    to bottom (row 0 the top) for axis "y", zero-width edge scalables included, so the emitter
    can crop each piece."""

    axis: str
    scalable: tuple[float, ...]
    insertable: tuple[float, ...]
    sections: list[tuple[str, int, int]] = field(default_factory=list)

    @property
    def m(self) -> int:
        """The number of insertable elements."""
        return len(self.insertable)


def rule_from_labels(labels: np.ndarray, length: float, axis: str = "x") -> Rule:
    """The runs of a labelling as a Rule whose pieces sum to ``length`` (each pixel is
    length / n long); always m + 1 scalables around m insertables (a zero-width first or last
    scalable where an insertable run touches the edge).  ``axis`` "y" reverses A and B into
    bottom-to-top order (the labels run top to bottom, as image rows do)."""
    if axis not in AXES:
        raise ValueError(f"axis must be 'x' or 'y', not {axis!r}")
    if not math.isfinite(length) or length < 0:
        raise ValueError(f"a rule's length must be a finite number >= 0, not {length}")
    labels = np.asarray(labels).ravel()
    n = labels.size
    kind, start, end = label_runs(labels)
    sections = [
        ("insertable" if k == INSERTABLE else "scalable", int(b), int(e))
        for k, b, e in zip(kind.tolist(), start.tolist(), end.tolist(), strict=True)
    ]
    if not sections or sections[0][0] == "insertable":
        sections.insert(0, ("scalable", 0, 0))
    if sections[-1][0] == "insertable":
        sections.append(("scalable", n, n))
    unit = length / n if n else 0.0
    sizes = [(e - b) * unit for _, b, e in sections]
    scalable, insertable = sizes[0::2], sizes[1::2]
    if axis == "y":
        scalable, insertable = scalable[::-1], insertable[::-1]
    return Rule(axis, tuple(scalable), tuple(insertable), sections)


def detect_rule(
    image: np.ndarray,
    axis: str,
    length: float,
    window: float | None = None,
    lam: float = LAMBDA,
    signal: str = "variance",
) -> Rule:
    """Section 4.3.4 end to end: the signal of ``image`` along ``axis``, its labelling
    (equation 3), the merge of fragments, and the rule scaled to ``length`` (the face's width
    for "x", height for "y").  ``window`` is the objective window size in the same unit as
    ``length`` (None: ``default_window``); ``signal`` "variance" is the paper's colour-variance
    signal, "edges" the curtain-wall variant (``edge_signal``).  A texture whose raw variance
    spans less than PLAIN_VARIANCE is a plain wall: one scalable section, no insertable."""
    if signal not in SIGNALS:
        raise ValueError(f"signal must be one of {sorted(SIGNALS)}, not {signal!r}")
    if signal == "variance":
        raw = colour_variance(image, axis)
        values = unit_range(raw)
        plain = float(np.ptp(raw)) < PLAIN_VARIANCE
    else:
        values, plain = SIGNALS[signal](image, axis), False
    labels = np.zeros(values.size, np.int8) if plain else label_signal(values, lam)
    if window is not None:
        if not math.isfinite(window) or window < 0 or length <= 0:
            raise ValueError(f"the window size must be a finite number >= 0, not {window}")
        window = window * values.size / length
    return rule_from_labels(merge_fragments(labels, window), length, axis)


# --- the splitting functions (section 5.2.3) --------------------------------------------------

_EPS = 1e-9  # relative slack for "fits": W = 2 patterns exactly must give x = 2


def _check(A: Sequence[float], B: Sequence[float], W: float) -> tuple[np.ndarray, np.ndarray]:
    a = np.asarray(A, dtype=np.float64).ravel()
    b = np.asarray(B, dtype=np.float64).ravel()
    if a.size != b.size + 1:
        raise ValueError(f"a rule holds m + 1 scalables for m insertables, not {a.size}, {b.size}")
    values = np.r_[a, b, W]
    if not np.isfinite(values).all() or (values < 0).any():
        raise ValueError("rule widths and the face's size must be finite numbers >= 0")
    return a, b


def _split(A: Sequence[float], B: Sequence[float], W: float) -> tuple[int, int, float]:
    """(x, y, Sr) of equations 8 and 9; see ``split_h``."""
    a, b = _check(A, B, W)
    m = b.size
    if m == 0:  # a plain wall: no insertable to count, one scalable stretched over W
        if a[0] <= 0:
            raise ValueError("a rule with no insertable needs a scalable of width > 0")
        return 0, 0, float(W / a[0])
    sum_a, sum_b = float(a.sum()), float(b.sum())
    pattern = sum_a + sum_b
    if pattern <= 0:
        raise ValueError("a rule whose widths are all 0 cannot split a face")
    x = math.floor(W / pattern + _EPS)  # equation 8: the whole repeats of the texture
    rest = W - x * pattern
    tail_b = np.cumsum(b)
    y = int(np.count_nonzero(tail_b <= rest + _EPS * max(W, 1.0)))  # insertables in the rest
    fill = W - x * sum_b - (tail_b[y - 1] if y else 0.0)  # what the scalables must cover
    scalables = x * sum_a + float(a[: y + 1].sum())
    if scalables <= 0:
        if fill <= _EPS * max(W, 1.0):
            return x, y, 1.0
        raise ValueError(
            f"a face of size {W} cannot be filled: the scalables it would hold all have width 0 "
            "(an insertable touches the rule's edge and the face is narrower than it)"
        )
    sr = max(fill, 0.0) / scalables
    if y == 0 and x > 0 and sum_a > 0:  # a tie in Sn: x - 1 repeats and the full tail
        alt = max(W - x * sum_b, 0.0) / (x * sum_a)
        if abs(alt - 1.0) < abs(sr - 1.0):
            return x - 1, m, alt
    return x, y, sr


def split_h(A: Sequence[float], B: Sequence[float], W: float) -> tuple[int, float]:
    """[Sn, Sr] = split_h(A, B, W), section 5.2.3: the number of insertables Sn and the scaling
    factor Sr of the scalables for a face of width W.

    Equation 8: x = floor(W / (sum B + sum A)) whole repeats of [a1 b1 .. bm a_(m+1)], then y,
    0 <= y <= m, the most insertables b1 .. by that fit in the rest W - x (sum B + sum A);
    Sn = x m + y.  The generated sequence holds x (m + 1) + y + 1 scalables.

    Deviation from equation 9 as printed: Sr = (W - x(sum B + sum A) - sum_(j<=y) b_j) /
    (x sum A + sum_(j<=y+1) a_j) leaves x sum A of the face uncovered when the scalables are
    scaled by it (its numerator already takes the x repeats' scalables out, at their original
    size, then scales them again).  The factor that makes the pieces sum to W, as section
    5.2.3's text asks ("the remaining space ... is to be filled by the scalable elements"), is
    Sr = (W - x sum B - sum_(j<=y) b_j) / (x sum A + sum_(j<=y+1) a_j): the two agree when
    x = 0.  Second deviation, a tie-break: equation 8 makes W = x patterns exactly into x
    repeats and a tail of a1 alone (y = 0), whose scalables, one more than the texture had,
    all shrink; x - 1 repeats and the full tail b1 .. bm (y = m) hold the same Sn = x m
    windows, and there every piece keeps the size it was measured at.  Of the two, the layout
    whose Sr is nearer 1 (whose walls stretch least) is taken, so a style sheet derived back
    on its source's own faces reproduces them.  With no insertable (m = 0) the face is one
    scalable a1 stretched: Sn = 0, Sr = W / a1.  Raises ValueError on non-finite or negative
    input, on a rule of zero width, and when the scalables a face would hold all have width 0
    but space is left."""
    x, y, sr = _split(A, B, W)
    return x * len(B) + y, sr


def split_v(C: Sequence[float], D: Sequence[float], H: float) -> tuple[int, float]:
    """[Sn, Sr] = split_v(C, D, H): ``split_h`` along the height, C and D bottom to top."""
    return split_h(C, D, H)


def layout(A: Sequence[float], B: Sequence[float], W: float) -> list[tuple[str, int, float]]:
    """The generated sequence of a face of size W (section 5.2.3): [a1 b1 a2 .. bm a_(m+1)]
    x times, then the tail a1 b1 .. by a_(y+1); each entry ("scalable" | "insertable", index
    into A or B, size), scalables scaled by Sr (``split_h``), so the sizes sum to W.  Left to
    right for a horizontal rule, bottom to top for a vertical one (C, D)."""
    x, y, sr = _split(A, B, W)
    m = len(B)
    if m == 0:
        return [("scalable", 0, float(W))]
    a, b = np.asarray(A, dtype=np.float64), np.asarray(B, dtype=np.float64)
    pattern = [("scalable", 0, float(a[0] * sr))]
    for j in range(m):
        pattern += [("insertable", j, float(b[j])), ("scalable", j + 1, float(a[j + 1] * sr))]
    return pattern * x + pattern[: 2 * y + 1]
