"""Scope frames of extruded shapes, as CGA sets them.

CityEngine's extrude sets the new scope so that y points along the extrusion, x keeps its old
direction as far as it can (the old x projected onto the plane orthogonal to y) and z completes
a right-handed frame; the sizes fit the new geometry.  Rules written for CGA rely on it: after
``extrude`` on a façade or roof face, ``comp(f) { top: ... }`` is the cap away from the face,
``split(y)`` cuts across the extrusion, and a tier extruded from a roof stands on it.

These helpers take plain 3-vectors (tuples of floats), like the rest of the scope code.
"""

from __future__ import annotations

import math

from ..shapes import Vec, cross, dot, normalise
from .meshes import PLANE_AXES
from .polygons import RECT, UNIT_SQUARE, is_unit_square, signed_area
from .polygons import normalise as normalise_polys

WORLD_UP: Vec = (0.0, 1.0, 0.0)
_PARALLEL = 1e-9  # |sin| below which two directions count as parallel


def extrusion_axes(axes, direction: Vec) -> tuple[Vec, Vec, Vec]:
    """(x, y, z) of the scope after extruding along ``direction`` (a unit vector).

    x is the old x projected onto the plane orthogonal to y; where the old x is parallel to the
    extrusion, the old z, then the old y, stand in for it.
    """
    y = tuple(direction)
    for ref in (axes[0], axes[2], axes[1]):
        along = dot(ref, y)
        x = normalise([ref[i] - along * y[i] for i in range(3)])
        if dot(x, x) > 0.5:
            break
    z = cross(x, y)
    return tuple(x), y, tuple(z)  # type: ignore[return-value]


def flat_points(origin, axes, size, k: int, polys) -> list[tuple[list, list[list]]]:
    """The polygons of a flat shape (flat along scope axis ``k``) as world points."""
    p, q = PLANE_AXES[k]
    rings = [(UNIT_SQUARE, ())] if polys == RECT else polys

    def world(u: float, v: float) -> list[float]:
        a, b = u * size[p], v * size[q]
        return [origin[i] + a * axes[p][i] + b * axes[q][i] for i in range(3)]

    return [
        ([world(u, v) for u, v in ext], [[world(u, v) for u, v in h] for h in holes])
        for ext, holes in rings
    ]


def _ccw(ring: list[tuple[float, float]], outer: bool) -> tuple:
    """A ring counter-clockwise if it is an exterior, clockwise if it is a hole."""
    if (signed_area(ring) > 0) != outer:
        ring = ring[::-1]
    return tuple(ring)


def reframe_flat(origin, axes, size, k: int, polys, frame):
    """A flat shape expressed in ``frame`` (x, y, z), flat along the new y.

    Returns (origin, size, polys, heights): the new scope origin (at the lowest point along y),
    its x and z sizes (y left 0), the unit polygons in the (x, z) plane, and each polygon
    point's height along y above that origin (all 0 when the shape lies in the plane
    orthogonal to y).
    """
    x, y, z = frame
    world_polys = flat_points(origin, axes, size, k, polys)
    o = origin
    rel = [
        (
            [[dot([pt[i] - o[i] for i in range(3)], a) for a in (x, y, z)] for pt in ext],
            [
                [[dot([pt[i] - o[i] for i in range(3)], a) for a in (x, y, z)] for pt in h]
                for h in holes
            ],
        )
        for ext, holes in world_polys
    ]
    heights = [c[1] for ext, holes in rel for ring in [ext, *holes] for c in ring]
    y0 = min(heights)
    metric = [
        (
            _ccw([(c[0], c[2]) for c in ext], outer=True),
            tuple(_ccw([(c[0], c[2]) for c in h], outer=False) for h in holes),
        )
        for ext, holes in rel
    ]
    unit, (x0, z0, w, d) = normalise_polys(metric)
    new_origin = [o[i] + x0 * x[i] + y0 * y[i] + z0 * z[i] for i in range(3)]
    flat = RECT if is_unit_square(unit) else unit
    return new_origin, [w, 0.0, d], flat, [h - y0 for h in heights]


def is_parallel(a: Vec, b: Vec) -> bool:
    """Do two unit vectors point along one line (either way)?"""
    c = cross(a, b)
    return math.sqrt(dot(c, c)) < _PARALLEL


def planar_faces(vertices, faces) -> list[tuple[list[list[list[float]]], list[float]]]:
    """The planar faces of a triangle mesh: (rings of 3D points, unit normal) per face.

    Triangles are grouped by their plane (normal and offset, to 1e-6 of the mesh's size), and
    each group's triangles are merged into polygons (an outer ring and its holes) in that
    plane, so a roof's slope or gable end comes out as one face, in the order the mesh first
    uses each plane.  Degenerate triangles are ignored.
    """
    import numpy as np
    import shapely
    from shapely.geometry import Polygon

    v = np.asarray(vertices, dtype=float)
    f = np.asarray(faces, dtype=np.int64)
    if len(f) == 0:
        return []
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    n = np.cross(b - a, c - a)
    length = np.linalg.norm(n, axis=1)
    scale = max(float(np.ptp(v, axis=0).max()), 1e-9)
    keep = length > 1e-12 * scale * scale
    n[keep] /= length[keep, None]
    offset = np.einsum("ij,ij->i", n, a)
    key = np.column_stack([np.round(n * 1e6), np.round(offset / scale * 1e6)]).astype(np.int64)
    out = []
    seen: dict[tuple, list[int]] = {}
    for i in np.flatnonzero(keep):
        seen.setdefault(tuple(key[i]), []).append(int(i))
    for rows in seen.values():
        normal = n[rows[0]]
        ref = np.array([0.0, 1.0, 0.0]) if abs(normal[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
        e1 = np.cross(ref, normal)
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(normal, e1)
        plane = float(offset[rows[0]])
        tris = [Polygon([(p @ e1, p @ e2) for p in (a[r], b[r], c[r])]) for r in rows]
        merged = shapely.union_all(tris)
        for poly in getattr(merged, "geoms", [merged]):
            if not isinstance(poly, Polygon) or poly.area <= 1e-12 * scale * scale:
                continue
            poly = shapely.geometry.polygon.orient(poly.simplify(0.0))
            rings = [_lift(r, e1, e2, plane, normal) for r in [poly.exterior, *poly.interiors]]
            out.append((rings, normal.tolist()))
    return out


def _lift(ring, e1, e2, plane: float, normal) -> list[list[float]]:
    """A ring of plane coordinates (x along e1, y along e2) back to 3D points on the plane."""
    return [(x * e1 + y * e2 + plane * normal).tolist() for x, y in list(ring.coords)[:-1]]
