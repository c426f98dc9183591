"""The largest rectangle inside a polygon, its sides along the scope's axes: CGA's
innerRectangle(scope).

The polygon is sampled on a grid of cells (``CELLS`` along its longer side); a cell counts when
its four corners and its centre lie inside.  The largest rectangle of such cells is found row
by row with the histogram-and-stack method (linear in the cells), so the rectangle is exact to
within one cell: 1/256 of the scope.  A rectangle (or any outline the grid fits) comes back
whole.
"""

from __future__ import annotations

import numpy as np
import shapely

from .polygons import from_shapely, metric, to_shapely

CELLS = 256


def inner_rectangle(polys, su: float, sv: float) -> tuple[list, list]:
    """(the rectangle, the remainder) of unit polygons in an ``su`` by ``sv`` scope, both as
    metric polygons."""
    whole = to_shapely(metric(polys, su, sv))
    if whole.is_empty:
        return [], []
    x0, y0, x1, y1 = whole.bounds
    if abs(whole.area - (x1 - x0) * (y1 - y0)) <= 1e-9 * max(whole.area, 1.0):
        return from_shapely(whole), []  # the outline is its own bounding box
    step = max(x1 - x0, y1 - y0) / CELLS
    nx, ny = max(1, round((x1 - x0) / step)), max(1, round((y1 - y0) / step))
    xs, ys = np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1)
    gx, gy = np.meshgrid(xs, ys)  # (ny + 1, nx + 1) corners
    shapely.prepare(whole)
    inside = shapely.contains_xy(whole, gx, gy) | shapely.intersects_xy(whole.boundary, gx, gy)
    cx, cy = np.meshgrid((xs[:-1] + xs[1:]) / 2, (ys[:-1] + ys[1:]) / 2)
    cells = (
        inside[:-1, :-1] & inside[1:, :-1] & inside[:-1, 1:] & inside[1:, 1:]
        & shapely.contains_xy(whole, cx, cy)
    )  # fmt: skip
    best, box = 0.0, None
    heights = np.zeros(nx, dtype=np.int64)
    for row in range(ny):
        heights = np.where(cells[row], heights + 1, 0)
        stack: list[int] = []
        for col in range(nx + 1):
            h = heights[col] if col < nx else 0
            while stack and heights[stack[-1]] >= h:
                top = stack.pop()
                left = stack[-1] + 1 if stack else 0
                area = heights[top] * (col - left)
                if area > best:
                    best, box = area, (left, col, row - heights[top] + 1, row + 1)
            stack.append(col)
    if box is None:
        return [], from_shapely(whole)
    left, right, bottom, top = box
    rect = shapely.box(xs[left], ys[bottom], xs[right], ys[top]).intersection(whole)
    return from_shapely(rect), from_shapely(whole.difference(rect))
