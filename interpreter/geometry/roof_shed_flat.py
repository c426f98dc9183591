"""Shed and flat roofs: one plane over the eave polygon, a shed's rising from the front edge
with vertical walls below it, a flat one at the eave with its courtyards left open (see
``shed`` and ``flat`` in the module docstring of :mod:`.roofs`)."""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry import Polygon

from .roof_footprint import (
    _CLEAN_TOL,
    MITRE_LIMIT,
    _eave_ring,
    _Footprint,
    _slope_plane,
    _wall_plane,
)
from .roof_model import RoofMesh, RoofPlane, _cross, _MeshBuilder
from .skeleton import edge_lines


def _shed_roof(fp: _Footprint, pitch: float, overhang: float) -> RoofMesh:
    """One plane rising from the front edge over the eave polygon, and walls below it."""
    pts = fp.points
    ring, source = _eave_ring(fp, overhang, np.ones(len(pts)))
    n = len(ring)
    _, nrm, c = edge_lines(pts)
    f = fp.front
    tan = math.tan(math.radians(pitch))
    behind = min(0.0, float((pts @ nrm[f] - c[f]).min()))  # corners behind the front line
    top = tan * (ring @ nrm[f] - c[f] - behind)
    bottom = float(top.min())
    low = top - bottom <= _CLEAN_TOL * fp.scale  # corners on the eave: one vertex, at the eave
    top[low] = bottom
    vertices = np.vstack(
        [np.column_stack([ring, top]), np.column_stack([ring, np.full(n, bottom)])]
    )
    below = np.where(low, np.arange(n), np.arange(n) + n)
    builder = _MeshBuilder(vertices)
    roof = builder.plane("roof", _slope_plane, fp, f, tan, behind, 0.0)
    builder.add_polygon(np.arange(n), ring, roof)
    for i in range(n):
        j = (i + 1) % n
        if low[i] and low[j]:
            continue
        edge = int(source[i])
        wall = builder.plane(("wall", edge), _wall_plane, fp, edge, "wall", ring[i])
        quad = [tri for tri in ([below[i], below[j], j], [below[i], j, i]) if len(set(tri)) == 3]
        builder.add(quad, wall)
    return builder.finish(vertices[below], overhang, "shed")


def _flat_roof(fp: _Footprint, overhang: float, holes=()) -> RoofMesh:
    """The eave polygon at z = 0, without the holes (each shrunk by the overhang)."""
    ring, _ = _eave_ring(fp, overhang, np.ones(len(fp.points)))
    vertices = np.column_stack([ring, np.zeros(len(ring))])
    builder = _MeshBuilder(vertices)
    plane = builder.plane("flat", RoofPlane, "flat", None, (), np.array([0.0, 0.0, 1.0]), 0.0, 0.0)
    open_holes = [
        h.buffer(-overhang, join_style="mitre", mitre_limit=MITRE_LIMIT) if overhang > 0 else h
        for h in (Polygon(np.asarray(hole, dtype=np.float64)) for hole in holes)
        if h.is_valid and h.area > 0
    ]
    if not open_holes:
        builder.add_polygon(np.arange(len(ring)), ring, plane)
        return builder.finish(vertices, overhang, "flat")
    from .polygons import from_shapely
    from .polygons import triangulate as earcut

    shape = Polygon(ring).difference(shapely.union_all(open_holes))
    points, tris = earcut(from_shapely(shape))
    if len(tris):  # counter-clockwise seen from above
        a, b, c = points[tris[:, 0]], points[tris[:, 1]], points[tris[:, 2]]
        flip = _cross(b - a, c - a) < 0
        tris[flip] = tris[flip][:, ::-1]
    builder = _MeshBuilder(np.column_stack([points, np.zeros(len(points))]))
    plane = builder.plane("flat", RoofPlane, "flat", None, (), np.array([0.0, 0.0, 1.0]), 0.0, 0.0)
    builder.add(tris, plane)
    return builder.finish(vertices, overhang, "flat")
