"""Texture coordinates of baked terminals, in the order :func:`meshes.place_corners` (glTF) or
:func:`meshes.bake` (OBJ, CityJSON) gives their corners.

A terminal's coordinates are an affine map of its unit-scope vertices (the terminal table's
``tex_uv``), so every corner's uv is one matrix product per unit mesh, numpy in bulk; an
inserted asset that shows its own texture (``tex_own``) takes its unit mesh's per-corner uvs
instead.  glTF puts v = 0 at the top of the image, CGA at the bottom: glTF files store 1 - v
(:func:`corner_uvs`); OBJ and CityJSON put v = 0 at the bottom as CGA does (:func:`baked_uvs`).
"""

from __future__ import annotations

import numpy as np

from bgr.interpreter.terminals import TerminalTable

from .meshes import MeshPool, face_offsets, mirrored


def corner_uvs(table: TerminalTable, rows: np.ndarray, pool: MeshPool, which: int) -> np.ndarray:
    """(T * 3, 2) float32 glTF texture coordinates of the triangles of ``rows`` (textured rows
    of the table, in the order given), for the colour map (``which`` 0) or the normal map (1)."""
    out = cga_corner_uvs(table, rows, pool, which)
    out[..., 1] = 1.0 - out[..., 1]
    return out.reshape(-1, 2).astype(np.float32)


def cga_corner_uvs(
    table: TerminalTable, rows: np.ndarray, pool: MeshPool, which: int
) -> np.ndarray:
    """(T, 3, 2) float64 texture coordinates the CGA way up (v = 0 at the image's bottom) of
    the triangles of ``rows``, corners in :func:`meshes.place_corners`'s order."""
    rows = np.asarray(rows, dtype=np.int64)
    slot = np.full(len(table), -1, dtype=np.int64)
    slot[np.asarray(table.tex_rows, dtype=np.int64)] = np.arange(len(table.tex_rows))
    maps = np.asarray(table.tex_uv)[slot[rows], which]  # (n, 2, 4)
    own = np.asarray(table.tex_own, dtype=bool).reshape(-1)
    # the colour map of an inserted asset that keeps its own coordinates (its unit mesh's)
    own = own[slot[rows]] if which == 0 and len(own) else np.zeros(len(rows), dtype=bool)
    mesh = table.mesh[rows].astype(np.int64)
    fcount = pool.fcount[mesh].astype(np.int64)
    start = np.concatenate([[0], np.cumsum(fcount)])
    out = np.empty((int(start[-1]), 3, 2), dtype=np.float64)
    flip = mirrored(table, rows)
    order = np.argsort(mesh, kind="stable")  # the rows of each unit mesh together
    cuts = np.flatnonzero(np.diff(mesh[order])) + 1
    for sel in np.split(order, cuts) if len(order) else []:
        m = mesh[sel[0]]  # one product per unit mesh shape, every row of it at once
        F = int(pool.fcount[m])
        if F == 0:
            continue
        lo = pool.foff[m]
        unit = pool.vertices[pool.faces[lo : lo + F].reshape(-1) + pool.voff[m]]  # (3F, 3)
        uv = np.matmul(maps[sel, :, :3], unit.T) + maps[sel, :, 3:]  # (n, 2, 3F)
        tri = uv.transpose(0, 2, 1).reshape(len(sel), F, 3, 2)
        if pool.uv is not None and own[sel].any():
            tri[own[sel]] = pool.uv[lo : lo + F]
        tri[flip[sel]] = tri[flip[sel]][:, :, [0, 2, 1]]  # re-wound as place_corners does
        at = (start[sel][:, None] + np.arange(F)).reshape(-1)
        out[at] = tri.reshape(-1, 3, 2)
    return out


def baked_uvs(table: TerminalTable, rows: np.ndarray, pool: MeshPool) -> np.ndarray:
    """(T, 3, 2) float64 texture coordinates the CGA way up (v runs up the image, as OBJ's
    ``vt`` and CityJSON's ``vertices-texture`` have it) of the triangles of ``rows`` (textured
    rows) in the corner order :func:`meshes.bake` gives them: the colour map's coordinates, or
    the normal map's for a row with a normal map only (these files hold one set per corner)."""
    rows = np.asarray(rows, dtype=np.int64)
    out = np.empty((int(face_offsets(table, rows, pool)[-1]), 3, 2), dtype=np.float64)
    if not len(rows):
        return out
    slot = np.full(len(table), -1, dtype=np.int64)
    slot[np.asarray(table.tex_rows, dtype=np.int64)] = np.arange(len(table.tex_rows))
    has_color = np.asarray(table.tex_maps)[slot[rows], 0] >= 0
    fstart = face_offsets(table, rows, pool)
    for which, chosen in ((0, has_color), (1, ~has_color)):
        if not chosen.any():
            continue
        sel = rows[chosen]
        uv = cga_corner_uvs(table, sel, pool, which)
        # place_corners re-winds a mirrored terminal's triangle (0, 2, 1), bake (2, 1, 0)
        flip = np.repeat(mirrored(table, sel), pool.fcount[table.mesh[sel]])
        uv[flip] = uv[flip][:, [1, 2, 0]]
        nf = pool.fcount[table.mesh[sel]].astype(np.int64)
        at = np.repeat(fstart[:-1][chosen], nf) + (
            np.arange(int(nf.sum())) - np.repeat(np.cumsum(nf) - nf, nf)
        )
        out[at] = uv
    return out


def corner_tangents(positions: np.ndarray, normals: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """(T * 3, 4) float32 glTF TANGENTs of flat triangles for a normal map: xyz the direction in
    which u grows (made perpendicular to the face normal), w the sign that makes
    cross(normal, tangent) * w point the way the image's up (v) grows, so the map's +Y is up as
    glTF's normal textures have it.  ``positions`` and ``normals`` (T * 3, 3), ``uv`` (T * 3, 2)
    in glTF's v-down convention, all in corner order.  A triangle whose uvs have no area gets a
    tangent along its first edge."""
    p = np.asarray(positions, dtype=np.float64).reshape(-1, 3, 3)
    n = np.asarray(normals, dtype=np.float64).reshape(-1, 3, 3)[:, 0]
    t = np.asarray(uv, dtype=np.float64).reshape(-1, 3, 2) * [1.0, -1.0]  # v up again
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    ok = np.abs(det) > 1e-20
    r = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)[:, None]
    tan = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * r
    bit = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * r
    tan = np.where(ok[:, None], tan, e1)
    tan -= n * np.einsum("ij,ij->i", n, tan)[:, None]  # into the face's plane
    length = np.sqrt(np.einsum("ij,ij->i", tan, tan))
    flat = ~(length > 1e-12)
    if flat.any():  # no direction in the plane: any unit vector perpendicular to the normal
        other = np.where(np.abs(n[flat, 0:1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        tan[flat] = np.cross(n[flat], other)
        length[flat] = np.sqrt(np.einsum("ij,ij->i", tan[flat], tan[flat]))
    tan /= np.where(length > 0, length, 1.0)[:, None]
    w = np.where(np.einsum("ij,ij->i", np.cross(n, tan), bit) < 0.0, -1.0, 1.0)
    out = np.empty((len(p), 3, 4), dtype=np.float32)
    out[:, :, :3] = tan[:, None, :]
    out[:, :, 3] = w[:, None]
    return out.reshape(-1, 4)
