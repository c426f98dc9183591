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
import io
import json
import shutil
import struct
import tempfile
from dataclasses import dataclass
from typing import Any, BinaryIO

import numpy as np

from bgr.grammar.errors import BgrError
from bgr.grammar.parser import no_gc
from bgr.interpreter.terminals import TerminalTable, lot_tables

from .gltf_materials import MaterialIndex, UvSets, image_members
from .instancing import CORNER_BYTES, INSTANCE_BYTES, plan, quaternions
from .meshes import MeshPool, bounds, face_offsets, place_corners, unit_normals
from .placement import gltf_translation
from .terminal_json import plain

INSTANCING = "EXT_mesh_gpu_instancing"
FLOAT, ARRAY_BUFFER = 5126, 34962
__all__ = ["Scene", "build", "write_glb", "write_gltf", "quaternions", "plan", "recentre"]


class _Builder:
    """float32 blocks of one part of the file's buffer, and a bufferView per accessor (glTF
    wants a ``byteStride`` when accessors share a view; one view each needs none).  ``base``:
    the bytes, views and accessors the file holds before this part."""

    def __init__(self, nbytes: int, base: tuple[int, int, int] = (0, 0, 0)) -> None:
        self.bin = np.zeros(nbytes, dtype=np.uint8)
        self.offset = 0
        self.byte_base, self.view_base, self.accessor_base = base
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
        limits: tuple | None = None,
    ) -> int:
        """A view on ``data`` (rows of a block starting at byte ``start``) and its accessor,
        with min/max if ``bounded`` (POSITION needs them) or given (``limits``)."""
        view = {"buffer": 0, "byteOffset": self.byte_base + start, "byteLength": int(data.nbytes)}
        if target is not None:
            view["target"] = target
        self.views.append(view)
        acc = {
            "bufferView": self.view_base + len(self.views) - 1,
            "componentType": FLOAT,
            "count": len(data),
            "type": f"VEC{data.shape[1]}",
        }
        if bounded and limits is None:
            limits = bounds(data)
        if limits is not None:
            acc["min"], acc["max"] = [float(v) for v in limits[0]], [float(v) for v in limits[1]]
        self.accessors.append(acc)
        return self.accessor_base + len(self.accessors) - 1

    def raw(self, data: bytes) -> int:
        """A bufferView (no accessor) holding ``data``, padded to 4 bytes: an embedded image."""
        start = self.offset
        self.bin[start : start + len(data)] = np.frombuffer(data, dtype=np.uint8)
        self.offset += len(data) + (-len(data) % 4)
        view = {"buffer": 0, "byteOffset": self.byte_base + start, "byteLength": len(data)}
        self.views.append(view)
        return self.view_base + len(self.views) - 1

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
    else zeros.  Taken from the lots' origins when the table has lots: a run that writes lots
    as they are derived knows those before any terminal (:func:`recentre_points`)."""
    if table.lots:
        return recentre_points(np.array([lot["origin"] for lot in table.lots]), limit)
    return recentre_points(table.origin, limit)


def recentre_points(points: np.ndarray, limit: float = 4096.0) -> np.ndarray:
    """The whole-metre centre of ``points`` (n, 3) when one lies beyond ``limit``, else zeros."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(points) == 0 or np.abs(points).max() <= limit:
        return np.zeros(3)
    return np.round((points.min(axis=0) + points.max(axis=0)) / 2) + 0.0


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
    # the labels sorted, each row's by a dict: np.unique sorted every row's string (1 % of
    # deriving Helsinki), where a lot has a few dozen distinct labels
    labels = sorted(set(table.label))
    index = {label: i for i, label in enumerate(labels)}
    label_of = np.fromiter(map(index.__getitem__, table.label), dtype=np.int64, count=n)
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


SPOOL_MEMORY = 1 << 20  # bytes a spool holds in memory before it moves to a temporary file


