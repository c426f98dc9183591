"""Weighted straight skeleton of a simple polygon without holes, by wavefront simulation.

The straight skeleton (Aichholzer et al. 1995) is traced by the *wavefront*: every edge of the
polygon moves inward, parallel to itself, at its own speed (its *weight*; 1 for an ordinary roof
slope, 0 for an edge that stays put, like a gable wall), and the polygon's vertices slide along
the bisectors so that they stay on both of their moving edges.  At time ``t`` an edge of weight
``w`` has moved ``w * t``; lifted to height ``t * tan(pitch)`` the path swept by each edge is a
roof plane at that pitch (a vertical plane for ``w = 0``), and the region it sweeps is its *face*.
The polygon's topology changes only at *events*:

* **edge event** — an edge shrinks to length zero; its two vertices merge into one, which carries
  on between the edge's two neighbours;
* **split event** — a vertex runs into an edge that is not its neighbour (only reflex vertices do
  this when every weight is 1); the polygon is cut in two there, a *vertex event* (two reflex
  vertices meeting) being the special case of hitting an edge at its end.

Felkel and Obdržálek (1998) keep a priority queue of such events and patch the wavefront's
circular lists in place; that bookkeeping is where implementations usually break down on the
simultaneous events that rectilinear footprints (L, T, U, plus shapes) are made of.  This module
uses the same events but a simpler, sturdier loop, affordable for building footprints (tens to a
few hundred vertices):

1. from the current wavefront polygons, compute the time of the earliest event of any kind, in
   closed form (every vertex moves linearly between events);
2. advance every vertex to that time;
3. *clean up* at that instant, within a small tolerance: merge vertices joined by zero-length
   edges (edge events, including several at once), cut a polygon wherever one of its vertices
   touches one of its other edges (split and vertex events), and retire polygons that have
   collapsed to zero area (their remaining edges are the ridges);
4. repeat until no polygon is left.

One more clean-up rule keeps nearly degenerate input (footprints with coordinate noise) sane: a
vertex between two nearly antiparallel edges runs almost infinitely fast along the thin spike
those edges form, so a tolerance-sized error in when it was made would send it anywhere; when the
spike is thinner than ``ZIP_TOL`` it is zipped up at once (the end of its shorter side is split
onto the other side), which is where that vertex was going.

Every vertex leaves a straight *arc* from where it was born to where it died; each arc bounds the
faces of the vertex's two edges, and each collapsed polygon's last edges bound their own faces.
The faces are then assembled from those segments: nodes closer than ``SNAP`` are merged,
segments are split where another node lies on them (no T-junctions), and each face's boundary is
walked as a planar graph.  Optional *break times* cut the whole wavefront at given offsets, so that
each face is split into stages (a mansard roof's steep lower band and shallow upper part).

The same wavefront run on the reversed polygon grows it outward (:func:`offset_outward`), with its
events: that is how a roof's eaves are laid out for an overhang.

Coordinates are scaled to a unit-size polygon while computing, so the tolerances are relative.
The loop is O(n^2) numpy work per event and O(n) events: a 200-vertex footprint takes a fraction
of a second.
"""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from .cyclic import following
from .earclip import signed_area

TOL = 1e-9  # event and touch tolerance, relative to the polygon's size
SNAP = 1e-6  # nodes closer than this (relative) are one node
_TINY = 1e-12  # a rate (speed) smaller than this is zero
_MAX_TOL = 1e-5  # the loop widens its tolerance up to this before it gives up
_SPIKE = 1e-3  # |n_in + n_out| below this: a vertex between nearly antiparallel edges
ZIP_TOL = 1e-7  # a spike thinner than this (relative) is zipped up at once


class SkeletonError(RuntimeError):
    """The wavefront simulation could not make progress (a degenerate input)."""


@dataclass
class Skeleton:
    """The result of :func:`straight_skeleton`.

    ``nodes[i] = (x, y, t)``: a point of the skeleton and the time (offset of a weight-1 edge) at
    which the wavefront passed it; the input polygon's vertices are nodes ``0 .. n-1`` at t = 0.
    ``faces[stage][k]`` lists the cycles (node ids) of the region swept by edge ``k`` (from
    ``polygon[k]`` to ``polygon[k+1]``) during that stage; stage ``s`` runs from
    ``breaks[s-1]`` to ``breaks[s]`` (from 0, to the end).  A cycle is counter-clockwise seen
    from above for a moving edge, and seen from outside the polygon for a weight-0 edge (whose
    face is vertical: it is drawn in the coordinates (position along the edge, t)).
    """

    nodes: np.ndarray
    faces: list[list[list[list[int]]]]
    weights: np.ndarray
    breaks: tuple[float, ...]
    t_max: float


