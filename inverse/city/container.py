"""The one assets file of an inferred city: a GLB with a node per mesh, as small as glTF allows.

A city's level 0 has hundreds of meshes of a few dozen triangles each, so what glTF spends per
mesh matters as much as the triangles: trimesh's exporter gives every mesh its own two buffer
views, 32-bit indices and names twice (Zurich's LoD2 tile: 108 KB of JSON for 177 KB of data).
Here all meshes share a few buffer views (indices of meshes under 65,536 vertices in one, 16-bit;
the others' in another; positions likewise), each accessor at its offset in them, and only the
node is named (``meshes.glb#type1`` names the node, interpreter/operations/inserts.py).

By default (``compress=True``) the file is what gltfpack makes of a model, in two standard
extensions: **KHR_mesh_quantization**, each mesh's positions as 16-bit integers on a grid of
``step`` metres (the grammar's own grid, doubled where a mesh is too large for 65,536 steps, never
coarser than ``coarsest``), the node scaling them back to metres; and
**EXT_meshopt_compression**, the buffer views encoded by meshoptimizer's codecs (its ``meshopt``
binding, MIT), triangles reordered for them.  The Zurich tile's assets: 111 KB plain, about 60 KB
so.  A mesh too large for the grid keeps float positions (still compressed).  three.js, Babylon.js
and gltfpack read such files; trimesh and older readers do not, hence ``compress=False``: plain
glTF 2.0, no extension (``bgr infer --plain-assets``).
"""

from __future__ import annotations

import json
import struct
from dataclasses import dataclass, field

import numpy as np

GLB_MAGIC, GLB_VERSION = 0x46546C67, 2
JSON_CHUNK, BIN_CHUNK = 0x4E4F534A, 0x004E4942
UNSIGNED_SHORT, UNSIGNED_INT, FLOAT = 5123, 5125, 5126
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
MESHOPT, QUANTIZED = "EXT_meshopt_compression", "KHR_mesh_quantization"
STEPS = 65_535  # the largest 16-bit grid coordinate


@dataclass
class Mesh:
    """One node of the file: its name, vertices (V, 3), triangles (F, 3), the node's ``extras``
    (JSON), and whether the triangles must stay in their order (``extras`` may point into it)."""

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    extras: dict | None = None
    keep_order: bool = False


@dataclass
class _View:
    """One buffer view being filled: its rows' bytes, its stride and what it holds."""

    dtype: str  # numpy dtype of a component
    width: int  # components a row (1: indices, 3 or 4: positions, padded)
    target: int
    data: bytearray = field(default_factory=bytearray)
    rows: int = 0
    filtered: bool = False  # rows already through meshopt's exponential filter

    def add(self, rows: np.ndarray) -> int:
        """Append rows (n, width) and return the byte offset they start at.  (An accessor's
        offset must be a multiple of its component size, which rows of whole components are.)"""
        at = len(self.data)
        self.data += np.ascontiguousarray(rows, dtype=self.dtype).tobytes()
        self.rows += len(rows)
        return at

    @property
    def stride(self) -> int:
        return self.width * np.dtype(self.dtype).itemsize


