"""Distances between two triangle meshes: how far a derived city is from the input it stands for.

``bgr infer --kind city`` promises that the grammar's level 0 reproduces every input triangle
within 1 mm (symmetric Hausdorff distance) and reports Chamfer and Hausdorff errors for the
coarser levels, so the measure must be exact where it looks, and fast on whole cities (a million
triangles a side).  Each surface is sampled (every vertex, face centroid and edge midpoint, which
is where a missing or moved triangle shows first, plus area-weighted random points for the
means), and each sample gets its *exact* distance to the other mesh's nearest triangle.

The nearest triangle is found without a BVH library (rtree and embree are not installed), with a
uniform grid.  A KD-tree of triangle centroids, asked for everything within the best distance
plus the largest triangle radius, is exact too, but a city's triangles are large (whole walls:
a radius of 7 m is typical) and each sample then gets hundreds of candidates; the grid gives it
about ten, whose bounding boxes cut most of them at once:

- the cell side is about the side of a square of a triangle's mean area; each triangle is
  registered in every cell its bounding box overlaps, after triangles much larger than a cell
  are cut along their longest edge into pieces whose boxes span at most ``SPAN`` cells (the
  distance to a piece is the distance to part of its triangle, so the least over the pieces is
  still exact);
- a sample measures the pieces of its own cell: the one whose box is nearest first, which gives
  a bound at once, then only those whose box is nearer than the best distance so far.  If the
  ball of that radius leaves the cell, it measures the neighbouring cells the ball reaches; from
  an empty cell, all 26 neighbours;
- a sample whose ball still reaches beyond those 27 cells (more than about a cell from the
  other surface) asks a :class:`scipy.spatial.cKDTree` of the pieces' box centres for more and
  more neighbours within the best distance plus the largest half-diagonal, until none is left:
  exact too, but some 50 µs a sample, so that two unrelated cities take minutes where two
  near-equal ones take seconds;
- the point-triangle distances are computed in bulk with Ericson's closest-point regions
  (Real-Time Collision Detection, 5.1.5), and, for degenerate (zero-area) triangles, as the
  least distance to their three edges; chunks of (sample, piece) pairs go to ``THREADS``
  threads (numpy lets go of the GIL) and bound the memory in use.

1 M triangles against the same moved 0.5 mm (8.5 M samples) take about 19 s and 1.5 GB on two
shared cores (bench/city_distance.py).

Both meshes are re-centred on one offset (the middle of their common bounding box) before any
arithmetic, so projected coordinates of millions of metres keep their millimetres.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from bgr.interpreter.limits import check_memory

# a triangle whose |ab x ac| is below this fraction of its longest edge squared is degenerate:
# it is measured as its three edges (its height is then under 1e-10 of its size)
FLAT = 1e-10
CELL = 1.4  # grid cell side, in units of the side of a square of a triangle's mean area
SPAN = 4  # a piece's bounding box spans at most this many grid cells a side
ENTRY_BYTES = 40  # what one (cell, piece) pair of a _Grid costs while it is built
MAX_ENTRIES = 16  # (cell, piece) pairs per triangle at most; coarser cells beyond
THREADS = min(2, os.cpu_count() or 1)  # chunks measured at once (each holds CHUNK_PAIRS)
CHUNK_POINTS = 500_000  # samples whose ball leaves their cell, taken a block at a time
CHUNK_PAIRS = 1_000_000  # (sample, candidate) pairs held at once: bounds the memory in use
# the 26 cells round a cell, the nearest (sharing a face) first
_NEIGHBOURS = sorted(
    (np.array(o) - 1 for o in np.ndindex(3, 3, 3) if o != (1, 1, 1)), key=lambda o: abs(o).sum()
)
MAX_SPLITS = 64  # bisection levels: a safety stop, reached only by non-finite input


@dataclass(frozen=True)
class Distances:
    """Distances between surfaces A and B, in the meshes' units (metres for bgr).

    ``a_to_b_max`` is the largest distance from a sample of A to B (the one-sided Hausdorff
    distance, as far as the samples see), ``hausdorff`` the larger of the two sides.  The means
    are taken over the area-weighted random samples only (each stands for the same area, so the
    mean estimates the surface integral; the vertices, centroids and midpoints would weight small
    triangles more); a surface of no area, which has no random samples, takes the mean of all
    its samples.  ``chamfer`` is the average of the two means.  ``samples`` counts the samples
    of both sides; ``worst`` is the sample, in the input's coordinates, where the Hausdorff
    distance is reached (None when a side is empty).
    """

    hausdorff: float
    chamfer: float
    a_to_b_max: float
    b_to_a_max: float
    a_to_b_mean: float
    b_to_a_mean: float
    samples: int
    worst: np.ndarray | None = None


def surface_distances(
    a_vertices: np.ndarray,
    a_faces: np.ndarray,
    b_vertices: np.ndarray,
    b_faces: np.ndarray,
    *,
    samples_per_m2: float = 4.0,
    min_samples: int = 1000,
    max_samples: int = 1_000_000,
    seed: int = 0,
) -> Distances:
    """Sampled symmetric Hausdorff and Chamfer distances between two triangle meshes.

    Each mesh is sampled at every vertex used by a face, every face centroid, every edge
    midpoint and ``samples_per_m2`` area-weighted random points per unit of area (at least
    ``min_samples``, at most ``max_samples``: a whole city at 4 per m² would be tens of
    millions), drawn from ``numpy.random.default_rng(seed)``.  Each sample's distance to the
    other mesh is exact.  A mesh with no faces is infinitely far from one with faces; two empty
    meshes are at distance 0.
    """
    av, af = _checked(a_vertices, a_faces, "a")
    bv, bf = _checked(b_vertices, b_faces, "b")
    used = [v[_used(len(v), f)] for v, f in ((av, af), (bv, bf)) if len(f)]
    if used:
        both = np.concatenate(used)
        offset = (both.min(axis=0) + both.max(axis=0)) / 2.0
    else:
        offset = np.zeros(3)
    a_tris = (av - offset)[af]
    b_tris = (bv - offset)[bf]
    rng = np.random.default_rng(seed)
    options = (samples_per_m2, min_samples, max_samples)
    a_points, a_random = surface_samples(av - offset, af, *options, rng=rng)
    b_points, b_random = surface_samples(bv - offset, bf, *options, rng=rng)
    a_to_b = mesh_distances(a_points, b_tris)
    b_to_a = mesh_distances(b_points, a_tris)
    a_max, a_at = _max(a_to_b)
    b_max, b_at = _max(b_to_a)
    a_mean = _mean(a_to_b, a_random)
    b_mean = _mean(b_to_a, b_random)
    if a_at is None or b_at is None:
        worst = None
    else:
        worst = (a_points[a_at] if a_max >= b_max else b_points[b_at]) + offset
    return Distances(
        hausdorff=max(a_max, b_max),
        chamfer=(a_mean + b_mean) / 2.0,
        a_to_b_max=a_max,
        b_to_a_max=b_max,
        a_to_b_mean=a_mean,
        b_to_a_mean=b_mean,
        samples=len(a_points) + len(b_points),
        worst=worst,
    )


def surface_samples(
    vertices: np.ndarray,
    faces: np.ndarray,
    samples_per_m2: float = 4.0,
    min_samples: int = 1000,
    max_samples: int = 1_000_000,
    *,
    rng: np.random.Generator | None = None,
) -> tuple[np.ndarray, int]:
    """The sample points of a surface and how many of them, at the end, are random.

    First every distinct vertex that a face uses, every face centroid and every distinct edge
    midpoint (vertices at the same place are welded first, so that a triangle soup gives each
    shared corner and edge once), then ``clip(area * samples_per_m2, min_samples, max_samples)``
    points drawn uniformly over the area (none on a surface of no area).
    """
    if samples_per_m2 < 0 or min_samples < 0 or max_samples < 0:
        raise ValueError("sample counts and densities cannot be negative")
    rng = rng if rng is not None else np.random.default_rng(0)
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if not len(faces):
        return np.zeros((0, 3)), 0
    used = _used(len(vertices), faces)
    vertices, welded = _weld(vertices[used])
    renumber = np.zeros(len(used), dtype=np.int64)
    renumber[used] = welded
    faces = renumber[faces]
    tris = vertices[faces]
    edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    key = np.sort(edges[:, 0] * len(vertices) + edges[:, 1])
    key = key[np.append(True, key[1:] != key[:-1])]
    mids = (vertices[key // len(vertices)] + vertices[key % len(vertices)]) / 2.0
    area = np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1) / 2
    total = float(area.sum())
    wanted = int(np.ceil(total * samples_per_m2)) if total > 0 else 0
    count = min(max(wanted, min_samples), max_samples) if total > 0 else 0
    structure = [vertices, tris.mean(axis=1), mids]  # every welded vertex is used
    if count == 0:
        return np.concatenate(structure), 0
    cumulative = np.cumsum(area)
    which = np.searchsorted(cumulative, rng.random(count) * cumulative[-1], side="right")
    which = np.minimum(which, len(tris) - 1)
    r1, r2 = rng.random((2, count))
    fold = r1 + r2 > 1.0  # the far half of the parallelogram folds back onto the triangle
    r1[fold], r2[fold] = 1.0 - r1[fold], 1.0 - r2[fold]
    t = tris[which]
    random = t[:, 0] + r1[:, None] * (t[:, 1] - t[:, 0]) + r2[:, None] * (t[:, 2] - t[:, 0])
    return np.concatenate([*structure, random]), count


def mesh_distances(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """The exact distance from each point (N, 3) to the nearest of ``triangles`` (F, 3, 3);
    infinity for every point when there is no triangle."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    triangles = np.asarray(triangles, dtype=np.float64).reshape(-1, 3, 3)
    if not len(triangles):
        return np.full(len(points), np.inf)
    return _Grid(triangles).distances(points)