def straight_skeleton(polygon, weights=None, breaks=()) -> Skeleton:
    """The weighted straight skeleton of a simple counter-clockwise polygon (K, 2).

    ``weights`` (K,) are the edges' speeds (default all 1; use 0 for an edge that must not move);
    ``breaks`` are increasing times at which the faces are cut into stages.  The polygon must be
    simple, counter-clockwise, without repeated or collinear consecutive vertices.
    """
    pts = np.asarray(polygon, dtype=np.float64)
    n = len(pts)
    if n < 3 or signed_area(pts) <= 0:
        raise ValueError("straight_skeleton needs a counter-clockwise polygon of 3+ vertices")
    w = np.ones(n) if weights is None else np.asarray(weights, dtype=np.float64)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre, scale = (lo + hi) / 2.0, float((hi - lo).max())
    unit = (pts - centre) / scale

    wave = _Wavefront(unit, w)
    polys, time = [wave.start(unit)], 0.0
    for stop in [b / scale for b in breaks]:
        polys, time = wave.run(polys, time, stop)
        polys = wave.cut(polys, time)
    wave.run(polys, time, None)

    nodes = np.array(wave.nodes, dtype=np.float64)
    faces = _assemble_faces(nodes, wave.segments, wave.d, w)
    nodes[:, :2] = nodes[:, :2] * scale + centre
    nodes[:, 2] *= scale
    nodes[:n, :2] = pts  # the footprint's own corners, bit for bit
    return Skeleton(
        nodes=nodes, faces=faces, weights=w, breaks=tuple(breaks), t_max=float(nodes[:, 2].max())
    )


def offset_outward(polygon, distance: float, weights=None):
    """The polygon grown outward by the wavefront of its outside: edge k moves out by
    ``weights[k] * distance``, corners mitred, and the outward wavefront's own events applied
    (a short edge between two reflex corners vanishes; a notch narrower than twice the distance
    closes, and a courtyard it would enclose is filled).

    Returns ``(points, source)``: the grown polygon (M, 2), counter-clockwise, and for each of its
    edges the index of the input edge it lies on (the line of input edge ``source[q]`` moved out
    by ``weights[source[q]] * distance``).
    """
    pts = np.asarray(polygon, dtype=np.float64)
    n = len(pts)
    if distance <= 0:
        return pts.copy(), np.arange(n)
    w = np.ones(n) if weights is None else np.asarray(weights, dtype=np.float64)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre, scale = (lo + hi) / 2.0, float((hi - lo).max())
    rev = ((pts - centre) / scale)[::-1]  # clockwise: its left normals point outward
    wave = _Wavefront(rev, w[(n - 2 - np.arange(n)) % n])  # its edge j is input edge n-2-j
    polys, _ = wave.run([wave.start(rev)], 0.0, distance / scale)
    polys, _ = wave._cleanup(polys, distance / scale, SNAP)  # nothing finer than a skeleton node
    front = min(polys, key=_area)  # the outer front is the one clockwise loop; drop courtyards
    ccw = front[::-1]
    m = len(ccw)
    source = [(n - 2 - ccw[(q + 1) % m].e_out) % n for q in range(m)]
    return _positions(ccw) * scale + centre, np.array(source, dtype=np.int64)


# --------------------------------------------------------------------------------------------
# the wavefront


def edge_lines(pts: np.ndarray):
    """Unit directions d, inward (left, for a counter-clockwise polygon) unit normals n and
    offsets c of the polygon's edges: edge k lies on the line n[k] . x = c[k]."""
    d = following(pts) - pts
    d /= np.linalg.norm(d, axis=1)[:, None]
    nrm = np.column_stack([-d[:, 1], d[:, 0]])
    return d, nrm, np.einsum("ij,ij->i", nrm, pts)


