"""A polygon cut into convex parts: CGA's convexify, by Hertel and Mehlhorn's method.

The polygon is triangulated (earcut), then the triangles are merged back across the diagonals
whose removal leaves the merged part convex; what stays are at most four times as many parts as
the fewest possible.  ``max_length`` is CGA's: a diagonal longer than it is never a cut, so the
parts it joins merge whatever their shape (one may stay concave).
"""

from __future__ import annotations

import math

import numpy as np

from .polygons import triangulate

_EPS = 1e-12


def convex_parts(polys: list, su: float, sv: float, max_length: float = math.inf) -> list:
    """Convex parts of unit polygons (with holes) in a scope ``su`` by ``sv`` metres, as unit
    polygons without holes, counter-clockwise."""
    out: list = []
    for poly in polys:
        pts, tris = triangulate([poly])
        if not len(tris):
            continue
        metres = pts * np.array([su, sv])
        parts = [_ccw(list(map(int, t)), metres) for t in tris]
        owner = list(range(len(parts)))  # each triangle's part, merged ones pointing on

        edges: dict[tuple[int, int], int] = {}
        diagonals = []
        for t, tri in enumerate(parts):
            for a, b in zip(tri, tri[1:] + tri[:1], strict=True):
                if (b, a) in edges:
                    diagonals.append((a, b, edges.pop((b, a)), t))
                else:
                    edges[(a, b)] = t
        # long diagonals first (never cuts), then the rest where the union stays convex
        length = {d: float(np.linalg.norm(metres[d[0]] - metres[d[1]])) for d in diagonals}
        diagonals.sort(key=lambda d: (length[d] <= max_length, -length[d]))
        for d in diagonals:
            a, b, t1, t2 = d
            p, q = _find(owner, t1), _find(owner, t2)
            if p == q:
                continue
            merged = _merge(parts[p], parts[q], a, b)
            if merged is None:
                continue
            if length[d] <= max_length and not _convex(merged, metres):
                continue
            parts[p] = merged
            owner[q] = p
        for i in range(len(parts)):
            if _find(owner, i) == i:
                out.append((tuple((float(pts[k][0]), float(pts[k][1])) for k in parts[i]), ()))
    return out


def _find(owner: list[int], i: int) -> int:
    """The part a triangle now belongs to (union-find, paths shortened on the way)."""
    while owner[i] != i:
        owner[i] = owner[owner[i]]
        i = owner[i]
    return i


def _ccw(ring: list[int], metres: np.ndarray) -> list[int]:
    x, y = metres[ring, 0], metres[ring, 1]
    area = float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
    return ring if area > 0 else ring[::-1]


def _merge(first: list[int], second: list[int], a: int, b: int) -> list[int] | None:
    """Two counter-clockwise parts that share the edge a-b joined into one, or None when they
    do not share it as one part's a->b and the other's b->a."""
    for one, two in ((first, second), (second, first)):
        if _has(one, a, b) and _has(two, b, a):
            i = one.index(b)
            start = one[i:] + one[:i]  # b ... a
            j = two.index(a)
            other = two[j:] + two[:j]  # a ... b
            return start + other[1:-1]
    return None


def _has(ring: list[int], a: int, b: int) -> bool:
    i = ring.index(a) if a in ring else -1
    return i >= 0 and ring[(i + 1) % len(ring)] == b


def _convex(ring: list[int], metres: np.ndarray) -> bool:
    pts = metres[ring]
    edges = np.roll(pts, -1, axis=0) - pts
    turns = edges[:, 0] * np.roll(edges[:, 1], -1) - edges[:, 1] * np.roll(edges[:, 0], -1)
    return bool((turns >= -_EPS * max(1.0, float(np.abs(turns).max()))).all())


def convex_faces(faces: list, max_length: float = math.inf) -> list:
    """The faces of a solid (comp(f)'s ``(rings of 3D points, normal, turns)``) with each
    concave one, or one with holes, cut into convex parts in its own plane: a convexified
    solid's comp(f) gives each part as a face (its corner turns then 0)."""
    out = []
    for rings, normal, turns in faces:
        n = np.asarray(normal, dtype=float)
        ref = np.array([0.0, 1.0, 0.0]) if abs(n[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
        e1 = np.cross(ref, n)
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(n, e1)
        origin = np.asarray(rings[0][0], dtype=float)
        flat = [(np.asarray(ring, dtype=float) - origin) @ np.stack([e1, e2]).T for ring in rings]
        metres = flat[0]
        if len(rings) == 1 and _convex(_ccw(list(range(len(metres))), metres), metres):
            out.append((rings, normal, turns))
            continue
        # counter-clockwise in (e1, e2) seen from the normal's side, holes clockwise
        parts = convex_parts(
            [(tuple(map(tuple, flat[0])), tuple(map(tuple, flat[1:])))], 1, 1, max_length
        )
        for ring, _ in parts:
            points = [list(origin + u * e1 + v * e2) for u, v in ring]
            out.append(([points], normal, (0.0, 0.0)))
    return out
