"""glTF 2.0 output (.glb and .gltf), built directly with numpy: the main output format.

Layout of the file (checked by the Khronos glTF validator in tests/test_gltf_validator.py):

* a scene tree people can work with: a root node ``bgr`` whose extras hold the grammar, seed,
  attrs, bgr version, and the CRS and origin of geographic lots; a node per lot named by its
  feature id or ``lot-N`` (extras: its attrs and feature properties); under it a node per
  terminal label (``Window``, ``Wall``, ...) whose mesh has one primitive per material
  (``group_by="lot"``, the default; ``"label"`` and ``"none"`` flatten it);
* one material per distinct (colour, material name) pair (:mod:`.materials`), shared by the
  whole file, PBR with the colour as ``baseColorFactor`` in linear light;
* every accessor has its own bufferView (no ``byteStride`` needed), POSITION with min/max.

**Instancing is off by default**: every terminal is baked to world space, so every reader sees
every triangle (trimesh and the Khronos validator do not know ``EXT_mesh_gpu_instancing``;
Blender's importer turns each instance into an object of its own; three.js makes an
InstancedMesh).  ``instancing="auto"`` (``bgr derive --instancing``) stores a repeated unit
mesh once with per-instance TRANSLATION / ROTATION / SCALE where that makes the file smaller
(:func:`plan`), and then lists the extension in ``extensionsRequired`` as well as
``extensionsUsed``, so that a reader without it refuses the file instead of showing one copy.

Triangles are flat shaded: every triangle has its own three vertices (no index buffer) carrying the
face normal.  All data is little-endian float32, every bufferView starts on a 4-byte boundary, and
the output is a pure function of the table: writing the same table twice gives identical bytes.
:func:`bgr.formats.read_glb` reads it back, expanding instances.
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


class _Builder:
    """float32 blocks in one preallocated little-endian buffer, and a bufferView per accessor
    (glTF wants a ``byteStride`` when accessors share a view; one view each needs none)."""

    def __init__(self, nbytes: int) -> None:
        self.bin = np.zeros(nbytes, dtype=np.uint8)
        self.offset = 0
        self.views: list[dict] = []
        self.accessors: list[dict] = []

    def block(self, count: int, width: int) -> tuple[int, np.ndarray]:
        """Reserve ``count`` float32 VEC<width>: the block's byte offset and an array to fill."""
        length = count * width * 4  # a multiple of 4, so every view stays 4-byte aligned
        start = self.offset
        self.offset += length
        return start, self.bin[start : start + length].view("<f4").reshape(count, width)

    def accessor(
        self,
        start: int,
        data: np.ndarray,
        target: int | None = ARRAY_BUFFER,
        bounded: bool = False,
    ) -> int:
        """A view on ``data`` (rows of a block starting at byte ``start``) and its accessor,
        with min/max if ``bounded`` (POSITION needs them)."""
        view = {"buffer": 0, "byteOffset": start, "byteLength": int(data.nbytes)}
        if target is not None:
            view["target"] = target
        self.views.append(view)
        acc = {
            "bufferView": len(self.views) - 1,
            "componentType": FLOAT,
            "count": len(data),
            "type": f"VEC{data.shape[1]}",
        }
        if bounded:
            lo, hi = bounds(data)
            acc["min"], acc["max"] = [float(v) for v in lo], [float(v) for v in hi]
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def vec(
        self, values: np.ndarray, target: int | None = ARRAY_BUFFER, bounded: bool = False
    ) -> int:
        """A block, its view and its accessor holding ``values`` (n, width)."""
        start, data = self.block(len(values), values.shape[1])
        data[:] = values
        return self.accessor(start, data, target, bounded)


def recentre(table: TerminalTable, limit: float = 4096.0) -> np.ndarray:
    """A whole-metre offset to subtract from positions (and put back as the root node's
    translation) when the scene lies far from the origin, where float32 would lose millimetres;
    else zeros."""
    if len(table) == 0 or np.abs(table.origin).max() <= limit:
        return np.zeros(3)
    return np.round((table.origin.min(axis=0) + table.origin.max(axis=0)) / 2) + 0.0


GROUPINGS = ("lot", "label", "none")


