"""Read a .glb/.gltf back into one trimesh, expanding EXT_mesh_gpu_instancing.

trimesh 5.2 loads glTF but ignores the instancing extension (each instanced group appears once,
at the node's own transform).  ``read_glb`` handles the subset of glTF that bgr writes — triangle
primitives, node hierarchies with TRS or matrices, instancing, ``baseColorFactor`` colours — and
returns world-space triangles with per-face sRGB colours: what tests and previews need.
"""

from __future__ import annotations

import base64
import json
import struct
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # imported where used: it costs a second of every command's start
    import trimesh

from bgr.grammar.errors import BgrError
from bgr.grammar.paths import read_input

_DTYPES = {5120: "i1", 5121: "u1", 5122: "<i2", 5123: "<u2", 5125: "<u4", 5126: "<f4"}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def parse(data: bytes) -> tuple[dict, bytes]:
    """(glTF JSON, binary buffer 0) of a .glb or .gltf file's bytes."""
    if data[:4] == b"glTF":
        _, version, length = struct.unpack_from("<4sII", data)
        if version != 2 or length != len(data):
            raise BgrError(
                f"not a glTF 2.0 binary (version {version}, length {length} of {len(data)})"
            )
        json_len, _ = struct.unpack_from("<II", data, 12)
        gltf = json.loads(data[20 : 20 + json_len])
        at = 20 + json_len
        blob = b""
        if at + 8 <= len(data):
            bin_len, kind = struct.unpack_from("<II", data, at)
            if kind == 0x004E4942:
                blob = data[at + 8 : at + 8 + bin_len]
        return gltf, blob
    gltf = json.loads(data)
    uri = gltf.get("buffers", [{}])[0].get("uri", "") if gltf.get("buffers") else ""
    blob = base64.b64decode(uri.split(",", 1)[1]) if uri.startswith("data:") else b""
    return gltf, blob


def accessor(gltf: dict, blob: bytes, index: int) -> np.ndarray:
    acc = gltf["accessors"][index]
    width = _WIDTH[acc["type"]]
    dtype = np.dtype(_DTYPES[acc["componentType"]])
    view = gltf["bufferViews"][acc["bufferView"]]
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    stride = view.get("byteStride", width * dtype.itemsize)
    count, elem = acc["count"], width * dtype.itemsize
    if count == 0:
        return np.zeros((0, width))
    raw = np.frombuffer(blob, dtype=np.uint8, count=(count - 1) * stride + elem, offset=start)
    if stride != elem:  # interleaved: gather each element's bytes
        raw = np.lib.stride_tricks.as_strided(raw, shape=(count, elem), strides=(stride, 1)).copy()
    out = raw.view(dtype).reshape(count, width)
    return out.astype(np.float64 if dtype.kind == "f" else np.int64)


def quat_matrix(q: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotation matrices of (n, 4) quaternions (x, y, z, w)."""
    x, y, z, w = (q / np.linalg.norm(q, axis=1, keepdims=True)).T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=1),
        ],
        axis=1,
    )


def _trs(t, r, s) -> np.ndarray:
    """(n, 4, 4) matrices T @ R @ S."""
    m = np.zeros((len(t), 4, 4))
    m[:, :3, :3] = quat_matrix(r) * s[:, None, :]
    m[:, :3, 3] = t
    m[:, 3, 3] = 1.0
    return m


def node_matrix(node: dict) -> np.ndarray:
    """A node's local 4x4 matrix, from ``matrix`` or from its translation, rotation and scale."""
    if "matrix" in node:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T  # column-major
    return _trs(
        np.array([node.get("translation", [0, 0, 0])], dtype=np.float64),
        np.array([node.get("rotation", [0, 0, 0, 1])], dtype=np.float64),
        np.array([node.get("scale", [1, 1, 1])], dtype=np.float64),
    )[0]


def _to_srgb(linear) -> np.ndarray:
    c = np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)
    return np.where(c <= 0.0031308, c * 12.92, 1.055 * c ** (1 / 2.4) - 0.055)


