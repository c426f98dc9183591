"""Which terminals a glTF file stores once and instances (``EXT_mesh_gpu_instancing``), and the
rotations it writes for them.

An instance is a unit mesh placed by TRANSLATION, ROTATION (a quaternion) and SCALE, so only
terminals whose axes are a rotation (orthonormal, right-handed) can be instanced; :func:`plan`
picks the (mesh, material) groups where that makes the file smaller.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bgr.interpreter.terminals import TerminalTable

from .materials import Materials
from .meshes import MeshPool, det3, orthonormal, shape_order

CORNER_BYTES = 24  # float32 position + normal per triangle corner
INSTANCE_BYTES = 40  # float32 translation (12) + rotation quaternion (16) + scale (12)
# JSON added by one instanced group (a mesh, a node, 5 accessors, 5 bufferViews): about 870
# bytes measured, more with long names; the decision only needs the right order of magnitude
GROUP_OVERHEAD = 1000


@dataclass
class Plan:
    baked: np.ndarray  # terminal rows baked to world space: by material, mesh shape, table order
    groups: list[tuple[int, int, np.ndarray]]  # instanced (mesh id, material, rows in table order)
    scale: (
        np.ndarray
    )  # (N, 3) instance scales: the size, with 1 on axes where the mesh is flat at 0


def plan(
    table: TerminalTable,
    pool: MeshPool,
    mats: Materials,
    instancing: str | bool = "auto",
    major: np.ndarray | None = None,
) -> Plan:
    """Which terminals to instance.

    A terminal can be instanced when its axes are orthonormal and right-handed (the rotation is a
    quaternion) and every size is positive, or zero along an axis where its unit mesh is flat at 0
    (a quad's z): there the scale is written as 1, which places the same vertices and keeps the
    normal matrix invertible.  A (mesh, material) group is instanced when
    ``stored once + 40 bytes per instance + JSON`` is smaller than baking every copy
    (``instancing="auto"``); ``True`` instances every group that can be, ``False`` none.
    """
    n = len(table)
    mesh = table.mesh.astype(np.int64)
    size = table.size
    flat = pool.flat_at_zero()[mesh] if n else np.zeros((0, 3), dtype=bool)
    scale = np.where((size == 0.0) & flat, 1.0, size)
    eligible = (
        orthonormal(table.axes)
        & (det3(table.axes) > 0)
        & (scale > 0).all(axis=1)
        & (pool.fcount[mesh] > 0)
    )
    if instancing is False or instancing == "never" or n == 0:
        eligible[:] = False
    if len(table.tex_rows):  # texture coordinates are each terminal's own: baked, not shared
        eligible[np.asarray(table.tex_rows, dtype=np.int64)] = False

    n_mesh = max(len(pool.vcount), 1)
    if major is None:  # the file's grouping of rows (scene group and material); else material
        major = mats.index.astype(np.int64)
    key = major * n_mesh + mesh
    keys, counts = np.unique(key[eligible], return_counts=True)
    faces = pool.fcount[keys % n_mesh]
    stored = faces * 3 * CORNER_BYTES
    if instancing is True or instancing == "always":
        chosen = keys
    else:
        chosen = keys[
            (counts >= 2) & (stored + counts * INSTANCE_BYTES + GROUP_OVERHEAD < counts * stored)
        ]

    instanced = eligible & np.isin(key, chosen)
    groups = []
    if chosen.size:
        rows = np.flatnonzero(instanced)
        order = np.argsort(key[rows], kind="stable")
        rows = rows[order]
        cuts = np.flatnonzero(np.diff(key[rows])) + 1
        for grp in np.split(rows, cuts):
            groups.append((int(mesh[grp[0]]), int(mats.index[grp[0]]), grp))
    baked = np.flatnonzero(~instanced)
    baked = shape_order(table, baked, pool, major[baked])
    return Plan(baked=baked, groups=groups, scale=scale)


def quaternions(axes: np.ndarray) -> np.ndarray:
    """(n, 4) unit quaternions (x, y, z, w), w >= 0, of rotations whose matrix columns are the
    rows of ``axes`` (orthonormal, right-handed)."""
    R = axes.transpose(0, 2, 1)
    m00, m11, m22 = R[:, 0, 0], R[:, 1, 1], R[:, 2, 2]
    q = np.empty((len(R), 4))
    # Shepperd's method: take the largest of w, x, y, z as the pivot, for accuracy
    pivots = np.stack([m00 + m11 + m22, m00, m11, m22], axis=1).argmax(axis=1)
    for case in range(4):
        sel = pivots == case
        if not sel.any():
            continue
        r = R[sel]
        a, b, c = r[:, 0, 0], r[:, 1, 1], r[:, 2, 2]
        if case == 0:
            s = np.sqrt(1.0 + a + b + c) * 2
            q[sel] = np.stack(
                [
                    (r[:, 2, 1] - r[:, 1, 2]) / s,
                    (r[:, 0, 2] - r[:, 2, 0]) / s,
                    (r[:, 1, 0] - r[:, 0, 1]) / s,
                    0.25 * s,
                ],
                axis=1,
            )
        elif case == 1:
            s = np.sqrt(1.0 + a - b - c) * 2
            q[sel] = np.stack(
                [
                    0.25 * s,
                    (r[:, 0, 1] + r[:, 1, 0]) / s,
                    (r[:, 0, 2] + r[:, 2, 0]) / s,
                    (r[:, 2, 1] - r[:, 1, 2]) / s,
                ],
                axis=1,
            )
        elif case == 2:
            s = np.sqrt(1.0 + b - a - c) * 2
            q[sel] = np.stack(
                [
                    (r[:, 0, 1] + r[:, 1, 0]) / s,
                    0.25 * s,
                    (r[:, 1, 2] + r[:, 2, 1]) / s,
                    (r[:, 0, 2] - r[:, 2, 0]) / s,
                ],
                axis=1,
            )
        else:
            s = np.sqrt(1.0 + c - a - b) * 2
            q[sel] = np.stack(
                [
                    (r[:, 0, 2] + r[:, 2, 0]) / s,
                    (r[:, 1, 2] + r[:, 2, 1]) / s,
                    0.25 * s,
                    (r[:, 1, 0] - r[:, 0, 1]) / s,
                ],
                axis=1,
            )
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q[q[:, 3] < 0] *= -1
    return q
