"""Bulk placement of unit meshes: every terminal's triangles in world space, with numpy only.

A terminal places its unit mesh by ``world = origin + (v * size) @ axes``.  Rather than loop over
terminals, :func:`bake` groups them by the *shape* of their mesh (vertex count, face count) — all
the window quads of a city, or every four-cornered roof face, fall into one group even when each
has its own unit mesh — and transforms each group as one ``(n, V, 3)`` array.  The number of Python
iterations is the number of distinct mesh shapes, not the number of terminals.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # trimesh is imported where it is used: it costs a second at start-up
    import trimesh

from bgr.interpreter.terminals import TerminalTable


@dataclass
class MeshPool:
    """All unit meshes of a library concatenated: ``vertices[voff[m]:voff[m] + vcount[m]]``."""

    vertices: np.ndarray  # (sum V, 3) float64
    faces: np.ndarray  # (sum F, 3) int64, local to their own mesh
    voff: np.ndarray
    vcount: np.ndarray
    foff: np.ndarray
    fcount: np.ndarray
    # per-corner texture coordinates of the meshes that have their own (inserted assets),
    # uv[foff[m]:foff[m] + fcount[m]] (zeros for the others); None when no mesh has any
    uv: np.ndarray | None = None

    @classmethod
    def of(cls, table: TerminalTable) -> MeshPool:
        meshes = table.library.meshes
        verts = [m.vertices for m in meshes] or [np.zeros((0, 3))]
        faces = [m.faces for m in meshes] or [np.zeros((0, 3), dtype=np.int64)]
        vcount = np.fromiter(map(len, verts), dtype=np.int64, count=len(verts))[: len(meshes)]
        fcount = np.fromiter(map(len, faces), dtype=np.int64, count=len(faces))[: len(meshes)]
        uv = None
        if any(m.uv is not None for m in meshes):
            uv = np.concatenate(
                [m.uv if m.uv is not None else np.zeros((len(m.faces), 3, 2)) for m in meshes]
            )
        return cls(
            vertices=np.concatenate(verts).astype(np.float64, copy=False),
            faces=np.concatenate(faces).astype(np.int64, copy=False),
            voff=np.concatenate([[0], np.cumsum(vcount)[:-1]]).astype(np.int64),
            vcount=vcount,
            foff=np.concatenate([[0], np.cumsum(fcount)[:-1]]).astype(np.int64),
            fcount=fcount,
            uv=uv,
        )

    def flat_at_zero(self) -> np.ndarray:
        """(M, 3) bool: mesh m has every vertex at coordinate 0 along axis k (a zero size there
        changes nothing, so an instance may scale that axis by 1 instead of 0)."""
        out = np.ones((len(self.vcount), 3), dtype=bool)
        used = self.vcount > 0
        if used.any():
            peak = np.maximum.reduceat(np.abs(self.vertices), self.voff[used], axis=0)
            out[used] = peak == 0.0
        return out


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of (..., 3) arrays (faster than np.cross on many small rows)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape), dtype=np.result_type(a, b))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def det3(m: np.ndarray) -> np.ndarray:
    """Determinants of (n, 3, 3) matrices: row 0 . (row 1 x row 2)."""
    return np.einsum("ni,ni->n", m[:, 0], cross(m[:, 1], m[:, 2]))


def orthonormal(axes: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """(n,) bool: the three rows of each (3, 3) matrix are orthonormal within ``tol``."""
    ok = np.ones(len(axes), dtype=bool)
    for i in range(3):
        for j in range(i, 3):
            dot = np.einsum("ni,ni->n", axes[:, i], axes[:, j])
            ok &= np.abs(dot - (1.0 if i == j else 0.0)) < tol
    return ok


def mirrored(table: TerminalTable, rows: np.ndarray | None = None) -> np.ndarray:
    """(n,) bool: the terminal's transform ``diag(size) @ axes`` reverses orientation."""
    axes = table.axes if rows is None else table.axes[rows]
    size = table.size if rows is None else table.size[rows]
    return det3(axes) * np.prod(size, axis=1) < 0


def bounds(points: np.ndarray, block: int = 1024) -> tuple[np.ndarray, np.ndarray]:
    """Per-column min and max of (n, 3) points; blocked so numpy reduces long contiguous rows."""
    k = len(points) // block * block
    head = points[:k].reshape(-1, block * 3)
    lo = np.minimum(
        head.min(axis=0, initial=np.inf).reshape(block, 3).min(axis=0),
        points[k:].min(axis=0, initial=np.inf),
    )
    hi = np.maximum(
        head.max(axis=0, initial=-np.inf).reshape(block, 3).max(axis=0),
        points[k:].max(axis=0, initial=-np.inf),
    )
    return lo, hi