def pack(
    named: list[Mesh] | list[tuple[str, np.ndarray, np.ndarray]],
    generator: str = "bgr",
    *,
    compress: bool = False,
    step: float = 0.001,
    coarsest: float = 0.0025,
) -> bytes:
    """A GLB holding each :class:`Mesh` (or (node name, vertices, triangles)) as a node and a
    mesh; a mesh with no triangles is left out.  ``compress``: quantized and meshopt-encoded (see
    the module docstring), positions on a grid of ``step`` x 2^k metres, k the least that fits
    the mesh in 16 bits, as long as that is at most ``coarsest``; a larger mesh's float positions
    are rounded to ``step`` / 2 by meshopt's exponential filter, which compresses them."""
    views = {
        "small": _View("<u2", 1, ELEMENT_ARRAY_BUFFER),
        "large": _View("<u4", 1, ELEMENT_ARRAY_BUFFER),
        "grid": _View("<u2", 4, ARRAY_BUFFER),  # 4-byte aligned rows: x, y, z, padding
        # compressed: the exponential filter's int32 codes of the floats (see _exponential)
        "float": _View("<i4" if compress else "<f4", 3, ARRAY_BUFFER, filtered=compress),
    }
    accessors: list[dict] = []
    meshes: list[dict] = []
    nodes: list[dict] = []
    for item in named:
        mesh = item if isinstance(item, Mesh) else Mesh(*item)
        if len(mesh.faces) == 0:
            continue
        points = np.asarray(mesh.vertices, dtype=np.float64).reshape(-1, 3)
        tri = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
        if compress and not mesh.keep_order:
            points, tri = reordered(points, tri)
        index_view = "small" if len(points) < 1 << 16 else "large"
        node: dict = {"name": mesh.name, "mesh": len(meshes)}
        node |= {"extras": mesh.extras} if mesh.extras else {}
        grid = _grid_step(points, step, coarsest) if compress else None
        if grid is None:
            rows = points.astype("<f4")
            values = rows
            if compress:  # the filter's codes are stored; the accessor's bounds are their values
                rows = _exponential(rows, _exponent_bits(float(np.abs(rows).max()), step))
                values = _exponential_values(rows)
            position_view = "float"
        else:
            low = np.round(points.min(axis=0) / step) * step
            cells = np.rint((points - low) / grid).astype(np.int64)
            rows = np.column_stack([cells, np.zeros(len(cells), dtype=np.int64)])
            position_view = "grid"
            values = cells
            node |= {"scale": [grid] * 3}
            if np.any(low != 0):
                node |= {"translation": [float(v) for v in low]}
        kinds = list(views)
        accessors.append(
            _at({"bufferView": kinds.index(index_view)}, views[index_view].add(tri.reshape(-1, 1)))
            | {
                "componentType": UNSIGNED_SHORT if index_view == "small" else UNSIGNED_INT,
                "count": int(tri.size),
                "type": "SCALAR",
            }
        )
        accessors.append(
            _at({"bufferView": kinds.index(position_view)}, views[position_view].add(rows))
            | {
                "componentType": UNSIGNED_SHORT if position_view == "grid" else FLOAT,
                "count": len(rows),
                "type": "VEC3",
                "min": [_shortest(v) for v in values.min(axis=0)],
                "max": [_shortest(v) for v in values.max(axis=0)],
            }
        )
        meshes.append(
            {
                "primitives": [
                    {"attributes": {"POSITION": len(accessors) - 1}, "indices": len(accessors) - 2}
                ]
            }
        )
        nodes.append(node)
    gltf: dict = {"asset": {"version": "2.0", "generator": generator}}
    body = b""
    if nodes:
        used = {k: v for k, v in views.items() if v.rows}
        renumber = {list(views).index(k): i for i, k in enumerate(used)}
        for acc in accessors:
            acc["bufferView"] = renumber[acc["bufferView"]]
        view_list, buffers, body = _views(list(used.values()), compress)
        gltf |= {
            "scene": 0,
            "scenes": [{"nodes": list(range(len(nodes)))}],
            "nodes": nodes,
            "meshes": meshes,
            "accessors": accessors,
            "bufferViews": view_list,
            "buffers": buffers,
        }
        if compress:
            extensions = [MESHOPT] + ([QUANTIZED] if "grid" in used else [])
            gltf |= {"extensionsUsed": extensions, "extensionsRequired": extensions}
    text = json.dumps(gltf, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<II", len(text), JSON_CHUNK) + text
    if body:
        chunks += struct.pack("<II", len(body), BIN_CHUNK) + body
    return struct.pack("<III", GLB_MAGIC, GLB_VERSION, 12 + len(chunks)) + chunks


def _views(used: list[_View], compress: bool) -> tuple[list[dict], list[dict], bytes]:
    """(bufferViews, buffers, the BIN chunk) for the filled views: plain, one after another in
    buffer 0; or compressed, their codes in buffer 0 and the views themselves in buffer 1, a
    fallback buffer with no data (EXT_meshopt_compression)."""
    body, plain, out = bytearray(), 0, []
    for view in used:
        plain += -plain % 4  # each view starts on a 4-byte boundary
        entry: dict = {"buffer": 1 if compress else 0, "byteLength": len(view.data)}
        entry |= {"byteOffset": plain} if plain else {}
        if view.target == ARRAY_BUFFER:
            entry["byteStride"] = view.stride  # the accessors share the view: glTF wants it said
        entry["target"] = view.target
        if compress:
            code = _encoded(view)
            at = len(body)
            body += code + b"\0" * (-len(code) % 4)
            entry["extensions"] = {
                MESHOPT: {
                    "buffer": 0,
                    "byteLength": len(code),
                    "byteStride": view.stride,
                    "count": view.rows,  # the view's byteLength is count x byteStride
                    "mode": "ATTRIBUTES" if view.target == ARRAY_BUFFER else "TRIANGLES",
                }
                | ({"byteOffset": at} if at else {})
                | ({"filter": "EXPONENTIAL"} if view.filtered else {})
            }
        else:
            body += b"\0" * (plain - len(body)) + view.data
        plain += len(view.data)
        out.append(entry)
    if not compress:
        body += b"\0" * (-len(body) % 4)
        return out, [{"byteLength": len(body)}], bytes(body)
    fallback = {"byteLength": plain, "extensions": {MESHOPT: {"fallback": True}}}
    return out, [{"byteLength": len(body)}, fallback], bytes(body)


def _encoded(view: _View) -> bytes:
    """A view's bytes as meshoptimizer encodes them: vertex rows by its attribute codec, a
    triangle list (every mesh's, one after another) by its index codec."""
    import meshopt

    data = np.frombuffer(bytes(view.data), dtype=view.dtype)
    if view.target == ARRAY_BUFFER:
        return meshopt.encode_gltf_buffer(data.reshape(view.rows, -1), "ATTRIBUTES")
    return meshopt.encode_gltf_buffer(data, "TRIANGLES")


def _exponential(rows: np.ndarray, bits: int) -> np.ndarray:
    """Float rows (n, 3) as meshoptimizer's exponential filter stores them (one int32 each: an
    8-bit exponent over a 24-bit mantissa of ``bits`` significant bits), one exponent per
    component for the mesh: fixed point, whose deltas its attribute codec compresses."""
    import meshopt

    codes = meshopt.encode_filter_exp(np.ascontiguousarray(rows, "<f4"), bits, "SharedComponent")
    return np.ascontiguousarray(codes).view("<i4").reshape(len(rows), 3)


def _exponential_values(codes: np.ndarray) -> np.ndarray:
    """The floats a reader decodes from exponential-filter codes: mantissa x 2^exponent."""
    codes = codes.astype(np.int64)
    exponent = codes >> 24  # arithmetic shift: the signed top byte
    mantissa = ((codes & 0xFFFFFF) ^ 0x800000) - 0x800000  # the signed low 24 bits
    return np.ldexp(mantissa.astype(np.float64), exponent).astype("<f4")


def _exponent_bits(largest: float, step: float) -> int:
    """Mantissa bits of the exponential filter that keep coordinates up to ``largest`` within
    ``step`` / 2 of themselves (one exponent per component: a grid of largest / 2^(bits - 1)),
    24 at most: float32's own."""
    bits = 2
    while bits < 24 and largest / 2.0 ** (bits - 1) > step:
        bits += 1
    return bits


def reordered(points: np.ndarray, tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The triangles in the order meshoptimizer's codecs compress best (its vertex cache order)
    and the vertices in the order they are first used: the same mesh, renumbered."""
    import meshopt

    indices, remap, unique = meshopt.reorder_mesh(
        tri.reshape(-1).astype(np.uint32), triangles=True, optsize=False
    )
    order = np.argsort(remap)[:unique]
    return points[order], indices.astype(np.int64).reshape(-1, 3)


def _grid_step(points: np.ndarray, step: float, coarsest: float) -> float | None:
    """The grid, ``step`` x 2^k metres, k the least that holds the mesh's extent in 16 bits;
    None when that would be coarser than ``coarsest`` (the mesh keeps float positions)."""
    extent = float((points.max(axis=0) - points.min(axis=0)).max()) if len(points) else 0.0
    grid = step
    while extent / grid > STEPS - 1:  # one step of room for the corner rounded to the grid
        grid *= 2
    return grid if grid <= coarsest else None


def _at(accessor: dict, offset: int) -> dict:
    """The accessor with its byte offset, left out where it is the default 0."""
    return accessor | {"byteOffset": offset} if offset else accessor


def _shortest(value) -> float | int:
    """The value as the shortest decimal that reads back to it as its own type (accessor bounds
    must be the data's own values: 2.015, not 2.015000104904175; 0, not 0.0)."""
    if np.issubdtype(np.asarray(value).dtype, np.integer):
        return int(value)
    number = float(str(np.float32(value)))
    return int(number) if number.is_integer() and abs(number) < 1 << 24 else number