def _bisector_velocity(na, nb, wa, wb):
    """Velocity v of a vertex between edges with inward normals na, nb moving at speeds wa, wb:
    the solution of na . v = wa, nb . v = wb.  None when undefined (antiparallel edges)."""
    dot = float(na @ nb)
    if wa == wb:  # the usual case: v = w (na + nb) / (1 + na.nb), with 1 + na.nb = |na + nb|^2 / 2
        s = na + nb  # computed this way it stays accurate for nearly antiparallel edges
        s2 = float(s @ s)
        return None if s2 < 1e-18 else 2.0 * wa * s / s2
    det = float(na[0] * nb[1] - na[1] * nb[0])
    if abs(det) < 1e-12:
        # collinear edges of different speeds (degenerate): follow the faster one
        return None if dot < 0 else max(wa, wb) * na
    return np.array([wa * nb[1] - wb * na[1], wb * na[0] - wa * nb[0]]) / det


class _Vertex:
    """A wavefront vertex: position ``p`` at time ``t``, velocity ``v``, its incoming and outgoing
    edges and the node where it was born (its arc runs from there to where it dies)."""

    __slots__ = ("p", "t", "v", "e_in", "e_out", "node")

    def __init__(self, p, t, v, e_in, e_out, node):
        self.p, self.t, self.v, self.e_in, self.e_out, self.node = p, t, v, e_in, e_out, node


