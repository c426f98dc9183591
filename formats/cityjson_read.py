"""CityJSON reading: each city object's triangles back from a ``.city.json`` or a
``.city.jsonl`` (tests, the inverse modules and the CityGML reader's triangulation use it).
Apart from the writer (:mod:`.cityjson`) because reading files made by anyone is its own
concern: any geometry nesting, holes, and input that must fail as a located error.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.grammar.paths import read_input

from .cityjson_checks import check_indices, fan, usable
from .meshes import cross

# points of one surface that repeat an earlier one (a ring must be simple; a keyhole repeats two):
# more, and earcut is not used.  A CityGML posList of a square repeated 1,000 times (4,000 points,
# 4 distinct) took earcut 16 to 20 s, 300 times 0.35 s; the surface is fanned instead
MAX_REPEATED_POINTS = 64


@dataclass
class CityObjectMesh:
    """One city object read back: its triangles in the file's coordinates (z up, transform
    applied), each with its semantic type (None where the file gives none) and the index of the
    surface it covers part of (surfaces counted in the order of the boundaries, shells and
    solids flattened)."""

    id: str
    type: str
    vertices: np.ndarray  # (V, 3) float64, only the vertices its triangles use
    faces: np.ndarray  # (F, 3) int64 into vertices, counter-clockwise seen from outside
    semantics: list[str | None]
    surface: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))  # (F,)
    lod: str | None = None
    attributes: dict = field(default_factory=dict)
    parents: list[str] = field(default_factory=list)
    children: list[str] = field(default_factory=list)


@dataclass
class CityModel:
    """A CityJSON file read back: its objects by id, the CRS URL it names, its transform."""

    objects: dict[str, CityObjectMesh]
    reference_system: str | None = None
    transform: dict | None = None
    lods: set[str] = field(default_factory=set)  # every geometry's lod the file has


def read_cityjson(path: str | Path, lod: str | None = None) -> CityModel:
    """Read a ``.city.json`` (or a ``.city.jsonl`` sequence) into triangles per city object.

    Of each object's geometries the one of ``lod`` is read (default: its highest lod);
    MultiSurface, CompositeSurface, Solid, MultiSolid and CompositeSolid are read, every
    surface triangulated (earcut, holes kept) and turned to face where its outer ring does;
    points, lines and GeometryInstances (templates) are not, nor appearances.  An object
    without such geometry has no triangles.  BgrError, naming the file, when it is not CityJSON
    this reader can use."""
    shown = str(path)
    try:
        text = read_input(path, "CityJSON file").decode("utf-8")
    except FileNotFoundError:
        raise BgrError(Diagnostic(shown, 0, 0, "no such CityJSON file")) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise BgrError(Diagnostic(shown, 0, 0, f"cannot read the CityJSON file: {exc}")) from None
    try:
        if shown.lower().endswith(".jsonl"):  # CityJSON Text Sequences: one object a line
            lines = [json.loads(line) for line in text.splitlines() if line.strip()]
            head, features = (lines or [None])[0], lines[1:]
        else:
            head, features = _parse(shown, text), []
        if not isinstance(head, dict) or head.get("type") != "CityJSON":
            raise ValueError("the first object is not of type CityJSON")
        transform = head.get("transform")
        model = CityModel({}, (head.get("metadata") or {}).get("referenceSystem"), transform)
        for doc in [head, *features]:
            if "vertices" not in doc:  # required of every CityJSON object and feature
                raise ValueError('it has no "vertices"')
            vertices = np.asarray(doc.get("vertices") or np.zeros((0, 3)), dtype=np.float64)
            if transform:
                with np.errstate(over="ignore", invalid="ignore"):  # inf: named further on
                    vertices = vertices * transform["scale"] + transform["translate"]
            vertices = vertices.reshape(-1, 3)
            for ident, obj in doc["CityObjects"].items():
                try:
                    model.lods.update(_lods(obj))
                    model.objects[ident] = _read_object(ident, obj, vertices, lod)
                except ValueError as exc:
                    raise ValueError(f"city object {ident[:80]!r}: {exc}") from None
        return model
    except (
        ValueError, KeyError, TypeError, IndexError, AttributeError, RecursionError, OverflowError
    ) as exc:  # fmt: skip
        raise BgrError(
            Diagnostic(shown, 0, 0, f"not a CityJSON file this reader can use: {exc}")
        ) from None


def _parse(shown: str, text: str) -> Any:
    """The JSON of a .city.json; a BgrError at the line and column where it stops parsing."""
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise BgrError(
            Diagnostic(shown, exc.lineno, exc.colno, f"not a CityJSON file: not JSON: {exc.msg}")
        ) from None


def _lod_key(lod: Any) -> float:
    try:
        return float(lod)
    except (TypeError, ValueError):
        return -1.0


# how deep surfaces sit in the boundaries of each kind of geometry this reader reads
_DEPTH = {
    "MultiSurface": 0,
    "CompositeSurface": 0,
    "Solid": 1,
    "MultiSolid": 2,
    "CompositeSolid": 2,
}


def _lods(obj: Any) -> set[str]:
    """The lods of a city object's geometries (what ``lod`` may pick), as the file writes them."""
    geoms = obj.get("geometry") if isinstance(obj, dict) else None
    if not isinstance(geoms, list):
        return set()
    return {str(g["lod"])[:20] for g in geoms if isinstance(g, dict) and "lod" in g}


