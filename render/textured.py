"""Textured scenes: the images a scene's triangles show, and textured models made into scenes.

A :class:`~.scene_model.Scene` may carry, per triangle, the index of a :class:`Texture` and the
texture coordinates of its three corners; :mod:`.texturing` samples them per pixel.  This module
fills them from the two places textures come from:

* a derivation's terminal table (``tex_rows``, ``tex_maps``, ``tex_uv``; the colour map only:
  the renderer draws flat-shaded triangles, so a normal map is not drawn);
* a :class:`~bgr.formats.textured_model.TexturedMesh` read from a CityGML, OBJ+MTL or glTF
  file.  A z-up model (CityGML) is turned into the renderer's y-up frame, in metres about its
  centre (:func:`local_frame`): a geographic CRS (PLATEAU's EPSG:6697, latitude, longitude and
  height) is projected (pyproj) onto a transverse Mercator centred on the model's bounding box.

Texture coordinates are kept as the model convention has them: (0, 0) at the image's lower-left
corner, v growing upwards (CGA, OBJ, CityGML); the glTF writer's flipped v is undone here.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..grammar.errors import BgrError, Diagnostic
from .scene_model import NO_LABEL, Scene, labels_index

WRAPS = ("wrap", "mirror", "clamp", "border", "none")


@dataclass(eq=False)
class Texture:
    """One decoded image: (H, W, 3) uint8 sRGB, row 0 at the image's top, and how coordinates
    outside 0..1 reach it (``wrap``: repeat, ``mirror``: mirrored repeat, else clamped to the
    edge)."""

    rgb: np.ndarray
    wrap: str = "wrap"
    name: str = ""
    _mipmaps: list | None = field(default=None, repr=False)  # texturing.mipmaps, made once


def decode(data: bytes) -> np.ndarray:
    """(H, W, 3) uint8 RGB of a PNG or JPEG file's bytes (an alpha channel is dropped: the
    renderer draws opaque surfaces).  Raises what Pillow raises for a broken image, and
    ValueError for one of more than MAX_IMAGE_PIXELS (its header is read first)."""
    from ..grammar.textures import open_image

    with open_image(data) as im:
        return np.ascontiguousarray(np.asarray(im.convert("RGB"), dtype=np.uint8))


def table_textures(table, pool, fstart: np.ndarray) -> tuple[np.ndarray, np.ndarray, list]:
    """(texture (T,), uv (T, 3, 2), textures) of a frozen terminal table's baked triangles
    (``fstart``: each row's first face, as :func:`bgr.formats.meshes.bake` made them with
    ``pool``).  Only rows with a colour map are textured; uv are in bake's corner order."""
    from ..formats.meshes import mirrored
    from ..formats.texcoords import corner_uvs

    T = int(fstart[-1])
    texture = np.full(T, -1, dtype=np.int64)
    uv = np.zeros((T, 3, 2), dtype=np.float64)
    if not len(table.tex_rows):
        return texture, uv, []
    maps = np.asarray(table.tex_maps, dtype=np.int64).reshape(-1, 2)[:, 0]
    rows = np.asarray(table.tex_rows, dtype=np.int64)[maps >= 0]
    maps = maps[maps >= 0]
    if not len(rows):
        return texture, uv, []
    used, slot = np.unique(maps, return_inverse=True)
    textures = [
        Texture(decode(table.images[int(k)].data), "wrap", table.images[int(k)].path) for k in used
    ]
    # corner_uvs gives glTF's v (1 - v) in place_corners' order: a mirrored row's unit corners
    # 0, 2, 1, where bake re-winds them 2, 1, 0
    per_corner = corner_uvs(table, rows, pool, 0).astype(np.float64).reshape(-1, 3, 2)
    per_corner[..., 1] = 1.0 - per_corner[..., 1]
    count = fstart[rows + 1] - fstart[rows]
    flip = np.repeat(mirrored(table, rows), count)
    per_corner[flip] = per_corner[flip][:, [1, 2, 0]]
    at = np.repeat(fstart[rows], count) + (
        np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
    )
    uv[at] = per_corner
    texture[at] = np.repeat(slot.reshape(-1), count)
    return texture, uv, textures


def geographic_axes(crs: str | None) -> tuple[Any, int, int] | None:
    """(the geographic CRS, column of longitude, column of latitude) when ``crs`` names a
    geographic CRS (or a compound one on a geographic CRS, as PLATEAU's EPSG:6697 is), read with
    pyproj; None for a projected CRS, no CRS, or one pyproj does not know."""
    if not crs:
        return None
    from pyproj import CRS
    from pyproj.exceptions import CRSError

    try:
        parsed = CRS.from_user_input(crs)
    except (CRSError, ValueError, TypeError):
        return None
    if not parsed.is_geographic:
        return None
    horizontal = parsed.sub_crs_list[0] if parsed.is_compound else parsed
    directions = [a.direction.lower() for a in horizontal.axis_info[:2]]
    if sorted(directions) != ["east", "north"]:
        return None
    return horizontal, directions.index("east"), directions.index("north")


