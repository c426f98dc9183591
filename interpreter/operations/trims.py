"""CGA's trim planes: what is inserted on a façade is cut where the façade meets the next one.

``comp(f)`` of a solid gives each wall face a plane at each of its vertical edges, the one that
halves the corner with the neighbouring wall (CGA's trim planes).  Every shape derived from the
face keeps them, and ``i()`` cuts the inserted mesh by them, so that a ledge or a cornice made
longer than its façade meets its neighbour's in a mitre at the corner instead of running past
it.  Splits do not cut (their pieces never leave the face).  The planes are in world
coordinates; the reuse of repeated subtrees keys on them relative to the shape's origin.
"""

from __future__ import annotations

import math

import numpy as np

from ..shapes import Shape
from ..terminals import UnitMesh

_EPS = 1e-9
# what an operation returns when nothing of the shape is left: the engine takes it as NIL
DELETED = "deleted"


def corner_planes(face: Shape, left: float, right: float) -> tuple:
    """The two vertical trim planes of a wall face whose corners turn ``left`` and ``right``
    degrees (comp.left, comp.right: 90 at a box's corners): through its left and right edges,
    halving each corner, kept on the face's side."""
    half_l, half_r = math.radians(left) / 2, math.radians(right) / 2
    at_left = tuple(face.origin)
    at_right = tuple(face.world((face.size[0], 0.0, 0.0)))
    n_left = tuple(face.direction((math.cos(half_l), 0.0, math.sin(half_l))))
    n_right = tuple(face.direction((-math.cos(half_r), 0.0, math.sin(half_r))))
    return ((at_left, n_left), (at_right, n_right))


def moved_trims(trims: tuple, origin) -> tuple:
    """Trim planes as seen from ``origin``: a subtree derived at the world's origin (reuse)."""
    return tuple(((p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]), n) for p, n in trims)


def relative(shape: Shape) -> tuple:
    """The shape's trim planes relative to its origin, rounded: part of a reuse key."""
    o = shape.origin
    return tuple(
        (
            round(p[0] - o[0], 9),
            round(p[1] - o[1], 9),
            round(p[2] - o[2], 9),
            round(n[0], 9),
            round(n[1], 9),
            round(n[2], 9),
        )
        for p, n in shape.trims
    )


def trim_insert(app, shape: Shape) -> bool:
    """Cut the shape's inserted mesh by its trim planes; False when nothing of it is left."""
    if not shape.trims:
        return True
    library = app.engine.table.library
    mesh = library.meshes[shape.geom.mesh]
    axes = np.asarray(shape.axes, dtype=np.float64)
    size = np.asarray(shape.size, dtype=np.float64)
    origin = np.asarray(shape.origin, dtype=np.float64)
    verts, faces, uv = mesh.vertices, mesh.faces, mesh.uv
    changed = False
    for point, normal in shape.trims:
        # the plane in the mesh's unit coordinates: u = ((w - o) . a_i) / s_i
        p = np.divide((np.asarray(point) - origin) @ axes.T, size, out=np.zeros(3), where=size > 0)
        n = (axes @ np.asarray(normal)) * size
        side = (verts - p) @ n
        scale = float(np.abs(n).max()) or 1.0
        if (side >= -_EPS * scale).all():
            continue
        if (side <= _EPS * scale).all():
            return False
        verts, faces, uv = _clip(verts, faces, uv, side, _EPS * scale)
        changed = True
        if not len(faces):
            return False
    if changed:
        trimmed = UnitMesh(mesh.name, verts, faces, uv, mesh.image)
        shape.geom = type(shape.geom)(library.add(trimmed), shape.geom.name)
    return True


def _clip(verts, faces, uv, side, eps):
    """Triangles cut to the side >= 0 of a plane (``side``: each vertex's signed distance);
    texture coordinates interpolated along the cut edges, winding kept."""
    inside = side >= -eps
    keep = inside[faces].all(axis=1)
    drop = (~inside[faces]).all(axis=1)
    out_f = [faces[keep]]
    out_uv = [uv[keep]] if uv is not None else None
    extra: list = []
    base = len(verts)
    for t in np.nonzero(~keep & ~drop)[0]:
        tri = faces[t]
        pts, d = verts[tri], side[tri]
        corners = uv[t] if uv is not None else None
        poly, poly_uv = [], []
        for i in range(3):
            j = (i + 1) % 3
            if d[i] >= -eps:
                poly.append(pts[i])
                if corners is not None:
                    poly_uv.append(corners[i])
            if (d[i] >= -eps) != (d[j] >= -eps):
                f = d[i] / (d[i] - d[j])
                poly.append(pts[i] + (pts[j] - pts[i]) * f)
                if corners is not None:
                    poly_uv.append(corners[i] + (corners[j] - corners[i]) * f)
        if len(poly) < 3:
            continue
        ids = np.arange(base, base + len(poly))
        base += len(poly)
        extra.append(np.asarray(poly))
        fan = [(ids[0], ids[k], ids[k + 1]) for k in range(1, len(poly) - 1)]
        out_f.append(np.asarray(fan, dtype=faces.dtype))
        if out_uv is not None:
            out_uv.append(
                np.asarray(
                    [(poly_uv[0], poly_uv[k], poly_uv[k + 1]) for k in range(1, len(poly) - 1)]
                )
            )
    new_verts = np.vstack([verts, *extra]) if extra else verts
    new_faces = np.vstack(out_f) if out_f else np.zeros((0, 3), dtype=faces.dtype)
    new_uv = np.concatenate(out_uv) if out_uv is not None else None
    return new_verts, new_faces, new_uv
