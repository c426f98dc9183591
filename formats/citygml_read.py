"""Read CityGML 2.0 buildings, with their appearances, into a :class:`TexturedMesh`.

What is read (:mod:`.citygml_parse` turns the XML into records first):

* every gml:Polygon (and Triangle, Rectangle) written inline under a city object, with holes,
  triangulated by earcut in its plane; polygons referenced by ``xlink:href`` (PLATEAU's
  ``lod2Solid`` points at its ``boundedBy`` polygons) are read once, where they are written;
* its level of detail (the nearest ``lodN...`` property above it), its semantic type (the
  thematic surface it bounds: WallSurface, RoofSurface, GroundSurface, ..., Window and Door
  under ``opening``) and its object (the nearest Building, BuildingPart, ... gml:id);
* per object, the highest level of detail it has, or the one ``lod`` asks for (CityJSON's
  ``bgr infer --lod`` rule);
* ``app:Appearance`` of any theme (or of ``theme``): ``app:ParameterizedTexture`` with
  ``app:TexCoordList`` (one list per ring, matched by ring id, first list kept where a file
  repeats it) and ``app:X3DMaterial`` (diffuseColor, transparency), each targeting a polygon or
  a surface above it; where several target one polygon the first in the file wins, a texture
  before a material;
* the CRS: the first ``gml:Envelope``'s ``srsName``, else the first ``srsName`` in the file.

Texture coordinates are kept as written, outside 0..1 too (``Material.wrap`` says how they
reach the image: CityGML's ``wrapMode``, default ``none``).  Image URIs must name files inside
the CityGML file's folder (an URL, absolute path or ``..`` out of it is an error); a missing
image is a warning and its surfaces are left with UVs but no image.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.grammar.paths import read_input, resolved

from .citygml_parse import RawCity, RawPolygon, RawTexture, parse_citygml
from .cityjson_read import _triangulate
from .gltf_checks import quoted
from .textured_model import WRAPS, Material, TexturedMesh, image_path

__all__ = ["read_citygml"]


def read_citygml(
    path: str | Path, *, lod: int | None = None, theme: str | None = None
) -> TexturedMesh:
    """The textured triangles of a CityGML 2.0 file (z up, the file's CRS and units).

    ``lod``: read only that level of detail (default: each object's highest); ``theme``: read
    only the appearances of that theme (default: all).  Raises :class:`BgrError` at the file's
    line and column for input it cannot read."""
    shown = str(path)
    try:
        data = read_input(path, "CityGML file")
    except FileNotFoundError:
        raise BgrError(Diagnostic(shown, 0, 0, "no such CityGML file")) from None
    except OSError as exc:
        raise BgrError(Diagnostic(shown, 0, 0, f"cannot read the CityGML file: {exc}")) from None
    try:
        raw = parse_citygml(data, shown)
        polygons = _levels(raw.polygons, lod, shown)
        materials, sources, of_target = _appearances(raw, theme, resolved(path).parent, shown)
        mesh = _mesh(polygons, materials, sources, of_target, raw, shown)
    except (ValueError, TypeError, IndexError, KeyError, OverflowError, RecursionError) as exc:
        # the reader turns what it expects into located messages; this is what it did not
        raise BgrError(
            Diagnostic(shown, 0, 0, f"cannot read the CityGML file: {str(exc)[:200]}")
        ) from None
    mesh.crs, mesh.source = raw.crs, shown
    return mesh


def _levels(polygons: list[RawPolygon], lod: int | None, shown: str) -> list[RawPolygon]:
    """The polygons of one level of detail per object: ``lod``, or each object's highest."""
    if not polygons:
        raise BgrError(Diagnostic(shown, 0, 0, "the file has no polygons (gml:Polygon) to read"))
    if lod is not None:
        kept = [p for p in polygons if p.lod == lod]
        if not kept:
            have = sorted({p.lod for p in polygons if p.lod >= 0})
            raise BgrError(
                Diagnostic(
                    shown,
                    0,
                    0,
                    f"the file has no LoD {lod} geometry",
                    f"it has LoD {', '.join(map(str, have))}" if have else None,
                )
            )
        return kept
    best: dict[str, int] = {}
    for p in polygons:
        best[p.object] = max(best.get(p.object, -1), p.lod)
    return [p for p in polygons if p.lod == best[p.object]]


def _appearances(
    raw: RawCity, theme: str | None, folder: Path, shown: str
) -> tuple[list[Material], list[RawTexture | None], dict[str, list[int]]]:
    """The materials (textures, then X3D materials, in file order), the ParameterizedTexture
    of each (None: an X3D material) and, per target id, the materials that target it."""
    materials: list[Material] = []
    sources: list[RawTexture | None] = []
    of_target: dict[str, list[int]] = {}
    for texture in raw.textures:
        if theme is None or texture.theme == theme:
            for target in texture.targets:
                of_target.setdefault(target, []).append(len(materials))
            materials.append(_texture_material(texture, folder, shown, raw))
            sources.append(texture)
    for k, m in enumerate(raw.materials):
        if theme is None or m.theme == theme:
            for target in m.targets:
                of_target.setdefault(target, []).append(len(materials))
            alpha = min(max(1.0 - m.transparency, 0.0), 1.0)
            r, g, b = (min(max(c, 0.0), 1.0) for c in m.diffuse)
            materials.append(
                Material(m.id or f"X3DMaterial {k + 1}", (r, g, b, alpha), wrap="none")
            )
            sources.append(None)
    return materials, sources, of_target


def _texture_material(texture: RawTexture, folder: Path, shown: str, raw: RawCity) -> Material:
    """A ParameterizedTexture's material, its image checked to lie inside ``folder``."""
    uri = texture.image_uri
    if not uri:
        raise BgrError(
            Diagnostic(shown, texture.line, 1, "an app:ParameterizedTexture has no app:imageURI")
        )
    try:
        image: Path | None = image_path(folder, uri)
    except ValueError as exc:
        raise BgrError(
            Diagnostic(
                shown,
                *texture.image_at,
                f"texture image {quoted(uri)} {exc}",
                "bgr reads texture images from the CityGML file's folder and below",
            )
        ) from None
    if image is not None and not image.is_file():
        raw.warnings.append(
            Diagnostic(
                shown,
                *texture.image_at,
                f"texture image {quoted(uri)} is missing: its surfaces are left untextured",
                severity="warning",
            )
        )
        image = None
    wrap = texture.wrap if texture.wrap in WRAPS else "none"
    return Material(uri, image=image, wrap=wrap)


def _mesh(
    polygons: list[RawPolygon],
    materials: list[Material],
    textures: list[RawTexture | None],
    of_target: dict[str, list[int]],
    raw: RawCity,
    shown: str,
) -> TexturedMesh:
    """Triangles, per-corner UVs and per-face tables of ``polygons``."""
    semantic_names: dict[str, int] = {}
    object_ids: dict[str, int] = {}
    verts, faces, uvs, mats, sems, objs, surf = [], [], [], [], [], [], []
    count = 0
    for s, poly in enumerate(polygons):
        points = np.concatenate(poly.rings)
        starts = np.cumsum([0] + [len(r) for r in poly.rings])
        rings = [list(range(a, b)) for a, b in zip(starts[:-1], starts[1:], strict=True)]
        tri = _triangulate(points, rings)
        material, uv = _look(poly, of_target, textures, raw, shown)
        verts.append(points)
        faces.append(tri + count)
        uvs.append(uv[tri] if uv is not None else np.zeros((len(tri), 3, 2)))
        n = len(tri)
        mats.append(np.full(n, material, dtype=np.int64))
        sems.append(np.full(n, semantic_names.setdefault(poly.semantic, len(semantic_names))))
        objs.append(np.full(n, object_ids.setdefault(poly.object, len(object_ids))))
        surf.append(np.full(n, s, dtype=np.int64))
        count += len(points)
    return TexturedMesh(
        vertices=np.concatenate(verts),
        faces=np.concatenate(faces).astype(np.int64),
        uv=np.concatenate(uvs).reshape(-1, 3, 2),
        material=np.concatenate(mats),
        materials=materials,
        semantic=np.concatenate(sems).astype(np.int64),
        semantic_names=list(semantic_names),
        object=np.concatenate(objs).astype(np.int64),
        object_ids=list(object_ids),
        surface=np.concatenate(surf),
        surface_ids=[p.id or "" for p in polygons],
        up="z",
        warnings=raw.warnings,
    )


def _look(
    poly: RawPolygon,
    of_target: dict[str, list[int]],
    textures: list[RawTexture | None],
    raw: RawCity,
    shown: str,
) -> tuple[int, np.ndarray | None]:
    """(material index or -1, the polygon's UVs (n, 2) in ring order or None) of a polygon:
    the first texture or material that targets it or a surface above it."""
    candidates = [m for owner in poly.owners for m in of_target.get(owner, [])]
    for m in sorted(candidates, key=lambda m: textures[m] is None):  # textures first (stable)
        texture = textures[m]
        if texture is None:
            return m, None
        uv = _ring_uvs(poly, texture, raw, shown)
        if uv is not None:
            return m, uv
    return -1, None


def _ring_uvs(poly: RawPolygon, texture: RawTexture, raw: RawCity, shown: str) -> np.ndarray | None:
    """The polygon's UVs from a texture's TexCoordList, one per ring point (a list that repeats
    the closing point has it dropped); None, with a warning, where a ring has none or a list
    of another length."""
    parts = []
    for ring, rid in zip(poly.rings, poly.ring_ids, strict=True):
        coords = texture.coords.get(rid or "")
        if coords is not None and len(coords) == len(ring) + 1:
            coords = coords[:-1]
        if coords is None or len(coords) != len(ring):
            what = "no texture coordinates" if coords is None else f"{len(coords)} coordinates"
            raw.warnings.append(
                Diagnostic(
                    shown,
                    poly.line,
                    1,
                    f"ring {quoted(rid or '(no gml:id)')} has {len(ring)} points but {what} "
                    f"in texture {quoted(texture.image_uri)}: the polygon is left untextured",
                    severity="warning",
                )
            )
            return None
        parts.append(coords)
    return np.concatenate(parts)