def point_triangle_distance(
    points: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray
) -> np.ndarray:
    """The exact distance from each point to its triangle (a, b, c), row by row (all (N, 3));
    a degenerate triangle (a segment, a point) is measured as its edges."""
    points, a, b, c = (np.asarray(x, dtype=np.float64).reshape(-1, 3) for x in (points, a, b, c))
    return _exact(points, _pack(a, b - a, c - a))


# --------------------------------------------------------------------------------------------
# point to triangle


def _pack(a: np.ndarray, ab: np.ndarray, ac: np.ndarray) -> np.ndarray:
    """Per triangle, what the distance needs, in one row (one gather per pair): a, ab, ac,
    ab.ab, ac.ac, ab.ac and 1 where the triangle is degenerate."""
    abab = np.einsum("ij,ij->i", ab, ab)
    acac = np.einsum("ij,ij->i", ac, ac)
    abac = np.einsum("ij,ij->i", ab, ac)
    bcbc = abab + acac - 2 * abac
    normal = np.cross(ab, ac)
    normal2 = np.einsum("ij,ij->i", normal, normal)
    longest2 = np.maximum(np.maximum(abab, acac), bcbc)
    flat = normal2 <= (FLAT * longest2) ** 2
    return np.column_stack([a, ab, ac, abab, acac, abac, flat])


