"""The terminal table: one row per terminal shape, as numpy arrays, and the unit meshes they use.

Terminals are data, not objects.  While deriving, rows are appended to Python lists (cheap);
``TerminalTable.freeze()`` turns them into arrays once.  Every terminal points at a *unit mesh*:
vertices in unit scope coordinates (each axis 0..1 of the scope's size), so that one mesh serves
every terminal of that shape — all the window quads of a city share one — and the writers
transform them in bulk (``world = origin + (v * size) @ axes``) or instance them.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Any

import numpy as np

_NO_MAP = (0.0,) * 8  # the affine map of a texture without coordinates: (0, 0) everywhere


@dataclass
class UnitMesh:
    """Triangles in unit scope coordinates.  ``name`` is what the JSON's ``geometry`` says.

    An inserted asset with a texture of its own keeps it here: ``uv`` its texture coordinates
    per triangle corner (v up, as CGA has them) and ``image`` the picture
    (grammar.textures.Image); a terminal whose shape sets no colour map of its own shows them
    (TerminalTable.tex_own)."""

    name: str
    vertices: np.ndarray  # (V, 3) float64, in [0, 1] per scope axis
    faces: np.ndarray  # (F, 3) int32, counter-clockwise seen from outside
    uv: np.ndarray | None = None  # (F, 3, 2) float64, per corner; None: no coordinates
    image: Any = None  # grammar.textures.Image of the asset's colour map, or None

    def __post_init__(self) -> None:
        self.vertices = np.ascontiguousarray(self.vertices, dtype=np.float64).reshape(-1, 3)
        self.faces = np.ascontiguousarray(self.faces, dtype=np.int32).reshape(-1, 3)
        if self.uv is not None:
            self.uv = np.ascontiguousarray(self.uv, dtype=np.float64).reshape(-1, 3, 2)


class MeshLibrary:
    """Unit meshes by id; identical meshes (same name and bytes) are stored once."""

    def __init__(self) -> None:
        self.meshes: list[UnitMesh] = []
        self._index: dict[tuple, int] = {}

    @staticmethod
    def key(mesh: UnitMesh) -> tuple:
        """What makes two meshes the same one: name, and vertices, faces (and an asset's
        texture coordinates and image) to 12 decimals."""
        key: tuple = (mesh.name, mesh.vertices.round(12).tobytes(), mesh.faces.tobytes())
        if mesh.uv is not None:  # a textured asset is another mesh than its bare shape
            key += (mesh.uv.round(12).tobytes(), getattr(mesh.image, "path", None))
        return key

    def add(self, mesh: UnitMesh, key: tuple | None = None) -> int:
        if key is None:
            key = self.key(mesh)
        found = self._index.get(key)
        if found is None:
            found = self._index[key] = len(self.meshes)
            self.meshes.append(mesh)
        return found


def _floats(rows: list, shape: tuple[int, ...]) -> np.ndarray:
    """Rows of nested float sequences as one (N, *shape) array: flattened through an
    iterator, twice as fast as ``np.asarray`` on the nested lists (0.11 s -> 0.05 s for the
    axes of 250,000 terminals), which stays the fallback for anything irregular."""
    width = int(np.prod(shape))
    flat = itertools.chain.from_iterable(rows)
    if len(shape) == 2:
        flat = itertools.chain.from_iterable(flat)
    try:
        data = np.fromiter(flat, dtype=np.float64, count=len(rows) * width)
    except (ValueError, TypeError):
        data = np.asarray(rows, dtype=np.float64)
    return data.reshape(-1, *shape)


def _shared_floats(rows: list, shape: tuple[int, ...]) -> np.ndarray:
    """:func:`_floats` of rows that are mostly the same few objects (the axes: every copy of a
    shape, and every replayed row, holds its parent's tuple): each distinct object converted
    once and gathered by identity (Helsinki: 730,863 rows of axes, 0.18 s -> 0.06 s)."""
    if not rows:
        return _floats(rows, shape)
    ids = np.fromiter(map(id, rows), dtype=np.int64, count=len(rows))
    _, first, where = np.unique(ids, return_index=True, return_inverse=True)
    if 2 * len(first) > len(rows):  # mostly distinct: nothing to share
        return _floats(rows, shape)
    return _floats([rows[i] for i in first.tolist()], shape)[where.reshape(-1)]


@dataclass
class TerminalTable:
    """Columns of the terminal list (LANGUAGE.md section 11), in derivation order."""

    label: list[str] = field(default_factory=list)
    rule: list[str] = field(default_factory=list)
    path: list[str] = field(default_factory=list)
    origin: Any = field(default_factory=list)  # a list while deriving; frozen: (N, 3)
    axes: Any = field(
        default_factory=list
    )  # a list while deriving; frozen: (N, 3, 3), rows are the unit x, y, z axes
    size: Any = field(default_factory=list)  # a list while deriving; frozen: (N, 3)
    color: Any = field(default_factory=list)  # a list while deriving; frozen: (N, 3) in 0..1
    material: list = field(default_factory=list)  # str or None
    mesh: Any = field(
        default_factory=list
    )  # a list while deriving; frozen: (N,) int32 ids into library
    library: MeshLibrary = field(default_factory=MeshLibrary)
    # per lot: {"path", "origin", "axes", "size"} (its frame), "rows" [first, end) of its
    # terminals, "id" (the feature's, or None), "name" (the id, or "lot-N"), "attrs" (after the
    # feature's overrides), "properties" (the feature's)
    lots: list = field(default_factory=list)
    # where local metres are on Earth, for geographic lots: {"crs": "EPSG:32635", "origin":
    # [easting, northing, height]}: local x is easting - origin, local -z northing - origin
    site: dict | None = None
    grammar: str = ""  # the grammar's file (or "<string>"): the glTF root's extras name it
    # textures (operations/texturing.py): each distinct image file once (grammar.textures.Image)
    images: list = field(default_factory=list)
    # the rows that carry a texture map, in order; frozen: (K,) int64
    tex_rows: Any = field(default_factory=list)
    # their (colour map, normal map) image indices, -1 for none; frozen: (K, 2) int32
    tex_maps: Any = field(default_factory=list)
    # their texture coordinates for the colour map (uv-set 0) and the normal map (uv-set 5, or 0
    # when 5 has none) as affine maps: while deriving from WORLD points (16 floats a row), frozen
    # from UNIT scope coordinates, (K, 2, 2, 4): uv = M[:, :3] @ v + M[:, 3] for a unit vertex v
    tex_uv: Any = field(default_factory=list)
    # whether the colour map's coordinates are the unit mesh's own (an inserted asset's uv,
    # UnitMesh.uv) instead of tex_uv's map; frozen: (K,) bool
    tex_own: Any = field(default_factory=list)
    frozen: bool = False
    # add_image's index: (the images list it was built for, its length then, path -> index)
    _image_at: tuple = field(default=(None, 0, None), init=False, repr=False, compare=False)

    def __len__(self) -> int:
        return len(self.label)

    def freeze(self) -> TerminalTable:
        if not self.frozen:
            self.origin = _floats(self.origin, (3,))
            self.axes = _shared_floats(self.axes, (3, 3))
            self.size = _floats(self.size, (3,))
            self.color = _floats(self.color, (3,))
            self.mesh = np.asarray(self.mesh, dtype=np.int32).reshape(-1)
            self.tex_rows = np.asarray(self.tex_rows, dtype=np.int64).reshape(-1)
            self.tex_maps = np.asarray(self.tex_maps, dtype=np.int32).reshape(-1, 2)
            self.tex_own = np.asarray(self.tex_own, dtype=bool).reshape(-1)
            self.tex_uv = unit_maps(
                np.asarray(self.tex_uv, dtype=np.float64).reshape(-1, 2, 2, 4),
                self.origin[self.tex_rows],
                self.axes[self.tex_rows],
                self.size[self.tex_rows],
            )
            self.frozen = True
        return self

    def add_image(self, image) -> int:
        """The index of a texture image, each distinct file (resolved path) stored once: looked
        up by path in a dict, not by a scan of ``images`` (a style sheet's derivation adds
        1,300 crops, and a scan per crop was a tenth of its time).  The dict is rebuilt when
        ``images`` was replaced or grown by another hand (``texture_part`` shares a list)."""
        images = self.images
        owner, count, at = self._image_at
        if owner is not images or count != len(images):
            at = {}
            for k, known in enumerate(images):
                at.setdefault(known.path, k)
        found = at.get(image.path)
        if found is None:
            found = at[image.path] = len(images)
            images.append(image)
        self._image_at = (images, len(images), at)
        return found

    def add_texturing(self, row: int, tex, own: int = -1) -> None:
        """Record the texture maps and coordinates of terminal ``row`` (a shape's
        ``texturing.Texturing``, or None); a shape without a texture map writes nothing here.
        ``own``: the image of the row's unit mesh (an inserted asset's texture), shown with the
        mesh's own coordinates when the shape sets no colour map (CGA: a material attribute set
        on the shape overrides the asset's)."""
        if tex is None:
            color_map = normal_map = -1
            color = normal = _NO_MAP
        else:
            color_map, normal_map, uv = tex.color, tex.normal, tex.uv
            color = uv[0] or _NO_MAP
            normal = uv[5] or color
        if color_map < 0 and normal_map < 0 and own < 0:
            return
        # flat lists while deriving: numpy reads a list of floats many times faster than a list
        # of tuples when the table is frozen
        self.tex_rows.append(row)
        self.tex_own.append(color_map < 0 and own >= 0)
        self.tex_maps += (color_map if color_map >= 0 else own, normal_map)
        self.tex_uv += color
        self.tex_uv += normal

    def textured(self) -> bool:
        return len(self.tex_rows) > 0

    def geometry_names(self) -> list[str]:
        names = [m.name for m in self.library.meshes]
        return [names[i] for i in self.mesh]

    def triangle_count(self) -> int:
        per_mesh = np.array([len(m.faces) for m in self.library.meshes] or [0], dtype=np.int64)
        return int(per_mesh[self.mesh].sum()) if len(self) else 0


