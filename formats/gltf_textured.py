"""Read a glTF 2.0 / GLB model with its base-colour textures into a :class:`TexturedMesh`.

The geometry is read by bgr's own checked reader (:mod:`.glb_read`: every accessor, bufferView,
node and instance checked before use, buffers only from the file or its folder); this module
adds what a textured model needs: ``TEXCOORD_n`` of each primitive (float, or normalized
unsigned bytes and shorts), and each material's ``pbrMetallicRoughness.baseColorTexture``
image, from a ``data:`` URI, a bufferView (GLB) or a file in the model's folder (a URL, an
absolute path or a file outside the folder is an error; a missing file a warning).

glTF's v runs down the image; the model's runs up (like CityGML, OBJ and CGA), so v is flipped.
Vertices are placed in world space and stay y up (``up = "y"``), as glTF has them.
"""

from __future__ import annotations

import base64
import struct
from pathlib import Path

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.grammar.paths import read_input, resolved

from .glb_read import (
    _instances,
    _placed,
    _primitive,
    _to_srgb,
    accessor,
    check_scene,
    mesh_nodes,
    parse,
    scene_roots,
    triangle_primitives,
)
from .gltf_checks import buffer_size, entry, fail, numbers, quoted, view_span, whole
from .textured_model import Material, TexturedMesh, image_path

__all__ = ["read_gltf_textured"]

WRAP_MODES = {10497: "wrap", 33648: "mirror", 33071: "clamp"}  # glTF sampler wrapS
NORMALIZED = {5121: 255.0, 5123: 65535.0}


def read_gltf_textured(path: str | Path) -> TexturedMesh:
    """The textured triangles of a .glb/.gltf (world space, y up); BgrError naming the file
    for anything it cannot read."""
    shown = str(path)
    try:
        data = read_input(path, "model file")
    except FileNotFoundError:
        raise BgrError(Diagnostic(shown, 0, 0, "no such glTF file")) from None
    except OSError as exc:
        raise BgrError(Diagnostic(shown, 0, 0, f"cannot read the glTF file: {exc}")) from None
    try:
        mesh = _read(data, resolved(path).parent, shown)
    except BgrError as exc:
        raise BgrError(
            Diagnostic(shown, 0, 0, f"not a glTF file bgr can read: {exc.message}", exc.hint)
        ) from None
    except (ValueError, TypeError, IndexError, KeyError, AttributeError, struct.error) as exc:
        raise BgrError(
            Diagnostic(shown, 0, 0, f"not a glTF file bgr can read: {str(exc)[:200]}")
        ) from None
    mesh.source = shown
    return mesh


def _read(data: bytes, folder: Path, shown: str) -> TexturedMesh:
    gltf, blob = parse(data, folder)
    roots = scene_roots(gltf)
    check_scene(gltf, blob, roots)
    warnings: list[Diagnostic] = []
    materials: dict[int, int] = {}  # glTF material -> index in the model's table
    table: list[Material] = []
    verts, faces, uvs, mats, objs, surf = [], [], [], [], [], []
    object_ids: list[str] = []
    surface_ids: dict[str, int] = {}
    count = 0
    for i, node, world in mesh_nodes(gltf, roots):
        copies = _instances(gltf, blob, node, i)
        placements = world[None] if copies is None else world @ copies
        object_ids.append(_name(node, f"node {i}"))
        for where, prim in triangle_primitives(gltf, node, i):
            pos, tri = _primitive(gltf, blob, prim, where)
            k, set_index = _material(
                gltf, blob, prim, where, folder, shown, table, materials, warnings
            )
            uv = _texcoords(gltf, blob, prim, where, set_index, len(pos))
            placed, tris = _placed(pos, tri, placements, f"node {i}")
            per_vertex = np.tile(uv, (len(placements), 1))
            verts.append(placed)
            faces.append(tris + count)
            uvs.append(per_vertex[tris])
            mats.append(np.full(len(tris), k, dtype=np.int64))
            objs.append(np.full(len(tris), len(object_ids) - 1, dtype=np.int64))
            surf.append(np.full(len(tris), surface_ids.setdefault(where, len(surface_ids))))
            count += len(placed)
    if not faces:
        raise BgrError(Diagnostic(shown, 0, 0, "the model has no triangles"))
    n = sum(len(f) for f in faces)
    return TexturedMesh(
        vertices=np.concatenate(verts),
        faces=np.concatenate(faces).astype(np.int64),
        uv=np.concatenate(uvs).reshape(-1, 3, 2),
        material=np.concatenate(mats),
        materials=table,
        semantic=np.zeros(n, dtype=np.int64),
        semantic_names=[""],
        object=np.concatenate(objs),
        object_ids=object_ids,
        surface=np.concatenate(surf).astype(np.int64),
        surface_ids=list(surface_ids),
        up="y",
        warnings=warnings,
    )