class _Spool:
    """A JSON array's items (or the binary buffer) written to a temporary file as they come:
    held in memory up to a few megabytes, on disk beyond, removed when closed."""

    def __init__(self, folder: str | None, memory: int = SPOOL_MEMORY) -> None:
        # closed by close(): a spool lives as long as the Scene that owns it
        self.file = tempfile.SpooledTemporaryFile(max_size=memory, dir=folder)  # noqa: SIM115
        self.memory = memory
        self.count = 0
        self.nbytes = 0

    def items(self, values: list) -> None:
        """The array's next items, comma-separated, from one ``json.dumps`` (a part of a
        textured style has thousands of accessors: a call each took a fifth of writing it)."""
        text = (b"," if self.count and values else b"") + _json_bytes(values)[1:-1]
        self.file.write(text)
        self.count += len(values)
        self.nbytes += len(text)

    def raw(self, data) -> None:
        size = len(memoryview(data).cast("B"))
        if self.nbytes + size > self.memory:  # straight to disk: not a second copy in memory
            self.file.rollover()
        self.file.write(data)
        self.nbytes += size

    def copy_to(self, stream: BinaryIO) -> None:
        self.file.seek(0)
        shutil.copyfileobj(self.file, stream, 1 << 20)

    def close(self) -> None:
        self.file.close()


