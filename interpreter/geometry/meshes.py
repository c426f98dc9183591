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


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``np.cross`` of two (N, 3) arrays, term for term as numpy computes it (so bit for bit the
    same), without its per-call overhead (moveaxis, broadcasting checks)."""
    u0, u1, u2 = u[:, 0], u[:, 1], u[:, 2]
    v0, v1, v2 = v[:, 0], v[:, 1], v[:, 2]
    out = np.empty((len(u), 3))
    out[:, 0] = u1 * v2 - u2 * v1
    out[:, 1] = u2 * v0 - u0 * v2
    out[:, 2] = u0 * v1 - u1 * v0
    return out


def _orient(verts: np.ndarray, faces: np.ndarray, outward) -> np.ndarray:
    """Flip triangles whose normal points against ``outward``: a fixed direction (3,) or a
    function ``outward(centroids) -> (T, 3)``."""
    if len(faces) == 0:
        return faces
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    normals = _cross(b - a, c - a)
    if callable(outward):
        return _flip(faces, np.einsum("ij,ij->i", normals, outward((a + b + c) / 3.0)) < 0)
    return _flip(faces, np.einsum("ij,j->i", normals, outward) < 0)


def _flip(faces: np.ndarray, flip: np.ndarray) -> np.ndarray:
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
    return verts, _orient(verts, tris, normal)


def prism_mesh(polys, k: int) -> tuple[np.ndarray, np.ndarray]:
    """A closed prism: the base polygon from 0 to 1 along axis k, caps and side walls.

    Vertices: the bottom cap's, the top cap's, then four per edge of every ring (polygon by
    polygon, the exterior before its holes, edge by edge): the edge's start and end at 0, its end
    and start at 1.  Each wall quad is two triangles, turned by whether a point just off the
    edge's middle lies in the polygon (all edges at once): an exterior's walls face out of the
    polygon, a hole's face into the polygon (away from the hole), as they always have.
    """
    polys = [(UNIT_SQUARE, ())] if polys == RECT else polys
    pts2, tris = triangulate(polys)
    bottom, top = _lift(pts2, k, 0.0), _lift(pts2, k, 1.0)
    normal = np.eye(3)[k]
    verts = [bottom, top]
    faces = [tris, tris]
    if len(tris):  # the caps' triangles have the same normals: they differ only along k
        a, b, c = bottom[tris[:, 0]], bottom[tris[:, 1]], bottom[tris[:, 2]]
        up = np.einsum("ij,j->i", _cross(b - a, c - a), normal)
        faces = [_flip(tris, -up < 0), _flip(tris, up < 0) + len(bottom)]
    rings = [
        [np.asarray(r, dtype=np.float64).reshape(-1, 2) for r in [ext, *holes]]
        for ext, holes in polys
    ]
    every = [r for poly in rings for r in poly]
    if not any(len(r) for r in every):
        return np.vstack(verts), np.vstack(faces)
    p, q = np.concatenate(every), np.concatenate([np.concatenate([r[1:], r[:1]]) for r in every])
    n = len(p)
    edge = q - p
    right = np.column_stack([edge[:, 1], -edge[:, 0]])
    # the right-hand normal, turned round where the point just left of the edge is inside the
    # polygon and the ring is a hole, or outside it and the ring is the exterior
    probe = (p + q) / 2 - 1e-6 * right
    turn = np.empty(n, dtype=bool)
    lo = 0
    with np.errstate(all="ignore"):  # the crossing test divides only where an edge crosses
        for poly in rings:
            hi = lo + sum(len(r) for r in poly)
            here = probe[lo:hi]
            inside = _in_ring(here, poly[0])
            for hole in poly[1:]:
                inside &= ~_in_ring(here, hole)
            inside[: len(poly[0])] ^= True  # the exterior's edges turn where it is outside
            turn[lo:hi] = inside
            lo = hi
    right = np.where(turn[:, None], -right, right)
    a, b = PLANE_AXES[k]
    plane = np.stack([p, q, q, p], axis=1)  # (E, 4, 2)
    quads = np.zeros((n, 4, 3))
    quads[:, :, a], quads[:, :, b] = plane[:, :, 0], plane[:, :, 1]
    quads[:, 2:, k] = 1.0
    out3 = np.zeros((n, 3))
    out3[:, a], out3[:, b] = right[:, 0], right[:, 1]
    # the triangles (0, 1, 2) and (0, 2, 3) of each quad, flipped where they face inwards
    to1, to2, to3 = quads[:, 1] - quads[:, 0], quads[:, 2] - quads[:, 0], quads[:, 3] - quads[:, 0]
    normals = np.stack([_cross(to1, to2), _cross(to2, to3)], axis=1).reshape(-1, 3)
    want = np.repeat(out3, 2, axis=0)
    flip = (np.einsum("ij,ij->i", normals, want) < 0).reshape(n, 2)
    tri = np.where(flip[:, :, None], _QUAD_TRIS[:, ::-1], _QUAD_TRIS)
    base = len(bottom) + len(top) + 4 * np.arange(n)
    verts.append(quads.reshape(-1, 3))
    faces.append((tri + base[:, None, None]).reshape(-1, 3))
    return np.vstack(verts), np.vstack(faces)


_QUAD_TRIS = np.array([[0, 1, 2], [0, 2, 3]])


def _in_ring(pts: np.ndarray, ring: np.ndarray) -> np.ndarray:
    """Whether each point (N, 2) is inside ``ring`` (M, 2), by the even-odd crossing rule (a ray
    towards +x); a point on the outline falls either way, as the rule's arithmetic has it.  The
    caller silences numpy's warnings: the division is used only where the edge crosses y."""
    inside = np.zeros(len(pts), dtype=bool)
    if len(ring) == 0 or len(pts) == 0:
        return inside
    x0, y0 = ring[:, 0], ring[:, 1]
    x1, y1 = np.concatenate([x0[1:], x0[:1]]), np.concatenate([y0[1:], y0[:1]])
    step = max(1, (1 << 20) // len(ring))  # at most ~1 M point-edge pairs at a time
    for lo in range(0, len(pts), step):
        x, y = pts[lo : lo + step, :1], pts[lo : lo + step, 1:]
        crosses = (y0 > y) != (y1 > y)
        left = x < (x1 - x0) * (y - y0) / (y1 - y0) + x0
        inside[lo : lo + step] = np.logical_xor.reduce(crosses & left, axis=1)
    return inside


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
