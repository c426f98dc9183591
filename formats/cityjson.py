"""CityJSON 2.0 (``.city.json``) and CityJSON Text Sequences (``.city.jsonl``): the writer, and a
reader that gives each city object's triangles back (tests, and the inverse modules, read it).

What the writer makes of a terminal table (docs/cli.md, "CityJSON", is the user's version):

- **Axes.** bgr is y up; CityJSON is z up (x east, y north): local bgr (x, y, z) is CityJSON
  (x, -z, y), a rotation, so faces keep their outward winding.  With a site (geographic lots,
  ``TerminalTable.site``) the site's origin is added and ``metadata.referenceSystem`` names its
  CRS; without one the coordinates are the local metres and no CRS is named.
- **Vertices** are integers on a millimetre grid: ``transform`` has scale 0.001 and translates
  by the site's origin plus the lowest corner, and every vertex is stored once (no duplicates,
  none unused).  A triangle whose corners fall on fewer than three distinct grid points, or on
  one line, is left out: it has no area a reader could use.
- **Objects.** One ``Building`` per lot, named by the lot (its feature id, else ``lot-N``;
  ``-2``, ``-3``... added when a name repeats), with the lot's attributes.  When straight cuts
  along the lot's own axes separate its terminals into groups that do not touch in plan (the
  grammar made several masses, as ``examples/city_block.bgr`` does on one lot), each group is a
  ``BuildingPart`` (``{building}-part-{k}``) and holds the geometry; otherwise the Building does.
- **Geometry.** One ``MultiSurface`` per object whose surfaces are bgr's triangles, one each,
  so a file holds exactly the triangles a GLB of the same run holds.  Its lod is "3" when it has
  Window or Door surfaces (openings are LoD 3 in CityGML), else "2".  It is not claimed to be a
  closed Solid: grammar output rarely is.
- **Semantics** per triangle, from the terminal's label, else the triangle's normal: see
  :func:`semantic_of_label` and :func:`semantic_types`.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.grammar.paths import read_input
from bgr.interpreter.terminals import TerminalTable, lot_tables

from .cityjson_checks import check_indices, fan, usable
from .meshes import bake, cross, unit_normals

VERSION = "2.0"
SCALE = 0.001  # metres per integer unit: a millimetre grid
MM = 1000  # integer units per metre (exactly 1 / SCALE)
# points of one surface that repeat an earlier one (a ring must be simple; a keyhole repeats two):
# more, and earcut is not used.  A CityGML posList of a square repeated 1,000 times (4,000 points,
# 4 distinct) took earcut 16 to 20 s, 300 times 0.35 s; the surface is fanned instead
MAX_REPEATED_POINTS = 64

# the semantic surface types CityJSON 2.0 allows on Building and BuildingPart geometry
SEMANTIC_TYPES = (
    "RoofSurface",
    "GroundSurface",
    "WallSurface",
    "ClosureSurface",
    "OuterCeilingSurface",
    "OuterFloorSurface",
    "Window",
    "Door",
    "InteriorWallSurface",
    "CeilingSurface",
    "FloorSurface",
)
ROOF, GROUND, WALL = 0, 1, 2
OUTER_CEILING, WINDOW, DOOR = 4, 6, 7
# words a label may contain, first match wins (so "RoofWindow" is a Window).  The façade's
# details are WallSurface all round: a sill's top is not a roof, a cornice's underside no ceiling
FACADE_DETAILS = ("frame", "sill", "mullion", "shutter", "trim", "cornice", "reveal", "lintel")
LABEL_WORDS = (
    ("window", WINDOW),
    ("glass", WINDOW),
    ("glazing", WINDOW),
    ("door", DOOR),
    ("roof", ROOF),
    ("wall", WALL),
    ("facade", WALL),
    ("façade", WALL),
    ("parapet", WALL),
    *((word, WALL) for word in FACADE_DETAILS),
    ("ground", GROUND),
)
UP = 0.7  # a unit normal whose z is above this faces up (within about 45 degrees)
GROUND_TOL = 0.05  # metres: a down-facing triangle this close to its building's lowest point
PART_GAP = 0.01  # metres: groups of terminals this far apart in plan are separate masses


# --------------------------------------------------------------------------------------------
# semantics


def semantic_of_label(label: str) -> int | None:
    """The semantic type (an index into SEMANTIC_TYPES) a terminal label names, or None when the
    triangle's normal decides.  A label that is a type's name (any case: ``label("RoofSurface")``
    in a grammar) is that type; otherwise the first of LABEL_WORDS the lower-cased label
    contains (``Glass`` and ``ShopWindow`` are Windows, ``GableWall`` and ``Sill`` WallSurfaces)."""
    lower = label.lower()
    for i, name in enumerate(SEMANTIC_TYPES):
        if lower == name.lower():
            return i
    for word, kind in LABEL_WORDS:
        if word in lower:
            return kind
    return None


def semantic_types(
    labels: list[str], row: np.ndarray, normal_z: np.ndarray, top_z: np.ndarray, base: np.ndarray
) -> np.ndarray:
    """(T,) semantic type of each triangle: its terminal's label decides (:func:`semantic_of_
    label`); else its unit normal's z (CityJSON axes) does: above UP a RoofSurface; below -UP a
    GroundSurface when its highest corner (``top_z``) is within GROUND_TOL of ``base`` (its
    building's lowest point), else an OuterCeilingSurface (the underside of an overhang);
    otherwise a WallSurface.  ``row`` is each triangle's terminal, an index into ``labels``."""
    cache: dict[str, int] = {}
    for label in set(labels):
        kind = semantic_of_label(label)
        cache[label] = -1 if kind is None else kind
    by_label = np.fromiter((cache[label] for label in labels), dtype=np.int64, count=len(labels))
    by_normal = np.full(len(row), WALL, dtype=np.int64)
    by_normal[normal_z > UP] = ROOF
    down = normal_z < -UP
    by_normal[down] = np.where(top_z[down] <= base[down] + GROUND_TOL, GROUND, OUTER_CEILING)
    kind = by_label[row]
    return np.where(kind >= 0, kind, by_normal)


def _semantics(kinds: np.ndarray) -> dict:
    """The ``semantics`` of one MultiSurface: one surface object per type present (in
    SEMANTIC_TYPES order), ``values`` one per triangle.  Windows and Doors are children of the
    geometry's WallSurface when it has one, as CityGML puts openings in walls."""
    present = np.unique(kinds)
    surfaces: list[dict[str, Any]] = [{"type": SEMANTIC_TYPES[int(k)]} for k in present]
    at = {int(k): i for i, k in enumerate(present)}
    openings = [at[k] for k in (WINDOW, DOOR) if k in at]
    if WALL in at and openings:
        surfaces[at[WALL]]["children"] = openings
        for i in openings:
            surfaces[i]["parent"] = at[WALL]
    return {"surfaces": surfaces, "values": np.searchsorted(present, kinds)}


# --------------------------------------------------------------------------------------------
# the table as triangles on the millimetre grid


@dataclass
class Triangles:
    """The table's triangles with an area, in CityJSON axes (z up), in table order."""

    mm: np.ndarray  # (T, 3, 3) int64: corners on the local millimetre grid
    row: np.ndarray  # (T,) the terminal each came from
    kind: np.ndarray  # (T,) semantic type, an index into SEMANTIC_TYPES


def to_cityjson_axes(points: np.ndarray) -> np.ndarray:
    """bgr's y-up (x, y, z) as CityJSON's z-up (x, -z, y); the last axis holds the coordinates."""
    return np.stack([points[..., 0], -points[..., 2], points[..., 1]], axis=-1)


def from_cityjson_axes(points: np.ndarray) -> np.ndarray:
    """CityJSON's z-up (x, y, z) as bgr's y-up (x, z, -y): the inverse of to_cityjson_axes."""
    return np.stack([points[..., 0], points[..., 2], -points[..., 1]], axis=-1)


def triangles(table: TerminalTable, lots: list[dict]) -> Triangles:
    """Every terminal's triangles (:func:`meshes.bake`), on the grid, degenerate ones left out,
    with their semantic types (the lowest point of each lot is its ground)."""
    table.freeze()
    baked = bake(table)
    corners = to_cityjson_axes(baked.vertices)[baked.faces]  # (T, 3, 3) float, local metres
    row = np.repeat(np.arange(len(table), dtype=np.int64), np.diff(baked.fstart))
    mm = np.rint(corners * MM).astype(np.int64)
    # fewer than three distinct grid points, or three in a line: no area
    twice_area = cross((mm[:, 1] - mm[:, 0]).astype(float), (mm[:, 2] - mm[:, 0]).astype(float))
    keep = np.abs(twice_area).max(axis=1) > 0
    mm, row, corners = mm[keep], row[keep], corners[keep]
    lot_of_row = np.repeat(
        np.arange(len(lots), dtype=np.int64), [end - first for first, end in _ranges(lots)]
    )
    lot = lot_of_row[row]
    base = np.full(len(lots), np.inf)
    np.minimum.at(base, lot, corners[:, :, 2].min(axis=1))
    normal_z = unit_normals(corners)[:, 2]
    kind = semantic_types(table.label, row, normal_z, corners[:, :, 2].max(axis=1), base[lot])
    return Triangles(mm, row, kind)


# --------------------------------------------------------------------------------------------
# buildings and their parts


@dataclass
class CityObjectPlan:
    """One city object to write: its id, type and links, attributes, and its triangles (indices
    into Triangles)."""

    id: str
    type: str
    triangles: np.ndarray
    attributes: dict = field(default_factory=dict)
    parents: list[str] = field(default_factory=list)
    children: list[str] = field(default_factory=list)


def _ranges(lots: list[dict]) -> list[tuple[int, int]]:
    return [(int(lot["rows"][0]), int(lot["rows"][1])) for lot in lots]


def lots_of(table: TerminalTable, attrs: dict) -> list[dict]:
    """The table's lots, which must cover its terminals in order (derive makes them so); a table
    built without lots is one lot, ``lot-0``, with the run's attrs."""
    if not table.lots:
        return [{"rows": [0, len(table)], "name": "lot-0", "attrs": attrs, "properties": {}}]
    at = 0
    for first, end in _ranges(table.lots):
        if first != at or end < first:
            break
        at = end
    if at != len(table):
        raise BgrError(
            "cannot write CityJSON: the table's lots do not cover its terminals in order "
            f"(rows 0..{len(table)}); a table made by bgr.derive always does"
        )
    return table.lots


def plan(
    table: TerminalTable, tris: Triangles, lots: list[dict], taken: set[str] | None = None
) -> list[list[CityObjectPlan]]:
    """Per lot, its Building first, then its BuildingParts (see the module's docstring).
    ``taken``: the object ids the file already holds (a file written lot by lot)."""
    starts = np.searchsorted(tris.row, [first for first, _ in _ranges(lots)] + [len(table)])
    taken = set() if taken is None else taken
    out = []
    for i, lot in enumerate(lots):
        name = _unique(str(lot.get("name") or f"lot-{i}"), taken)
        attributes = {**_json_safe(lot.get("properties") or {}), **_json_safe(lot.get("attrs", {}))}
        mine = np.arange(starts[i], starts[i + 1], dtype=np.int64)
        groups = _masses(tris, mine, lot.get("axes"))
        building = CityObjectPlan(name, "Building", mine, attributes)
        if len(groups) <= 1:
            out.append([building])
            continue
        building.triangles = np.zeros(0, dtype=np.int64)
        parts = [
            CityObjectPlan(_unique(f"{name}-part-{k}", taken), "BuildingPart", g, parents=[name])
            for k, g in enumerate(groups, start=1)
        ]
        building.children = [p.id for p in parts]
        out.append([building, *parts])
    return out


def _unique(name: str, taken: set[str]) -> str:
    shown, n = name, 1
    while shown in taken:
        n += 1
        shown = f"{name}-{n}"
    taken.add(shown)
    return shown


def _masses(tris: Triangles, mine: np.ndarray, axes: list | None) -> list[np.ndarray]:
    """The lot's triangles grouped by mass: each terminal's plan box (along the lot's own x and
    z axes, world axes without a lot frame) and straight cuts through gaps of more than
    PART_GAP between boxes, along one axis then the other until no cut is left (an XY cut)."""
    if not len(mine):
        return []
    rows, first = np.unique(tris.row[mine], return_index=True)
    if len(rows) == 1:
        return [mine]
    ax = np.array([[1.0, 0.0], [0.0, -1.0]])  # bgr x and z in CityJSON plan (x, y)
    if axes is not None:
        ax = np.array([[axes[0][0], -axes[0][2]], [axes[2][0], -axes[2][2]]], dtype=np.float64)
    plan_xy = tris.mm[mine][:, :, :2].astype(np.float64) / MM @ ax.T  # (t, 3, 2)
    bounds = np.append(first, len(mine))
    lo = np.minimum.reduceat(plan_xy.min(axis=1), first, axis=0)
    hi = np.maximum.reduceat(plan_xy.max(axis=1), first, axis=0)
    groups = []
    pending = [(np.arange(len(rows)), 0, False)]
    while pending:
        members, axis, tried_other = pending.pop()
        pieces = _cut(lo, hi, members, axis) if len(members) > 1 else [members]
        if len(pieces) > 1:
            pending += [(p, 1 - axis, False) for p in pieces]
        elif not tried_other and len(members) > 1:
            pending.append((members, 1 - axis, True))
        else:
            groups.append(np.sort(members))
    groups.sort(key=lambda g: int(g[0]))
    return [np.concatenate([mine[bounds[r] : bounds[r + 1]] for r in g]) for g in groups]


def _cut(lo: np.ndarray, hi: np.ndarray, members: np.ndarray, axis: int) -> list[np.ndarray]:
    """``members`` split where a gap of more than PART_GAP along ``axis`` separates them."""
    order = members[np.argsort(lo[members, axis], kind="stable")]
    reach = np.maximum.accumulate(hi[order, axis])
    gaps = np.flatnonzero(lo[order[1:], axis] > reach[:-1] + PART_GAP) + 1
    return np.split(order, gaps)


def _json_safe(value: Any, depth: int = 0) -> Any:
    """A value as JSON can hold it: non-finite numbers become null, integers beyond 2**63 and
    anything not JSON a string, and lists or objects nested more than 32 deep null."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, np.integer)):
        return int(value) if abs(int(value)) < 2**63 else _text(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if depth >= 32:
        return None
    if isinstance(value, dict):
        return {str(k): _json_safe(v, depth + 1) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_safe(v, depth + 1) for v in value]
    return _text(value)


def _text(value: Any) -> str:
    try:
        return str(value)
    except ValueError:  # an int of more digits than str() converts
        return "a number of thousands of digits"


# --------------------------------------------------------------------------------------------
# writing


@dataclass
class Grid:
    """The shared transform: integer vertex = local millimetres - ``low``."""

    low: np.ndarray  # (3,) int64
    translate: list[float]

    @classmethod
    def of(cls, tris: Triangles, site: dict | None) -> Grid:
        low = tris.mm.reshape(-1, 3).min(axis=0) if len(tris.mm) else np.zeros(3, np.int64)
        origin = [float(v) for v in site["origin"]] if site else [0.0, 0.0, 0.0]
        return cls(low, [round(o + int(lo) / MM, 3) for o, lo in zip(origin, low, strict=True)])

    def transform(self) -> dict:
        return {"scale": [SCALE] * 3, "translate": self.translate}


def reference_system(site: dict | None) -> str | None:
    """The OGC CRS URL of a site's ``EPSG:NNNN``; None without a site or for another authority
    (CityJSON names CRSs by URL, and only EPSG's are common ground)."""
    crs = str(site.get("crs", "")) if site else ""
    match = re.fullmatch(r"EPSG:(\d+)", crs)
    return f"https://www.opengis.net/def/crs/EPSG/0/{match.group(1)}" if match else None


def unique_rows(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(rows, inverse) of a (n, 3) array of integers >= 0, rows in lexicographic order, like
    ``np.unique(points, axis=0, return_inverse=True)`` but packing each row into one int64 when
    the ranges allow it (15 times faster on 3 million rows)."""
    if not len(points):
        return np.zeros((0, 3), dtype=np.int64), np.zeros(0, dtype=np.int64)
    span = [int(v) + 1 for v in points.max(axis=0)]
    if span[0] * span[1] * span[2] >= 2**63:
        rows, inverse = np.unique(points, axis=0, return_inverse=True)
        return rows, inverse.reshape(-1)
    key = (points[:, 0] * span[1] + points[:, 1]) * span[2] + points[:, 2]
    keys, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    return points[first], inverse.reshape(-1)


def _rows_text(rows: np.ndarray, pattern: str) -> str:
    """A JSON array of integer rows, each written by ``pattern`` (``"[%d,%d,%d]"``): printf
    formatting in C, some five times faster than json.dumps of nested lists."""
    if not len(rows):
        return "[]"
    return "[" + ((pattern + ",") * len(rows) % tuple(rows.ravel().tolist()))[:-1] + "]"


def _dumps(value: Any) -> str:
    return json.dumps(value, ensure_ascii=False, allow_nan=False, separators=(",", ":"))


def _objects(objs: list[CityObjectPlan], tris: Triangles, grid: Grid) -> tuple[str, np.ndarray]:
    """(the CityObjects member's JSON text, vertices) of some objects: the vertices their
    triangles use, each once.  The large arrays are written as text directly."""
    used = np.concatenate([o.triangles for o in objs]) if objs else np.zeros(0, np.int64)
    points = tris.mm[used].reshape(-1, 3) - grid.low
    low = points.min(axis=0) if len(points) else np.zeros(3, np.int64)
    vertices, inverse = unique_rows(points - low)  # it packs numbers >= 0
    vertices = vertices + low
    index = inverse.reshape(-1, 3)
    items, at = [], 0
    for o in objs:
        item: dict[str, Any] = {"type": o.type}
        if o.attributes:
            item["attributes"] = o.attributes
        if o.parents:
            item["parents"] = o.parents
        if o.children:
            item["children"] = o.children
        text = _dumps(item)
        n = len(o.triangles)
        if n:
            kinds = tris.kind[o.triangles]
            semantics = _semantics(kinds)
            lod = "3" if np.isin(kinds, (WINDOW, DOOR)).any() else "2"
            geometry = (
                f'{{"type":"MultiSurface","lod":"{lod}",'
                f'"boundaries":{_rows_text(index[at : at + n], "[[%d,%d,%d]]")},'
                f'"semantics":{{"surfaces":{_dumps(semantics["surfaces"])},'
                f'"values":{_rows_text(semantics["values"][:, None], "%d")}}}}}'
            )
            text = text[:-1] + f',"geometry":[{geometry}]}}'
        at += n
        items.append(f"{_dumps(o.id)}:{text}")
    return "{" + ",".join(items) + "}", vertices


def _prepare(table: TerminalTable, attrs: dict) -> tuple[Triangles, list, Grid, str]:
    """The triangles, the buildings' plans, the grid and the text of the members every
    document of the table starts with (type, version, transform, metadata)."""
    table.freeze()
    lots = lots_of(table, attrs)
    tris = triangles(table, lots)
    grid = Grid.of(tris, table.site)
    head: dict[str, Any] = {"type": "CityJSON", "version": VERSION, "transform": grid.transform()}
    metadata: dict[str, Any] = {}
    crs = reference_system(table.site)
    if crs:
        metadata["referenceSystem"] = crs
    if len(tris.mm):
        flat = tris.mm.reshape(-1, 3)
        low, high = (flat.min(axis=0) - grid.low), (flat.max(axis=0) - grid.low)
        metadata["geographicalExtent"] = [
            round(float(v) * SCALE + t, 3)
            for v, t in zip([*low, *high], grid.translate * 2, strict=True)
        ]
    if metadata:
        head["metadata"] = metadata
    return tris, plan(table, tris, lots), grid, _dumps(head)[:-1]


def write_cityjson(table: TerminalTable, stream: BinaryIO, *, seed: int, attrs: dict) -> None:
    """The whole table as one CityJSON 2.0 document (the module's docstring says how)."""
    tris, buildings, grid, head = _prepare(table, attrs)
    objects, vertices = _objects([o for b in buildings for o in b], tris, grid)
    text = f'{head},"CityObjects":{objects},"vertices":{_rows_text(vertices, "[%d,%d,%d]")}}}\n'
    stream.write(text.encode("utf-8"))


def write_cityjsonseq(table: TerminalTable, stream: BinaryIO, *, seed: int, attrs: dict) -> None:
    """CityJSON Text Sequences (:class:`SequenceWriter`), the table's lots one by one."""
    writer = SequenceWriter(stream, site=table.site)
    for part in lot_tables(table):
        writer.add(part, attrs)


class SequenceWriter:
    """CityJSON Text Sequences written as lots come: a first line that is a CityJSON object
    with no objects and no vertices, then one ``CityJSONFeature`` per Building (with its
    parts), each with its own vertices.

    The first line's ``transform`` holds for every line, so it is fixed before any lot is seen:
    it translates by the site's origin (0, 0, 0 without a site) and vertices are millimetres
    from there (negative where a building lies west, south or below it).  The metadata names
    the CRS but leaves out ``geographicalExtent``, which only the last lot would settle (it is
    optional).  Object ids stay unique across the file (``-2``, ``-3``... as in one document).
    """

    def __init__(self, stream: BinaryIO, *, site: dict | None) -> None:
        self.stream = stream
        origin = [float(v) for v in site["origin"]] if site else [0.0, 0.0, 0.0]
        self.grid = Grid(np.zeros(3, dtype=np.int64), origin)
        self.taken: set[str] = set()
        head: dict[str, Any] = {
            "type": "CityJSON",
            "version": VERSION,
            "transform": self.grid.transform(),
        }
        crs = reference_system(site)
        if crs:
            head["metadata"] = {"referenceSystem": crs}
        stream.write(f'{_dumps(head)[:-1]},"CityObjects":{{}},"vertices":[]}}\n'.encode())

    def add(self, table: TerminalTable, attrs: dict) -> None:
        """Write the Buildings of a table's lots (a table without lots is one, ``lot-0``)."""
        table.freeze()
        lots = lots_of(table, attrs)
        tris = triangles(table, lots)
        for objs in plan(table, tris, lots, self.taken):
            objects, vertices = _objects(objs, tris, self.grid)
            text = (
                f'{{"type":"CityJSONFeature","id":{_dumps(objs[0].id)},"CityObjects":{objects},'
                f'"vertices":{_rows_text(vertices, "[%d,%d,%d]")}}}\n'
            )
            self.stream.write(text.encode("utf-8"))


# --------------------------------------------------------------------------------------------
# reading


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