class Scene:
    """A glTF file built part by part — a part is one lot's terminals, or a whole table — so
    that a city can be written as its lots are derived: the nodes, meshes, accessors and views
    of each part and its binary data go to spools (:class:`_Spool`) and the part is dropped;
    :meth:`write_glb` puts the file together at the end.  Only the root node and the materials
    stay in memory.

    Writing a table, and writing its lots one by one (:func:`lot_tables`), give the same bytes:
    :func:`build` and :func:`write_glb` add a table with lots lot by lot too.  ``group_by``
    "label" and "none" gather several lots under one node, so they take one part, the whole
    table.  ``shift``: see :func:`recentre`.  ``folder``: where spools that outgrow memory go
    (the output's folder; None: the system's temporary folder).
    """

    def __init__(
        self,
        *,
        seed: int,
        attrs: dict,
        grammar: str = "",
        site: dict | None = None,
        instancing: str | bool = False,
        group_by: str = "lot",
        shift: np.ndarray | None = None,
        folder: str | None = None,
    ) -> None:
        if group_by not in GROUPINGS:
            raise BgrError(f"unknown grouping '{group_by}': use one of {', '.join(GROUPINGS)}")
        self.seed, self.attrs, self.instancing, self.group_by = seed, attrs, instancing, group_by
        self.shift = np.zeros(3) if shift is None else np.asarray(shift, dtype=np.float64)
        self.materials = MaterialIndex()
        self.used: set[int] = set()  # materials some primitive uses
        self.instanced = False
        self.parts = 0
        self.images: dict[str, int] = {}  # image path -> its number in the file
        self.image_views: list[tuple[int, str]] = []  # per image: (bufferView, mimeType)
        self.image_alpha: dict[str, bool] = {}
        self.root: dict = {"name": "bgr", "children": []}
        # the recentring shift, and the site's origin: a reader applying the root's transform
        # sees the input's coordinates (formats/placement.py)
        translation = self.shift + gltf_translation(site)
        if translation.any():
            self.root["translation"] = translation.tolist()
        meta = TerminalTable(site=site, grammar=grammar)
        self.root["extras"] = root_extras(meta, seed, attrs)
        self.spools = {k: _Spool(folder) for k in ("nodes", "meshes", "accessors", "views")}
        self.spools["bin"] = _Spool(folder, memory=16 << 10)  # the bulk: on disk at once

    def close(self) -> None:
        for spool in self.spools.values():
            spool.close()

    def __enter__(self) -> Scene:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    @no_gc()  # thousands of dicts and no cycles: a full collection took 0.25 s of a restyle
    def add(self, table: TerminalTable) -> None:
        """Add a part: its lots' nodes (``group_by="lot"``) or its label nodes, its meshes and
        their data.  With ``group_by`` "label" or "none" a file takes one part."""
        table.freeze()
        if self.group_by != "lot" and self.parts:
            raise BgrError(f"group_by='{self.group_by}' writes one table, not several parts")
        self.parts += 1
        if not len(table):
            return
        sp = self.spools
        pool = MeshPool.of(table)
        mats = self.materials.of(table)
        groups = groups_of(table, self.group_by)
        # a row's instancing group and place in the file: its scene group first, then material
        major = groups.of_row * max(len(self.materials), 1) + mats.index
        p = plan(table, pool, mats, self.instancing, major)

        fstart = face_offsets(table, p.baked, pool)
        n_corner = 3 * int(fstart[-1])
        nbytes = n_corner * CORNER_BYTES
        fresh: dict[str, Any] = {}  # by path, first seen first: a scan per image was O(n^2)
        for im in (im for im in table.images if im.path not in self.images):
            fresh.setdefault(im.path, im)
        new_images = list(fresh.values())
        nbytes += sum(len(im.data) + (-len(im.data) % 4) for im in new_images)
        uvs = UvSets.of(table, p.baked, mats, self.materials.textures, pool)
        nbytes += uvs.nbytes
        for mesh_id, _, rows in p.groups:
            nbytes += int(pool.fcount[mesh_id]) * 3 * CORNER_BYTES + len(rows) * INSTANCE_BYTES
        b = _Builder(nbytes, (sp["bin"].nbytes, sp["views"].count, sp["accessors"].count))
        for im in new_images:  # each distinct file once in the whole file, as given
            self.image_alpha[im.path] = im.alpha
            self.images[im.path] = len(self.image_views)
            self.image_views.append((b.raw(im.data), im.mime))
        uvs.fill(b.block, table, pool)

        # baked terminals: one primitive per (group, material), a slice of two big blocks
        prims: list[list[dict]] = [[] for _ in groups.name]
        if n_corner:
            pos_at, pos_data = b.block(n_corner, 3)
            nrm_at, nrm_data = b.block(n_corner, 3)
            place_corners(
                table,
                p.baked,
                pool,
                pos_data.reshape(-1, 3, 3),
                nrm_data.reshape(-1, 3, 3),
                self.shift,
            )
            uvs.tangents(table, p.baked, fstart, pos_data, nrm_data, pool)
            key = major[p.baked]
            cuts = np.flatnonzero(np.diff(key)) + 1
            los = np.concatenate([[0], cuts])
            corner = 3 * fstart[np.concatenate([los, [len(key)]])]
            keep = corner[1:] > corner[:-1]  # primitives with corners: consecutive, covering
            los, starts, ends = los[keep], corner[:-1][keep], corner[1:][keep]
            # every POSITION's min/max in one go (a style: a primitive per crop, thousands)
            low = np.minimum.reduceat(pos_data, starts, axis=0).tolist()
            high = np.maximum.reduceat(pos_data, starts, axis=0).tolist()
            for k, (lo, first, end) in enumerate(
                zip(los.tolist(), starts.tolist(), ends.tolist(), strict=True)
            ):
                row = p.baked[lo]
                attributes = {
                    "POSITION": b.accessor(
                        pos_at + first * 12, pos_data[first:end], limits=(low[k], high[k])
                    ),
                    "NORMAL": b.accessor(nrm_at + first * 12, nrm_data[first:end]),
                }
                attributes.update(uvs.attributes(int(row), end - first, b.accessor))
                prims[int(groups.of_row[row])].append(
                    {"attributes": attributes, "material": int(mats.index[row]), "mode": 4}
                )

        nodes: list[dict] = []  # this part's; node k is number node_base + k of the file
        node_base = 1 + sp["nodes"].count  # node 0 is the root
        meshes: list[dict] = []
        mesh_base = sp["meshes"].count

        def new_node(node: dict, parent: dict) -> dict:
            nodes.append(node)
            parent.setdefault("children", []).append(node_base + len(nodes) - 1)
            return node

        lot_node: dict[int, dict] = {}

        def node_of(group: int) -> dict:
            if self.group_by == "none":
                return self.root
            if group not in group_node:
                parent = self.root
                lot = groups.lot[group]
                if lot >= 0:
                    if lot not in lot_node:
                        lot_node[lot] = new_node(lot_extras(table, lot), self.root)
                    parent = lot_node[lot]
                group_node[group] = new_node({"name": groups.name[group]}, parent)
            return group_node[group]

        group_node: dict[int, dict] = {}
        for group, primitives in enumerate(prims):
            if primitives:
                meshes.append({"name": groups.name[group], "primitives": primitives})
                node_of(group)["mesh"] = mesh_base + len(meshes) - 1

        # instanced groups (opt-in): the unit mesh once, a child node with per-instance TRS
        names = [m.name for m in table.library.meshes]
        labels = self.materials.all().labels if p.groups else []
        for mesh_id, mat, rows in p.groups:
            unit = pool.vertices[pool.voff[mesh_id] : pool.voff[mesh_id] + pool.vcount[mesh_id]]
            faces = pool.faces[pool.foff[mesh_id] : pool.foff[mesh_id] + pool.fcount[mesh_id]]
            corners = unit[faces]
            normals = unit_normals(corners, fallback=(0.0, 0.0, 1.0))
            pos = b.vec(corners.reshape(-1, 3), bounded=True)
            nrm = b.vec(np.repeat(normals, 3, axis=0))
            trs = {
                "TRANSLATION": b.vec(table.origin[rows] - self.shift, None),
                "ROTATION": b.vec(quaternions(table.axes[rows]), None),
                "SCALE": b.vec(p.scale[rows], None),
            }
            name = f"{names[mesh_id]} {labels[mat]}"
            meshes.append(
                {
                    "name": name,
                    "primitives": [
                        {"attributes": {"POSITION": pos, "NORMAL": nrm}, "material": mat, "mode": 4}
                    ],
                }
            )
            new_node(
                {
                    "name": name,
                    "mesh": mesh_base + len(meshes) - 1,
                    "extensions": {INSTANCING: {"attributes": trs}},
                },
                node_of(int(groups.of_row[rows[0]])),
            )
        assert b.offset == nbytes
        self.instanced |= bool(p.groups)
        self.used.update(prim["material"] for mesh in meshes for prim in mesh["primitives"])
        sp["nodes"].items(nodes)
        sp["meshes"].items(meshes)
        sp["accessors"].items(b.accessors)
        sp["views"].items(b.views)
        sp["bin"].raw(b.bin.data)

    def _pieces(self) -> list[bytes | _Spool]:
        """The JSON document as text pieces and spools, in order."""
        sp = self.spools
        head: dict = {
            "asset": {
                "version": "2.0",
                "generator": f"bgr {_version()}",
                "extras": {"bgr": 1, "seed": self.seed, "attrs": self.attrs},
            }
        }
        if self.instanced:  # a reader without the extension must refuse the file
            head["extensionsUsed"] = [INSTANCING]
            head["extensionsRequired"] = [INSTANCING]
        if self.used and (optional := self.materials.extensions()):  # a reader may ignore it
            head["extensionsUsed"] = head.get("extensionsUsed", []) + optional
        head["scene"] = 0
        head["scenes"] = [{"name": "bgr", "nodes": [0]}]
        root = dict(self.root)
        if not root["children"]:
            del root["children"]
        pieces: list[bytes | _Spool] = [_json_bytes(head)[:-1] + b',"nodes":[' + _json_bytes(root)]
        if sp["nodes"].count:
            pieces += [b",", sp["nodes"]]
        pieces.append(b"]")
        if sp["meshes"].count:
            pieces += [b',"meshes":[', sp["meshes"], b"]"]
        if self.used:
            materials = self.materials.members(self.images, self.image_alpha)
            pieces.append(b',"materials":' + _json_bytes(materials))
        if self.image_views:  # a texture per image, all with one repeating sampler
            for key, value in image_members(self.image_views):
                pieces.append(f',"{key}":'.encode() + _json_bytes(value))
        if sp["accessors"].count:
            pieces += [b',"accessors":[', sp["accessors"], b'],"bufferViews":[', sp["views"]]
            pieces.append(b'],"buffers":' + _json_bytes([{"byteLength": sp["bin"].nbytes}]))
        pieces.append(b"}")
        return pieces

    def write_glb(self, stream: BinaryIO) -> None:
        """The binary glTF: header, JSON chunk (space-padded), BIN chunk."""
        pieces = self._pieces()
        length = sum(p.nbytes if isinstance(p, _Spool) else len(p) for p in pieces)
        pad = -length % 4
        nbin = self.spools["bin"].nbytes  # a multiple of 4: every block is float32
        total = 12 + 8 + length + pad + (8 + nbin if nbin else 0)
        stream.write(struct.pack("<4sII", b"glTF", 2, total))
        stream.write(struct.pack("<II", length + pad, 0x4E4F534A))
        for piece in pieces:
            piece.copy_to(stream) if isinstance(piece, _Spool) else stream.write(piece)
        stream.write(b" " * pad)
        if nbin:
            stream.write(struct.pack("<II", nbin, 0x004E4942))
            self.spools["bin"].copy_to(stream)

    def document(self) -> tuple[dict, bytes]:
        """The glTF JSON as Python data and the binary buffer (for .gltf, and tests)."""
        text = io.BytesIO()
        for piece in self._pieces():
            piece.copy_to(text) if isinstance(piece, _Spool) else text.write(piece)
        data = io.BytesIO()
        self.spools["bin"].copy_to(data)
        return json.loads(text.getvalue()), data.getvalue()


