"""Cleaning one footprint outline: repeated and collinear corners, self-crossings, slivers.

Split from :mod:`bgr.interpreter.lots` (which reads GeoJSON and builds lots) because cleaning is
a concern of its own and must stay fast on outlines of any size: a round footprint traced with
100,000 corners is ordinary GIS output, and each step here is linear or n log n (a quadratic
collinear-corner pass once took 35 s for 20,000 corners).  The results are the same corner
for corner as the quadratic passes gave; tests/test_linear.py compares them.
"""

from __future__ import annotations

import heapq
import math
import struct

import numpy as np
import shapely
from shapely.geometry import Polygon
from shapely.validation import make_valid

from .geometry.cyclic import following, preceding
from .geometry.earclip import signed_area as ring_area

CLEAN_TOL = 1e-3  # metres: a corner this close to the previous one or to a straight line goes
MIN_WIDTH = 0.05  # metres: an outline whose mean width (2 area / perimeter) is less is skipped


class FootprintError(ValueError):
    """A feature's outline cannot be a lot; the message says why (it follows "skipped: ")."""


def clean_ring(ring) -> tuple[np.ndarray, str | None]:
    """A footprint outline (k, 2) in metres made fit to build on, and a note when that lost
    part of it; raises FootprintError when nothing usable is left.

    - the closing point and corners within CLEAN_TOL of the previous one are dropped;
    - an outline that crosses or touches itself is repaired with shapely's ``make_valid`` and
      the largest polygon it yields is kept (the note says how much was dropped), without any
      hole the repair makes (the input's own holes are rings of their own: see _clean_holes);
    - corners within CLEAN_TOL of the straight line through their neighbours are dropped;
    - an outline whose mean width (2 area / perimeter) is under MIN_WIDTH is not used.

    The first edge (the front) stays the one that carries the input's first edge; a repaired
    outline starts at its corner nearest the input's first corner and keeps its orientation.
    """
    pts = drop_repeats(np.asarray(ring, dtype=np.float64))
    if len(pts) < 3:
        raise FootprintError("its outline has fewer than three distinct corners")
    note = None
    poly = Polygon(pts)
    if not poly.is_valid:
        pts, note = _repair(pts, poly)
    kept = drop_straight(pts)
    if len(kept) >= 3 and Polygon(pts[kept]).is_valid:
        # the front edge is the kept edge that carries input edge 0: start at the last kept
        # corner at or before corner 0 (cyclically); kept is ascending, so 0 can only be first
        start = 0 if kept[0] == 0 else len(kept) - 1
        pts = pts[kept[start:] + kept[:start]]
    area, perimeter = abs(ring_area(pts)), float(lengths(pts).sum())
    if area == 0 or 2 * area / perimeter < MIN_WIDTH:
        raise FootprintError(
            "its outline has no area"
            if area < 1e-6
            else f"its outline is thinner than {MIN_WIDTH * 100:g} cm ({area:.2g} m²)"
        )
    return pts, note


def lengths(pts: np.ndarray) -> np.ndarray:
    """The length of each edge of a closed ring (edge i runs from corner i to corner i + 1)."""
    return np.linalg.norm(following(pts) - pts, axis=1)


def drop_repeats(pts: np.ndarray) -> np.ndarray:
    """The ring without its closing point and without corners within CLEAN_TOL of the one
    before (a corner is compared with the last one kept, so a run of near-repeats is one).

    Corners farther than CLEAN_TOL from their predecessor are kept in one vectorised test; only
    runs of near-repeats are walked one corner at a time, against the last corner kept."""
    n = len(pts)
    if n == 0:
        return pts
    step = np.linalg.norm(np.diff(pts, axis=0), axis=1)  # step[i - 1]: corner i from i - 1
    keep = np.ones(n, dtype=bool)
    close = (np.flatnonzero(step <= CLEAN_TOL) + 1).tolist()
    k = 0
    while k < len(close):
        i, last = close[k], close[k] - 1  # corner i - 1 is kept: every run ends at a kept one
        while i < n and np.linalg.norm(pts[i] - pts[last]) <= CLEAN_TOL:
            keep[i] = False
            i += 1
        while k < len(close) and close[k] <= i:
            k += 1
    kept = np.flatnonzero(keep).tolist()
    while len(kept) > 1 and np.linalg.norm(pts[kept[-1]] - pts[kept[0]]) <= CLEAN_TOL:
        kept.pop()
    return pts[kept]


