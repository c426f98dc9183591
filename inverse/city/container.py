"""The one assets file of an inferred city: a GLB with a node per mesh, as small as glTF allows.

A city's level 0 has hundreds of meshes of a few dozen triangles each, so what glTF spends per
mesh matters as much as the triangles: trimesh's exporter gives every mesh its own two buffer
views, 32-bit indices and names twice (Zurich's LoD2 tile: 108 KB of JSON for 177 KB of data).
Here every mesh's indices share one buffer view and its positions another, each accessor at its
offset in them; indices are 16-bit where the mesh has under 65,536 vertices; only the node is
named (``meshes.glb#type1`` names the node, interpreter/operations/inserts.py).  Positions stay
float32 and every reader of plain glTF 2.0 reads the file (no extension is used).
"""

from __future__ import annotations

import json
import struct

import numpy as np

GLB_MAGIC, GLB_VERSION = 0x46546C67, 2
JSON_CHUNK, BIN_CHUNK = 0x4E4F534A, 0x004E4942
UNSIGNED_SHORT, UNSIGNED_INT, FLOAT = 5123, 5125, 5126
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963


def pack(named: list[tuple[str, np.ndarray, np.ndarray]], generator: str = "bgr") -> bytes:
    """A GLB holding each (node name, vertices (V, 3), triangles (F, 3)) as a node and a mesh;
    a mesh with no triangles is left out."""
    indices, positions = bytearray(), bytearray()
    accessors: list[dict] = []
    meshes: list[dict] = []
    nodes: list[dict] = []
    for name, vertices, faces in named:
        if len(faces) == 0:
            continue
        small = len(vertices) < 1 << 16
        tri = np.ascontiguousarray(faces, dtype="<u2" if small else "<u4").reshape(-1)
        _align(indices, 4)
        points = np.ascontiguousarray(vertices, dtype="<f4").reshape(-1, 3)
        low, high = points.min(axis=0), points.max(axis=0)
        accessors.append(
            _at(
                {"bufferView": 0, "componentType": UNSIGNED_SHORT if small else UNSIGNED_INT},
                len(indices),
            )
            | {"count": int(tri.size), "type": "SCALAR"}
        )
        accessors.append(
            _at({"bufferView": 1, "componentType": FLOAT}, len(positions))
            | {
                "count": len(points),
                "type": "VEC3",
                "min": [_shortest(v) for v in low],
                "max": [_shortest(v) for v in high],
            }
        )
        indices += tri.tobytes()
        positions += points.tobytes()
        meshes.append(
            {
                "primitives": [
                    {"attributes": {"POSITION": len(accessors) - 1}, "indices": len(accessors) - 2}
                ]
            }
        )
        nodes.append({"name": name, "mesh": len(meshes) - 1})
    _align(indices, 4)
    gltf: dict = {"asset": {"version": "2.0", "generator": generator}}
    if nodes:
        gltf |= {
            "scene": 0,
            "scenes": [{"nodes": list(range(len(nodes)))}],
            "nodes": nodes,
            "meshes": meshes,
            "accessors": accessors,
            "bufferViews": [
                {"buffer": 0, "byteLength": len(indices), "target": ELEMENT_ARRAY_BUFFER},
                {
                    "buffer": 0,
                    "byteOffset": len(indices),
                    "byteLength": len(positions),
                    "byteStride": 12,  # the accessors share the view: glTF wants it said
                    "target": ARRAY_BUFFER,
                },
            ],
            "buffers": [{"byteLength": len(indices) + len(positions)}],
        }
    text = json.dumps(gltf, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    body = bytes(indices + positions) if nodes else b""
    chunks = struct.pack("<II", len(text), JSON_CHUNK) + text
    if body:
        chunks += struct.pack("<II", len(body), BIN_CHUNK) + body
    return struct.pack("<III", GLB_MAGIC, GLB_VERSION, 12 + len(chunks)) + chunks


def _at(accessor: dict, offset: int) -> dict:
    """The accessor with its byte offset, left out where it is the default 0."""
    return accessor | {"byteOffset": offset} if offset else accessor


def _align(data: bytearray, to: int) -> None:
    data += b"\0" * (-len(data) % to)


def _shortest(value: np.float32) -> float | int:
    """The float32 as the shortest decimal that reads back to it (accessor bounds must be the
    data's own values: 2.015, not 2.015000104904175; 0, not 0.0)."""
    number = float(str(np.float32(value)))
    return int(number) if number.is_integer() and abs(number) < 1 << 24 else number
