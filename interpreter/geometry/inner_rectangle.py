"""The largest rectangle inside a polygon, its sides along the scope's axes (CGA's
innerRectangle(scope)) or along one of its edges (innerRectangle(edge): the same search in the
polygon turned so that the edge runs along x, for each edge longer than a quarter of its
ring's longest).

The polygon is cut into cells by grid lines through each of its corners and ``CELLS`` more
evenly spaced along each side of its bounding box; a cell counts when its four corners and its
centre lie inside.  The largest rectangle of such cells is found row by row with the
histogram-and-stack method, weighting each cell by its size.  An outline whose sides run along
the scope (an L, a U) gives its exact largest rectangle; any other is exact to within one cell,
1/64 of the scope.
"""

from __future__ import annotations

import numpy as np
import shapely

from .polygons import from_shapely, metric, to_shapely

CELLS = 64


def inner_rectangle(polys, su: float, sv: float) -> tuple[list, list]:
    """(the rectangle, the remainder) of unit polygons in an ``su`` by ``sv`` scope, both as
    metric polygons."""
    whole = to_shapely(metric(polys, su, sv))
    if whole.is_empty:
        return [], []
    rect = _largest(whole)
    if rect is None:
        return [], from_shapely(whole)
    return from_shapely(rect), from_shapely(whole.difference(rect))


def inner_rectangle_edge(polys, su: float, sv: float) -> tuple[list, list]:
    """CGA's innerRectangle(edge): the largest rectangle with a side along one of the outline's
    edges (those longer than a quarter of its ring's longest), as metric polygons."""
    from shapely import affinity

    whole = to_shapely(metric(polys, su, sv))
    if whole.is_empty:
        return [], []
    best = None
    for angle in _edge_angles(polys, su, sv):
        turned = affinity.rotate(whole, -angle, origin=(0, 0), use_radians=True)
        rect = _largest(turned)
        if rect is not None and (best is None or rect.area > best.area + 1e-9):
            best = affinity.rotate(rect, angle, origin=(0, 0), use_radians=True)
    if best is None:
        return [], from_shapely(whole)
    best = best.intersection(whole)
    return from_shapely(best), from_shapely(whole.difference(best))


def _edge_angles(polys, su: float, sv: float) -> list[float]:
    """The directions (radians, 0..pi) of the rings' edges longer than a quarter of their
    ring's longest, each once."""
    out: list[float] = []
    for ext, holes in metric(polys, su, sv):
        for ring in (ext, *holes):
            pts = np.asarray(ring, dtype=np.float64)
            d = np.roll(pts, -1, axis=0) - pts
            lengths = np.hypot(d[:, 0], d[:, 1])
            for (dx, dy), length in zip(d, lengths, strict=True):
                if length > lengths.max() / 4:
                    angle = float(np.arctan2(dy, dx)) % np.pi
                    if all(abs(angle - a) > 1e-9 for a in out):
                        out.append(angle)
    return out


def _largest(whole):
    """The largest rectangle along the axes inside a shapely (multi)polygon, or None."""
    x0, y0, x1, y1 = whole.bounds
    if abs(whole.area - (x1 - x0) * (y1 - y0)) <= 1e-9 * max(whole.area, 1.0):
        return whole  # the outline is its own bounding box
    corners = shapely.get_coordinates(whole)  # every ring's corners, the holes' too
    xs = np.unique(np.round(np.concatenate([corners[:, 0], np.linspace(x0, x1, CELLS + 1)]), 9))
    ys = np.unique(np.round(np.concatenate([corners[:, 1], np.linspace(y0, y1, CELLS + 1)]), 9))
    nx, ny = len(xs) - 1, len(ys) - 1
    gx, gy = np.meshgrid(xs, ys)  # (ny + 1, nx + 1) corners
    shapely.prepare(whole)
    inside = shapely.contains_xy(whole, gx, gy) | shapely.intersects_xy(whole.boundary, gx, gy)
    cx, cy = np.meshgrid((xs[:-1] + xs[1:]) / 2, (ys[:-1] + ys[1:]) / 2)
    cells = (
        inside[:-1, :-1] & inside[1:, :-1] & inside[:-1, 1:] & inside[1:, 1:]
        & shapely.contains_xy(whole, cx, cy)
    )  # fmt: skip
    best, box = 0.0, None
    heights = [0.0] * nx  # metres of inside cells straight below, row by row
    xl, yl = xs.tolist(), ys.tolist()
    rows = cells.tolist()
    for row in range(ny):
        tall = yl[row + 1] - yl[row]
        heights = [
            h + tall if inside else 0.0 for h, inside in zip(heights, rows[row], strict=True)
        ]
        stack: list[int] = []
        for col in range(nx + 1):
            h = heights[col] if col < nx else 0.0
            while stack and heights[stack[-1]] >= h:
                top = stack.pop()
                left = stack[-1] + 1 if stack else 0
                area = heights[top] * (xl[col] - xl[left])
                if area > best:
                    best, box = area, (xl[left], xl[col], yl[row + 1] - heights[top], yl[row + 1])
            stack.append(col)
    if box is None:
        return None
    return shapely.box(box[0], box[2], box[1], box[3]).intersection(whole)
