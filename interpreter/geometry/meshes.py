"""Unit meshes of the interpreter's geometries: flat polygons, prisms and the primitives.

All vertices are in unit scope coordinates (0..1 along each scope axis); triangles are oriented
counter-clockwise seen from outside.  A geometry's normal axis ``k`` is the scope axis it is flat
along (a lot: y, a façade face: z) or extruded along (a prism).
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np

from .polygons import RECT, UNIT_SQUARE, triangulate

PLANE_AXES = {0: (1, 2), 1: (0, 2), 2: (0, 1)}


def _orient(verts: np.ndarray, faces: np.ndarray, outward) -> np.ndarray:
    """Flip triangles whose normal points against ``outward(centroids) -> (T, 3)``."""
    if len(faces) == 0:
        return faces
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    normals = np.cross(b - a, c - a)
    want = outward((a + b + c) / 3.0)
    flip = np.einsum("ij,ij->i", normals, want) < 0
    faces = faces.copy()
    faces[flip] = faces[flip][:, ::-1]
    return faces


def _lift(pts2: np.ndarray, k: int, level: float) -> np.ndarray:
    a, b = PLANE_AXES[k]
    out = np.zeros((len(pts2), 3))
    out[:, a], out[:, b], out[:, k] = pts2[:, 0], pts2[:, 1], level
    return out


def flat_mesh(polys, k: int) -> tuple[np.ndarray, np.ndarray]:
    """A planar polygon facing +k."""
    pts2, tris = triangulate([(UNIT_SQUARE, ())] if polys == RECT else polys)
    verts = _lift(pts2, k, 0.0)
    normal = np.eye(3)[k]
    return verts, _orient(verts, tris, lambda c: np.broadcast_to(normal, c.shape))


def prism_mesh(polys, k: int) -> tuple[np.ndarray, np.ndarray]:
    """A closed prism: the base polygon from 0 to 1 along axis k, caps and side walls."""
    polys = [(UNIT_SQUARE, ())] if polys == RECT else polys
    pts2, tris = triangulate(polys)
    bottom, top = _lift(pts2, k, 0.0), _lift(pts2, k, 1.0)
    normal = np.eye(3)[k]
    verts = [bottom, top]
    faces = [
        _orient(bottom, tris, lambda c: np.broadcast_to(-normal, c.shape)),
        _orient(top, tris, lambda c: np.broadcast_to(normal, c.shape)) + len(bottom),
    ]
    base = len(bottom) + len(top)
    for ext, holes in polys:
        for ring, is_hole in [(ext, False)] + [(h, True) for h in holes]:
            ring = np.asarray(ring, dtype=np.float64)
            nxt = np.roll(ring, -1, axis=0)
            for p, q in zip(ring, nxt, strict=True):
                quad = np.vstack([_lift(np.array([p, q]), k, 0.0), _lift(np.array([q, p]), k, 1.0)])
                # outward: away from the ring's interior (towards it for holes)
                edge = q - p
                n2 = np.array([edge[1], -edge[0]])
                mid = (p + q) / 2
                inside_probe = mid - 1e-6 * n2
                if _inside(inside_probe, ext, holes) == is_hole:
                    n2 = -n2
                n3 = _lift(n2[None, :], k, 0.0)[0]
                tri = _orient(
                    quad,
                    np.array([[0, 1, 2], [0, 2, 3]]),
                    lambda c, n3=n3: np.broadcast_to(n3, c.shape),
                )
                verts.append(quad)
                faces.append(tri + base)
                base += 4
    return np.vstack(verts), np.vstack(faces)


def _inside(pt, ext, holes) -> bool:
    def in_ring(ring):
        x, y, inside = pt[0], pt[1], False
        n = len(ring)
        for i in range(n):
            (x0, y0), (x1, y1) = ring[i], ring[(i + 1) % n]
            if (y0 > y) != (y1 > y) and x < (x1 - x0) * (y - y0) / (y1 - y0) + x0:
                inside = not inside
        return inside

    return in_ring(ext) and not any(in_ring(h) for h in holes)


@cache
def primitive(name: str) -> tuple[np.ndarray, np.ndarray]:
    """The unit meshes of i(): cube, quad, wedge, cylinder (y up), sphere."""
    if name == "cube":
        return prism_mesh(RECT, 1)
    if name == "quad":
        return flat_mesh(RECT, 2)
    if name == "wedge":  # a right prism on a triangle in the yz plane, sloping down to +z
        tri = [(((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)), ())]  # a right triangle in the (y, z) plane
        return prism_mesh(tri, 0)
    if name == "cylinder":
        n = 24
        ring = tuple(
            (0.5 + 0.5 * math.cos(2 * math.pi * i / n), 0.5 + 0.5 * math.sin(2 * math.pi * i / n))
            for i in range(n)
        )
        return prism_mesh([(ring, ())], 1)
    if name == "sphere":
        rows, cols = 12, 24
        verts, faces = [], []
        for r in range(rows + 1):
            phi = math.pi * r / rows
            for c in range(cols):
                th = 2 * math.pi * c / cols
                verts.append(
                    (
                        0.5 + 0.5 * math.sin(phi) * math.cos(th),
                        0.5 + 0.5 * math.cos(phi),
                        0.5 + 0.5 * math.sin(phi) * math.sin(th),
                    )
                )
        for r in range(rows):
            for c in range(cols):
                a, b = r * cols + c, r * cols + (c + 1) % cols
                d, e = a + cols, b + cols
                if r > 0:
                    faces.append((a, b, e))
                if r < rows - 1:
                    faces.append((a, e, d))
        v, f = np.array(verts), np.array(faces)
        return v, _orient(v, f, lambda c: c - 0.5)
    raise KeyError(name)


def clip_below(
    vertices: np.ndarray, faces: np.ndarray, select: np.ndarray, level: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Cut away the part of the ``select``-ed triangles below ``level`` along z.

    A roof's gable ends and a shed's side walls reach down to its eaves, below the top of the
    wall they stand on; there they lie in the wall's own plane, and two coplanar faces flicker
    (z-fighting) in every viewer.  Triangles keep their winding; the rest are untouched.
    """
    eps = 1e-9
    kept = [faces[~select]]
    extra: list[np.ndarray] = []
    base = len(vertices)
    for tri in faces[select]:
        pts = vertices[tri]
        z = pts[:, 2] - level
        if (z >= -eps).all():
            kept.append(tri[None, :])
            continue
        if (z <= eps).all():
            continue
        poly = []  # Sutherland-Hodgman against z >= level
        for i in range(3):
            p, q, zp, zq = pts[i], pts[(i + 1) % 3], z[i], z[(i + 1) % 3]
            if zp >= -eps:
                poly.append(p)
            if (zp >= -eps) != (zq >= -eps):
                poly.append(p + (q - p) * (zp / (zp - zq)))
        if len(poly) < 3:
            continue
        ids = np.arange(base, base + len(poly))
        base += len(poly)
        extra.append(np.array(poly))
        kept.append(np.array([[ids[0], ids[j], ids[j + 1]] for j in range(1, len(poly) - 1)]))
    out_v = np.vstack([vertices, *extra]) if extra else vertices
    return out_v, np.vstack(kept).astype(faces.dtype)