def _exact(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Distances from points p (M, 3) to packed triangles (M, 13) (see :func:`_pack`).

    Ericson's regions (Real-Time Collision Detection, 5.1.5) give the closest point as
    a + v ab + w ac; the six dot products of his code come from two, since ab.bp = ab.ap - ab.ab
    and so on.  Degenerate triangles are measured as their three edges instead.
    """
    a, ab, ac = tri[:, 0:3], tri[:, 3:6], tri[:, 6:9]
    abab, acac, abac, flat = tri[:, 9], tri[:, 10], tri[:, 11], tri[:, 12] > 0
    ap = p - a
    d1 = np.einsum("ij,ij->i", ab, ap)
    d2 = np.einsum("ij,ij->i", ac, ap)
    d3, d4 = d1 - abab, d2 - abac  # ab.bp, ac.bp
    d5, d6 = d1 - abac, d2 - acac  # ab.cp, ac.cp
    vc = d1 * d4 - d3 * d2
    vb = d5 * d2 - d1 * d6
    va = d3 * d6 - d5 * d4
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = va + vb + vc
        v, w = vb / denom, vc / denom  # inside the triangle
        bc = d4 - d3 + d5 - d6  # bc.bc
        on = (va <= 0) & (d4 >= d3) & (d5 >= d6)  # edge bc
        v, w = np.where(on, (d5 - d6) / bc, v), np.where(on, (d4 - d3) / bc, w)
        on = (vb <= 0) & (d2 >= 0) & (d6 <= 0)  # edge ac
        v, w = np.where(on, 0.0, v), np.where(on, d2 / acac, w)
        on = (d6 >= 0) & (d5 <= d6)  # corner c
        v, w = np.where(on, 0.0, v), np.where(on, 1.0, w)
        on = (vc <= 0) & (d1 >= 0) & (d3 <= 0)  # edge ab
        v, w = np.where(on, d1 / abab, v), np.where(on, 0.0, w)
        on = (d3 >= 0) & (d4 <= d3)  # corner b
        v, w = np.where(on, 1.0, v), np.where(on, 0.0, w)
        on = (d1 <= 0) & (d2 <= 0)  # corner a
        v, w = np.where(on, 0.0, v), np.where(on, 0.0, w)
    gap = ap - v[:, None] * ab - w[:, None] * ac
    out = np.sqrt(np.einsum("ij,ij->i", gap, gap))
    if flat.any():
        out[flat] = _edges(ap[flat], ab[flat], ac[flat], d1[flat], d2[flat], tri[flat, 9:12])
    return out


def _edges(
    ap: np.ndarray, ab: np.ndarray, ac: np.ndarray, d1: np.ndarray, d2: np.ndarray, dots: np.ndarray
) -> np.ndarray:
    """The least distance to the three edges of degenerate triangles (a segment of no length
    is its one point)."""
    abab, acac, abac = dots[:, 0], dots[:, 1], dots[:, 2]
    bc = ac - ab
    bcbc = abab + acac - 2 * abac

    def along(t: np.ndarray, length2: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(length2 > 0, np.clip(t / length2, 0.0, 1.0), 0.0)[:, None]

    def norm(x: np.ndarray) -> np.ndarray:
        return np.sqrt(np.einsum("ij,ij->i", x, x))

    on_ab = norm(ap - along(d1, abab) * ab)
    on_ac = norm(ap - along(d2, acac) * ac)
    bp = ap - ab
    on_bc = norm(bp - along(d2 - d1 - abac + abab, bcbc) * bc)
    return np.minimum(np.minimum(on_ab, on_ac), on_bc)


# --------------------------------------------------------------------------------------------
# nearest triangle


class _Grid:
    """A mesh's triangles registered in the cubic cells (side ``cell``) their bounding boxes
    overlap, to find every triangle within a distance of a point.

    A triangle far larger than a cell is first cut along its longest edge, again and again,
    into pieces whose boxes span at most ``SPAN`` cells a side, so that a big slanted triangle
    is not registered in the many cells of its box that it does not touch.  Distances to the
    pieces are distances to parts of the triangle, so the least of them is still exact.
    """

    def __init__(self, triangles: np.ndarray):
        area = float(_areas(triangles).sum())
        lo, hi = triangles.min(axis=1), triangles.max(axis=1)
        extent = float((hi.max(axis=0) - lo.min(axis=0)).max())
        # about one triangle's worth of surface per cell; for slivers and degenerate triangles,
        # which have little or no area, a quarter of their mean size; at least a millionth of
        # the extent
        size = float(np.ptp(triangles, axis=1).max(axis=1).mean())
        cell = max(CELL * np.sqrt(area / len(triangles)), size / SPAN, 1e-6 * extent, 1e-9)
        while True:
            pieces, _ = _bisect(triangles, SPAN * cell)
            lo, hi = pieces.min(axis=1), pieces.max(axis=1)
            self.origin = lo.min(axis=0)
            first = np.floor((lo - self.origin) / cell).astype(np.int64)
            last = np.floor((hi - self.origin) / cell).astype(np.int64)
            size = last - first + 1
            entries = int(np.prod(size, axis=1).sum())
            if entries <= MAX_ENTRIES * max(len(triangles), 1024):
                break
            cell *= 1.5  # many thin pieces spanning many cells: coarser cells
        # the (cell, piece) pairs below: five arrays of 8 bytes an entry while they are sorted
        check_memory("measuring distances", entries * ENTRY_BYTES)
        self.cell = cell
        self.count = len(pieces)
        self.span = last.max(axis=0) + 1
        self.data = _pack(pieces[:, 0], pieces[:, 1] - pieces[:, 0], pieces[:, 2] - pieces[:, 0])
        self.box = np.vstack([np.hstack([lo, hi]), [np.inf] * 3 + [-np.inf] * 3])
        # every (cell, piece) pair, sorted by cell: a piece's cells are those of its box,
        # first + (i, j, l) for i < size x, j < size y, l < size z
        count = np.prod(size, axis=1)
        piece = np.repeat(
            np.arange(self.count, dtype=np.int32 if self.count < 2**31 else np.int64), count
        )
        n = np.arange(entries) - np.repeat(np.cumsum(count) - count, count)
        sy, sz = size[piece, 1], size[piece, 2]
        i, n = np.divmod(n, sy * sz)
        j, n = np.divmod(n, sz)
        key = self._key(first)[piece] + (i * self.span[1] + j) * self.span[2] + n
        del i, j, n, sy, sz
        order = np.argsort(key, kind="stable")
        key = key[order]
        self.members = piece[order]
        new = np.ones(len(key), dtype=bool)
        new[1:] = key[1:] != key[:-1]
        self.keys = key[new]
        self.starts = np.append(np.flatnonzero(new), len(key))
        self.tol = 1e-12 * (1.0 + extent)  # below this a distance is as good as 0
        self._tree: cKDTree | None = None

    def _key(self, cells: np.ndarray) -> np.ndarray:
        return (cells[:, 0] * self.span[1] + cells[:, 1]) * self.span[2] + cells[:, 2]

    def _slots(self, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """For integer cells (N, 3): where each cell's pieces start and end in ``members``
        (an empty range for a cell that holds none, or lies off the grid)."""
        inside = np.all((cells >= 0) & (cells < self.span), axis=1)
        key = self._key(np.where(inside[:, None], cells, 0))
        slot = np.minimum(np.searchsorted(self.keys, key), len(self.keys) - 1)
        hit = inside & (self.keys[slot] == key)
        start = np.where(hit, self.starts[slot], 0)
        return start, np.where(hit, self.starts[slot + 1], 0)

    def distances(self, points: np.ndarray) -> np.ndarray:
        """Exact distances of points to the mesh.

        Each point measures the pieces of its own cell (nearest box first, then those whose box
        is nearer than the best distance found); if the ball of that distance leaves the cell,
        the pieces of the cells it reaches; if it reaches beyond the next cells, or the cell is
        empty, the point goes to :meth:`_search`.  Points are taken cell by cell, so that
        neighbouring points read the same pieces.
        """
        n = len(points)
        # cells off the grid are clipped to the ring round it (all empty), so that the integers
        # stay small; their "gap" below is then negative and they are measured further
        cells = np.floor((points - self.origin) / self.cell)
        cells = np.clip(cells, -2, self.span + 1).astype(np.int64)
        order = np.argsort(self._key(cells), kind="stable")
        points, cells = points[order], cells[order]
        best = np.full(n, np.inf)
        start, end = self._slots(cells)
        self._measure(points, np.arange(n), start, end, best, first=True)
        # the points whose ball of radius best leaves their cell
        reach = best * (1 + 1e-12) + self.tol
        inner = points - self.origin - cells * self.cell
        gap = np.minimum(inner, self.cell - inner).min(axis=1)
        out = np.flatnonzero(~(reach <= gap))  # nan-safe: an infinite reach is out
        for at in range(0, len(out), CHUNK_POINTS):  # a block at a time: bounded memory
            self._beyond(points, cells, out[at : at + CHUNK_POINTS], best)
        result = np.empty(n)
        result[order] = best
        return result

    def _beyond(
        self, points: np.ndarray, cells: np.ndarray, out: np.ndarray, best: np.ndarray
    ) -> None:
        """Lower ``best[out]`` for points whose ball leaves their cell: the neighbouring cells
        the ball reaches (all 26 from an empty cell), then :meth:`_search` for those that
        reach farther."""
        c = cells[out]
        lo, hi = self._reach(points[out], best[out])
        # a point with nothing in its own cell asks all the next ones
        empty = ~np.isfinite(best[out])
        lo[empty], hi[empty] = c[empty] - 1, c[empty] + 1
        near = np.all((lo >= c - 1) & (hi <= c + 1), axis=1)
        for offset in _NEIGHBOURS:
            other = c + offset
            take = near & np.all((other >= lo) & (other <= hi), axis=1)
            if take.any():
                s, e = self._slots(other[take])
                self._measure(points, out[take], s, e, best, first=True)
        # those that found a piece there are done if their ball stays in the 27 cells
        lo, hi = self._reach(points[out], best[out])
        empty &= ~np.all((lo >= c - 1) & (hi <= c + 1), axis=1)
        far = out[~near | empty]
        if len(far):
            best[far] = self._search(points[far], best[far])

    def _reach(self, points: np.ndarray, best: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The first and last cells of the box of each ball (point, best), a side at most
        five cells (more is as good as "beyond the next cells")."""
        r = np.minimum(best * (1 + 1e-12) + self.tol, 2 * self.cell)[:, None]
        lo = np.floor((points - r - self.origin) / self.cell).astype(np.int64)
        return lo, np.floor((points + r - self.origin) / self.cell).astype(np.int64)

    def _measure(
        self,
        points: np.ndarray,
        idx: np.ndarray,
        start: np.ndarray,
        end: np.ndarray,
        best: np.ndarray,
        *,
        first: bool,
    ) -> None:
        """Lower ``best[idx]`` (idx increasing) to the exact distance to the pieces
        ``members[start:end]`` of each point whose box is nearer than it, CHUNK_PAIRS pairs at
        a time.  ``first``: measure the nearest box of each point before the others, so that
        the bound is good at once (most points lie on, or next to, the other surface)."""
        count = end - start
        total = np.cumsum(count)
        chunks, at = [], 0
        while at < len(idx):
            done = int(total[at - 1]) if at else 0
            stop = max(at + 1, int(np.searchsorted(total, done + CHUNK_PAIRS, "right")))
            if total[stop - 1] > done:
                chunks.append((at, stop))
            at = stop

        def measure(chunk: tuple[int, int]) -> None:
            at, stop = chunk
            c = count[at:stop]
            rows = np.repeat(idx[at:stop], c)  # the point of each pair, increasing
            slots = np.arange(len(rows)) + np.repeat(start[at:stop] - (np.cumsum(c) - c), c)
            self._pairs(points, rows, self.members[slots], best, first)

        # chunks touch rows of best of their own: numpy lets go of the GIL, so threads help
        if len(chunks) > 1 and THREADS > 1:
            with ThreadPoolExecutor(THREADS) as pool:
                list(pool.map(measure, chunks))
        else:
            for chunk in chunks:
                measure(chunk)

    def _pairs(
        self, points: np.ndarray, rows: np.ndarray, piece: np.ndarray, best: np.ndarray, first: bool
    ) -> None:
        """The work of :meth:`_measure` on (point, piece) pairs, points ``rows`` increasing."""
        p = points[rows]
        box = self.box[piece]
        gap = np.maximum(np.maximum(box[:, :3] - p, p - box[:, 3:]), 0.0)
        lower = np.einsum("ij,ij->i", gap, gap)  # squared distance to the box
        if first:
            heads = np.flatnonzero(np.append(True, rows[1:] != rows[:-1]))
            least = np.repeat(
                np.minimum.reduceat(lower, heads), np.diff(np.append(heads, len(rows)))
            )
            tie = np.flatnonzero(lower == least)
            nearest = tie[np.append(True, rows[tie][1:] != rows[tie][:-1])]
            nearest = nearest[lower[nearest] < best[rows[nearest]] ** 2]
            got = _exact(p[nearest], self.data[piece[nearest]])
            best[rows[nearest]] = np.minimum(best[rows[nearest]], got)
            lower[nearest] = np.inf
        bound = best[rows]
        keep = np.flatnonzero(lower < bound * bound)
        if len(keep):
            got = _exact(p[keep], self.data[piece[keep]])
            rk = rows[keep]
            heads = np.flatnonzero(np.append(True, rk[1:] != rk[:-1]))
            best[rk[heads]] = np.minimum(best[rk[heads]], np.minimum.reduceat(got, heads))

    def _search(self, p: np.ndarray, best: np.ndarray) -> np.ndarray:
        """Points far from the mesh (or in empty cells): ask a KD-tree of the pieces' box
        centres for ever more neighbours of each point, within the bound best + the largest
        half-diagonal, until every piece whose box may be nearer than best is measured."""
        if self._tree is None:
            self._tree = cKDTree((self.box[:-1, :3] + self.box[:-1, 3:]) / 2.0)
            half = (self.box[:-1, 3:] - self.box[:-1, :3]) / 2.0
            self._radius = np.append(np.sqrt(np.einsum("ij,ij->i", half, half)), 0.0)
        tree, radius, count = self._tree, self._radius, self.count
        h = float(radius.max())
        best = best.copy()
        k = min(64, count)
        todo = np.arange(len(p))
        while len(todo):
            todo = todo[np.argsort(best[todo], kind="stable")]  # batches of like bounds
            step = max(1, CHUNK_PAIRS // k)
            more = []
            for i in range(0, len(todo), step):
                batch = todo[i : i + step]
                bound = float(best[batch].max()) + h
                upper = bound * (1 + 1e-9) + self.tol if np.isfinite(bound) else np.inf
                reach, cand = tree.query(p[batch], k=k, distance_upper_bound=upper, workers=-1)
                reach, cand = reach.reshape(len(batch), k), cand.reshape(len(batch), k)
                r, c = np.nonzero(reach - radius[cand] < best[batch, None])
                if len(r):
                    got = np.full(len(batch), np.inf)
                    np.minimum.at(got, r, _exact(p[batch[r]], self.data[cand[r, c]]))
                    best[batch] = np.minimum(best[batch], got)
                last = reach[:, -1]
                go_on = np.isfinite(last) & (last - h < best[batch]) & (best[batch] > self.tol)
                more.append(batch[go_on])
            if k >= count:
                break
            todo = np.concatenate(more)
            k = min(4 * k, count)
        return best


def _areas(triangles: np.ndarray) -> np.ndarray:
    cross = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    return np.sqrt(np.einsum("ij,ij->i", cross, cross)) / 2.0


def _bisect(triangles: np.ndarray, size: float) -> tuple[np.ndarray, np.ndarray]:
    """The triangles cut along their longest edge, again and again, until every piece's
    bounding box is at most ``size`` a side: (pieces, the triangle each comes from)."""
    done, whose = [], []
    todo, parent = triangles, np.arange(len(triangles))
    for _ in range(MAX_SPLITS):
        big = np.ptp(todo, axis=1).max(axis=1) > size
        done.append(todo[~big])
        whose.append(parent[~big])
        todo, parent = todo[big], parent[big]
        if not len(todo):
            break
        length = np.sum((todo[:, [1, 2, 0]] - todo) ** 2, axis=2)  # edge i runs from i to i+1
        i = np.argmax(length, axis=1)
        rows = np.arange(len(todo))
        p0, p1, p2 = todo[rows, i], todo[rows, (i + 1) % 3], todo[rows, (i + 2) % 3]
        mid = (p0 + p1) / 2.0
        todo = np.concatenate([np.stack([p0, mid, p2], axis=1), np.stack([mid, p1, p2], axis=1)])
        parent = np.concatenate([parent, parent])
    done.append(todo)
    whose.append(parent)
    return np.concatenate(done), np.concatenate(whose)


def _weld(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices at exactly the same place made one: (distinct vertices, index of each)."""
    order = np.lexsort(vertices.T[::-1])
    ordered = vertices[order]
    new = np.ones(len(vertices), dtype=bool)
    new[1:] = np.any(ordered[1:] != ordered[:-1], axis=1)
    index = np.empty(len(vertices), dtype=np.int64)
    index[order] = np.cumsum(new) - 1
    return ordered[new], index


# --------------------------------------------------------------------------------------------
# inputs and results


def _checked(vertices: np.ndarray, faces: np.ndarray, name: str) -> tuple[np.ndarray, np.ndarray]:
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    f = np.asarray(faces).reshape(-1, 3)
    if len(f) and not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"{name}_faces must hold integers")
    f = f.astype(np.int64)
    if len(f) and (f.min() < 0 or f.max() >= len(v)):
        raise ValueError(f"{name}_faces index vertices that {name}_vertices does not have")
    if len(f) and not np.isfinite(v[_used(len(v), f)]).all():
        raise ValueError(f"{name}_vertices used by faces must be finite")
    return v, f


def _used(count: int, faces: np.ndarray) -> np.ndarray:
    """Which of ``count`` vertices a face uses (a mask: cheaper than np.unique)."""
    used = np.zeros(count, dtype=bool)
    used[faces.ravel()] = True
    return used


def _max(d: np.ndarray) -> tuple[float, int | None]:
    if not len(d):
        return 0.0, None
    i = int(np.argmax(d))
    return float(d[i]), i


def _mean(d: np.ndarray, random: int) -> float:
    if not len(d):
        return 0.0
    return float(d[-random:].mean()) if random else float(d.mean())
