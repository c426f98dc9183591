"""i(): insert a primitive or an asset mesh fitted to the scope (LANGUAGE.md section 5)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from bgr.grammar.errors import BgrError, suggest
from bgr.grammar.paths import ALLOW_HINT, check_input, within
from bgr.grammar.registry import PRIMITIVES

from ..expressions import runtime_error
from ..shapes import Solid
from ..terminals import UnitMesh
from .trims import DELETED, trim_insert


def insert(app, shape, step, args) -> bool:
    name = args[0]
    if name in PRIMITIVES:
        # CGA's built-in primitives fit a zero-size scope as assets do: a cube inserted into a
        # face (z size 0) gets a depth, not a flattened box; ``quad`` is flat by nature
        extent = (1.0, 1.0, 0.0) if name == "quad" else (1.0, 1.0, 1.0)
        shape.size = fitted_size(shape.size, extent)
        shape.geom = Solid(app.engine.primitive_id(name), name)
        return False if trim_insert(app, shape) else DELETED
    module, member = app.module.lookup_module(name)
    asset = module.assets[member]
    mesh_id, extent, offset = _load_asset(app, step, module, asset)
    if all(s <= 1e-12 for s in shape.size):  # keep the asset's own size and offset
        shape.origin = shape.world(offset)
    shape.size = fitted_size(shape.size, extent)
    shape.geom = Solid(mesh_id, member)
    return False if trim_insert(app, shape) else DELETED


def fitted_size(size, extent) -> list[float]:
    """The scope size an inserted mesh of size ``extent`` takes (LANGUAGE.md section 5, CGA).

    Zero scope sizes are filled in: all three zero keep the mesh's own size, two zero scale it
    uniformly by the non-zero axis, one zero takes that axis from the mean of the other two
    scale factors.  An axis along which the mesh itself is flat stays as the scope has it.
    """
    size = list(size)
    zero = [s <= 1e-12 and e > 0 for s, e in zip(size, extent, strict=True)]
    if not any(zero):
        return size
    if all(s <= 1e-12 for s in size):
        return list(extent)
    factors = [size[i] / extent[i] for i in range(3) if not zero[i] and extent[i] > 0]
    factor = sum(factors) / len(factors) if factors else 1.0
    return [extent[i] * factor if zero[i] else size[i] for i in range(3)]


def _load_asset(app, step, module, asset):
    """Load an OBJ, GLB or PLY once per derivation; its unit mesh, bounding size and offset."""
    cache = app.engine.__dict__.setdefault("asset_cache", {})
    base = Path(module.path).parent if module.path not in ("<text>", "<stdin>") else Path.cwd()
    base = module.folder or base  # the real folder: a stdlib module's path is only its name
    file_name, mesh_name = split_fragment(base, asset.path)
    path = (base / file_name).resolve()
    key = (path, mesh_name)
    if key in cache:
        return cache[key]
    if module.roots and not within(path, module.roots):
        raise runtime_error(
            module,
            asset.pos,
            f"asset file '{asset.path}' is outside the folders this grammar may read",
            ALLOW_HINT,
        )
    try:
        check_input(path, "asset file")
    except BgrError as e:  # located at the asset line, as the other asset errors are
        raise runtime_error(module, asset.pos, e.message, e.hint) from None
    try:
        found = path.is_file()
    except (OSError, ValueError) as e:  # a name the system refuses: too long, a NUL byte
        raise runtime_error(
            module, asset.pos, f"asset file '{asset.path[:200]}' cannot be opened: {e.strerror}"
        ) from None
    if not found:
        raise runtime_error(
            module, asset.pos, f"asset file '{asset.path}' not found", f"looked for {path}"
        )
    textured = None if mesh_name is not None else _textured(app, module, asset, path)
    if mesh_name is not None:
        uv = image = None
        verts, faces = _named_mesh(app, module, asset, path, mesh_name)
    elif textured is not None:
        verts, faces, uv, image = textured
    else:
        uv = image = None
        try:
            import trimesh

            loaded = trimesh.load(path, force="mesh")
            verts, faces = np.asarray(loaded.vertices, dtype=float), np.asarray(loaded.faces)
        except Exception as e:  # any reader failure is the file's fault, not ours
            raise runtime_error(
                module, asset.pos, f"cannot read asset '{asset.path}': {e}"
            ) from None
    if len(verts) == 0:
        raise runtime_error(module, asset.pos, f"asset '{asset.path}' has no geometry")
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    extent = hi - lo
    unit = (verts - lo) / np.where(extent > 0, extent, 1.0)
    mesh_id = app.engine.table.library.add(UnitMesh(asset.name, unit, faces, uv, image))
    cache[key] = (mesh_id, tuple(extent.tolist()), tuple(lo.tolist()))
    return cache[key]


def split_fragment(base: Path, path: str) -> tuple[str, str | None]:
    """``("meshes.glb", "type1")`` for ``meshes.glb#type1``: a glTF file and the mesh it holds
    under that node name (``bgr infer --kind city`` writes one file of every type's mesh); the
    path itself, and None, when it names a file as it is or holds no ``#``."""
    head, mark, name = path.rpartition("#")
    if not mark or not name or not head.lower().endswith((".glb", ".gltf")):
        return path, None
    try:
        if (base / path).is_file():  # a file whose name holds a '#'
            return path, None
    except (OSError, ValueError):
        pass
    return head, name


def _named_mesh(app, module, asset, path: Path, name: str) -> tuple[np.ndarray, np.ndarray]:
    """The triangles of node ``name`` of a glTF file (its transform applied), the file read
    once per derivation however many of its meshes the grammar inserts."""
    files = app.engine.__dict__.setdefault("asset_files", {})
    if path not in files:
        from bgr.formats.glb_read import load, named_meshes

        try:  # bgr's reader: every number checked; meshopt-compressed and quantized files read
            files[path] = named_meshes(*load(path))
        except BgrError as e:
            raise runtime_error(
                module, asset.pos, f"cannot read asset '{asset.path}': {e.message}", e.hint
            ) from None
    nodes = files[path]
    if name not in nodes:
        raise runtime_error(
            module,
            asset.pos,
            f"asset '{asset.path}': {path.name} has no mesh named '{name}'",
            suggest(name, nodes) or f"it holds {len(nodes)} meshes",
        )
    return nodes[name]


TEXTURED_ASSETS = (".obj", ".glb", ".gltf")


def _textured(app, module, asset, path: Path):
    """(vertices, faces, per-corner uv, image) of an OBJ+MTL or glTF asset whose every triangle
    shows one image, read by bgr's textured-model readers; None for any other asset, which
    trimesh then reads as before.  An asset with several images, or with an image that is not
    a PNG or JPEG, is inserted without its texture, with a warning saying why."""
    if path.suffix.lower() not in TEXTURED_ASSETS:
        return None
    from bgr.formats.gltf_textured import read_gltf_textured
    from bgr.formats.obj_textured import read_obj_textured
    from bgr.grammar.textures import MAX_IMAGE_BYTES, TextureError, decode_image

    reader = read_obj_textured if path.suffix.lower() == ".obj" else read_gltf_textured
    try:
        model = reader(path)
    except BgrError:  # what bgr's stricter readers refuse, trimesh may still read untextured
        return None
    if not len(model.faces) or not model.textured().all():
        return None  # some faces without an image: the asset's colours, as before
    used = sorted(set(model.material.tolist()))
    images = {_image_key(model.materials[k], path) for k in used}
    if len(images) > 1:
        app.engine.warn(
            module,
            asset.pos,
            f"asset '{asset.path}' uses {len(images)} images: inserted without its textures",
            "bgr carries one image per asset; bake its textures into one image",
        )
        return None
    material = model.materials[used[0]]
    key = images.pop()
    try:
        data = material.image_bytes()
        if len(data) > MAX_IMAGE_BYTES:
            raise TextureError(f"its image is larger than {MAX_IMAGE_BYTES >> 20} MB")
        image = decode_image(data, key, f"{asset.path}: {material.name}")
    except (OSError, ValueError, BgrError) as e:  # TextureError is a ValueError
        reason = getattr(e, "message", None) or str(e)
        app.engine.warn(
            module, asset.pos, f"asset '{asset.path}': {reason}; inserted without its texture"
        )
        return None
    return model.vertices, model.faces, model.uv, image


def _image_key(material, path: Path) -> str:
    """What tells two asset images apart: the image file, or the model and its material."""
    if material.image is not None:
        return str(material.image)
    return f"{path}#{material.name}"
