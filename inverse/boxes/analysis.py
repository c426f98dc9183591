"""The offline analysis of a box hierarchy along one axis (Lin et al. 2011, section 5).

* **Alignment groups**: the faces across the axis of the finest boxes, clustered by position
  within epsilon; a cluster of two or more faces whose total area exceeds the average cluster's
  is a group.  Boxes higher up inherit the index where their faces coincide with the group's.
* **Compatibility graph** of each node's children: an edge from box a to box b when a face of a
  touches b across the axis (b above a, their cross-sections overlapping; or b next above a
  across empty space), or when a and b share a whole face beside each other and have the same
  behaviour along the axis.
* **Sequences**: the primary is the longest path (in boxes) from the child at the node's
  bottom-front-left corner to the top, never moving down, left or back; the secondaries are
  longest paths of what remains, from the lowest to the highest boxes of its components, each
  attached to the boxes of earlier sequences it touches (its anchors).
* **Sequence hierarchy**: the order the retargeting visits them, depth first.

"Up" is the axis being retargeted; the two other axes are the sideways directions.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.interpreter.limits import check_memory

from .model import EPS, MAX_CHILDREN, MAX_PAIRS, MAX_PARENTS, PAIRS_AT_ONCE, Box, shown

SPARSE_COST = 30  # a product of a sparse product costs about as much as 30 of a dense one
PAIR_BYTES = 16  # what the n x n arrays of a node's analysis cost per pair of its children


@dataclass
class Unit:
    """Boxes of a sequence side by side over the same interval: resized as one box."""

    boxes: list[int]  # indices into the node's children
    lo: float
    hi: float
    tag: str

    @property
    def length(self) -> float:
        return self.hi - self.lo


@dataclass
class Sequence:
    units: list[Unit]
    below: list[int]  # children the first unit rests on (empty: the node's bottom)
    above: list[int]  # children resting on the last unit (empty: the node's top)
    primary: bool = False

    @property
    def boxes(self) -> list[int]:
        return [b for u in self.units for b in u.boxes]


@dataclass
class NodeAnalysis:
    """A node's children along one axis: their graph's edges and their sequences in order."""

    edges: list[tuple[int, int]]
    sequences: list[Sequence]
    touch: np.ndarray  # touch[i, j]: child j rests on child i across the axis
    below: np.ndarray  # below[i, j]: child i under child j, their cross-sections overlapping


@dataclass
class Analysis:
    axis: int
    groups: dict[int, list[float]]  # alignment index -> [position, total area]
    nodes: dict[int, NodeAnalysis] = field(default_factory=dict)  # by id() of the box

    def of(self, box: Box) -> NodeAnalysis:
        return self.nodes[id(box)]

    def group_at(self, position: float) -> int | None:
        """The alignment index of a face at ``position``, or None."""
        for index, (where, _) in self.groups.items():
            if abs(where - position) <= EPS:
                return index
        return None

    @property
    def sequence_count(self) -> int:
        return sum(len(n.sequences) for n in self.nodes.values())


def analyse(root: Box, axis: int) -> Analysis:
    """Alignment groups, compatibility graphs and sequences of every node along ``axis``; a
    BgrError, before any work, when :func:`check_analysable` refuses the hierarchy."""
    check_analysable(root, axis)
    result = Analysis(axis, alignment_groups(root, axis))
    for box in root.walk():
        if box.children:
            result.nodes[id(box)] = analyse_node(box, axis)
    return result


def check_analysable(root: Box, axis: int) -> None:
    """Refuse, before any work along ``axis`` (the analysis, min_length), a hierarchy of more
    than MAX_PARENTS boxes with children or MAX_PAIRS pairs of siblings to compare."""
    parents = [box for box in root.walk() if box.children]
    widest = max(parents, key=lambda box: len(box.children), default=None)
    if widest is not None and len(widest.children) > MAX_CHILDREN:
        raise _too_many_children(widest, axis)
    counts = [len(box.children) for box in parents]
    if len(counts) > MAX_PARENTS:
        raise BgrError(
            Diagnostic(
                "",
                0,
                0,
                f"along {'xyz'[axis]}, {len(counts):,} boxes have children to analyse (with any "
                f"copies made along an earlier axis), more than the {MAX_PARENTS:,} bgr analyses "
                "along one axis",
                "ask a smaller size, or another --order, so that fewer copies are made first",
            )
        )
    pairs = sum(n * n for n in counts)
    if pairs > MAX_PAIRS:
        raise BgrError(
            Diagnostic(
                "",
                0,
                0,
                f"along {'xyz'[axis]}, analysing these boxes would compare {pairs:,} pairs of "
                f"sibling boxes (with any copies made along an earlier axis), more than the "
                f"{MAX_PAIRS:,} bgr compares along one axis",
                "ask a smaller size, or another --order, so that fewer copies are made first; "
                "or give the boxes fewer children each",
            )
        )


def alignment_groups(root: Box, axis: int) -> dict[int, list[float]]:
    """Clusters of leaf faces across ``axis`` whose total area is above the average cluster's."""
    others = [a for a in range(3) if a != axis]
    faces = []  # (position, area)
    for leaf in root.leaves():
        area = float(leaf.size[others[0]] * leaf.size[others[1]])
        faces.append((float(leaf.lo[axis]), area))
        faces.append((float(leaf.hi[axis]), area))
    faces.sort()
    clusters: list[list[tuple[float, float]]] = []
    for face in faces:
        if clusters and face[0] - clusters[-1][-1][0] <= EPS:
            clusters[-1].append(face)
        else:
            clusters.append([face])
    candidates = [c for c in clusters if len(c) >= 2]
    if not candidates:
        return {}
    totals = [sum(a for _, a in c) for c in candidates]
    average = sum(totals) / len(totals)
    groups: dict[int, list[float]] = {}
    for c, total in zip(candidates, totals, strict=True):
        if total > average - 1e-9 * average:  # "exceeds the average"; all equal: all kept
            groups[len(groups)] = [sum(p for p, _ in c) / len(c), total]
    return groups


