"""Read a .glb/.gltf back into one trimesh, expanding EXT_mesh_gpu_instancing.

trimesh 5.2 loads glTF but ignores the instancing extension (each instanced group appears once,
at the node's own transform).  ``read_glb`` handles the subset of glTF that bgr writes — triangle
primitives, node hierarchies with TRS or matrices, instancing, ``baseColorFactor`` colours — and
returns world-space triangles with per-face sRGB colours: what tests and previews need.

The files come from anywhere, so nothing in them is believed: every accessor, bufferView, index
and node is checked (:mod:`.gltf_checks`) before a byte is read or a node placed, and a file that
breaks a rule is a located :class:`BgrError`.  The buffers are read by :mod:`.gltf_file` (from
the GLB's BIN chunk, base64 ``data:`` URIs or files in the model's own folder), views compressed
by EXT_meshopt_compression decoded first (:mod:`.gltf_meshopt`); integer positions are read
where the file uses KHR_mesh_quantization; sparse accessors and Draco are refused.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # imported where used: it costs a second of every command's start
    import trimesh

from bgr.interpreter.limits import DEFAULT_MAX_TRIANGLES

from .gltf_checks import (
    FLOAT,
    UNSIGNED,
    buffer_size,
    check_finite,
    check_kind,
    check_roots,
    entry,
    fail,
    layout,
    node_paths,
    numbers,
    values,
    whole,
)
from .gltf_file import load, parse

__all__ = [
    "accessor",
    "check_scene",
    "instance_count",
    "load",
    "mesh_nodes",
    "named_meshes",
    "node_matrix",
    "parse",
    "quat_matrix",
    "read_glb",
    "scene_roots",
    "triangle_primitives",
    "world_mesh",
]

INSTANCING = "EXT_mesh_gpu_instancing"
INSTANCE_TYPES = {"TRANSLATION": "VEC3", "ROTATION": "VEC4", "SCALE": "VEC3"}


def accessor(
    gltf: dict,
    blob: bytes,
    index: int,
    use: str = "",
    components: tuple[int, ...] = (),
    types: tuple[str, ...] = (),
) -> np.ndarray:
    """Accessor ``index`` as (count, width) float64 (float data, checked finite) or int64, after
    :func:`~.gltf_checks.layout` has put every element inside its bufferView and buffer 0.
    ``use`` names what the accessor is for ("POSITION of mesh 0 primitive 0"); with
    ``components`` and ``types`` it must be one of those."""
    at = layout(gltf, buffer_size(gltf, blob), index, use)
    if components:
        check_kind(gltf, index, use, components, types)
    out = values(blob, at)
    if at.dtype.kind == "f":
        check_finite(out, index)
        return out.astype(np.float64)
    return out.astype(np.int64)


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


def _unit_scaled(r: np.ndarray, where: str) -> np.ndarray:
    """Quaternions (n, 4) divided by their largest component, so that tiny ones do not vanish
    when squared; the zero quaternion (no rotation at all) is an error."""
    big = np.abs(r).max(axis=1)
    if (big == 0).any():
        fail(where, f"rotation {int(np.argmin(big))} is the zero quaternion")
    return r / big[:, None]


def node_matrix(node: dict, index: int | None = None) -> np.ndarray:
    """A node's local 4x4 matrix, from ``matrix`` or from its translation, rotation and scale,
    each checked to be finite numbers (``index`` names the node in the error)."""
    where = "node" if index is None else f"node {index}"
    if "matrix" in node:
        return numbers(node["matrix"], 16, where, "matrix").reshape(4, 4).T  # column-major
    t, r, s = _trs_of(node, where)
    return _trs(t[None], r[None], s[None])[0]


def _to_srgb(linear) -> np.ndarray:
    c = np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)
    return np.where(c <= 0.0031308, c * 12.92, 1.055 * c ** (1 / 2.4) - 0.055)


def scene_roots(gltf: dict) -> list[int]:
    """The root nodes of the default scene (without scenes: every node that is nobody's child),
    the node tree under them checked: no missing child, none listed twice, no cycle, at most
    MAX_NODE_VISITS placements."""
    return check_roots(gltf)


def read_glb(path: Path | str) -> trimesh.Trimesh:
    """World-space triangles of every node of the default scene, with per-face colours."""
    gltf, blob = load(path)
    return world_mesh(gltf, blob, scene_roots(gltf))


def check_scene(gltf: dict, blob: bytes, roots: list[int]) -> None:
    """Refuse a scene that would make more than DEFAULT_MAX_TRIANGLES triangles, before any is
    made: the count comes from the accessors' counts, the instances and the node tree's paths,
    so a file that instances a mesh a million times is refused without a vertex placed.
    :func:`world_mesh` checks its own roots; a caller that reads a scene a subtree at a time
    (bgr infer: a subtree per building) checks the whole scene first, with ``checked=True``."""
    _check_triangles(gltf, blob, node_paths(gltf, roots))


def _check_triangles(gltf: dict, blob: bytes, paths: dict[int, int]) -> None:
    """Refuse placing each node ``paths[node]`` times if that makes too many triangles."""
    triangles, vertices = _planned(gltf, blob, paths)
    if triangles > DEFAULT_MAX_TRIANGLES or vertices > 3 * DEFAULT_MAX_TRIANGLES:
        fail(
            "the scene",
            f"it makes {max(triangles, vertices // 3):,} triangles or more, past the "
            f"{DEFAULT_MAX_TRIANGLES:,} bgr reads from one model",
            "instancing or nodes shared by several parents repeat a mesh many times",
        )


def _planned(gltf: dict, blob: bytes, paths: dict[int, int]) -> tuple[int, int]:
    """(triangles, vertices) a walk placing each node ``paths[node]`` times will make."""
    nodes = gltf["nodes"]
    per_mesh: dict[int, tuple[int, int]] = {}
    triangles = vertices = 0
    for i, times in paths.items():
        node = nodes[i]
        if "mesh" not in node:
            continue
        m = node["mesh"]
        if not isinstance(m, int) or m not in per_mesh:
            per_mesh[m] = _mesh_size(gltf, buffer_size(gltf, blob), node, i)
        copies = times * (instance_count(gltf, blob, node, i) or 1)
        triangles += copies * per_mesh[m][0]
        vertices += copies * per_mesh[m][1]
    return triangles, vertices


def _mesh_size(gltf: dict, size: int, node: dict, i: int) -> tuple[int, int]:
    """(triangles, vertices) of one copy of node ``i``'s mesh, from its accessors' counts."""
    triangles = vertices = 0
    for where, prim in triangle_primitives(gltf, node, i):
        attrs = prim.get("attributes")
        if not isinstance(attrs, dict) or "POSITION" not in attrs:
            fail(where, "has no POSITION attribute")
        n = layout(gltf, size, attrs["POSITION"], f"POSITION of {where}").count
        if "indices" in prim:
            triangles += layout(gltf, size, prim["indices"], f"indices of {where}").count // 3
        else:
            triangles += n // 3
        vertices += n
    return triangles, vertices


def mesh_nodes(
    gltf: dict,
    roots: list[int],
    parent: np.ndarray | None = None,
    paths: dict[int, int] | None = None,
) -> Iterator[tuple[int, dict, np.ndarray]]:
    """(index, node, world matrix) of every node with a mesh under ``roots``, depth first in the
    order of the children lists; a node shared by several parents once per path.  The tree is
    checked and its placements counted (at most MAX_NODE_VISITS) before the walk starts, and
    the walk is iterative: a 100,000-deep chain is fine.  ``paths``: :func:`node_paths` of
    ``roots``, where the caller has them."""
    paths = node_paths(gltf, roots) if paths is None else paths
    nodes = gltf.get("nodes", [])
    local = local_matrices(nodes, list(paths))
    base = np.eye(4) if parent is None else parent
    stack = [(r, base) for r in reversed(roots)]
    while stack:
        i, above = stack.pop()
        node = nodes[i]
        world = above
        if i in local:
            with np.errstate(over="ignore", invalid="ignore"):  # checked just below
                world = above @ local[i]
            if not np.isfinite(world).all():
                fail(f"node {i}", "its placement overflows (a scale or translation too large)")
        if "mesh" in node:
            yield i, node, world
        stack.extend((k, world) for k in reversed(node.get("children", [])))


TRANSFORMS = ("matrix", "translation", "rotation", "scale")


def local_matrices(nodes: list, indices: list[int]) -> dict[int, np.ndarray]:
    """The local 4x4 matrices of the nodes ``indices`` that have a transform (the others are
    left out: identity), each checked; the TRS ones made together in one batch."""
    out: dict[int, np.ndarray] = {}
    trs: list[int] = []
    for i in indices:
        node = nodes[i]
        if "matrix" in node:
            out[i] = node_matrix(node, i)
        elif any(key in node for key in TRANSFORMS):
            trs.append(i)
    if trs:
        parts = [_trs_of(nodes[i], f"node {i}") for i in trs]
        t, r, s = (np.array(column) for column in zip(*parts, strict=True))
        out.update(zip(trs, _trs(t, r, s), strict=True))
    return out


def _trs_of(node: dict, where: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A node's checked translation, rotation (scaled so its largest component is 1) and scale."""
    rotation = numbers(node.get("rotation", [0, 0, 0, 1]), 4, where, "rotation")
    return (
        numbers(node.get("translation", [0, 0, 0]), 3, where, "translation"),
        _unit_scaled(rotation[None], where)[0],
        numbers(node.get("scale", [1, 1, 1]), 3, where, "scale"),
    )


def triangle_primitives(gltf: dict, node: dict, i: int) -> Iterator[tuple[str, dict]]:
    """(name, primitive) of the triangle primitives (mode 4) of node ``i``'s mesh."""
    m = node["mesh"]
    prims = entry(gltf, "meshes", m, f"node {i}").get("primitives")
    if not isinstance(prims, list):
        fail(f"mesh {m}", "primitives must be a list")
    for p, prim in enumerate(prims):
        where = f"mesh {m} primitive {p}"
        if not isinstance(prim, dict):
            fail(where, "is not a JSON object")
        if whole(prim.get("mode", 4), where, "mode", 0, 6) == 4:
            yield where, prim


def instance_count(gltf: dict, blob: bytes, node: dict, i: int) -> int | None:
    """How many instances EXT_mesh_gpu_instancing makes of node ``i`` (None: not instanced),
    its attributes checked: at least one, all with the same count, at least 1."""
    extensions = node.get("extensions", {})
    if not isinstance(extensions, dict):
        fail(f"node {i}", "extensions must be an object")
    if INSTANCING not in extensions:
        return None
    where = f"node {i} {INSTANCING}"
    inst = extensions[INSTANCING]
    attrs = inst.get("attributes") if isinstance(inst, dict) else None
    if not isinstance(attrs, dict) or not attrs:
        fail(where, "has no attributes", "give it TRANSLATION, ROTATION or SCALE accessors")
    size = buffer_size(gltf, blob)
    counts = {layout(gltf, size, a, f"{name} of {where}").count for name, a in attrs.items()}
    if len(counts) > 1:
        fail(where, f"its attributes have different counts ({sorted(counts)})")
    n = counts.pop()
    if n == 0:
        fail(where, "has no instances (its attributes' count is 0)")
    return n


def _instances(gltf: dict, blob: bytes, node: dict, i: int) -> np.ndarray | None:
    """(n, 4, 4) instance matrices of node ``i`` (None: not instanced)."""
    n = instance_count(gltf, blob, node, i)
    if n is None:
        return None
    where = f"node {i} {INSTANCING}"
    attrs = node["extensions"][INSTANCING]["attributes"]
    got = {
        name: accessor(gltf, blob, attrs[name], f"{name} of {where}", FLOAT, (kind,))
        for name, kind in INSTANCE_TYPES.items()
        if name in attrs
    }
    rotation = got.get("ROTATION", np.tile([0.0, 0, 0, 1], (n, 1)))
    return _trs(
        got.get("TRANSLATION", np.zeros((n, 3))),
        _unit_scaled(rotation, f"accessor {attrs.get('ROTATION')}"),
        got.get("SCALE", np.ones((n, 3))),
    )


def _primitive(gltf: dict, blob: bytes, prim: dict, where: str) -> tuple[np.ndarray, np.ndarray]:
    """(positions (n, 3), triangles (m, 3)) of a primitive: float VEC3 positions, unsigned
    indices that make whole triangles and point at existing vertices."""
    attrs = prim.get("attributes")
    if not isinstance(attrs, dict) or "POSITION" not in attrs:
        fail(where, "has no POSITION attribute")
    p = attrs["POSITION"]
    pos = _positions(gltf, blob, p, f"POSITION of {where}")
    if "indices" in prim:
        name, what = f"accessor {prim['indices']}", "indices"
        flat = accessor(gltf, blob, prim["indices"], f"indices of {where}", UNSIGNED, ("SCALAR",))
        flat = flat.reshape(-1)
    else:
        name, what, flat = f"accessor {p}", "vertices", np.arange(len(pos))
    if len(flat) % 3:
        fail(name, f"its {len(flat)} {what} do not make whole triangles ({where})")
    if len(flat) and flat.max() >= len(pos):
        k = int(np.argmax(flat >= len(pos)))
        fail(name, f"index {flat[k]} (element {k}) is past the {len(pos)} vertices of accessor {p}")
    return pos, flat.reshape(-1, 3)


QUANTIZED = "KHR_mesh_quantization"
NORMALIZED = {5120: 127.0, 5121: 255.0, 5122: 32767.0, 5123: 65535.0}  # glTF 2.0, 3.11


def _positions(gltf: dict, blob: bytes, index: int, use: str) -> np.ndarray:
    """Float VEC3 positions; with KHR_mesh_quantization (listed in extensionsUsed) also 8- and
    16-bit integers, normalized ones mapped to [0, 1] or [-1, 1] as glTF states (the node's
    scale, applied by the caller, turns them into metres)."""
    used = gltf.get("extensionsUsed")
    quantized = isinstance(used, list) and QUANTIZED in used
    kinds = FLOAT + (tuple(NORMALIZED) if quantized else ())
    pos = accessor(gltf, blob, index, use, kinds, ("VEC3",))
    ctype = gltf["accessors"][index]["componentType"]
    if ctype in NORMALIZED and gltf["accessors"][index].get("normalized") is True:
        pos = np.maximum(pos / NORMALIZED[ctype], -1.0)
    return pos


def _colour(gltf: dict, prim: dict, where: str) -> np.ndarray:
    """The sRGB bytes (4,) of a primitive's material's baseColorFactor (white without one)."""
    factor = np.ones(4)
    if "material" in prim:
        k = prim["material"]
        pbr = entry(gltf, "materials", k, where).get("pbrMetallicRoughness", {})
        if not isinstance(pbr, dict):
            fail(f"material {k}", "pbrMetallicRoughness must be an object")
        if "baseColorFactor" in pbr:
            factor = numbers(pbr["baseColorFactor"], 4, f"material {k}", "baseColorFactor")
    alpha = np.clip(factor[3], 0.0, 1.0)
    return np.append(np.rint(_to_srgb(factor[:3]) * 255), np.rint(alpha * 255)).astype(np.uint8)


def world_mesh(
    gltf: dict,
    blob: bytes,
    roots: list[int],
    parent: np.ndarray | None = None,
    checked: bool = False,
) -> trimesh.Trimesh:
    """World-space triangles of the nodes ``roots`` and everything under them, placed by
    ``parent`` (the 4x4 world matrix of their parent; identity for a scene's roots), with
    per-face sRGB colours.  Callers that want one mesh per subtree (one per building) call it
    once per subtree, after :func:`check_scene` on the whole scene (``checked``)."""
    import trimesh

    paths = node_paths(gltf, roots)
    if not checked:
        _check_triangles(gltf, blob, paths)
    verts, faces, colours = [], [], []
    count = 0
    primitives: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}  # read once each
    instances: dict[int, np.ndarray | None] = {}
    placed_before: set[tuple[str, bytes]] = set()
    for i, node, world in mesh_nodes(gltf, roots, parent, paths):
        if i not in instances:
            instances[i] = _instances(gltf, blob, node, i)
        copies = instances[i]
        with np.errstate(over="ignore", invalid="ignore"):  # placed vertices are checked
            placements = world[None] if copies is None else world @ copies
        for where, prim in triangle_primitives(gltf, node, i):
            # the same primitive placed the same way again adds no surface, only work: a
            # mesh listing one primitive 3,000 times made 2 million triangles (66 s of infer)
            key = (json.dumps(prim, sort_keys=True), placements.tobytes())
            if key in placed_before:
                continue
            placed_before.add(key)
            if where not in primitives:
                primitives[where] = (
                    *_primitive(gltf, blob, prim, where),
                    _colour(gltf, prim, where),
                )
            pos, tri, rgba = primitives[where]
            placed, tris = _placed(pos, tri, placements, f"node {i}")
            verts.append(placed)
            faces.append(tris + count)
            colours.append(np.tile(rgba, (len(tris), 1)))
            count += len(placed)
    if not faces:
        return trimesh.Trimesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), process=False)
    return trimesh.Trimesh(
        np.concatenate(verts),
        np.concatenate(faces),
        face_colors=np.concatenate(colours),
        process=False,
    )


