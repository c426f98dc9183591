"""Pyramid roofs: one apex over the footprint's kernel, one triangle per edge (see ``pyramid``
and "Overhang" in the module docstring of :mod:`.roofs`)."""

from __future__ import annotations

import math

import numpy as np
from shapely.geometry import Point, Polygon
from shapely.ops import polylabel

from .earclip import signed_area
from .roof_footprint import MITRE_LIMIT, _Footprint
from .roof_model import RoofMesh, RoofPlane, _MeshBuilder, _unit
from .skeleton import edge_lines


def _pyramid_apex(fp: _Footprint):
    """Where the apex goes (see ``pyramid`` in the module docstring), or None (empty kernel)."""
    _, nrm, c = edge_lines(fp.points)
    margin = 1e-6 * fp.scale
    shape = Polygon(fp.points)

    def sees_all(p) -> bool:
        return bool(np.all(nrm @ p - c > margin))

    candidates = [
        np.array(shape.centroid.coords[0]),
        np.array(polylabel(shape, 1e-4 * fp.scale).coords[0]),
    ]
    seeing = [p for p in candidates if sees_all(p)]
    if seeing:  # the one farther from the boundary; the centroid on a tie (a rectangle)
        clearance = [shape.exterior.distance(Point(p)) for p in seeing]
        return seeing[int(np.argmax(np.round(clearance, 9)))]
    kernel = _kernel(fp.points, nrm, c, margin)
    if kernel is None:
        return None
    p = np.array(polylabel(Polygon(kernel), 1e-4 * fp.scale).coords[0])
    return p if sees_all(p) else None


def _kernel(pts: np.ndarray, nrm: np.ndarray, c: np.ndarray, margin: float):
    """The polygon's kernel (where every edge is seen from inside), shrunk by ``margin``."""
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    box = ((lo[0], lo[1]), (hi[0], lo[1]), hi, (lo[0], hi[1]))
    poly = [np.array(p, dtype=np.float64) for p in box]
    for k in range(len(pts)):
        poly = _clip_half_plane(poly, nrm[k], c[k] + margin)
        if len(poly) < 3:
            return None
    poly = np.array(poly)
    return poly if signed_area(poly) > margin * margin else None


def _clip_half_plane(poly, normal, level):
    """Sutherland–Hodgman: the part of a convex polygon where normal . x >= level."""
    out = []
    for i, p in enumerate(poly):
        q = poly[(i + 1) % len(poly)]
        sp, sq = normal @ p - level, normal @ q - level
        if sp >= 0:
            out.append(p)
        if (sp >= 0) != (sq >= 0):
            out.append(p + (q - p) * (sp / (sp - sq)))
    return out


def _pyramid_growth(pts: np.ndarray, apex: np.ndarray, run: np.ndarray, overhang: float):
    """How far each corner's hip is carried on past the corner, as a fraction of the corner's
    distance from the apex: until the eave is ``overhang`` beyond the nearer of the corner's two
    walls (``run``: the apex's distance from each edge's line), but no more than MITRE_LIMIT
    overhangs from the corner.  The old single fraction, ``overhang`` over the apex's clearance,
    gave a 6 m x 70 m footprint 5.8 m eaves at its ends for 0.5 m, and a needle kilometres."""
    if overhang == 0:
        return np.zeros(len(pts))
    nearer = np.minimum(run, np.roll(run, 1))  # corner j is between edges j-1 and j
    reach = np.linalg.norm(pts - apex, axis=1)
    return np.minimum(overhang / nearer, MITRE_LIMIT * overhang / reach)


def _pyramid_roof(fp: _Footprint, pitch: float, overhang: float, apex: np.ndarray) -> RoofMesh:
    """One triangle per edge up to the apex; with overhang, each hip carried on past its corner
    (see ``pyramid`` in the module docstring), so that every face keeps its plane."""
    pts = fp.points
    n = len(pts)
    radius = Polygon(pts).exterior.distance(Point(apex))
    tan = math.tan(math.radians(pitch))
    height = tan * radius
    _, nrm, c = edge_lines(pts)
    grow = _pyramid_growth(pts, apex, nrm @ apex - c, overhang)
    eave = np.column_stack([pts + grow[:, None] * (pts - apex), -grow * height])
    builder = _MeshBuilder(np.vstack([eave, [[apex[0], apex[1], height]]]))
    for k in range(n):
        a, b = np.append(pts[k], 0.0), np.append(pts[(k + 1) % n], 0.0)
        normal = _unit(np.cross(b - a, np.append(apex, height) - a))
        run = float(nrm[k] @ apex - c[k])  # horizontal distance from the edge to the apex
        slope = math.degrees(math.atan2(height, run))
        plane = builder.plane(
            k, RoofPlane, "slope", fp.label[k], fp.edges[k], normal, float(normal @ a), slope
        )
        builder.add([[k, (k + 1) % n, n]], plane)
    return builder.finish(eave, overhang, "pyramid")
