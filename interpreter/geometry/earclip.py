"""Ear-clipping triangulation of one simple polygon that keeps every vertex.

Roof faces share their boundaries with their neighbours vertex for vertex, and some of those
vertices are collinear with their two neighbours (a ridge crossed by a valley, a wall edge with a
node on it).  A triangulator that drops such "flat" vertices would leave T-junctions and the roof
would no longer be watertight, so this one never drops a vertex, and never makes a zero-area
triangle: an ear is clipped only at a strictly convex vertex whose closed triangle holds no other
vertex of the polygon.  Cost is O(n^2) numpy-vectorised work, plenty for roof faces and
footprints (up to a few thousand vertices).
"""

from __future__ import annotations

import numpy as np

from .cyclic import following, preceding


def signed_area(points: np.ndarray) -> float:
    """Shoelace area, positive for a counter-clockwise polygon."""
    p = np.asarray(points, dtype=np.float64)
    q = following(p)
    return 0.5 * float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))


def triangulate(points: np.ndarray) -> np.ndarray:
    """Triangles (T, 3) of indices into ``points`` (a simple polygon (K, 2), either orientation).

    The triangles have the polygon's own orientation (counter-clockwise for a counter-clockwise
    input), use every vertex that is needed to cover the polygon and none that is not in it,
    and are never degenerate.  A polygon of (near) zero area gives no triangle.
    """
    pts = np.asarray(points, dtype=np.float64)
    n = len(pts)
    if n < 3:
        return np.zeros((0, 3), dtype=np.int64)
    area = signed_area(pts)
    scale = float(np.ptp(pts, axis=0).max()) or 1.0
    eps = 1e-12 * scale * scale
    if abs(area) <= eps:
        return np.zeros((0, 3), dtype=np.int64)
    ccw = area > 0
    idx = list(range(n)) if ccw else list(range(n - 1, -1, -1))
    tris: list[tuple[int, int, int]] = []
    while len(idx) > 3:
        i = _find_ear(pts[idx], eps)
        m = len(idx)
        tris.append((idx[(i - 1) % m], idx[i], idx[(i + 1) % m]))
        del idx[i]
    a, b, c = pts[idx]
    if _cross(b - a, c - b) > eps:
        tris.append((idx[0], idx[1], idx[2]))
    tris = _flip_slivers(pts, tris, eps)
    out = np.array(tris, dtype=np.int64).reshape(-1, 3)
    return out if ccw else out[:, ::-1]


def _cross(u: np.ndarray, v: np.ndarray):
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def _find_ear(poly: np.ndarray, eps: float) -> int:
    """Index of a clippable ear of the counter-clockwise polygon ``poly``.

    Candidates are the strictly convex vertices, the most convex first is not needed: the first
    one whose closed triangle contains no other vertex is taken.  Should floating-point trouble
    leave no such ear, the most convex vertex is clipped so that the loop always ends.
    """
    prev = preceding(poly)
    nxt = following(poly)
    turn = _cross(poly - prev, nxt - poly)
    convex = np.flatnonzero(turn > eps)
    m = len(poly)
    for i in convex:
        a, b, c = prev[i], poly[i], nxt[i]
        others = np.ones(m, dtype=bool)
        others[[(i - 1) % m, i, (i + 1) % m]] = False
        q = poly[others]
        # a vertex sitting exactly on a, b or c (a pinch) does not block the ear
        same = (
            np.all(np.abs(q - a) <= 1e-12, axis=1)
            | np.all(np.abs(q - c) <= 1e-12, axis=1)
            | np.all(np.abs(q - b) <= 1e-12, axis=1)
        )
        q = q[~same]
        inside = (
            (_cross(b - a, q - a) >= -eps)
            & (_cross(c - b, q - b) >= -eps)
            & (_cross(a - c, q - c) >= -eps)
        )
        if not inside.any():
            return int(i)
    return int(np.argmax(turn))


def _shape(p, a: int, b: int, c: int) -> float:
    """Shape quality of a counter-clockwise triangle: area over the sum of its squared sides
    (1 / (4 sqrt 3) for an equilateral one, 0 for a sliver)."""
    (ax, ay), (bx, by), (cx, cy) = p[a], p[b], p[c]
    sides = (
        (bx - ax) ** 2
        + (by - ay) ** 2
        + (cx - bx) ** 2
        + (cy - by) ** 2
        + (ax - cx) ** 2
        + (ay - cy) ** 2
    )
    return 0.5 * ((bx - ax) * (cy - ay) - (by - ay) * (cx - ax)) / sides


_POOR = 0.05  # triangles shaped worse than this are worth a flip


def _flip_slivers(pts: np.ndarray, tris: list, eps: float) -> list:
    """Flip diagonals while that improves the worse-shaped of two poorly shaped neighbours."""
    p = pts.tolist()
    tris = [tuple(int(v) for v in t) for t in tris]
    owner = {}
    for i, (a, b, c) in enumerate(tris):
        owner[(a, b)] = owner[(b, c)] = owner[(c, a)] = i
    for _ in range(20):  # sweeps
        flipped = False
        for i in range(len(tris)):
            for k in range(3):
                tri = tris[i]
                a, b, c = tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]
                j = owner.get((b, a))
                if j is None or j == i:
                    continue
                other = tris[j]
                d = other[(other.index(b) + 2) % 3]  # the apex of the neighbour across a-b
                old = min(_shape(p, *tri), _shape(p, *other))
                if old >= _POOR or not _strictly_convex([p[a], p[d], p[b], p[c]], eps):
                    continue
                first, second = (a, d, c), (d, b, c)
                if min(_shape(p, *first), _shape(p, *second)) > old * (1.0 + 1e-9):
                    for t in (tri, other):
                        for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
                            del owner[e]
                    tris[i], tris[j] = first, second
                    for n, t in ((i, first), (j, second)):
                        for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
                            owner[e] = n
                    flipped = True
        if not flipped:
            break
    return tris


def _strictly_convex(quad, eps: float) -> bool:
    for q in range(4):
        (ax, ay), (bx, by), (cx, cy) = quad[q], quad[(q + 1) % 4], quad[(q + 2) % 4]
        if (bx - ax) * (cy - by) - (by - ay) * (cx - bx) <= eps:
            return False
    return True
