"""Texture coordinates of baked terminals, in the order :func:`meshes.place_corners` (glTF) or
:func:`meshes.bake` (OBJ, CityJSON) gives their corners.

A terminal's coordinates are an affine map of its unit-scope vertices (the terminal table's
``tex_uv``), so every corner's uv is one matrix product per unit mesh, numpy in bulk.  glTF puts
v = 0 at the top of the image, CGA at the bottom: glTF files store 1 - v (:func:`corner_uvs`);
OBJ and CityJSON put v = 0 at the bottom as CGA does (:func:`baked_uvs`).
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
    mesh = table.mesh[rows].astype(np.int64)
    fcount = pool.fcount[mesh].astype(np.int64)
    start = np.concatenate([[0], np.cumsum(fcount)])
    out = np.empty((int(start[-1]), 3, 2), dtype=np.float64)
    flip = mirrored(table, rows)
    for m in np.unique(mesh):  # one product per unit mesh shape, every row of it at once
        sel = np.flatnonzero(mesh == m)
        F = int(pool.fcount[m])
        if F == 0:
            continue
        lo = pool.foff[m]
        unit = pool.vertices[pool.faces[lo : lo + F].reshape(-1) + pool.voff[m]]  # (3F, 3)
        uv = np.einsum("nij,vj->nvi", maps[sel, :, :3], unit) + maps[sel, None, :, 3]
        tri = uv.reshape(len(sel), F, 3, 2)
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