def local_frame(vertices: np.ndarray, up: str, crs: str | None) -> np.ndarray:
    """(V, 3) vertices in the renderer's frame (x east, y up, z south: y up, right-handed), in
    metres about the centre of their bounding box.

    A y-up model (glTF, OBJ) is kept as it is.  A z-up model in projected metres (or a CRS pyproj
    does not know) is moved to its centre and turned to y up.  A z-up model in a geographic CRS
    (degrees, height in metres: PLATEAU's EPSG:6697 is latitude, longitude, height) is projected
    with pyproj onto a transverse Mercator centred there on the CRS's own ellipsoid: a local
    metric frame whose scale error over a city block is under 10^-8; heights are kept.
    ValueError, saying why, for degrees outside -90..90 / -180..180 or a model too large to
    project (pyproj refused such a centre with a CRSError, or made infinite coordinates)."""
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    if up != "z" or not len(v):
        return v
    centre = (v.min(axis=0) + v.max(axis=0)) / 2.0
    geographic = geographic_axes(crs)
    if geographic is None:
        east, north = v[:, 0] - centre[0], v[:, 1] - centre[1]
    else:
        from pyproj import CRS, Transformer

        source, lon, lat = geographic
        if not ((np.abs(v[:, lat]) <= 90.0).all() and (np.abs(v[:, lon]) <= 180.0).all()):
            raise ValueError(
                f"coordinates outside latitude -90..90 or longitude -180..180, but the CRS "
                f"{str(crs)[:100]!r} is geographic (degrees)"
            )
        lat0, lon0 = float(centre[lat]), float(centre[lon])
        local = CRS.from_proj4(
            f"+proj=tmerc +lat_0={lat0!r} +lon_0={lon0!r} +k=1 +x_0=0 +y_0=0 "
            f"+a={source.ellipsoid.semi_major_metre!r} "
            f"+rf={source.ellipsoid.inverse_flattening!r} +units=m +no_defs"
        )
        to_local = Transformer.from_crs(source, local, always_xy=True)
        east, north = to_local.transform(v[:, lon], v[:, lat])
        east, north = np.asarray(east, dtype=np.float64), np.asarray(north, dtype=np.float64)
        if not (np.isfinite(east).all() and np.isfinite(north).all()):
            raise ValueError(
                f"the model spans too much of the globe to be drawn on a local map of its "
                f"CRS {str(crs)[:100]!r}"
            )
    return np.column_stack([east, v[:, 2], -north])


def mesh_textures(mesh, shown: str) -> tuple[np.ndarray, list, list[Diagnostic]]:
    """(texture index per face, textures, warnings) of a TexturedMesh: each material with an
    image decoded once; one that cannot be read or decoded is a warning, its faces drawn in
    the material's colour."""
    index = np.full(len(mesh.materials) + 1, -1, dtype=np.int64)  # the last: no material
    textures: list[Texture] = []
    warnings: list[Diagnostic] = []
    used = set(np.unique(mesh.material).tolist())
    for k, material in enumerate(mesh.materials):
        if k not in used or not material.has_image():
            continue
        try:
            rgb = decode(material.image_bytes())
        except Exception as exc:  # noqa: BLE001 - any unreadable image: draw the colour instead
            warnings.append(
                Diagnostic(
                    shown,
                    0,
                    0,
                    f"texture image of material '{material.name[:200]}' cannot be read "
                    f"({_why(exc)}): its faces are drawn in their colour",
                    severity="warning",
                )
            )
            continue
        wrap = material.wrap if material.wrap in WRAPS else "wrap"
        index[k] = len(textures)
        textures.append(Texture(rgb, wrap, material.name))
    return index[mesh.material], textures, warnings


def _why(exc: Exception) -> str:
    """Why an image cannot be read, in a few words: our own ValueError's message (a pixel
    limit), else the exception's type (Pillow's messages quote bytes of the file)."""
    if type(exc) is ValueError:
        return str(exc)[:200]
    return type(exc).__name__


def from_textured_mesh(mesh, shown: str = "") -> Scene:
    """A TexturedMesh as a scene in the renderer's frame (:func:`local_frame`).

    Colours are the materials' (grey 200 where a face has none); a textured face shows its image
    multiplied by that colour, as a glTF viewer shows ``baseColorTexture`` times
    ``baseColorFactor``.  Labels are the surfaces' semantic types where the file has them
    (CityGML's WallSurface, RoofSurface ...), else the material names (``(none)`` without one);
    parts are the polygon or primitive each triangle comes from."""
    try:
        vertices = local_frame(mesh.vertices, mesh.up, mesh.crs)
    except ValueError as exc:
        raise BgrError(
            Diagnostic(
                shown or mesh.source,
                0,
                0,
                f"cannot be drawn: {exc}",
                "check the gml:Envelope's srsName against the coordinates",
            )
        ) from None
    faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    rgb = [np.rint(np.clip(m.color[:3], 0.0, 1.0) * 255.0) for m in mesh.materials]
    table = np.array([*rgb, (200, 200, 200)], dtype=np.uint8).reshape(-1, 3)
    texture, textures, warnings = mesh_textures(mesh, shown or mesh.source)
    if any(mesh.semantic_names):
        names = [name or NO_LABEL for name in mesh.semantic_names]
        label, labels = labels_index(np.asarray(names, dtype=object)[mesh.semantic])
    else:
        names = [m.name or NO_LABEL for m in mesh.materials] + [NO_LABEL]
        label, labels = labels_index(np.asarray(names, dtype=object)[mesh.material])
    return Scene(
        triangles=vertices[faces] if len(faces) else np.zeros((0, 3, 3)),
        colors=table[mesh.material],
        part=np.asarray(mesh.surface, dtype=np.int64).copy(),
        label=label,
        labels=labels,
        warnings=list(mesh.warnings) + warnings,
        uv=np.asarray(mesh.uv, dtype=np.float64).reshape(-1, 3, 2),
        texture=texture,
        textures=textures,
    )
