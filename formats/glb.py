"""glTF 2.0 output (.glb and .gltf), built directly with numpy: the main output format.

Layout of the file:

* one material per distinct (colour, material name) pair (:mod:`.materials`), PBR with the colour
  as ``baseColorFactor`` in linear light;
* node ``terminals``: every terminal that is not instanced, baked to world space, one primitive per
  material;
* one node per instanced (unit mesh, material) group: the unit mesh stored once and placed by the
  ``EXT_mesh_gpu_instancing`` TRANSLATION / ROTATION / SCALE attributes.  A group is instanced
  when that makes the file smaller (:func:`plan`), so ``extensionsUsed`` names the extension only
  when some group is.

Triangles are flat shaded: every triangle has its own three vertices (no index buffer) carrying the
face normal.  All data is little-endian float32, every bufferView starts on a 4-byte boundary, and
the output is a pure function of the table: writing the same table twice gives identical bytes.

Readers without EXT_mesh_gpu_instancing (trimesh 5.2 among them) show one copy of each instanced
group; :func:`bgr.formats.read_glb` expands them.
"""

from __future__ import annotations

import base64
import json
import struct
from dataclasses import dataclass
from typing import BinaryIO

import numpy as np

from bgr.grammar.errors import BgrError
from bgr.interpreter.terminals import TerminalTable

from .materials import Materials, materials_of
from .meshes import (
    MeshPool,
    bounds,
    det3,
    face_offsets,
    orthonormal,
    place_corners,
    shape_order,
    unit_normals,
)
from .terminal_json import plain

INSTANCING = "EXT_mesh_gpu_instancing"
FLOAT, ARRAY_BUFFER = 5126, 34962
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
    table: TerminalTable, pool: MeshPool, mats: Materials, instancing: str | bool = "auto"
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

    n_mesh = max(len(pool.vcount), 1)
    key = mats.index * n_mesh + mesh
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
    baked = shape_order(table, baked, pool, mats.index[baked])
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


class _Builder:
    """bufferViews and float32 accessors over one preallocated little-endian buffer."""

    def __init__(self, nbytes: int) -> None:
        self.bin = np.zeros(nbytes, dtype=np.uint8)
        self.offset = 0
        self.views: list[dict] = []
        self.accessors: list[dict] = []
        self._data: list[np.ndarray] = []

    def view(
        self, count: int, width: int, target: int | None = ARRAY_BUFFER
    ) -> tuple[int, np.ndarray]:
        """Reserve ``count`` float32 VEC<width>: the bufferView's index and an array to fill."""
        length = count * width * 4  # a multiple of 4, so every view stays 4-byte aligned
        view = {"buffer": 0, "byteOffset": self.offset, "byteLength": length}
        if target is not None:
            view["target"] = target
        self.views.append(view)
        data = self.bin[self.offset : self.offset + length].view("<f4").reshape(count, width)
        self._data.append(data)
        self.offset += length
        return len(self.views) - 1, data

    def accessor(
        self, view: int, first: int = 0, count: int | None = None, bounded: bool = False
    ) -> int:
        """An accessor on elements ``first:first + count`` of a view, min/max if ``bounded``."""
        data = self._data[view]
        count = len(data) - first if count is None else count
        acc = {
            "bufferView": view,
            "componentType": FLOAT,
            "count": count,
            "type": f"VEC{data.shape[1]}",
        }
        if first:
            acc["byteOffset"] = first * data.shape[1] * 4
        if bounded:
            lo, hi = bounds(data[first : first + count])
            acc["min"], acc["max"] = [float(v) for v in lo], [float(v) for v in hi]
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def vec(
        self, values: np.ndarray, target: int | None = ARRAY_BUFFER, bounded: bool = False
    ) -> int:
        """A view and its accessor holding ``values`` (n, width)."""
        view, data = self.view(len(values), values.shape[1], target)
        data[:] = values
        return self.accessor(view, bounded=bounded)


def recentre(table: TerminalTable, limit: float = 4096.0) -> np.ndarray:
    """A whole-metre offset to subtract from positions (and put back as the node translation)
    when the scene lies far from the origin, where float32 would lose millimetres; else zeros."""
    if len(table) == 0 or np.abs(table.origin).max() <= limit:
        return np.zeros(3)
    return np.round((table.origin.min(axis=0) + table.origin.max(axis=0)) / 2) + 0.0