def drop_straight(pts: np.ndarray) -> list[int]:
    """Indices of the corners that are not within CLEAN_TOL of the straight line through their
    neighbours (lying between them); repeated until none is left, so a run of them goes.

    The straightest corner goes first (the lowest index among equals), then its two neighbours
    are measured again.  The corners dropped are the ones that measuring every corner after
    each removal dropped (O(n²)), found in O(n log n): rounds of numpy drop many at once while
    that provably drops the same ones (:func:`_round`), then a heap finishes (:class:`_Ring`).
    """
    idx = np.arange(len(pts))
    while len(idx) > 3:
        gone = _round(pts[idx], idx)
        if gone is None:
            return idx[_Ring(pts[idx]).run()].tolist()
        if not len(gone):
            break
        idx = np.delete(idx, gone)
    return idx.tolist()


def _round(pts: np.ndarray, idx: np.ndarray) -> np.ndarray | None:
    """Positions of corners of the ring ``pts`` (original indices ``idx``, ascending) that the
    one-at-a-time removal drops next, before any corner it measures again could go; [] when no
    corner is straight, None when too few go for a round to pay (under 1/16 of the ring).

    Keys (offset, index) are measured once.  The key a corner gets when one neighbour goes is
    known beforehand; below the least of those (``bound``) every straight corner goes in key
    order unless a neighbour went before it.  A corner both of whose neighbours went is
    measured afterwards, and the round ends below its key."""
    m = len(pts)
    key = _keys(pts, preceding(pts), following(pts))
    straight = np.flatnonzero(key < math.inf)
    if not len(straight):
        return straight
    at = straight
    bound = min(
        _least(_keys(pts[at - 1], pts[at - 2], pts[(at + 1) % m]), idx[at - 1]),
        _least(_keys(pts[(at + 1) % m], pts[at - 1], pts[(at + 2) % m]), idx[(at + 1) % m]),
    )
    below = (key[at] < bound[0]) | ((key[at] == bound[0]) & (idx[at] < bound[1]))
    order = at[below][np.lexsort((idx[at][below], key[at][below]))].tolist()
    gone = [False] * m
    taken = []
    for p in order:
        if not (gone[p - 1] or gone[(p + 1) % m]):
            gone[p] = True
            taken.append(p)
    both = np.flatnonzero(np.roll(gone, 1) & np.roll(gone, -1))
    if len(both):
        again = _keys(pts[both], pts[both - 2], pts[(both + 2) % m])
        bound = min(bound, _least(again, idx[both]))
    out = np.array(taken, dtype=np.intp)
    over = (key[out] > bound[0]) | ((key[out] == bound[0]) & (idx[out] >= bound[1]))
    out = out[: min(int(np.argmax(over)) if over.any() else len(out), m - 3)]
    return out if len(out) * _ROUND_SHARE >= m else None


_ROUND_SHARE = 16  # a round that drops under 1/16 of the ring leaves the rest to the heap


def _least(keys: np.ndarray, ids: np.ndarray) -> tuple[float, float]:
    """The least (key, index) pair, (inf, inf) when there is none."""
    if not len(keys):
        return (math.inf, math.inf)
    low = keys.min()
    return (float(low), float(ids[keys == low].min())) if low < math.inf else (math.inf, math.inf)