def color_hex(rgb) -> str:
    r, g, b = (int(round(min(max(c, 0.0), 1.0) * 255)) for c in rgb)
    return f"#{r:02x}{g:02x}{b:02x}"


def world_vertices(table: TerminalTable, rows: np.ndarray, mesh: UnitMesh) -> np.ndarray:
    """(len(rows), V, 3) world positions of one unit mesh placed at the given terminals."""
    local = mesh.vertices[None, :, :] * table.size[rows][:, None, :]
    return table.origin[rows][:, None, :] + np.einsum("nvk,nkj->nvj", local, table.axes[rows])


def unit_maps(world: np.ndarray, origin: np.ndarray, axes: np.ndarray, size: np.ndarray):
    """Texture maps from world points (K, S, 2, 4) made maps from unit scope coordinates of the
    K terminals: world x = origin + (v * size) @ axes, so uv = (L @ axes.T * size) v + L o + m."""
    lin = world[..., :3]
    out = np.empty_like(world)
    out[..., :3] = np.einsum("ksij,klj->ksil", lin, axes) * size[:, None, None, :]
    out[..., 3] = np.einsum("ksij,kj->ksi", lin, origin) + world[..., 3]
    return out


def texture_part(table: TerminalTable, part: TerminalTable, first: int, end: int) -> None:
    """Give ``part`` (rows first..end of a frozen ``table``) their texturing, rows from 0."""
    part.images = table.images
    keep = (table.tex_rows >= first) & (table.tex_rows < end)
    part.tex_rows = table.tex_rows[keep] - first
    part.tex_maps, part.tex_uv = table.tex_maps[keep], table.tex_uv[keep]
    part.tex_own = table.tex_own[keep]