def build(
    table: TerminalTable, *, seed: int, attrs: dict, instancing: str | bool = "auto"
) -> tuple[dict, np.ndarray]:
    """The glTF JSON document and its binary buffer (uint8) for a table."""
    table.freeze()
    pool = MeshPool.of(table)
    mats = materials_of(table)
    p = plan(table, pool, mats, instancing)

    fstart = face_offsets(table, p.baked, pool)
    n_corner = 3 * int(fstart[-1])
    nbytes = n_corner * CORNER_BYTES
    for mesh_id, _, rows in p.groups:
        nbytes += int(pool.fcount[mesh_id]) * 3 * CORNER_BYTES + len(rows) * INSTANCE_BYTES
    b = _Builder(nbytes)
    meshes, nodes = [], []
    shift = recentre(table)
    place = {"translation": shift.tolist()} if shift.any() else {}

    # baked terminals: one view per attribute, one primitive (a slice of them) per material
    if n_corner:
        pos_view, pos_data = b.view(n_corner, 3)
        nrm_view, nrm_data = b.view(n_corner, 3)
        place_corners(
            table, p.baked, pool, pos_data.reshape(-1, 3, 3), nrm_data.reshape(-1, 3, 3), shift
        )
        mat_of_row = mats.index[p.baked]
        cuts = np.flatnonzero(np.diff(mat_of_row)) + 1
        prims = []
        for lo, hi in zip(
            np.concatenate([[0], cuts]), np.concatenate([cuts, [len(mat_of_row)]]), strict=True
        ):
            first, count = 3 * int(fstart[lo]), 3 * int(fstart[hi] - fstart[lo])
            if count:
                prims.append(
                    {
                        "attributes": {
                            "POSITION": b.accessor(pos_view, first, count, bounded=True),
                            "NORMAL": b.accessor(nrm_view, first, count),
                        },
                        "material": int(mat_of_row[lo]),
                        "mode": 4,
                    }
                )
        meshes.append({"name": "terminals", "primitives": prims})
        nodes.append({"name": "terminals", "mesh": 0, **place})

    # instanced groups: the unit mesh once, one node with per-instance TRS
    names = [m.name for m in table.library.meshes]
    for mesh_id, mat, rows in p.groups:
        unit = pool.vertices[pool.voff[mesh_id] : pool.voff[mesh_id] + pool.vcount[mesh_id]]
        corners = unit[pool.faces[pool.foff[mesh_id] : pool.foff[mesh_id] + pool.fcount[mesh_id]]]
        normals = unit_normals(corners, fallback=(0.0, 0.0, 1.0))
        pos = b.vec(corners.reshape(-1, 3), bounded=True)
        nrm = b.vec(np.repeat(normals, 3, axis=0))
        trs = {
            "TRANSLATION": b.vec(table.origin[rows] - shift, None),
            "ROTATION": b.vec(quaternions(table.axes[rows]), None),
            "SCALE": b.vec(p.scale[rows], None),
        }
        name = f"{names[mesh_id]} {mats.labels[mat]}"
        meshes.append(
            {
                "name": name,
                "primitives": [
                    {"attributes": {"POSITION": pos, "NORMAL": nrm}, "material": mat, "mode": 4}
                ],
            }
        )
        nodes.append(
            {
                "name": name,
                "mesh": len(meshes) - 1,
                **place,
                "extensions": {INSTANCING: {"attributes": trs}},
            }
        )
    assert b.offset == nbytes

    gltf: dict = {
        "asset": {
            "version": "2.0",
            "generator": f"bgr {_version()}",
            "extras": {"bgr": 1, "seed": seed, "attrs": attrs},
        }
    }
    if p.groups:
        gltf["extensionsUsed"] = [INSTANCING]
    gltf["scene"] = 0
    gltf["scenes"] = [{"name": "bgr", "nodes": list(range(len(nodes)))}]
    gltf["nodes"] = nodes
    if meshes:
        gltf["meshes"] = meshes
    if len(mats):
        gltf["materials"] = [
            {
                "name": mats.labels[k],
                "pbrMetallicRoughness": {
                    "baseColorFactor": mats.linear(k) + [1.0],
                    "metallicFactor": 0.0,
                    "roughnessFactor": 0.8,
                },
                "doubleSided": True,
                "extras": {"color": mats.hex(k), "material": mats.names[k]},
            }
            for k in range(len(mats))
        ]
    if b.accessors:
        gltf["accessors"] = b.accessors
        gltf["bufferViews"] = b.views
        gltf["buffers"] = [{"byteLength": int(b.bin.nbytes)}]
    return gltf, b.bin


def _version() -> str:
    try:
        from importlib.metadata import version

        return version("bgr")
    except Exception:  # pragma: no cover - source tree without install
        return "0"


def _json_bytes(gltf: dict, **layout) -> bytes:
    layout = layout or {"separators": (",", ":")}
    try:
        return json.dumps(
            gltf, ensure_ascii=False, allow_nan=False, default=plain, **layout
        ).encode("utf-8")
    except (TypeError, ValueError) as exc:
        raise BgrError(f"cannot write glTF: {exc}") from exc


def write_glb(
    table: TerminalTable,
    stream: BinaryIO,
    *,
    seed: int,
    attrs: dict,
    instancing: str | bool = "auto",
) -> None:
    """A binary glTF: header, JSON chunk (space-padded), BIN chunk.

    ``instancing``: see :func:`plan`.
    """
    gltf, bin_ = build(table, seed=seed, attrs=attrs, instancing=instancing)
    text = _json_bytes(gltf)
    text += b" " * (-len(text) % 4)
    chunks: list[bytes | np.ndarray] = [struct.pack("<II", len(text), 0x4E4F534A), text]
    if bin_.nbytes:
        chunks += [struct.pack("<II", bin_.nbytes, 0x004E4942), bin_]  # already a multiple of 4
    total = 12 + sum(len(c) if isinstance(c, bytes) else c.nbytes for c in chunks)
    stream.write(struct.pack("<4sII", b"glTF", 2, total))
    for c in chunks:
        stream.write(c if isinstance(c, bytes) else c.data)


def write_gltf(
    table: TerminalTable,
    stream: BinaryIO,
    *,
    seed: int,
    attrs: dict,
    instancing: str | bool = "auto",
) -> None:
    """One self-contained .gltf: JSON with the buffer as a base64 data URI."""
    gltf, bin_ = build(table, seed=seed, attrs=attrs, instancing=instancing)
    if bin_.nbytes:
        gltf["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(
            bin_.tobytes()
        ).decode("ascii")
    stream.write(_json_bytes(gltf, indent=1) + b"\n")