class _Ring:
    """The corners of an outline, linked both ways; a heap drops the straightest, measures its
    neighbours again, and so on.

    A heap entry is one int, the bits of the corner's key (its offset, a float >= 0, whose
    bits order as it does) above its index, so that equal keys go lowest index first and the
    heap compares ints, three times faster than (key, index) tuples.  ``entry[i]`` is corner
    i's live entry (None when it is not straight or is gone); any other is stale."""

    def __init__(self, pts: np.ndarray) -> None:
        n = len(pts)
        self.xy, self.count, self.shift = pts.tolist(), n, max(n.bit_length(), 1)
        self.before, self.after = [n - 1, *range(n - 1)], [*range(1, n), 0]
        key = _keys(pts, preceding(pts), following(pts))
        bits = key.view(np.int64).tolist()
        self.entry: list[int | None] = [
            (b << self.shift) | i if k < math.inf else None
            for i, (k, b) in enumerate(zip(key.tolist(), bits, strict=True))
        ]
        self.alive = [True] * n

    def run(self) -> list[int]:
        """Drop corners straightest first (the lowest index among equals) until none is
        straight or three are left; the positions of those kept."""
        entry, mask = self.entry, (1 << self.shift) - 1
        heap = [e for e in entry if e is not None]
        heapq.heapify(heap)
        while heap and self.count > 3:
            e = heapq.heappop(heap)
            i = e & mask
            if entry[i] != e:
                continue
            for j in self._drop(i):
                if entry[j] is not None:
                    heapq.heappush(heap, entry[j])
        return [i for i, alive in enumerate(self.alive) if alive]

    def _drop(self, i: int) -> tuple[int, int]:
        """Drop corner i, measure its two neighbours again and return them."""
        before, after, xy = self.before, self.after, self.xy
        a, c = before[i], after[i]
        after[a], before[c] = c, a
        self.alive[i], self.entry[i], self.count = False, None, self.count - 1
        for j in (a, c):
            key = _key(xy[before[j]], xy[j], xy[after[j]])
            bits = int.from_bytes(_DOUBLE.pack(key), "little")
            self.entry[j] = (bits << self.shift) | j if key < math.inf else None
        return a, c


_DOUBLE = struct.Struct("<d")


def _keys(b: np.ndarray, a: np.ndarray, c: np.ndarray) -> np.ndarray:
    """The key of each corner b between neighbours a and c (rows): its offset from the line
    a-c when it is straight, inf when not."""
    off, straight = _straightness(a, b, c)
    return np.where(straight, off, math.inf)


def _straightness(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For corners b between neighbours a and c (rows): the distance of b from the line a-c,
    and whether b counts as straight (a and c apart, b near the line and between them)."""
    ac = c - a
    span = np.linalg.norm(ac, axis=1)
    off = np.abs(ac[:, 0] * (b - a)[:, 1] - ac[:, 1] * (b - a)[:, 0]) / np.maximum(span, 1e-300)
    between = np.einsum("ij,ij->i", b - a, c - b) > 0
    return off, (span > CLEAN_TOL) & (off <= CLEAN_TOL) & between


def _key(a: list, b: list, c: list) -> float:
    """:func:`_straightness` of one corner in plain floats (the same operations in the same
    order, so the same bits): its offset if it is straight, inf if it is not."""
    acx, acy = c[0] - a[0], c[1] - a[1]
    abx, aby = b[0] - a[0], b[1] - a[1]
    span = math.sqrt(acx * acx + acy * acy)
    off = abs(acx * aby - acy * abx) / max(span, 1e-300)
    if span > CLEAN_TOL and off <= CLEAN_TOL and abx * (c[0] - b[0]) + aby * (c[1] - b[1]) > 0:
        return off
    return math.inf


def _repair(pts: np.ndarray, poly: Polygon) -> tuple[np.ndarray, str | None]:
    """The largest polygon ``make_valid`` makes of a self-crossing outline, as a ring in the
    input's orientation starting at the corner nearest the input's first one."""
    fixed = make_valid(poly)
    parts = [
        g
        for g in shapely.get_parts(fixed)
        for g in (shapely.get_parts(g) if g.geom_type == "GeometryCollection" else [g])
        if g.geom_type in ("Polygon", "MultiPolygon")
    ]
    polygons = [p for g in parts for p in shapely.get_parts(g) if p.area > 0]
    if not polygons:
        raise FootprintError("its outline has no area")
    best = max(polygons, key=lambda p: p.area)
    ring = np.array(best.exterior.coords[:-1], dtype=np.float64)
    if (ring_area(ring) > 0) != (ring_area(pts) > 0):
        ring = ring[::-1]
    ring = np.roll(ring, -int(np.argmin(np.linalg.norm(ring - pts[0], axis=1))), axis=0)
    note = None
    if len(polygons) > 1:
        total = sum(p.area for p in polygons)
        note = (
            f"its outline crosses itself; repaired, keeping the largest of its {len(polygons)} "
            f"parts ({best.area:.3g} of {total:.3g} m²)"
        )
    return drop_repeats(ring), note