def scene_of(
    table: TerminalTable,
    *,
    seed: int,
    attrs: dict,
    instancing: str | bool = False,
    group_by: str = "lot",
    folder: str | None = None,
) -> Scene:
    """A table's :class:`Scene`, lot by lot when it groups by lot."""
    table.freeze()
    scene = Scene(
        seed=seed,
        attrs=attrs,
        grammar=getattr(table, "grammar", "") or "",
        site=table.site,
        instancing=instancing,
        group_by=group_by,
        shift=recentre(table),
        folder=folder,
    )
    try:
        for part in lot_tables(table) if group_by == "lot" else [table]:
            scene.add(part)
    except BaseException:
        scene.close()
        raise
    return scene


def build(
    table: TerminalTable,
    *,
    seed: int,
    attrs: dict,
    instancing: str | bool = False,
    group_by: str = "lot",
) -> tuple[dict, bytes]:
    """The glTF JSON document and its binary buffer for a table.

    The scene is one root node ``bgr`` (extras: grammar, seed, attrs, bgr version, and the CRS
    and origin of geographic lots); under it, with ``group_by="lot"``, a node per lot named by
    its feature id or ``lot-N`` (extras: its attrs and feature properties) holding a node per
    terminal label; with ``"label"`` the label nodes sit under the root; with ``"none"`` the
    root holds every terminal.  A node's mesh has one primitive per material; materials are
    shared by the whole file.  ``instancing``: see :func:`plan` (off by default: every reader
    then sees every triangle).
    """
    with scene_of(table, seed=seed, attrs=attrs, instancing=instancing, group_by=group_by) as scene:
        return scene.document()


def root_extras(table: TerminalTable, seed: int, attrs: dict) -> dict:
    """What the root node says of the run: grammar, seed, attrs, version; where it lies."""
    extras: dict = {"bgr": _version(), "seed": seed, "attrs": attrs}
    grammar = getattr(table, "grammar", None)
    if grammar:
        extras["grammar"] = grammar
    if table.site:
        extras["crs"] = table.site.get("crs")
        extras["origin"] = table.site.get("origin")
        extras["axes"] = (
            "x east, y up, z south; the root's translation holds the origin: a point the "
            "root's transform gives as (x, y, z) is (x, -z, y) in the CRS"
        )
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


def _json_bytes(gltf, **layout) -> bytes:
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
    with scene_of(table, seed=seed, attrs=attrs, instancing=instancing, group_by=group_by) as scene:
        scene.write_glb(stream)


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
    if bin_:
        gltf["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(
            bin_
        ).decode("ascii")
    stream.write(_json_bytes(gltf, indent=1) + b"\n")
