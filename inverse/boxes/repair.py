"""A node's children made to fit when the paper's placement does not (a documented deviation).

Lin et al.'s placement (:mod:`.retarget`) resizes one sequence at a time; nothing in it promises
that boxes of different sequences still fit together: a sequence can be pushed past a fixed box
of another, a replicable box holding a fixed one cannot be scaled below it, and the cascade
deletes a box only at a whole share.  The paper does not discuss it; a tool must not write boxes
that overlap or stick out of their parent.

So after the placement of a node's children, :func:`valid` checks them; when they do not fit,
or open a gap between children that touched in the input (:func:`tiled`: a hole in a wall the
input closed), :func:`fit` finds the valid layout closest to what the placement
proposed, as two small linear programmes (scipy's HiGHS):

* hard: every child inside the node; a child below another (their cross-sections overlapping)
  stays below it; fixed children keep their length; the others at least their minimum (copies
  times :func:`.analysis.min_length`, and an R copy at least ``RHO`` of its length: repeated,
  not squeezed); deleted children keep a place of no length (the paper's virtual deletion);
* first the least total gap between children that touched (and between a child and the node's
  end it touched): none wherever a tessellation is possible; then, that gap kept, each face as
  near as it can be to where the placement put it (so alignments it kept stay kept).

If even that has no solution, replicable children lose copies (down to deletion) until it does:
a node at least :func:`.analysis.min_length` long always has one, since that minimum counts a
replicable child as deletable.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog
from scipy.sparse import coo_matrix

from bgr.grammar.errors import BgrError

from .model import EPS

RHO = 0.8  # an R copy is made no shorter than this share of its own length (nor, when snapped
# to an alignment, longer than its length over RHO): repeated, not squeezed or stretched
NUDGE = 1e-9  # floor(x + NUDGE) as the cascade counts copies
GAP = 100.0  # a metre of gap against a metre moved, once the least gap is found


@dataclass
class Placed:
    """Where a child goes along the axis: ``count`` copies (0: deleted) filling lo..hi."""

    lo: float
    hi: float
    count: int


@dataclass
class Layout:
    """What the fitting needs of a node's children along the axis (all indexed by child)."""

    old_lo: np.ndarray
    old_hi: np.ndarray
    tags: list[str]
    mins: list[float]  # the shortest one copy can be (its length if fixed)
    below: np.ndarray  # below[i, j]: child i under child j, their cross-sections overlapping
    touch: np.ndarray  # touch[i, j]: child j rested on child i in the input
    ends: tuple[float, float]  # the node's new ends
    old_ends: tuple[float, float]


def fits(layout: Layout, i: int, p: Placed) -> bool:
    """Whether child ``i`` placed at ``p`` is inside the node and no shorter than it can be; a
    deleted child, whether it keeps a place of no length (else its place would be a hole)."""
    if p.count == 0:
        return p.hi - p.lo <= EPS
    bottom, top = layout.ends
    if p.lo < bottom - EPS or p.hi > top + EPS:
        return False
    if layout.tags[i] == "F":
        return abs(p.hi - p.lo - layout.mins[i]) <= EPS
    return p.hi - p.lo >= p.count * layout.mins[i] - EPS


def valid(layout: Layout, placed: list[Placed]) -> bool:
    """Whether the placed children fit: each as :func:`fits` says, in order, and tiled as they
    were (:func:`tiled`)."""
    if not all(fits(layout, i, p) for i, p in enumerate(placed)):
        return False
    lo = np.array([p.lo for p in placed])
    hi = np.array([p.hi for p in placed])
    kept = np.array([p.count > 0 for p in placed])
    pairs = layout.below & kept[:, None] & kept[None, :]
    under, over = np.nonzero(pairs)
    return bool(np.all(hi[under] <= lo[over] + EPS)) and tiled(layout, lo, hi)


def tiled(layout: Layout, lo: np.ndarray, hi: np.ndarray) -> bool:
    """Whether children that touched in the input (one on the other, or on the node's end) still
    touch: no gap opens in a wall the input closed.  Deleted children keep a place of no length,
    so their neighbours touch through them."""
    under, over = np.nonzero(layout.touch)
    if np.any(np.abs(lo[over] - hi[under]) > EPS):
        return False
    bottom, top = layout.ends
    at_bottom = layout.old_lo <= layout.old_ends[0] + EPS
    at_top = layout.old_hi >= layout.old_ends[1] - EPS
    return bool(np.all(lo[at_bottom] <= bottom + EPS) and np.all(hi[at_top] >= top - EPS))


