"""CGA's setback: some edges of a 2D shape moved in by a distance, each edge's strip a piece of
its own and what is left the remainder.

A strip is the part of the polygon within the distance of its edge, on the inside, no further
along the edge's line than the distance past its ends; where two strips meet at a corner, the
square they share goes to the edge that comes first round the outline.  Edges are classified by
their outward normal in the polygon's plane, as the scope's quadrants: ``left``/``right`` along
x, ``bottom``/``top`` along y, ``front``/``back`` along z (so a lot's street edge is ``front``).
"""

from __future__ import annotations

import math

import shapely
from shapely.geometry import Polygon

from .polygons import from_shapely, metric, to_shapely

_NAMES = {0: ("left", "right"), 1: ("bottom", "top"), 2: ("front", "back")}


def edge_kinds(polys, su: float, sv: float, p: int, q: int) -> list[tuple[tuple, str]]:
    """Each exterior edge ((a, b) in metres, counter-clockwise) with its selector word."""
    out = []
    for ext, _ in metric(polys, su, sv):
        ring = list(ext)
        if _area(ring) < 0:
            ring.reverse()
        for a, b in zip(ring, ring[1:] + ring[:1], strict=True):
            dx, dy = b[0] - a[0], b[1] - a[1]
            if math.hypot(dx, dy) < 1e-12:
                continue
            nu, nv = dy, -dx  # outward: the interior of a counter-clockwise ring is on the left
            axis, sign = (p, nu) if abs(nu) >= abs(nv) else (q, nv)
            out.append(((tuple(a), tuple(b)), _NAMES[axis][1 if sign > 0 else 0]))
    return out


def strips(polys, su: float, sv: float, edges: list[tuple], distance) -> tuple:
    """(the strip of each edge, in metric polygons, in the edges' order; the remainder).
    ``distance`` is one for all edges, or a list of one per edge (setbackPerEdge): each strip
    as wide as its own distance (and as far past its ends), the corner two strips share going
    to the edge that comes first; an edge of distance 0 has no strip."""
    distances = distance if isinstance(distance, list) else [distance] * len(edges)
    whole = to_shapely(metric(polys, su, sv))
    taken = shapely.Polygon()
    parts = []
    for (a, b), d in zip(edges, distances, strict=True):
        if d <= 0:
            parts.append([])
            continue
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        tx, ty = (b[0] - a[0]) / length, (b[1] - a[1]) / length
        ix, iy = -ty, tx  # inward
        s = (a[0] - tx * d, a[1] - ty * d)
        e = (b[0] + tx * d, b[1] + ty * d)
        band = Polygon(
            [s, e, (e[0] + ix * d, e[1] + iy * d), (s[0] + ix * d, s[1] + iy * d)]
        )  # fmt: skip
        piece = whole.intersection(band).difference(taken)
        taken = taken.union(piece)
        parts.append(from_shapely(piece))
    return parts, from_shapely(whole.difference(taken))


def _area(ring) -> float:
    return sum(
        x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(ring, ring[1:] + ring[:1], strict=True)
    )