@dataclass
class Groups:
    """The scene's grouping of terminals: ``of_row`` the group of every table row, and per
    group its parent lot (or -1 at the root) and its node name."""

    of_row: np.ndarray
    lot: list[int]
    name: list[str]


def groups_of(table: TerminalTable, group_by: str) -> Groups:
    """Terminals by (lot, label), by label, or all in one group."""
    n = len(table)
    if group_by == "none" or n == 0:
        return Groups(np.zeros(n, dtype=np.int64), [-1], ["terminals"])
    labels, label_of = np.unique(np.asarray(table.label, dtype=object), return_inverse=True)
    label_of = label_of.astype(np.int64)
    if group_by == "label":
        return Groups(label_of, [-1] * len(labels), [str(v) for v in labels])
    lot_of = lot_rows(table)
    key = lot_of * len(labels) + label_of
    keys, of_row = np.unique(key, return_inverse=True)
    return Groups(
        of_row.astype(np.int64),
        [int(k) // len(labels) for k in keys],
        [str(labels[int(k) % len(labels)]) for k in keys],
    )


def lot_rows(table: TerminalTable) -> np.ndarray:
    """The lot of every terminal row, from each lot's ``rows`` range (0 for rows outside)."""
    out = np.zeros(len(table), dtype=np.int64)
    for i, lot in enumerate(table.lots):
        first, end = lot.get("rows", (0, 0))
        out[first:end] = i
    return out


def build(
    table: TerminalTable,
    *,
    seed: int,
    attrs: dict,
    instancing: str | bool = False,
    group_by: str = "lot",
) -> tuple[dict, np.ndarray]:
    """The glTF JSON document and its binary buffer (uint8) for a table.

    The scene is one root node ``bgr`` (extras: grammar, seed, attrs, bgr version, and the CRS
    and origin of geographic lots); under it, with ``group_by="lot"``, a node per lot named by
    its feature id or ``lot-N`` (extras: its attrs and feature properties) holding a node per
    terminal label; with ``"label"`` the label nodes sit under the root; with ``"none"`` the
    root holds every terminal.  A node's mesh has one primitive per material; materials are
    shared by the whole file.  ``instancing``: see :func:`plan` (off by default: every reader
    then sees every triangle).
    """
    if group_by not in GROUPINGS:
        raise BgrError(f"unknown grouping '{group_by}': use one of {', '.join(GROUPINGS)}")
    table.freeze()
    pool = MeshPool.of(table)
    mats = materials_of(table)
    groups = groups_of(table, group_by)
    n_groups = len(groups.name)
    # a row's instancing group and place in the file: its scene group first, then material
    major = groups.of_row * max(len(mats), 1) + mats.index
    p = plan(table, pool, mats, instancing, major)

    fstart = face_offsets(table, p.baked, pool)
    n_corner = 3 * int(fstart[-1])
    nbytes = n_corner * CORNER_BYTES
    for mesh_id, _, rows in p.groups:
        nbytes += int(pool.fcount[mesh_id]) * 3 * CORNER_BYTES + len(rows) * INSTANCE_BYTES
    b = _Builder(nbytes)
    shift = recentre(table)

    # baked terminals: one primitive per (group, material), a slice of two big blocks
    prims: list[list[dict]] = [[] for _ in range(n_groups)]
    if n_corner:
        pos_at, pos_data = b.block(n_corner, 3)
        nrm_at, nrm_data = b.block(n_corner, 3)
        place_corners(
            table, p.baked, pool, pos_data.reshape(-1, 3, 3), nrm_data.reshape(-1, 3, 3), shift
        )
        key = major[p.baked]
        cuts = np.flatnonzero(np.diff(key)) + 1
        for lo, hi in zip(
            np.concatenate([[0], cuts]), np.concatenate([cuts, [len(key)]]), strict=True
        ):
            first, end = 3 * int(fstart[lo]), 3 * int(fstart[hi])
            if end > first:
                row = p.baked[lo]
                prims[int(groups.of_row[row])].append(
                    {
                        "attributes": {
                            "POSITION": b.accessor(
                                pos_at + first * 12, pos_data[first:end], bounded=True
                            ),
                            "NORMAL": b.accessor(nrm_at + first * 12, nrm_data[first:end]),
                        },
                        "material": int(mats.index[row]),
                        "mode": 4,
                    }
                )

    meshes: list[dict] = []
    nodes: list[dict] = [{"name": "bgr", "children": []}]
    if shift.any():
        nodes[0]["translation"] = shift.tolist()
    nodes[0]["extras"] = root_extras(table, seed, attrs)
    lot_node: dict[int, dict] = {}

    def parent_of(group: int) -> dict:
        lot = groups.lot[group]
        if lot < 0:
            return nodes[0]
        if lot not in lot_node:
            lot_node[lot] = node = lot_extras(table, lot)
            nodes.append(node)
            nodes[0]["children"].append(len(nodes) - 1)
        return lot_node[lot]

    group_node: dict[int, dict] = {}

    def node_of(group: int) -> dict:
        if group not in group_node:
            if group_by == "none":
                group_node[group] = nodes[0]
            else:
                parent = parent_of(group)
                nodes.append({"name": groups.name[group]})
                parent.setdefault("children", []).append(len(nodes) - 1)
                group_node[group] = nodes[-1]
        return group_node[group]

    for group in range(n_groups):
        if prims[group]:
            meshes.append({"name": groups.name[group], "primitives": prims[group]})
            node_of(group)["mesh"] = len(meshes) - 1

    # instanced groups (opt-in): the unit mesh once, a child node with per-instance TRS
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
        parent = node_of(int(groups.of_row[rows[0]]))
        nodes.append(
            {
                "name": name,
                "mesh": len(meshes) - 1,
                "extensions": {INSTANCING: {"attributes": trs}},
            }
        )
        parent.setdefault("children", []).append(len(nodes) - 1)
    assert b.offset == nbytes
    if not nodes[0]["children"]:
        del nodes[0]["children"]

    gltf: dict = {
        "asset": {
            "version": "2.0",
            "generator": f"bgr {_version()}",
            "extras": {"bgr": 1, "seed": seed, "attrs": attrs},
        }
    }
    if p.groups:  # a reader without the extension must refuse the file, not drop geometry
        gltf["extensionsUsed"] = [INSTANCING]
        gltf["extensionsRequired"] = [INSTANCING]
    gltf["scene"] = 0
    gltf["scenes"] = [{"name": "bgr", "nodes": [0]}]
    gltf["nodes"] = nodes
    if meshes:
        gltf["meshes"] = meshes
    used = sorted({prim["material"] for mesh in meshes for prim in mesh["primitives"]})
    if used:
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


def root_extras(table: TerminalTable, seed: int, attrs: dict) -> dict:
    """What the root node says of the run: grammar, seed, attrs, version; where it lies."""
    extras: dict = {"bgr": _version(), "seed": seed, "attrs": attrs}
    grammar = getattr(table, "grammar", None)
    if grammar:
        extras["grammar"] = grammar
    if table.site:
        extras["crs"] = table.site.get("crs")
        extras["origin"] = table.site.get("origin")
        extras["axes"] = "x east, y up, z south; a position is origin + (x, -z, y) in the CRS"
    return extras


def lot_extras(table: TerminalTable, index: int) -> dict:
    """A lot's node: named by its feature id (or ``lot-N``), with its attrs and properties."""
    lot = table.lots[index] if index < len(table.lots) else {}
    extras: dict = {"path": lot.get("path", "")}
    for key in ("id", "attrs", "properties"):
        if lot.get(key) is not None:
            extras[key] = lot[key]
    return {"name": str(lot.get("name", f"lot-{index}")), "extras": extras}


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
    instancing: str | bool = False,
    group_by: str = "lot",
) -> None:
    """A binary glTF: header, JSON chunk (space-padded), BIN chunk.

    ``instancing`` and ``group_by``: see :func:`build`.
    """
    gltf, bin_ = build(table, seed=seed, attrs=attrs, instancing=instancing, group_by=group_by)
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
    instancing: str | bool = False,
    group_by: str = "lot",
) -> None:
    """One self-contained .gltf: JSON with the buffer as a base64 data URI."""
    gltf, bin_ = build(table, seed=seed, attrs=attrs, instancing=instancing, group_by=group_by)
    if bin_.nbytes:
        gltf["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(
            bin_.tobytes()
        ).decode("ascii")
    stream.write(_json_bytes(gltf, indent=1) + b"\n")