def lot_tables(table: TerminalTable) -> list[TerminalTable]:
    """The table cut into one table per lot (its ``rows`` range), each with only the unit meshes
    its rows use and its lot's ``rows`` counted from 0: what the streaming writers take, so that
    writing a whole table and writing lots as they are derived give the same bytes.  A table
    without lots is one part."""
    table.freeze()
    if not table.lots:
        return [table]
    parts = []
    for lot in table.lots:
        first, end = (int(v) for v in lot.get("rows", (0, 0)))
        part = TerminalTable(site=table.site, grammar=table.grammar)
        part.label, part.rule, part.path = (
            table.label[first:end],
            table.rule[first:end],
            table.path[first:end],
        )
        part.material = table.material[first:end]
        part.origin, part.axes = table.origin[first:end], table.axes[first:end]
        part.size, part.color = table.size[first:end], table.color[first:end]
        used, local = np.unique(table.mesh[first:end], return_inverse=True)
        part.mesh = local.astype(np.int32).reshape(-1)
        for mesh_id in used:
            part.library.meshes.append(table.library.meshes[int(mesh_id)])
        part.lots = [{**lot, "rows": [0, end - first]}]
        texture_part(table, part, first, end)
        part.frozen = True
        parts.append(part)
    return parts


def concat(
    parts: list[TerminalTable], site: dict | None = None, grammar: str = ""
) -> TerminalTable:
    """One table of several (frozen) ones in order: rows appended, unit meshes merged (equal ones
    stored once, in order of first use), each lot's ``rows`` moved to its place."""
    out = TerminalTable(site=site, grammar=grammar)
    meshes, lots = [], []
    at = 0
    for part in parts:
        part.freeze()
        remap = np.array([out.library.add(m) for m in part.library.meshes] or [0], dtype=np.int32)
        meshes.append(remap[part.mesh] if len(part) else part.mesh)
        out.label += part.label
        out.rule += part.rule
        out.path += part.path
        out.material += part.material
        for lot in part.lots:
            first, end = lot.get("rows", (0, len(part)))
            lots.append({**lot, "rows": [at + int(first), at + int(end)]})
        at += len(part)
    out.lots = lots

    def stacked(column: str, shape: tuple) -> np.ndarray:
        arrays = [getattr(p, column) for p in parts]
        return np.concatenate(arrays) if arrays else np.zeros(shape)

    out.origin, out.axes = stacked("origin", (0, 3)), stacked("axes", (0, 3, 3))
    out.size, out.color = stacked("size", (0, 3)), stacked("color", (0, 3))
    out.mesh = np.concatenate(meshes).astype(np.int32) if meshes else np.zeros(0, np.int32)
    rows, maps, uvs, own = (
        [np.zeros(0, np.int64)],
        [np.zeros((0, 2), np.int32)],
        [np.zeros((0, 2, 2, 4))],
        [np.zeros(0, bool)],
    )
    at = 0
    for part in parts:
        if part.textured():  # image numbers of the part -> of the whole, each file once
            remap = np.array([out.add_image(im) for im in part.images] + [-1], dtype=np.int32)
            rows.append(part.tex_rows + at)
            maps.append(remap[part.tex_maps])  # -1 stays -1: the appended last entry
            uvs.append(part.tex_uv)
            own.append(part.tex_own)
        at += len(part)
    out.tex_rows, out.tex_maps = np.concatenate(rows), np.concatenate(maps).astype(np.int32)
    out.tex_uv, out.tex_own = np.concatenate(uvs), np.concatenate(own)
    out.frozen = True
    return out
