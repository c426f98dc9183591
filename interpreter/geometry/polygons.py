"""Planar polygons in unit scope coordinates: clipping for splits, insets, triangulation.

A 2D shape's geometry is a list of polygons, each an exterior ring and holes, with coordinates
(u, v) in 0..1 along the two scope axes of its plane.  The common case — a rectangle filling its
scope, as every façade tile is — is kept symbolic (``RECT``) so splitting it costs nothing and
every such terminal shares one instanced mesh.
"""

from __future__ import annotations

import math

import mapbox_earcut
import numpy as np
import shapely
from shapely.geometry import MultiPolygon, Polygon

Ring = tuple[tuple[float, float], ...]
Poly = tuple[Ring, tuple[Ring, ...]]  # exterior, holes

UNIT_SQUARE: Ring = ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))
RECT = "rect"  # a geometry of exactly the unit square


def to_shapely(polys: list[Poly]) -> MultiPolygon:
    return MultiPolygon([Polygon(ext, holes) for ext, holes in polys])


def from_shapely(geom) -> list[Poly]:
    """Polygons of a shapely result, dropping slivers, lines and points."""
    out = []
    for g in getattr(geom, "geoms", [geom]):
        if isinstance(g, Polygon) and g.area > 1e-12:
            g = shapely.geometry.polygon.orient(g)
            out.append(
                (tuple(g.exterior.coords[:-1]), tuple(tuple(h.coords[:-1]) for h in g.interiors))
            )
        elif hasattr(g, "geoms"):
            out += from_shapely(g)
    return out


def clip(polys: list[Poly], axis: int, lo: float, hi: float) -> list[Poly]:
    """The part of the polygons with lo <= coordinate[axis] <= hi (unit coordinates)."""
    box = (lo, -1.0, hi, 2.0) if axis == 0 else (-1.0, lo, 2.0, hi)
    return from_shapely(shapely.clip_by_rect(to_shapely(polys), *box))


def renormalise(polys: list[Poly], axis: int, lo: float, hi: float) -> list[Poly]:
    """Map coordinate[axis] from [lo, hi] to [0, 1]: the piece's own unit frame."""
    span = hi - lo
    if span <= 0:
        return []

    def f(pt):
        return ((pt[0] - lo) / span, pt[1]) if axis == 0 else (pt[0], (pt[1] - lo) / span)

    return [(tuple(map(f, ext)), tuple(tuple(map(f, h)) for h in holes)) for ext, holes in polys]


def is_unit_square(polys: list[Poly], tol: float = 1e-9) -> bool:
    if len(polys) != 1 or polys[0][1]:
        return False
    ring = polys[0][0]
    if len(ring) != 4:
        return False
    return sorted((round(x / tol) * tol, round(y / tol) * tol) for x, y in ring) == [
        (0.0, 0.0),
        (0.0, 1.0),
        (1.0, 0.0),
        (1.0, 1.0),
    ]


def metric(polys: list[Poly], su: float, sv: float) -> list[Poly]:
    return [
        (
            tuple((x * su, y * sv) for x, y in ext),
            tuple(tuple((x * su, y * sv) for x, y in h) for h in holes),
        )
        for ext, holes in polys
    ]


def normalise(polys: list[Poly]) -> tuple[list[Poly], tuple[float, float, float, float]]:
    """Polygons in any metric frame -> unit coordinates of their bounding box, and the box."""
    xs = [x for ext, _ in polys for x, _ in ext]
    ys = [y for ext, _ in polys for _, y in ext]
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    w, h = (x1 - x0) or 1.0, (y1 - y0) or 1.0

    def f(pt):
        return ((pt[0] - x0) / w, (pt[1] - y0) / h)

    return [(tuple(map(f, e)), tuple(tuple(map(f, r)) for r in hs)) for e, hs in polys], (
        x0,
        y0,
        x1 - x0,
        y1 - y0,
    )


def inset(
    polys: list[Poly], su: float, sv: float, distance: float
) -> tuple[list[Poly], list[Poly]]:
    """(inside, border) of an offset by ``distance`` metres (positive shrinks), in metric coords."""
    shape = to_shapely(metric(polys, su, sv))
    inner = shape.buffer(-distance, join_style="mitre", mitre_limit=10.0)
    if distance >= 0:
        border = shape.difference(inner)
    else:
        inner, border = inner, inner.difference(shape)
    return from_shapely(inner), from_shapely(border)