def fit(layout: Layout, placed: list[Placed]) -> list[Placed]:
    """The valid layout nearest ``placed`` (see the module's docstring)."""
    counts = [p.count for p in placed]
    solved = _solve(layout, placed, counts, drop_r=False)
    if solved is None:
        # no room for every replicable child as it is: let them shrink, then count what fits
        loose = _solve(layout, placed, counts, drop_r=True)
        if loose is None:
            raise BgrError(
                "internal error: the boxes along this axis cannot be fitted; please report it "
                "with the boxes file"
            )
        lo, hi = loose
        for i, tag in enumerate(layout.tags):
            m = _copy_min(layout, i)
            if tag == "R" and counts[i] and m > 0 and hi[i] - lo[i] < counts[i] * m - EPS:
                counts[i] = min(counts[i], math.floor((hi[i] - lo[i]) / m + NUDGE))
        solved = _solve(layout, placed, counts, drop_r=False)
        if solved is None:  # cannot happen: the loose solution, deleted boxes emptied, fits
            raise BgrError("internal error: fitting the boxes along this axis failed")
    lo, hi = solved
    return [Placed(float(lo[i]), float(hi[i]), counts[i]) for i in range(len(placed))]


def _copy_min(layout: Layout, i: int) -> float:
    """The shortest one copy of child ``i`` may be made here: an R child no less than ``RHO``
    of its own length (a window repeated stays about a window), others their minimum."""
    if layout.tags[i] == "R":
        return max(layout.mins[i], RHO * float(layout.old_hi[i] - layout.old_lo[i]))
    return layout.mins[i]


def _solve(layout: Layout, placed, counts, drop_r: bool):
    """lo, hi of every child from the linear programmes, or None if they have no solution.

    Variables: lo (n), hi (n), the distances |lo - proposed|, |hi - proposed| (2n).  First the
    least total gap between children that touched (and between a child and the node's end it
    touched); then, that total kept, the least distance from the proposed faces."""
    n = len(placed)
    bottom, top = layout.ends
    want_lo = np.clip([p.lo for p in placed], bottom, top)
    want_hi = np.clip([p.hi for p in placed], bottom, top)
    rows: list[tuple[list[int], list[float], float]] = []  # sum(coef * x) <= bound
    eq_rows: list[tuple[list[int], list[float], float]] = []
    LO, HI, DLO, DHI = 0, n, 2 * n, 3 * n
    for i in range(n):
        rows.append(([LO + i, DLO + i], [1, -1], want_lo[i]))
        rows.append(([LO + i, DLO + i], [-1, -1], -want_lo[i]))
        rows.append(([HI + i, DHI + i], [1, -1], want_hi[i]))
        rows.append(([HI + i, DHI + i], [-1, -1], -want_hi[i]))
        if layout.tags[i] == "F":
            eq_rows.append(([HI + i, LO + i], [1, -1], layout.mins[i]))
        elif counts[i] == 0:
            eq_rows.append(([HI + i, LO + i], [1, -1], 0.0))
        else:
            least = 0.0 if drop_r and layout.tags[i] == "R" else counts[i] * _copy_min(layout, i)
            rows.append(([LO + i, HI + i], [1, -1], -least))
    for i, j in zip(*np.nonzero(layout.below), strict=True):
        rows.append(([HI + int(i), LO + int(j)], [1, -1], 0.0))
    gaps = np.zeros(4 * n)  # the total gap, as a linear function (its constant dropped)
    for i, j in zip(*np.nonzero(layout.touch), strict=True):
        gaps[LO + j] += 1.0  # the gap lo[j] - hi[i]
        gaps[HI + i] -= 1.0
    for i in range(n):
        if layout.old_lo[i] <= layout.old_ends[0] + EPS:
            gaps[LO + i] += 1.0  # the gap to the node's bottom
        if layout.old_hi[i] >= layout.old_ends[1] - EPS:
            gaps[HI + i] -= 1.0
    bounds = [(bottom, top)] * (2 * n) + [(0, None)] * (2 * n)
    a_ub, b_ub = _matrix(rows, 4 * n)
    a_eq, b_eq = _matrix(eq_rows, 4 * n) if eq_rows else (None, None)
    first = linprog(gaps, A_ub=a_ub, b_ub=b_ub, A_eq=a_eq, b_eq=b_eq, bounds=bounds)
    if first.status != 0:
        return None
    # the least gap is a hard bound now (with a little slack for the solver's tolerance)
    rows.append((list(range(4 * n)), gaps.tolist(), float(first.fun) + 1e-9))
    a_ub, b_ub = _matrix(rows, 4 * n)
    cost = GAP * gaps  # (and the slack not spent on moving faces)
    cost[DLO:] = 1.0
    result = linprog(cost, A_ub=a_ub, b_ub=b_ub, A_eq=a_eq, b_eq=b_eq, bounds=bounds)
    x = (result if result.status == 0 else first).x
    lo = np.clip(x[LO:HI], bottom, top)
    hi = np.clip(x[HI:DLO], bottom, top)
    return lo, np.maximum(hi, lo)


def _matrix(rows, width: int):
    data, r, c, bound = [], [], [], []
    for k, (cols, coefs, b) in enumerate(rows):
        r += [k] * len(cols)
        c += cols
        data += coefs
        bound.append(b)
    return coo_matrix((data, (r, c)), shape=(len(rows), width)).tocsr(), np.array(bound)
