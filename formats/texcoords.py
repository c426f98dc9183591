"""Texture coordinates of baked terminals, in the order :func:`meshes.place_corners` writes
their corners, and the glTF material keys of textured terminals.

A terminal's coordinates are an affine map of its unit-scope vertices (the terminal table's
``tex_uv``), so every corner's uv is one matrix product per unit mesh, numpy in bulk.  glTF puts
v = 0 at the top of the image, CGA at the bottom: the files store 1 - v.
"""

from __future__ import annotations

import numpy as np

from bgr.interpreter.terminals import TerminalTable

from .meshes import MeshPool, mirrored


def corner_uvs(table: TerminalTable, rows: np.ndarray, pool: MeshPool, which: int) -> np.ndarray:
    """(T * 3, 2) float32 glTF texture coordinates of the triangles of ``rows`` (textured rows
    of the table, in the order given), for the colour map (``which`` 0) or the normal map (1)."""
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
    out[..., 1] = 1.0 - out[..., 1]
    return out.reshape(-1, 2).astype(np.float32)


def texture_keys(table: TerminalTable) -> list[tuple[str | None, str | None]]:
    """Per row, the (colour map, normal map) image paths; (None, None) for plain rows."""
    keys: list[tuple[str | None, str | None]] = [(None, None)] * len(table)
    images = table.images
    for row, (c, nm) in zip(
        np.asarray(table.tex_rows).tolist(), np.asarray(table.tex_maps).tolist(), strict=True
    ):
        keys[row] = (images[c].path if c >= 0 else None, images[nm].path if nm >= 0 else None)
    return keys