def scene_roots(gltf: dict) -> list[int]:
    """The root nodes of the default scene (without scenes: every node that is nobody's child)."""
    if gltf.get("scenes"):
        return list(gltf["scenes"][gltf.get("scene", 0)].get("nodes", []))
    children = {c for node in gltf.get("nodes", []) for c in node.get("children", [])}
    return [i for i in range(len(gltf.get("nodes", []))) if i not in children]


def read_glb(path: Path | str) -> trimesh.Trimesh:
    """World-space triangles of every node of the default scene, with per-face colours."""
    gltf, blob = parse(read_input(path, "model file"))
    return world_mesh(gltf, blob, scene_roots(gltf))


def world_mesh(
    gltf: dict, blob: bytes, roots: list[int], parent: np.ndarray | None = None
) -> trimesh.Trimesh:
    """World-space triangles of the nodes ``roots`` and everything under them, placed by
    ``parent`` (the 4x4 world matrix of their parent; identity for a scene's roots), with
    per-face sRGB colours.  Callers that want one mesh per subtree (one per building) call it
    once per subtree."""
    import trimesh

    nodes, meshes, materials = (
        gltf.get("nodes", []),
        gltf.get("meshes", []),
        gltf.get("materials", []),
    )
    verts, faces, colours = [], [], []
    count = 0

    def visit(index: int, above: np.ndarray) -> None:
        nonlocal count
        node = nodes[index]
        world = above @ node_matrix(node)
        if "mesh" in node:
            inst = node.get("extensions", {}).get("EXT_mesh_gpu_instancing")
            if inst:
                a = inst["attributes"]
                n = gltf["accessors"][next(iter(a.values()))]["count"]
                t = (
                    accessor(gltf, blob, a["TRANSLATION"])
                    if "TRANSLATION" in a
                    else np.zeros((n, 3))
                )
                r = (
                    accessor(gltf, blob, a["ROTATION"])
                    if "ROTATION" in a
                    else np.tile([0.0, 0, 0, 1], (n, 1))
                )
                s = accessor(gltf, blob, a["SCALE"]) if "SCALE" in a else np.ones((n, 3))
                placements = world @ _trs(t, r, s)
            else:
                placements = world[None]
            for prim in meshes[node["mesh"]]["primitives"]:
                if prim.get("mode", 4) != 4:
                    continue
                pos = accessor(gltf, blob, prim["attributes"]["POSITION"])
                tri = (
                    accessor(gltf, blob, prim["indices"]).reshape(-1, 3)
                    if "indices" in prim
                    else np.arange(len(pos)).reshape(-1, 3)
                )
                placed = pos @ placements[:, :3, :3].transpose(0, 2, 1) + placements[:, None, :3, 3]
                flip = np.linalg.det(placements[:, :3, :3]) < 0
                tris = np.broadcast_to(tri, (len(placements),) + tri.shape).copy()
                tris[flip] = tris[flip][:, :, ::-1]
                tris += (count + np.arange(len(placements)) * len(pos))[:, None, None]
                verts.append(placed.reshape(-1, 3))
                faces.append(tris.reshape(-1, 3))
                count += len(placements) * len(pos)
                factor = [1.0, 1.0, 1.0, 1.0]
                if "material" in prim:
                    factor = (
                        materials[prim["material"]]
                        .get("pbrMetallicRoughness", {})
                        .get("baseColorFactor", factor)
                    )
                rgba = np.append(np.rint(_to_srgb(factor[:3]) * 255), np.rint(factor[3] * 255))
                colours.append(np.tile(rgba.astype(np.uint8), (len(tris) * len(tri), 1)))
        for child in node.get("children", []):
            visit(child, world)

    for root in roots:
        visit(root, np.eye(4) if parent is None else parent)
    if not faces:
        return trimesh.Trimesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), process=False)
    return trimesh.Trimesh(
        np.concatenate(verts),
        np.concatenate(faces),
        face_colors=np.concatenate(colours),
        process=False,
    )