@dataclass
class Baked:
    """Placed triangles of some terminals, in the order of ``rows``."""

    vertices: np.ndarray  # (sum V, 3) float64, world
    faces: np.ndarray  # (sum F, 3) int64 into vertices; mirrored terminals are re-wound
    vstart: np.ndarray  # (n + 1,) vertex offsets per row
    fstart: np.ndarray  # (n + 1,) face offsets per row


def bake(
    table: TerminalTable, rows: np.ndarray | None = None, pool: MeshPool | None = None
) -> Baked:
    """World vertices and faces of the terminals ``rows`` (default: all), concatenated in order."""
    table.freeze()
    pool = pool or MeshPool.of(table)
    rows = (
        np.arange(len(table), dtype=np.int64) if rows is None else np.asarray(rows, dtype=np.int64)
    )
    mesh = table.mesh[rows].astype(np.int64)
    nv, nf = pool.vcount[mesh], pool.fcount[mesh]
    vstart = np.concatenate([[0], np.cumsum(nv)]).astype(np.int64)
    fstart = np.concatenate([[0], np.cumsum(nf)]).astype(np.int64)
    vertices = np.empty((int(vstart[-1]), 3), dtype=np.float64)
    faces = np.empty((int(fstart[-1]), 3), dtype=np.int64)
    flip = mirrored(table, rows)

    for group in _shape_groups(nv, nf):
        V, F = int(nv[group[0]]), int(nf[group[0]])
        r, m = rows[group], mesh[group]
        # a group of consecutive rows is computed straight into its slice of the output
        run = int(group[-1]) - int(group[0]) + 1 == len(group)
        if V:
            local = pool.vertices[pool.voff[m][:, None] + np.arange(V)]
            local *= table.size[r][:, None, :]
            axes = table.axes[r]
            if run:
                lo, hi = vstart[group[0]], vstart[group[-1] + 1]
                world = vertices[lo:hi].reshape(len(group), V, 3)
            else:
                world = np.empty((len(group), V, 3))
            # origin + x a0 + y a1 + z a2, added in that order
            np.multiply(local[:, :, 0:1], axes[:, None, 0, :], out=world)
            world += table.origin[r][:, None, :]
            term = np.empty_like(world)
            for k in (1, 2):
                np.multiply(local[:, :, k : k + 1], axes[:, None, k, :], out=term)
                world += term
            if not run:
                vertices[vstart[group][:, None] + np.arange(V)] = world
        if F:
            tri = pool.faces[pool.foff[m][:, None] + np.arange(F)] + vstart[group][:, None, None]
            flipped = flip[group]
            if flipped.any():
                tri[flipped] = tri[flipped][:, :, ::-1]
            if run:
                faces[fstart[group[0]] : fstart[group[-1] + 1]] = tri.reshape(-1, 3)
            else:
                faces[fstart[group][:, None] + np.arange(F)] = tri
    return Baked(vertices, faces, vstart, fstart)


def _shape_groups(nv: np.ndarray, nf: np.ndarray) -> list[np.ndarray]:
    """Indices grouped by (vertex count, face count), each group in increasing order."""
    key = nv * (int(nf.max(initial=0)) + 1) + nf
    order = np.argsort(key, kind="stable")
    return [g for g in np.split(order, np.flatnonzero(np.diff(key[order])) + 1) if len(g)]


def face_offsets(table: TerminalTable, rows: np.ndarray, pool: MeshPool) -> np.ndarray:
    """(n + 1,) offsets of each row's first triangle when the rows' meshes are concatenated."""
    return np.concatenate([[0], np.cumsum(pool.fcount[table.mesh[rows]])]).astype(np.int64)


def unit_normals(tri: np.ndarray, fallback=(0.0, 1.0, 0.0)) -> np.ndarray:
    """(n, 3) unit normals of (n, 3, 3) triangles (corners counter-clockwise); degenerate
    triangles get ``fallback``."""
    n = cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length2 = np.einsum("ij,ij->i", n, n)
    bad = ~(length2 > 0) | ~np.isfinite(length2)
    if bad.any():
        length2[bad] = 1.0
        n[bad] = fallback
    n *= (1.0 / np.sqrt(length2))[:, None]
    return n


def shape_order(
    table: TerminalTable, rows: np.ndarray, pool: MeshPool, major: np.ndarray
) -> np.ndarray:
    """``rows`` sorted by ``major`` (e.g. material), then mesh shape, then table order: the order
    in which :func:`place_corners` writes whole blocks instead of scattering triangles."""
    mesh = table.mesh[rows]
    nf = pool.fcount[mesh]
    shape = pool.vcount[mesh] * (int(nf.max(initial=0)) + 1) + nf
    return rows[np.lexsort((rows, shape, major))]


CHUNK_TRIANGLES = 1 << 17  # triangles placed at a time: bounds place_corners' temporaries