class _Wavefront:
    """The simulation state: edge lines, the nodes made so far, and each face's segments."""

    def __init__(self, pts: np.ndarray, weights: np.ndarray):
        self.d, self.n, self.c = edge_lines(pts)
        self.w = weights
        self.nodes: list[tuple[float, float, float]] = []
        self.segments: list[list[list[tuple[int, int]]]] = [[[] for _ in pts]]
        self.stage = 0
        self.max_steps = 100 * len(pts) + 1000

    # -- records ----------------------------------------------------------------------------

    def _node(self, p, t: float) -> int:
        self.nodes.append((float(p[0]), float(p[1]), float(t)))
        return len(self.nodes) - 1

    def _segment(self, edge: int, a: int, b: int) -> None:
        if a != b:
            self.segments[self.stage][edge].append((a, b))

    def _vertex(self, p, t, e_in, e_out, node) -> _Vertex:
        v = _bisector_velocity(self.n[e_in], self.n[e_out], self.w[e_in], self.w[e_out])
        return _Vertex(
            np.array(p, dtype=np.float64), t, np.zeros(2) if v is None else v, e_in, e_out, node
        )

    def _die(self, vx: _Vertex, node: int) -> None:
        """End the vertex's arc at ``node``: the arc bounds the faces of both its edges."""
        self._segment(vx.e_in, vx.node, node)
        self._segment(vx.e_out, vx.node, node)

    # -- the loop ---------------------------------------------------------------------------

    def start(self, pts: np.ndarray) -> list[_Vertex]:
        """The input polygon as a wavefront at t = 0 (nodes 0..n-1), its edges bounding faces."""
        n = len(pts)
        ids = [self._node(p, 0.0) for p in pts]
        for k in range(n):
            self._segment(k, ids[k], ids[(k + 1) % n])
        return [self._vertex(pts[k], 0.0, (k - 1) % n, k, ids[k]) for k in range(n)]

    def run(self, polys, time: float, stop: float | None):
        """Run events from ``time`` until the wavefront is gone (``stop`` None) or until
        ``stop``; returns the polygons alive at ``stop`` and the time reached."""
        polys, _ = self._cleanup(polys, time, TOL)
        tol = TOL
        for _ in range(self.max_steps):
            if not polys:
                return [], time
            t_next = min(self.next_event(p, time) for p in polys)
            if stop is not None and t_next >= stop - TOL:
                self._advance(polys, stop)
                polys, _ = self._cleanup(polys, stop, TOL)
                return polys, stop
            if not math.isfinite(t_next):
                raise SkeletonError("the wavefront has no further event but has not collapsed")
            t_next = max(t_next, time)
            self._advance(polys, t_next)
            stalled = t_next - time <= TOL
            polys, changed = self._cleanup(polys, t_next, tol)
            time = t_next
            if changed or not stalled:
                tol = TOL
            else:  # an event predicted now that the cleanup did not see: look a little wider
                tol *= 10.0
                if tol > _MAX_TOL:
                    raise SkeletonError(f"no progress at offset {time:.6g}")
        raise SkeletonError("too many events")

    def cut(self, polys, time: float):
        """End the current stage at ``time``: every vertex dies there, the wavefront's edges close
        this stage's faces and open the next stage's, and new vertices carry on."""
        rings = []
        for poly in polys:
            ids = [self._node(vx.p, time) for vx in poly]
            for vx, nid in zip(poly, ids, strict=True):
                self._die(vx, nid)
            rings.append(ids)
        for stage_delta in (0, 1):
            if stage_delta:
                self.stage += 1
                self.segments.append([[] for _ in self.w])
            for poly, ids in zip(polys, rings, strict=True):
                for q, vx in enumerate(poly):
                    self._segment(vx.e_out, ids[q], ids[(q + 1) % len(poly)])
        return [
            [
                self._vertex(vx.p, time, vx.e_in, vx.e_out, nid)
                for vx, nid in zip(poly, ids, strict=True)
            ]
            for poly, ids in zip(polys, rings, strict=True)
        ]

    @staticmethod
    def _advance(polys, time: float) -> None:
        for poly in polys:
            for vx in poly:
                vx.p = vx.p + (time - vx.t) * vx.v
                vx.t = time

    def next_event(self, poly, time: float) -> float:
        """Time of the polygon's earliest edge or split event after ``time`` (inf if none)."""
        m = len(poly)
        P = np.array([vx.p + (time - vx.t) * vx.v for vx in poly])
        V = np.array([vx.v for vx in poly])
        E = np.array([vx.e_out for vx in poly])
        nxt = np.r_[1:m, 0]
        D = self.d[E]
        best = math.inf

        # edge events: edge j (vertex j -> j+1) shrinks along its direction
        length = np.einsum("ij,ij->i", D, P[nxt] - P)
        rate = np.einsum("ij,ij->i", D, V[nxt] - V)
        shrink = rate < -_TINY
        if shrink.any():
            best = min(best, time + float((np.maximum(length[shrink], 0.0) / -rate[shrink]).min()))

        # split events: vertex i reaches the moving line of edge j within the edge's extent
        N, C, W = self.n[E], self.c[E], self.w[E]
        dist = P @ N.T - C - W * time  # dist[i, j]: how far vertex i is in front of edge j
        closing = V @ N.T - W  # its rate of change
        ok = (closing < -_TINY) & (dist > -TOL)
        ok[np.arange(m), np.arange(m)] = False  # vertex i's own outgoing edge
        ok[np.arange(m), np.arange(m) - 1] = False  # ... and incoming edge
        ii, jj = np.nonzero(ok)
        if len(ii):
            dt = np.maximum(dist[ii, jj], 0.0) / -closing[ii, jj]
            hit = P[ii] + dt[:, None] * V[ii]
            a = P[jj] + dt[:, None] * V[jj]
            b = P[nxt[jj]] + dt[:, None] * V[nxt[jj]]
            along = np.einsum("ij,ij->i", D[jj], hit - a)
            extent = np.einsum("ij,ij->i", D[jj], b - a)
            inside = (along > -TOL) & (along < extent + TOL)
            if inside.any():
                best = min(best, time + float(dt[inside].min()))
        return best

    # -- topology changes at one instant ------------------------------------------------------

    def _cleanup(self, polys, time: float, tol: float):
        """Apply every event that holds at ``time`` (within ``tol``); see the module docstring."""
        out, queue, changed = [], list(polys), False
        while queue:
            poly = queue.pop()
            while True:
                if len(poly) < 3 or abs(_area(poly)) <= tol * _perimeter(poly):
                    self._retire(poly, time)
                    changed = True
                    break
                j = _short_edge(poly, tol)
                if j is not None:
                    poly = self._merge(poly, j, time)
                    changed = True
                    continue
                hit = _touch(poly, tol)
                if hit is None:
                    hit = self._spike(poly)
                if hit is not None:
                    queue.extend(self._split(poly, hit[0], hit[1], time))
                    changed = True
                    break
                out.append(poly)
                break
        return out, changed

    def _spike(self, poly):
        """A zero-width spike to zip up, as (vertex, edge) for :meth:`_split`, or None.

        A vertex between two nearly antiparallel edges moves almost infinitely fast along the
        spike they form, so errors of the size of the tolerance in when it was made would send it
        anywhere.  When the spike is thin — its shorter side ends within ZIP_TOL of the other
        side's edge — it is zipped at once, which is where that vertex would have gone: the end
        of the shorter side is split onto the other side's edge.
        """
        m = len(poly)
        for v, vx in enumerate(poly):
            if np.linalg.norm(self.n[vx.e_in] + self.n[vx.e_out]) > _SPIKE:
                continue
            before, after = poly[v - 1], poly[(v + 1) % m]
            if np.linalg.norm(after.p - vx.p) <= np.linalg.norm(before.p - vx.p):
                tip, edge, a, b = (v + 1) % m, (v - 1) % m, before.p, vx.p
            else:
                tip, edge, a, b = (v - 1) % m, v, vx.p, after.p
            if _segment_distance(poly[tip].p, a, b) < ZIP_TOL:
                return tip, edge
        return None

    def _merge(self, poly, j: int, time: float):
        """Edge event: vertices j and j+1 become one vertex between their outer edges."""
        m = len(poly)
        a, b = poly[j], poly[(j + 1) % m]
        mid = (a.p + b.p) / 2.0
        node = self._node(mid, time)
        self._die(a, node)
        self._die(b, node)
        merged = self._vertex(mid, time, a.e_in, b.e_out, node)
        if j + 1 < m:
            return poly[:j] + [merged] + poly[j + 2 :]
        return poly[1:j] + [merged]

    def _split(self, poly, i: int, j: int, time: float):
        """Split event: vertex i touches edge j (vertex j -> j+1); the polygon becomes the loop
        i..j closed along edge j and the loop j+1..i closed along edge j."""
        m = len(poly)
        vx = poly[i]
        node = self._node(vx.p, time)
        self._die(vx, node)
        k = poly[j].e_out
        first = [self._vertex(vx.p, time, k, vx.e_out, node)]
        first += [poly[(i + 1 + q) % m] for q in range((j - i) % m)]
        second = [self._vertex(vx.p, time, vx.e_in, k, node)]
        second += [poly[(j + 1 + q) % m] for q in range((i - j - 1) % m)]
        return [first, second]

    def _retire(self, poly, time: float) -> None:
        """A polygon of zero area: its vertices die where they are, and its edges (ridges, or
        nothing at all) close the faces of their edges."""
        ids = [self._node(vx.p, time) for vx in poly]
        for vx, nid in zip(poly, ids, strict=True):
            self._die(vx, nid)
        for q, vx in enumerate(poly):
            self._segment(vx.e_out, ids[q], ids[(q + 1) % len(poly)])


