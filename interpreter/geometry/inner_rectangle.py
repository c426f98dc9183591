"""The largest rectangle inside a polygon, its sides along the scope's axes: CGA's
innerRectangle(scope).

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
    x0, y0, x1, y1 = whole.bounds
    if abs(whole.area - (x1 - x0) * (y1 - y0)) <= 1e-9 * max(whole.area, 1.0):
        return from_shapely(whole), []  # the outline is its own bounding box
    corners = np.asarray([p for ext, holes in metric(polys, su, sv) for r in (ext, *holes)
                          for p in r])  # fmt: skip
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
        return [], from_shapely(whole)
    rect = shapely.box(box[0], box[2], box[1], box[3]).intersection(whole)
    return from_shapely(rect), from_shapely(whole.difference(rect))