def _contacts(lo: np.ndarray, hi: np.ndarray, axis: int) -> np.ndarray:
    """touch[i, j]: box j rests on box i across ``axis`` with overlapping cross-sections."""
    return _blocks(_touch_rows, lo, hi, axis)


def _below(lo: np.ndarray, hi: np.ndarray, axis: int) -> np.ndarray:
    """below[i, j]: box i lies under box j along ``axis``, their cross-sections overlapping
    (so that i must stay under j whatever their lengths become)."""
    return _blocks(_below_rows, lo, hi, axis)


def _blocks(relation, lo: np.ndarray, hi: np.ndarray, axis: int) -> np.ndarray:
    """``relation`` of every pair of boxes, a block of rows at a time: only the n x n booleans
    are kept, the float64 differences of a block stay within PAIRS_AT_ONCE pairs (all of them
    at once took 12 GB for 10,000 children)."""
    n = len(lo)
    out = np.empty((n, n), dtype=bool)
    step = max(1, PAIRS_AT_ONCE // max(n, 1))
    for start in range(0, n, step):
        rows = slice(start, min(start + step, n))
        out[rows] = relation(lo[rows], hi[rows], lo, hi, axis)
    return out


def _across(lo_r, hi_r, lo, hi, axis: int) -> np.ndarray:
    """Rows' boxes against all: their cross-sections (the two other axes) overlap by more than
    EPS.  min(hi) - max(lo) > EPS is each of the four differences > EPS (the least of them is
    the one min - max picks, rounding and all): two of them are the boxes' own sizes."""
    out = np.ones((len(lo_r), len(lo)), dtype=bool)
    for a in range(3):
        if a != axis:
            out &= hi_r[:, None, a] - lo[None, :, a] > EPS
            out &= hi[None, :, a] - lo_r[:, None, a] > EPS
            out &= (hi_r[:, a] - lo_r[:, a] > EPS)[:, None] & (hi[:, a] - lo[:, a] > EPS)[None, :]
    return out


def _touch_rows(lo_r, hi_r, lo, hi, axis: int) -> np.ndarray:
    return (np.abs(hi_r[:, None, axis] - lo[None, :, axis]) <= EPS) & _across(
        lo_r, hi_r, lo, hi, axis
    )


def _below_rows(lo_r, hi_r, lo, hi, axis: int) -> np.ndarray:
    under = (hi_r[:, None, axis] <= lo[None, :, axis] + EPS) & (
        lo_r[:, None, axis] < lo[None, :, axis]
    )
    return under & _across(lo_r, hi_r, lo, hi, axis)


def _side_rows(lo_r, hi_r, lo, hi, axis: int) -> np.ndarray:
    """side[i, j]: box i and box j share a whole face beside each other (the same interval
    along ``axis`` and along the third axis)."""

    def near(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return np.abs(x[:, None] - y[None, :]) <= EPS

    same = near(lo_r[:, axis], lo[:, axis]) & near(hi_r[:, axis], hi[:, axis])
    out = np.zeros(same.shape, dtype=bool)
    others = [a for a in range(3) if a != axis]
    for k, c in enumerate(others):
        d = others[1 - k]
        out |= near(hi_r[:, c], lo[:, c]) & near(lo_r[:, d], lo[:, d]) & near(hi_r[:, d], hi[:, d])
    return out & same


def _nothing_between(under: np.ndarray) -> np.ndarray:
    """[i, j]: no box k lies under j and over i.  As a sparse product where few boxes are under
    others (a grid's columns: about n^1.5 pairs), else in float32 by BLAS, a block of rows at a
    time (a tower, where every box is under every box above it)."""
    n = len(under)
    work = float(under.sum(axis=0).astype(np.float64) @ under.sum(axis=1))  # sparse products
    if work * SPARSE_COST < float(n) ** 3:
        from scipy.sparse import csr_matrix

        weights = csr_matrix(under, dtype=np.float32)
        out = np.ones((n, n), dtype=bool)
        out[(weights @ weights).nonzero()] = False
        return out
    weights = under.astype(np.float32)
    out = np.empty((n, n), dtype=bool)
    step = max(1, 8 * PAIRS_AT_ONCE // max(n, 1))  # large blocks: BLAS is fastest on those
    for start in range(0, n, step):
        rows = slice(start, min(start + step, n))
        out[rows] = (weights[rows] @ weights) == 0
    return out


def _too_many_children(box: Box, axis: int) -> BgrError:
    return BgrError(
        Diagnostic(
            "",
            0,
            0,
            f"along {'xyz'[axis]}, box '{shown(box.id)}' has {len(box.children):,} children (with "
            f"the copies made along an earlier axis), more than the {MAX_CHILDREN:,} bgr analyses "
            "in one box",
            "ask a smaller size, or another --order, so that fewer copies are made first",
        )
    )


def analyse_node(box: Box, axis: int) -> NodeAnalysis:
    kids = box.children
    n = len(kids)
    if n > MAX_CHILDREN:  # the commands refuse such an input: these are copies
        raise _too_many_children(box, axis)
    check_memory(f"analysing the {n:,} children of box '{shown(box.id)}'", n * n * PAIR_BYTES)
    lo = np.array([c.lo for c in kids])
    hi = np.array([c.hi for c in kids])
    tags = [c.tags[axis] for c in kids]
    others = [a for a in range(3) if a != axis]
    up = _contacts(lo, hi, axis)
    side = _blocks(_side_rows, lo, hi, axis)
    same_tag = np.array(tags)[:, None] == np.array(tags)[None, :]
    side &= same_tag
    under = _below(lo, hi, axis)
    # boxes with empty space between them (children need not fill their parent) follow each
    # other too when nothing lies between: the space scales like an S box in their sequence
    step = up | (under & _nothing_between(under))
    edge = step | side
    # a topological order: every edge goes up, or sideways towards larger coordinates
    order = sorted(
        range(n),
        key=lambda i: (
            round(lo[i, axis], 9),
            round(lo[i, others[0]], 9),
            round(lo[i, others[1]], 9),
            i,
        ),
    )
    rank = np.empty(n, dtype=int)
    rank[order] = np.arange(n)
    pairs = np.nonzero(edge)
    edges = [(int(i), int(j)) for i, j in zip(*pairs, strict=True)]
    succ: list[list[int]] = [[] for _ in range(n)]
    for i, j in edges:
        if rank[i] < rank[j]:  # degenerate (zero-length) boxes could otherwise make a cycle
            succ[i].append(j)
    for s in succ:
        s.sort(key=lambda j: rank[j])

    sequences: list[Sequence] = []
    used = np.zeros(n, dtype=bool)
    bottom, top = box.lo[axis], box.hi[axis]
    corner = [i for i in range(n) if np.all(np.abs(lo[i] - box.lo) <= EPS)]
    while not used.all():
        free = ~used
        if not sequences:
            starts = corner or [int(min(np.nonzero(free)[0], key=lambda i: rank[i]))]
            # the primary ends at a box touching the top (the whole height, in a tessellation)
            ends = [i for i in range(n) if hi[i, axis] >= top - EPS] or list(range(n))
        else:
            starts, ends = _lowest_and_highest(free, pairs, lo[:, axis], hi[:, axis])
        path = _longest_path(order, succ, free, starts, set(ends))
        used[path] = True
        units = _units(path, lo[:, axis], hi[:, axis], tags)
        first, last = path[0], path[-1]
        below = [int(j) for j in np.nonzero(step[:, first] & used)[0] if j not in path]
        above = [int(j) for j in np.nonzero(step[last, :] & used)[0] if j not in path]
        if lo[first, axis] <= bottom + EPS:
            below = []
        if hi[last, axis] >= top - EPS:
            above = []
        sequences.append(Sequence(units, below, above, primary=not sequences))
    return NodeAnalysis(edges, sequences, up, under)


def _lowest_and_highest(free, edge, lo, hi) -> tuple[list[int], list[int]]:
    """The lowest and highest boxes of every component of the graph left (undirected): ``edge``
    is the graph's edges as (from, to) arrays, so that a node of many children, which has many
    sequences, costs no n x n work for each."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    left = np.flatnonzero(free)
    a, b = edge
    keep = free[a] & free[b]
    if not keep.any():  # boxes apart from one another: each its own lowest and highest
        return left.tolist(), left.tolist()
    where = np.full(len(free), -1)
    where[left] = np.arange(len(left))
    graph = coo_matrix(
        (np.ones(int(keep.sum()), dtype=np.int8), (where[a[keep]], where[b[keep]])),
        (len(left), len(left)),
    )
    _, comp = connected_components(graph, directed=False)
    low = np.full(comp.max(initial=-1) + 1, np.inf)
    high = np.full(len(low), -np.inf)
    np.minimum.at(low, comp, lo[left])
    np.maximum.at(high, comp, hi[left])
    starts = left[lo[left] <= low[comp] + EPS]
    ends = left[hi[left] >= high[comp] - EPS]
    return starts.tolist(), ends.tolist()


def _longest_path(order, succ, free, starts, ends: set[int]) -> list[int]:
    """The longest path (in boxes) through free boxes from a start to an end, by dynamic
    programming over the topological order; ties go to the earlier box in that order.  Python
    lists, not arrays: a node of many children runs it once per sequence, over all of them."""
    n = len(order)
    free = free.tolist()
    length = [0] * n  # 0: not reached
    before = [-1] * n
    for s in starts:
        if free[s]:
            length[s] = 1
    best, best_len = -1, 0
    for i in order:
        here = length[i]
        if not here or not free[i]:
            continue
        if here > best_len and i in ends:
            best, best_len = i, here
        for j in succ[i]:
            if free[j] and here + 1 > length[j]:
                length[j] = here + 1
                before[j] = i
    if best < 0:  # no end reachable (boxes hanging free): the first free box alone
        best = next(i for i in order if free[i])
    path = [int(best)]
    while before[path[-1]] >= 0:
        path.append(int(before[path[-1]]))
    return path[::-1]


def _units(path: list[int], lo, hi, tags) -> list[Unit]:
    """Consecutive boxes of a path over the same interval (sideways moves) are one unit."""
    units: list[Unit] = []
    for i in path:
        if units and abs(units[-1].lo - lo[i]) <= EPS and abs(units[-1].hi - hi[i]) <= EPS:
            units[-1].boxes.append(i)
        else:
            units.append(Unit([i], float(lo[i]), float(hi[i]), tags[i]))
    return units


def min_length(box: Box, axis: int, memo: dict | None = None) -> float:
    """The shortest a box can become along ``axis``: its length when fixed, else the tallest
    stack of its children's minimums (R children can be deleted, S leaves shrink to nothing).

    A stack is any chain of children each under the next with overlapping cross-sections,
    touching or not: their order along the axis is kept whatever the lengths."""
    memo = {} if memo is None else memo
    key = id(box)
    if key in memo:
        return memo[key]
    if box.tags[axis] == "F":
        out = float(box.size[axis])
    elif not box.children:
        out = 0.0
    else:
        kids = box.children
        lo = np.array([c.lo for c in kids])
        hi = np.array([c.hi for c in kids])
        under = _below(lo, hi, axis)
        need = [0.0 if c.tags[axis] == "R" else min_length(c, axis, memo) for c in kids]
        reach: dict[int, float] = {}
        for i in sorted(range(len(kids)), key=lambda i: lo[i, axis]):
            below = [reach[int(j)] for j in np.nonzero(under[:, i])[0] if int(j) in reach]
            reach[i] = max(below, default=0.0) + need[i]
        out = max(reach.values(), default=0.0)
    memo[key] = out
    return out
