"""Solids cut by planes, closed again where a closed solid is cut: split of a mesh solid and
envelope's sloped planes.

trimesh's ``slice_mesh_plane`` does the cutting and, for a watertight mesh, triangulates the
section (``cap``) with earcut; an open mesh (a roof without its underside) is cut without caps.
"""

from __future__ import annotations

import numpy as np


def _mesh(vertices: np.ndarray, faces: np.ndarray):
    import trimesh  # 0.36 s to import: only a derivation that cuts a solid pays it

    return trimesh.Trimesh(vertices=vertices, faces=faces, process=True, validate=False)


def keep_side(vertices, faces, planes) -> tuple[np.ndarray, np.ndarray]:
    """The part of a mesh on the kept side of every plane (normal, point): normal . (p - point)
    >= 0.  Empty arrays when nothing is left."""
    import trimesh

    mesh = _mesh(np.asarray(vertices, float), np.asarray(faces, np.int64))
    for normal, point in planes:
        if len(mesh.faces) == 0:
            break
        closed = bool(mesh.is_watertight)
        mesh = trimesh.intersections.slice_mesh_plane(
            mesh, plane_normal=np.asarray(normal, float), plane_origin=np.asarray(point, float),
            cap=closed,
        )  # fmt: skip
    if mesh is None or len(mesh.faces) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int32)
    return np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int32)


def slab(vertices, faces, axis: int, lo: float, hi: float) -> tuple[np.ndarray, np.ndarray]:
    """The part of a unit mesh between ``lo`` and ``hi`` along ``axis``, rescaled so that the
    slab spans 0..1 there (the piece's own unit coordinates)."""
    v = np.asarray(vertices, float)
    along = v[:, axis] if len(v) else v
    if len(v) == 0 or (along.min() >= lo - 1e-12 and along.max() <= hi + 1e-12):
        out = v.copy()
    else:
        low, high = np.zeros(3), np.zeros(3)
        low[axis], high[axis] = lo, hi
        up, down = np.zeros(3), np.zeros(3)
        up[axis], down[axis] = 1.0, -1.0
        planes = [(up, low), (down, high)]
        out, faces = keep_side(v, faces, planes)
    if len(out):
        out[:, axis] = (out[:, axis] - lo) / (hi - lo)
    return out, np.asarray(faces, np.int32)
