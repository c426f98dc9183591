"""The CityJSON reader of ``bgr infer --kind city``: CityJSON and CityJSON Text Sequences.

The file is read by ``formats/cityjson_read.py`` at one level of detail; each city object with
triangles is an object, Buildings and BuildingParts (:data:`PROCEDURAL_TYPES`) to
proceduralize and the rest (roads, land use, water, terrain...) carried.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .model import CityObject
from .read_scene import Found, _template

PROCEDURAL_TYPES = ("Building", "BuildingPart")  # CityJSON types that are proceduralized


def _lod_order(lod: str) -> tuple[float, str]:
    try:
        return float(lod), lod
    except ValueError:
        return float("inf"), lod


def _read_cityjson(path: str | Path, lod: str | None) -> Found:
    """Every city object with triangles: Buildings and BuildingParts to proceduralize, the
    rest (roads, land use, water, terrain...) carried.  A Building whose geometry is all in
    its BuildingParts has no triangles of its own, so only its parts are objects."""
    from bgr.formats.cityjson_read import read_cityjson

    model = read_cityjson(path, lod)
    vertices, faces, owner = [], [], []
    objects: list[CityObject] = []
    count = 0
    for ident, mesh in model.objects.items():
        if not len(mesh.faces):
            continue
        vertices.append(mesh.vertices)
        faces.append(mesh.faces + count)
        owner.append(np.full(len(mesh.faces), len(objects), dtype=np.int64))
        objects.append(
            _template(
                ident,
                mesh.type,
                proceduralize=mesh.type in PROCEDURAL_TYPES,
                attributes=dict(mesh.attributes),
            )
        )
        count += len(mesh.vertices)
    crs = model.reference_system
    hint = None
    if lod is not None:
        has = ", ".join(sorted(model.lods, key=_lod_order)[:12]) or "none"
        hint = f"no city object has geometry of lod {lod[:40]}; the file has lods {has}"
    if not faces:
        return Found(
            np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), None, None, crs=crs, hint=hint
        )
    return Found(
        np.concatenate(vertices),
        np.concatenate(faces),
        None,
        np.concatenate(owner),
        objects,
        crs=None if crs is None else str(crs),
        hint=hint,
    )