def place_corners(
    table: TerminalTable,
    rows: np.ndarray,
    pool: MeshPool,
    positions: np.ndarray,
    normals: np.ndarray,
    shift: np.ndarray | None = None,
) -> None:
    """Flat-shaded triangles of the terminals ``rows``, in float32, written in place.

    ``positions`` and ``normals`` are (T, 3, 3) float32 arrays (T = total triangles, rows in
    order, see :func:`face_offsets`): every triangle's three world corners (minus ``shift``)
    and its face normal repeated on each corner.  Mirrored terminals are re-wound so that faces
    keep pointing out.  Fastest when rows of one mesh shape are consecutive (:func:`shape_order`):
    each run is then computed straight into its slice of the output.
    """
    f32 = np.float32
    rows = np.asarray(rows, dtype=np.int64)
    mesh = table.mesh[rows].astype(np.int64)
    fstart = face_offsets(table, rows, pool)
    vpool = pool.vertices.astype(f32)

    def columns(at: np.ndarray) -> tuple[np.ndarray, ...]:
        """float32 origin (less ``shift``), axes and size of the rows ``at``, and their flips."""
        origin = table.origin[at] if shift is None else table.origin[at] - shift
        return (
            origin.astype(f32),
            table.axes[at].astype(f32),
            table.size[at].astype(f32),
            mirrored(table, at),
        )

    # a lot's few thousand rows gathered once; a whole city's a chunk at a time, so that the
    # temporaries stay a few MB (grid_city n = 40: 1,253 -> 954 MB peak with its GLB)
    gathered = columns(rows) if len(rows) <= CHUNK_TRIANGLES // 8 else None

    def corners(sel: np.ndarray, F: int, out: np.ndarray) -> None:
        """World corners of the rows ``sel`` (one shape, F faces each) into out (len(sel) * F, 3,
        3)."""
        if gathered is None:
            origin, axes, size, flip = columns(rows[sel])
        else:
            origin, axes, size, flip = (column[sel] for column in gathered)
        m = mesh[sel]
        if m[0] == m[-1] and (m == m[0]).all():  # one shared unit mesh
            lo = pool.foff[m[0]]
            unit = vpool[pool.faces[lo : lo + F].reshape(-1) + pool.voff[m[0]]]
            local = unit[None] * size[:, None, :]
        else:
            idx = pool.faces[pool.foff[m][:, None] + np.arange(F)] + pool.voff[m][:, None, None]
            local = vpool[idx.reshape(len(sel), 3 * F)] * size[:, None, :]
        world = out.reshape(len(sel), 3 * F, 3)
        np.matmul(local, axes, out=world)
        world += origin[:, None, :]
        if flip.any():
            tri = world.reshape(len(sel), F, 3, 3)
            tri[flip] = tri[flip][:, :, [0, 2, 1]]

    for whole in _shape_groups(pool.vcount[mesh], pool.fcount[mesh]):
        F = int(pool.fcount[mesh[whole[0]]])
        if F == 0:
            continue
        step = max(1, CHUNK_TRIANGLES // F)  # temporaries a few MB, not the size of the file
        for group in (whole[i : i + step] for i in range(0, len(whole), step)):
            runs = np.split(group, np.flatnonzero(np.diff(group) != 1) + 1)
            if len(runs) <= max(16, len(group) // 256):  # long runs: write each in place
                for run in runs:
                    lo, hi = fstart[run[0]], fstart[run[-1] + 1]
                    corners(run, F, positions[lo:hi])
                    normals[lo:hi] = unit_normals(positions[lo:hi])[:, None, :]
            else:  # scattered rows: compute the group, then scatter its triangles
                tri = np.empty((len(group) * F, 3, 3), dtype=f32)
                corners(group, F, tri)
                at = (fstart[group][:, None] + np.arange(F)).reshape(-1)
                positions[at] = tri
                normals[at] = unit_normals(tri)[:, None, :]


def srgb8(table: TerminalTable) -> np.ndarray:
    """(N, 3) uint8 colours, rounded exactly as :func:`terminals.color_hex` rounds them."""
    return np.rint(np.clip(table.color, 0.0, 1.0) * 255.0).astype(np.uint8)


def to_trimesh(table: TerminalTable) -> trimesh.Trimesh:
    """Every terminal as one concatenated mesh with per-face colours (nothing merged or removed).

    ``mesh.metadata["terminal"]`` holds, per face, the index of the terminal it came from.
    """
    import trimesh  # here, not at the top: importing it costs a second of every command's start

    table.freeze()
    baked = bake(table)
    face_row = np.repeat(np.arange(len(table)), np.diff(baked.fstart))
    rgba = np.full((len(face_row), 4), 255, dtype=np.uint8)
    rgba[:, :3] = srgb8(table)[face_row]
    mesh = trimesh.Trimesh(baked.vertices, baked.faces, face_colors=rgba, process=False)
    mesh.metadata["terminal"] = face_row
    return mesh
