"""i(): insert a primitive or an asset mesh fitted to the scope (LANGUAGE.md section 5)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from bgr.grammar.registry import PRIMITIVES

from ..expressions import runtime_error
from ..shapes import Solid
from ..terminals import UnitMesh


def insert(app, shape, step, args) -> bool:
    name = args[0]
    if name in PRIMITIVES:
        shape.geom = Solid(app.engine.primitive_id(name), name)
        return False
    module, member = app.module.lookup_module(name)
    asset = module.assets[member]
    mesh_id, extent, offset = _load_asset(app, step, module, asset)
    size = list(shape.size)
    zero = [s <= 1e-12 for s in size]
    if all(zero):  # keep the asset's own size and offset
        size = list(extent)
        shape.origin = shape.world(offset)
    elif sum(zero) == 2:  # scale uniformly by the non-zero axis
        k = zero.index(False)
        factor = size[k] / extent[k] if extent[k] else 1.0
        size = [e * factor for e in extent]
    elif sum(zero) == 1:  # that axis from the mean of the other two scale factors
        k = zero.index(True)
        factors = [size[i] / extent[i] for i in range(3) if i != k and extent[i]]
        size[k] = extent[k] * (sum(factors) / len(factors) if factors else 1.0)
    shape.size = size
    shape.geom = Solid(mesh_id, member)
    return False


def _load_asset(app, step, module, asset):
    """Load an OBJ, GLB or PLY once per derivation; its unit mesh, bounding size and offset."""
    cache = app.engine.__dict__.setdefault("asset_cache", {})
    base = Path(module.path).parent if module.path not in ("<text>", "<stdin>") else Path.cwd()
    path = (base / asset.path).resolve()
    if path in cache:
        return cache[path]
    if not path.is_file():
        raise runtime_error(
            module, asset.pos, f"asset file '{asset.path}' not found", f"looked for {path}"
        )
    try:
        import trimesh

        loaded = trimesh.load(path, force="mesh")
        verts, faces = np.asarray(loaded.vertices, dtype=float), np.asarray(loaded.faces)
    except Exception as e:  # any reader failure is the file's fault, not ours
        raise runtime_error(module, asset.pos, f"cannot read asset '{asset.path}': {e}") from None
    if len(verts) == 0:
        raise runtime_error(module, asset.pos, f"asset '{asset.path}' has no geometry")
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    extent = hi - lo
    unit = (verts - lo) / np.where(extent > 0, extent, 1.0)
    mesh_id = app.engine.table.library.add(UnitMesh(asset.name, unit, faces))
    cache[path] = (mesh_id, tuple(extent.tolist()), tuple(lo.tolist()))
    return cache[path]