def _read_object(ident: str, obj: dict, vertices: np.ndarray, lod: str | None) -> CityObjectMesh:
    geoms = [g for g in obj.get("geometry") or [] if g.get("type") in _DEPTH]
    if lod is not None:
        geoms = [g for g in geoms if str(g.get("lod")) == str(lod)]
    out = CityObjectMesh(
        ident,
        obj["type"],
        np.zeros((0, 3)),
        np.zeros((0, 3), dtype=np.int64),
        [],
        attributes=dict(obj.get("attributes") or {}),
        parents=list(obj.get("parents") or []),
        children=list(obj.get("children") or []),
    )
    if not geoms:
        return out
    geom = max(geoms, key=lambda g: _lod_key(g.get("lod")))
    out.lod = None if geom.get("lod") is None else str(geom["lod"])
    surfaces = list(_surfaces(geom))
    names = [s["type"] for s in (geom.get("semantics") or {}).get("surfaces", [])]
    faces, kinds, counts = [], [], []
    for rings, value in surfaces:
        tri = _triangulate(vertices, rings)
        faces.append(tri)
        counts.append(len(tri))
        kinds += [names[value] if value is not None else None] * len(tri)
    flat = np.concatenate(faces) if faces else np.zeros((0, 3), dtype=np.int64)
    used, inverse = np.unique(flat.reshape(-1), return_inverse=True)
    out.vertices = vertices[used]
    out.faces = inverse.reshape(-1, 3).astype(np.int64)
    out.semantics = kinds
    out.surface = np.repeat(np.arange(len(counts), dtype=np.int64), counts)
    return out


def _surfaces(geom: dict) -> Iterator[tuple[list, int | None]]:
    """(rings, semantic value) of every surface of a geometry, whatever its nesting."""
    depth = _DEPTH[geom["type"]]
    values = (geom.get("semantics") or {}).get("values")

    def walk(bounds: list, vals: Any, level: int) -> Iterator[tuple[list, int | None]]:
        for i, item in enumerate(bounds):
            sub = vals[i] if isinstance(vals, list) and i < len(vals) else None
            if level == 0:
                yield item, sub if isinstance(sub, int) else None
            else:
                yield from walk(item, sub, level - 1)

    yield from walk(geom["boundaries"], values, depth)


def _triangulate(vertices: np.ndarray, rings: list) -> np.ndarray:
    """Triangles (k, 3) of vertex indices covering one surface (outer ring, then holes),
    facing where the outer ring's Newell normal does."""
    outer = np.asarray(rings[0], dtype=np.int64)
    if len(rings) == 1 and len(outer) == 3:
        if not 0 <= min(rings[0]) <= max(rings[0]) < len(vertices):  # builtins: 3 numbers
            check_indices(outer, len(vertices))
        return outer[None, :]
    import mapbox_earcut

    index = np.concatenate([np.asarray(r, dtype=np.int64) for r in rings])
    check_indices(index, len(vertices))
    points = vertices[index]
    if not usable(points):  # earcut (C++) and the normals must not see it; the caller names it
        return fan(outer)
    if len(points) > MAX_REPEATED_POINTS and (
        len(points) - len(np.unique(points, axis=0)) > MAX_REPEATED_POINTS
    ):  # not a simple ring: earcut's time grows as a power of the copies; fanned, bounded
        return fan(outer)
    ring = vertices[outer]
    normal = np.sum(cross(ring, np.roll(ring, -1, axis=0)), axis=0)  # Newell
    drop = int(np.argmax(np.abs(normal)))
    flat = np.delete(points, drop, axis=1)
    ends = np.cumsum([len(r) for r in rings]).astype(np.uint32)
    tri = index[mapbox_earcut.triangulate_float64(flat, ends).reshape(-1, 3).astype(np.int64)]
    if len(tri):
        corners = vertices[tri]
        facing = cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]) @ normal
        tri[facing < 0] = tri[facing < 0][:, ::-1]
    return tri