def _positions(poly) -> np.ndarray:
    return np.array([vx.p for vx in poly])


def _area(poly) -> float:
    return signed_area(_positions(poly))


def _perimeter(poly) -> float:
    p = _positions(poly)
    return float(np.linalg.norm(following(p) - p, axis=1).sum())


def _short_edge(poly, tol: float):
    """Index of the shortest edge if it is shorter than ``tol``."""
    p = _positions(poly)
    lengths = np.linalg.norm(following(p) - p, axis=1)
    j = int(np.argmin(lengths))
    return j if lengths[j] < tol else None


def _segment_distance(p, a, b) -> float:
    ab = b - a
    s = float(np.clip((p - a) @ ab / max(float(ab @ ab), 1e-300), 0.0, 1.0))
    return float(np.linalg.norm(p - a - s * ab))


def _touch(poly, tol: float):
    """(i, j) of the vertex i closest to a non-adjacent edge j, if closer than ``tol``."""
    p = _positions(poly)
    m = len(p)
    a, b = p, following(p)
    ab = b - a
    len2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    rel = p[:, None, :] - a[None, :, :]  # (vertex i, edge j, 2)
    s = np.clip(np.einsum("ijk,jk->ij", rel, ab) / len2[None, :], 0.0, 1.0)
    gap = np.linalg.norm(rel - s[:, :, None] * ab[None, :, :], axis=2)
    gap[np.arange(m), np.arange(m)] = np.inf
    gap[np.arange(m), np.arange(m) - 1] = np.inf
    i, j = np.unravel_index(int(np.argmin(gap)), gap.shape)
    return (int(i), int(j)) if gap[i, j] < tol else None


# --------------------------------------------------------------------------------------------
# faces from segments