def triangulate(polys: list[Poly]) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (V, 2), triangles (T, 3)) of polygons with holes, by earcut."""
    verts, tris, base = [], [], 0
    for ext, holes in polys:
        rings = [ext, *holes]
        pts = np.array([p for r in rings for p in r], dtype=np.float64).reshape(-1, 2)
        ends = np.cumsum([len(r) for r in rings]).astype(np.uint32)
        idx = mapbox_earcut.triangulate_float64(pts, ends).reshape(-1, 3).astype(np.int64)
        verts.append(pts)
        tris.append(idx + base)
        base += len(pts)
    if not verts:
        return np.zeros((0, 2)), np.zeros((0, 3), dtype=np.int64)
    return np.concatenate(verts), np.concatenate(tris)


def signed_area(ring) -> float:
    a = 0.0
    for (x0, y0), (x1, y1) in zip(ring, ring[1:] + ring[:1], strict=True):
        a += x0 * y1 - x1 * y0
    return a / 2.0


def named_footprint(kind: str, a: float, b: float) -> list[Poly]:
    """A building outline in the unit square, counter-clockwise, first edge on the front (v = 0).

    ``a`` and ``b`` are wing widths as fractions of the scope (``a`` along u, ``b`` along v);
    for ``circle`` ``a`` is the number of sides, the first side centred on the front so that
    ``comp(f) { front: ... }`` finds it.  The caller has checked the ranges.
    """
    if kind == "rect":
        ring = UNIT_SQUARE
    elif kind == "L":  # a bar along the front, a wing up the left side
        ring = ((0, 0), (1, 0), (1, b), (a, b), (a, 1), (0, 1))
    elif kind == "U":  # a bar along the front, wings up both sides, open at the back
        ring = ((0, 0), (1, 0), (1, 1), (1 - a, 1), (1 - a, b), (a, b), (a, 1), (0, 1))
    elif kind == "T":  # a bar along the front, a centred wing to the back
        lo, hi = 0.5 - a / 2, 0.5 + a / 2
        ring = ((0, 0), (1, 0), (1, b), (hi, b), (hi, 1), (lo, 1), (lo, b), (0, b))
    elif kind == "cross":  # a centred bar each way
        ulo, uhi, vlo, vhi = 0.5 - a / 2, 0.5 + a / 2, 0.5 - b / 2, 0.5 + b / 2
        ring = (
            (ulo, 0),
            (uhi, 0),
            (uhi, vlo),
            (1, vlo),
            (1, vhi),
            (uhi, vhi),
            (uhi, 1),
            (ulo, 1),
            (ulo, vhi),
            (0, vhi),
            (0, vlo),
            (ulo, vlo),
        )
    elif kind == "circle":
        n = int(a)
        angles = -np.pi / 2 - np.pi / n + 2 * np.pi * np.arange(n) / n
        ring = tuple(
            zip(
                (0.5 + 0.5 * np.cos(angles)).tolist(),
                (0.5 + 0.5 * np.sin(angles)).tolist(),
                strict=True,
            )
        )
    else:
        raise ValueError(f"unknown footprint {kind!r}")
    return [(tuple((float(u), float(v)) for u, v in ring), ())]


def is_rectangle(polys, su: float, sv: float, tolerance_deg: float = 1.0) -> bool:
    """Is the outline one rectangle without holes (CGA's ``geometry.isRectangular``)?

    ``polys`` are unit polygons (or RECT) of a scope ``su`` x ``sv`` metres.  Vertices where
    the outline runs on straight (within the tolerance) are ignored, so a rectangle with an
    extra point on an edge still counts; every remaining corner must be within
    ``tolerance_deg`` of a right angle, and there must be four of them.
    """
    if polys == RECT:
        return True
    if len(polys) != 1 or polys[0][1]:
        return False
    ring = metric(polys, su, sv)[0][0]
    n = len(ring)
    corners = 0
    for i in range(n):
        (ax, ay), (bx, by), (cx, cy) = ring[i - 1], ring[i], ring[(i + 1) % n]
        d1, d2 = (bx - ax, by - ay), (cx - bx, cy - by)
        if math.hypot(*d1) < 1e-12 or math.hypot(*d2) < 1e-12:
            continue  # a repeated point
        turn = math.degrees(
            math.atan2(d1[0] * d2[1] - d1[1] * d2[0], d1[0] * d2[0] + d1[1] * d2[1])
        )
        if abs(turn) <= tolerance_deg:
            continue  # straight on
        if abs(abs(turn) - 90.0) > tolerance_deg:
            return False
        corners += 1
    return corners == 4