def _texcoords(
    gltf: dict, blob: bytes, prim: dict, where: str, set_index: int, n: int
) -> np.ndarray:
    """(n, 2) UVs of TEXCOORD_<set_index>, v flipped to run up the image; zeros without."""
    attrs = prim["attributes"]
    key = f"TEXCOORD_{set_index}"
    if key not in attrs:
        return np.zeros((n, 2))
    use = f"{key} of {where}"
    raw = accessor(gltf, blob, attrs[key], use, (5126, 5121, 5123), ("VEC2",))
    kind = entry(gltf, "accessors", attrs[key], where).get("componentType")
    uv = raw / NORMALIZED[kind] if kind in NORMALIZED else raw
    if len(uv) != n:
        fail(f"accessor {attrs[key]}", f"{use} has {len(uv)} elements for {n} positions")
    return np.stack([uv[:, 0], 1.0 - uv[:, 1]], axis=1)


def _material(
    gltf: dict,
    blob: bytes,
    prim: dict,
    where: str,
    folder: Path,
    shown: str,
    table: list[Material],
    seen: dict[int, int],
    warnings: list[Diagnostic],
) -> tuple[int, int]:
    """(index in ``table`` or -1, its texture's TEXCOORD set) of a primitive's material, read
    once per glTF material."""
    if "material" not in prim:
        return -1, 0
    m = whole(prim["material"], where, "material")
    material = entry(gltf, "materials", m, where)
    pbr = material.get("pbrMetallicRoughness", {})
    if not isinstance(pbr, dict):
        fail(f"material {m}", "pbrMetallicRoughness must be an object")
    info = pbr.get("baseColorTexture")
    set_index = 0
    if isinstance(info, dict):
        set_index = whole(info.get("texCoord", 0), f"material {m}", "texCoord", 0, 7)
    if m in seen:
        return seen[m], set_index
    factor = np.ones(4)
    if "baseColorFactor" in pbr:
        factor = numbers(pbr["baseColorFactor"], 4, f"material {m}", "baseColorFactor")
    r, g, b = (float(c) for c in _to_srgb(factor[:3]))
    out = Material(_name(material, f"material {m}"), (r, g, b, float(np.clip(factor[3], 0.0, 1.0))))
    if isinstance(info, dict):
        _texture(gltf, blob, info, f"material {m}", folder, shown, out, warnings)
    seen[m] = len(table)
    table.append(out)
    return seen[m], set_index


def _texture(
    gltf: dict,
    blob: bytes,
    info: dict,
    where: str,
    folder: Path,
    shown: str,
    out: Material,
    warnings: list[Diagnostic],
) -> None:
    """Fill ``out``'s image and wrap from a baseColorTexture's texture, sampler and image."""
    t = info.get("index")
    texture = entry(gltf, "textures", t, where)
    if "sampler" in texture:
        sampler = entry(gltf, "samplers", texture["sampler"], f"texture {t}")
        out.wrap = WRAP_MODES.get(sampler.get("wrapS", 10497), "wrap")
    if "source" not in texture:
        return
    s = texture["source"]
    image = entry(gltf, "images", s, f"texture {t}")
    if "bufferView" in image:
        v = whole(image["bufferView"], f"image {s}", "bufferView")
        view = entry(gltf, "bufferViews", v, f"image {s}")
        _, start, length = view_span(view, v, [buffer_size(gltf, blob)])
        out.data = blob[start : start + length]
        return
    uri = image.get("uri")
    if not isinstance(uri, str):
        fail(f"image {s}", "has neither a uri nor a bufferView")
    if uri.startswith("data:"):
        try:
            out.data = base64.b64decode(uri.partition(",")[2], validate=True)
        except ValueError:
            fail(f"image {s}", "its data: URI is not valid base64")
        return
    try:
        path = image_path(folder, uri)
    except ValueError as exc:
        fail(f"image {s}", f"uri {quoted(uri)} {exc}", "bgr reads images from the model's folder")
    if path.is_file():
        out.image = path
    else:
        message = f"image {s}: {quoted(uri)} is missing: its faces are left untextured"
        warnings.append(Diagnostic(shown, 0, 0, message, severity="warning"))


def _name(item: dict, default: str) -> str:
    """An item's ``name`` where it is a string, else ``default``."""
    name = item.get("name")
    return name if isinstance(name, str) else default