def _assemble_faces(nodes: np.ndarray, segments, d: np.ndarray, w: np.ndarray):
    """Turn each face's arc segments into closed cycles of node ids (see :class:`Skeleton`).

    Nodes closer than SNAP are merged (the survivor's id is kept), zero-length and repeated
    segments dropped, segments split at any node lying on them, and each face's segment graph
    walked: at every node the walk turns to the next segment clockwise from where it came, which
    traces each bounded region counter-clockwise; clockwise (outer) loops are dropped.
    """
    rep = _snap(nodes, SNAP)
    faces = []
    for stage in segments:
        per_edge = []
        for segs in stage:
            uniq = {tuple(sorted((int(rep[a]), int(rep[b])))) for a, b in segs}
            per_edge.append([s for s in uniq if s[0] != s[1]])
        faces.append(per_edge)
    used = sorted({v for stage in faces for segs in stage for s in segs for v in s})
    used = np.array(used, dtype=np.int64)
    out = []
    for stage in faces:
        cycles_of_stage = []
        for k, segs in enumerate(stage):
            segs = sorted({tuple(sorted(s)) for s in _split_at_nodes(segs, nodes, used)})
            # a sloped face is drawn from above; a vertical one from outside, as
            # (position along the edge, t)
            flat = nodes[:, :2] if w[k] > 0 else np.column_stack([nodes[:, :2] @ d[k], nodes[:, 2]])
            cycles_of_stage.append(_walk_cycles(segs, flat))
        out.append(cycles_of_stage)
    return out


def _snap(pts: np.ndarray, tol: float) -> np.ndarray:
    """Representative index of each point: points within ``tol`` (transitively) share one."""
    parent = np.arange(len(pts))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    cells = defaultdict(list)
    keys = np.floor(pts / tol).astype(np.int64)
    offsets = [(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)]
    for i, key in enumerate(map(tuple, keys)):
        for off in offsets:
            for j in cells.get((key[0] + off[0], key[1] + off[1], key[2] + off[2]), ()):
                if np.linalg.norm(pts[i] - pts[j]) <= tol:
                    ri, rj = find(i), find(j)
                    if ri != rj:
                        parent[max(ri, rj)] = min(ri, rj)
        cells[key].append(i)
    return np.array([find(i) for i in range(len(pts))])


def _split_at_nodes(segs, nodes: np.ndarray, used: np.ndarray):
    """Split every segment at the nodes lying on it (closer than SNAP), in order."""
    out = []
    q = nodes[used]
    for a, b in segs:
        pa, pb = nodes[a], nodes[b]
        ab = pb - pa
        len2 = float(ab @ ab)
        s = (q - pa) @ ab / len2
        gap = np.linalg.norm(q - pa - s[:, None] * ab, axis=1)
        on = (s > 0) & (s < 1) & (gap <= SNAP) & (used != a) & (used != b)
        chain = [a] + [int(v) for v in used[on][np.argsort(s[on])]] + [b]
        out += [(chain[i], chain[i + 1]) for i in range(len(chain) - 1)]
    return out


def _walk_cycles(segs, flat: np.ndarray) -> list[list[int]]:
    """Counter-clockwise cycles of the planar graph ``segs`` drawn with coordinates ``flat``."""
    adj = defaultdict(set)
    for a, b in segs:
        adj[a].add(b)
        adj[b].add(a)
    ring = {}
    for v, nbrs in adj.items():
        nbrs = list(nbrs)
        ang = [math.atan2(flat[u, 1] - flat[v, 1], flat[u, 0] - flat[v, 0]) for u in nbrs]
        ring[v] = [nbrs[i] for i in np.argsort(ang)]
    seen, cycles = set(), []
    for a, b in segs:
        for start in ((a, b), (b, a)):
            if start in seen:
                continue
            cycle, (u, v) = [], start
            while (u, v) not in seen:
                seen.add((u, v))
                cycle.append(u)
                around = ring[v]
                u, v = v, around[around.index(u) - 1]  # next clockwise from the way back
            cycle = _drop_spikes(cycle)
            if len(cycle) >= 3 and signed_area(flat[cycle]) > 1e-14:
                cycles.append(cycle)
    return cycles


def _drop_spikes(cycle: list[int]) -> list[int]:
    """Remove back-and-forth excursions (u, v, u) that dangling segments leave in a walk."""
    changed = True
    while changed and len(cycle) >= 3:
        changed = False
        for i in range(len(cycle)):
            if cycle[i - 1] == cycle[(i + 1) % len(cycle)]:
                del cycle[i]
                del cycle[i - 1 if i > 0 else -1]
                changed = True
                break
    return cycle
