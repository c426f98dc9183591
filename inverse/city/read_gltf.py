"""The glTF reader of ``bgr infer --kind city``: a .glb or .gltf, an object per node.

The file is parsed and checked by bgr's own glTF reader (``formats/glb_read.py``); the nodes
under the scene's one root (bgr's tree: root, then a node per lot), else the root nodes, are the
objects, their ``extras`` the objects' attributes.
"""

from __future__ import annotations

import struct
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic

from .model import CityObject
from .read_ply import _mesh_colors
from .read_scene import Found, _read_bytes, _reason, _template

if TYPE_CHECKING:
    import trimesh


def _read_gltf(path: str | Path) -> Found:
    """A .glb/.gltf's triangles, an object per node under the scene's one root node (bgr's
    tree: root, then a node per lot), else per root node; when that makes one object, its
    connected components are the objects instead.  The file is checked as it is read
    (formats/gltf_checks.py), its triangles counted for the whole scene before any is made."""
    from bgr.formats.glb_read import check_scene, node_matrix, parse, scene_roots, world_mesh
    from bgr.grammar.paths import resolved

    shown = str(path)
    data = _read_bytes(path, shown)
    parts: list[tuple[str, trimesh.Trimesh, dict]] = []
    try:
        gltf, blob = parse(data, resolved(path).parent)
        nodes = gltf.get("nodes", [])
        roots = scene_roots(gltf)
        check_scene(gltf, blob, roots)
        if len(roots) == 1 and nodes[roots[0]].get("children"):
            root = nodes[roots[0]]
            alone = {key: value for key, value in root.items() if key != "children"}
            own = world_mesh({**gltf, "nodes": [alone]}, blob, [0], checked=True)
            parts.append((_node_name(root, roots[0]), own, {}))
            world = node_matrix(root, roots[0])
            for child in root["children"]:
                mesh = world_mesh(gltf, blob, [child], world, checked=True)
                parts.append((_node_name(nodes[child], child), mesh, _extras(nodes[child])))
        else:
            for r in roots:
                mesh = world_mesh(gltf, blob, [r], checked=True)
                parts.append((_node_name(nodes[r], r), mesh, _extras(nodes[r])))
    except BgrError as exc:
        raise BgrError(
            Diagnostic(shown, 0, 0, f"not a glTF file bgr can read: {exc.message}", exc.hint)
        ) from None
    except (
        ValueError,
        KeyError,
        TypeError,
        IndexError,
        AttributeError,
        RecursionError,
        struct.error,
    ) as exc:
        raise BgrError(
            Diagnostic(shown, 0, 0, f"not a glTF file bgr can read: {_reason(exc)}")
        ) from None
    return _gathered(parts)


def _node_name(node: dict, index: int) -> str:
    name = node.get("name")
    return name if isinstance(name, str) and name else f"node-{index}"


def _extras(node: dict) -> dict:
    extras = node.get("extras")
    return dict(extras) if isinstance(extras, dict) else {}


def _gathered(parts: list[tuple[str, trimesh.Trimesh, dict]]) -> Found:
    """One Found of several meshes, an object each (names made unique, meshes without
    triangles left out); a single object is left to connected components."""
    vertices, faces, colors, owner = [], [], [], []
    objects: list[CityObject] = []
    taken: set[str] = set()
    count = 0
    for name, mesh, attrs in parts:
        if not len(mesh.faces):
            continue
        shown, n = name, 1
        while shown in taken:
            n += 1
            shown = f"{name}-{n}"
        taken.add(shown)
        vertices.append(np.asarray(mesh.vertices, dtype=np.float64))
        faces.append(np.asarray(mesh.faces, dtype=np.int64) + count)
        colors.append(_mesh_colors(mesh))
        owner.append(np.full(len(mesh.faces), len(objects), dtype=np.int64))
        objects.append(_template(shown, attributes=attrs))
        count += len(vertices[-1])
    if not faces:
        return Found(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), None, None)
    found = Found(
        np.concatenate(vertices),
        np.concatenate(faces),
        np.concatenate(colors),
        np.concatenate(owner),
        objects,
    )
    if len(objects) == 1:
        found.owner, found.objects = None, []
    return found