def named_meshes(gltf: dict, blob: bytes) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """(vertices, triangles) of every named node with a mesh, placed in the default scene (its
    ancestors' transforms and its own applied, instances expanded), by node name: what a grammar's
    ``asset a = "meshes.glb#name"`` inserts.  Where several nodes share a name, the first in the
    walk's order; the whole scene is held to the triangle cap first."""
    roots = scene_roots(gltf)
    paths = node_paths(gltf, roots)
    _check_triangles(gltf, blob, paths)
    out: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    primitives: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for i, node, world in mesh_nodes(gltf, roots, None, paths):
        name = node.get("name")
        if not isinstance(name, str) or name in out:
            continue
        copies = _instances(gltf, blob, node, i)
        placements = world[None] if copies is None else world @ copies
        verts, faces, count = [np.zeros((0, 3))], [np.zeros((0, 3), dtype=np.int64)], 0
        for where, prim in triangle_primitives(gltf, node, i):
            if where not in primitives:
                primitives[where] = _primitive(gltf, blob, prim, where)
            placed, tris = _placed(*primitives[where], placements, f"node {i}")
            verts.append(placed)
            faces.append(tris + count)
            count += len(placed)
        out[name] = (np.concatenate(verts), np.concatenate(faces))
    return out


def _placed(
    pos: np.ndarray, tri: np.ndarray, placements: np.ndarray, where: str
) -> tuple[np.ndarray, np.ndarray]:
    """(vertices, triangles) of a primitive placed by each of ``placements`` (n, 4, 4), the
    winding turned where a placement mirrors; vertices that overflow are an error."""
    with np.errstate(over="ignore", invalid="ignore"):  # checked just below
        placed = pos @ placements[:, :3, :3].transpose(0, 2, 1)
        placed += placements[:, None, :3, 3]
    if not np.isfinite(placed).all():
        fail(where, "its placed vertices overflow (a scale or translation too large)")
    flip = np.linalg.det(placements[:, :3, :3]) < 0
    tris = np.broadcast_to(tri, (len(placements),) + tri.shape).copy()
    tris[flip] = tris[flip][:, :, ::-1]
    tris += (np.arange(len(placements)) * len(pos))[:, None, None]
    return placed.reshape(-1, 3), tris.reshape(-1, 3)
