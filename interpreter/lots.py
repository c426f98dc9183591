"""Lots: the shapes the axiom receives — a W x D rectangle, or footprints from GeoJSON.

A lot is a 2D shape in the xz plane (y up, sy = 0) whose scope has x along the footprint's front
edge (the street side: its first edge, or the one :class:`LotOptions` chooses) and z pointing into
the lot (LANGUAGE.md section 4).  A footprint's inner rings (courtyards) are holes of its shape.

Footprints from real data (OpenStreetMap, cadastres) are rarely clean: rings that cross
themselves, repeated and collinear corners, slivers of no width, coordinates as longitude and
latitude, numbers written as strings.  :func:`read_geojson` makes each feature a usable lot or
skips it with one warning naming it (docs/cli.md, "Lots", states the rules), so that one bad
feature among thousands does not stop a run.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import shapely
from shapely.geometry import Polygon

from bgr.grammar.errors import BgrError, Diagnostic, HeldWarnings, Warnings, read_json

from .geometry.polygons import RECT, is_unit_square, normalise, signed_area
from .outline import CLEAN_TOL, FootprintError, clean_ring
from .outline import lengths as _lengths
from .shapes import IDENTITY, Flat, Shape
from .values import MAX_COORDINATE, is_number, number_of, number_problem

DEFAULT_LOT = (20.0, 20.0)

# GeoJSON's own CRS (RFC 7946): longitude, latitude on WGS84
CRS84 = "OGC:CRS84"


@dataclass
class Lot:
    shape: Shape
    properties: dict = field(default_factory=dict)
    name: str = ""  # how messages name it, e.g. "feature 12 (id 4253124)"; "" for --lot W,D
    source: str = ""  # the file it came from, where property warnings point
    feature_id: str | None = None  # the GeoJSON feature's id (or "id" property), as a string
    feature: int | None = None  # its feature's index in the file: warnings come in that order
    # where its local metres are on Earth, for lots of a file with a known CRS (see _project):
    # {"crs": "EPSG:32635", "origin": [easting, northing, height]}; None for plain metres
    site: dict | None = None
    # attr -> value that --map gave this lot from its properties, coerced at read time (see
    # PropertyMap); attr_overrides applies them over the properties of the attrs' own names
    mapped: dict = field(default_factory=dict)


# --------------------------------------------------------------------------------------------
# options: which edge is the front, which properties feed which attrs

FRONTS = ("first", "longest", "street")
MAP_TYPES = ("int", "float", "str", "bool")
STREET_TIE = CLEAN_TOL  # metres: edges whose midpoints are this close to equally near tie


@dataclass(frozen=True)
class PropertyMap:
    """``--map ATTR=PROP[:TYPE]``: the feature property ``prop`` gives the attr ``attr``.

    ``type`` coerces the value when the file is read (:func:`coerce`): ``int`` (a number or a
    string that is one, rounded to the nearest whole number, halves away from zero: "3.5" is 4),
    ``float``, ``bool`` (true/false, yes/no, 1/0) or ``str`` (any single value); None passes the
    value as it is, for the attr's own type to judge, as a property of the attr's name is."""

    attr: str
    prop: str
    type: str | None = None

    def __str__(self) -> str:
        return f"{self.attr}={self.prop}" + (f":{self.type}" if self.type else "")


@dataclass(frozen=True)
class LotOptions:
    """How a GeoJSON lot file becomes lots (``bgr derive --front``, ``--map``).

    ``front``: ``first`` (the outline's first edge, the default), ``longest`` (its longest edge
    once cleaned) or ``street`` (the edge whose midpoint is nearest to a line of the GeoJSON file
    ``streets``; on a tie within a millimetre, the longer edge).  ``mapping``: the properties that
    give attrs, applied over the properties of the attrs' own names."""

    front: str = "first"
    streets: str | None = None
    mapping: tuple[PropertyMap, ...] = ()

    def __post_init__(self) -> None:
        if self.front not in FRONTS:
            raise BgrError(f"front must be one of {', '.join(FRONTS)}, got {_shown(self.front)}")
        if (self.front == "street") != (self.streets is not None):
            raise BgrError("front 'street' needs a street file (streets=...), and only it does")
        if not all(isinstance(m, PropertyMap) for m in self.mapping):
            raise BgrError("mapping must be a tuple of PropertyMap (see parse_map)")


def parse_map(text: str) -> PropertyMap:
    """``NAME=PROPERTY[:TYPE]`` as ``--map`` takes it.  A property name may hold colons
    (``building:levels``): the last ``:``-segment is the TYPE only when it is one of int, float,
    str, bool (``floors=building:levels:int``)."""
    name, sep, prop = text.partition("=")
    name, prop = name.strip(), prop.strip()
    kind = None
    head, colon, tail = prop.rpartition(":")
    if colon and tail in MAP_TYPES:
        prop, kind = head, tail
    if not sep or not name or not prop:
        raise BgrError(
            Diagnostic(
                "",
                0,
                0,
                f"--map {text[:60]}: write NAME=PROPERTY[:TYPE]",
                "NAME is an attr of the grammar, PROPERTY a property of the lot file's "
                "features, TYPE int, float, str or bool: --map floors=building:levels:int",
            )
        )
    return PropertyMap(name, prop, kind)


def parse_front(text: str) -> tuple[str, str | None]:
    """``first``, ``longest`` or ``street:LINES.geojson`` as ``--front`` takes it: the front
    and the street file (None but for ``street``)."""
    if text in ("first", "longest"):
        return text, None
    kind, colon, path = text.partition(":")
    if kind == "street" and colon and path:
        return "street", path
    raise BgrError(
        Diagnostic(
            "",
            0,
            0,
            f"--front {text[:60]}: write first, longest or street:LINES.geojson",
            "street:FILE takes the edge nearest to a LineString of FILE (same CRS as the lots)",
        )
    )


def check_mapping(options: LotOptions | None, attrs, path: str = "") -> None:
    """A BgrError, as ``--set`` gives, when ``--map`` names an attr the grammar does not have."""
    from bgr.grammar.errors import suggest

    for item in options.mapping if options is not None else ():
        if item.attr not in attrs:
            hint = suggest(item.attr, attrs) or (
                "attrs: " + ", ".join(attrs) if attrs else "the grammar declares no attrs"
            )
            raise BgrError(
                Diagnostic(
                    path, 0, 0, f"--map {item}: the grammar has no attr '{item.attr}' to set", hint
                )
            )


def coerce(value, kind: str | None) -> tuple[object, str | None]:
    """``(value, None)`` coerced to a --map TYPE, or ``(None, why)`` when it cannot be (why
    follows "is <value>, ")."""
    if isinstance(value, (dict, list)):
        return None, "not a single value"
    if kind is None:
        return value, None
    if kind in ("int", "float"):
        number = number_of(value) if isinstance(value, str) else value
        if not is_number(number):
            return None, "not a number"
        problem = number_problem(number)
        if problem:
            return None, problem
        if kind == "float":
            return float(number), None
        whole = math.floor(abs(number) + 0.5)  # halves away from zero, as round() in .bgr
        return int(whole if number >= 0 else -whole), None
    if kind == "bool":
        if isinstance(value, bool):
            return value, None
        text = value.strip().lower() if isinstance(value, str) else value
        if text in ("true", "yes", "1", 1):
            return True, None
        if text in ("false", "no", "0", 0):
            return False, None
        return None, "not true/false, yes/no or 1/0"
    if isinstance(value, str):
        return value, None
    if isinstance(value, bool):
        return ("true" if value else "false"), None
    return _shown(value), None


def rectangle(width: float, depth: float) -> Lot:
    """A W x D lot; each side must be a number over 0 and at most MAX_COORDINATE metres."""
    sides = []
    for side in (width, depth):
        try:
            sides.append(float(side))
        except OverflowError:  # an int of more than about 309 digits
            sides.append(math.inf)
    width, depth = sides
    if not all(0 < side <= MAX_COORDINATE for side in sides):  # also refuses nan
        limit = f"{MAX_COORDINATE:.0e}".replace("e+0", "e")
        raise BgrError(
            Diagnostic(
                "",
                0,
                0,
                f"--lot {width:g},{depth:g}: a lot needs a width and depth over 0 and at most "
                f"{limit} metres",
                "write the lot as WIDTH,DEPTH in metres, e.g. 20,30",
            )
        )
    return Lot(Shape((0.0, 0.0, 0.0), IDENTITY, (width, 0.0, depth), Flat(1, RECT)))


def footprint(
    points_xz: list[tuple[float, float]],
    properties: dict | None = None,
    name: str = "",
    holes: list | tuple = (),
) -> Lot:
    """A lot on a polygon given in world (x, z), first edge = front, with ``holes`` (rings in
    world (x, z) inside it: courtyards) cut out of its shape."""
    pts = [tuple(map(float, p)) for p in points_xz]
    if len(pts) > 1 and pts[0] == pts[-1]:
        pts = pts[:-1]
    if len(pts) < 3 or abs(signed_area(pts)) < 1e-9:
        raise BgrError("a footprint needs at least three corners and a non-zero area")
    (x0, z0), (x1, z1) = pts[0], pts[1]
    ex, ez = x1 - x0, z1 - z0
    length = math.hypot(ex, ez)
    xa = (ex / length, 0.0, ez / length)
    za = (-xa[2], 0.0, xa[0])  # z = x cross y with y up: the frame (xa, up, za) is right-handed

    def to_local(ring) -> list[tuple[float, float]]:
        return [
            ((x - x0) * xa[0] + (z - z0) * xa[2], (x - x0) * za[0] + (z - z0) * za[2])
            for x, z in ring
        ]

    local = to_local(pts)
    # z must point into the lot: the interior is left of the first edge (u along it, w = z) when
    # the ring runs counter-clockwise in (u, w); otherwise walk it backwards.  (The mean of the
    # corners, used before, can lie outside a concave outline, on the wrong side of the edge.)
    if signed_area(local) < 0:
        return footprint([pts[1], pts[0], *reversed(pts[2:])], properties, name, holes)
    inner = []
    for hole in holes:
        ring = to_local([tuple(map(float, p)) for p in hole])
        inner.append(tuple(ring if signed_area(ring) < 0 else ring[::-1]))  # holes clockwise
    unit, (u0, w0, width, depth) = normalise([(tuple(local), tuple(inner))])
    origin = (x0 + u0 * xa[0] + w0 * za[0], 0.0, z0 + u0 * xa[2] + w0 * za[2])
    axes = (xa, (0.0, 1.0, 0.0), za)
    geom = Flat(1, RECT if is_unit_square(unit) else [(tuple(unit[0][0]), tuple(unit[0][1]))])
    return Lot(Shape(origin, axes, (width, 0.0, depth), geom), dict(properties or {}), name)


# WIDTHxDEPTH, as --size WxH: two numbers (the .bgr number syntax, checked by number_of) about
# an x; never a file name, whether or not a file of that name exists (write ./20x30 for one)
_BY = re.compile(r"\s*([0-9.][0-9.eE+-]*)\s*[xX]\s*([0-9.][0-9.eE+-]*)\s*")


def names_a_file(value: str) -> bool:
    """Whether a ``--lot`` value names a GeoJSON file (many lots) rather than W,D or WxD."""
    return not (
        _BY.fullmatch(value) or ("," in value and not value.lower().endswith((".json", ".geojson")))
    )


def parse_lot_option(
    value: str, warnings: Warnings | None = None, options: LotOptions | None = None
) -> list[Lot]:
    """``W,D`` (or ``WxD``) or a GeoJSON file of footprints, read with ``options`` (a W x D lot
    takes none).  A value that spells two numbers is always a rectangle, never a file."""
    by = _BY.fullmatch(value)
    if not names_a_file(value):
        parts = [by[1], by[2]] if by else value.split(",")
        sides = [number_of(v) for v in parts]  # ASCII numbers only, as in .bgr
        if len(sides) != 2 or sides[0] is None or sides[1] is None:  # "nan", "1_0", "1e400"
            raise BgrError(
                f"--lot {value[:60]}: write the lot as WIDTH,DEPTH (or WIDTHxDEPTH), two numbers "
                "in metres (e.g. 20,30), or give a GeoJSON file"
            )
        if options is not None and options != LotOptions():
            raise BgrError(
                f"--lot {value[:60]}: --front and --map apply to the footprints of a GeoJSON "
                "lot file, not to a WIDTH,DEPTH rectangle"
            )
        return [rectangle(sides[0], sides[1])]
    return read_geojson(Path(value), warnings, options)


# --------------------------------------------------------------------------------------------
# GeoJSON


def read_geojson(
    path: Path, warnings: Warnings | None = None, options: LotOptions | None = None
) -> list[Lot]:
    """Every Polygon / MultiPolygon feature becomes a lot (each polygon of it, with its holes).

    Longitude/latitude (a legacy ``crs`` member naming a geographic CRS, or, without one, every
    coordinate within +-180, +-90 and the whole set within one degree) are projected to the UTM
    zone of the collection's centre, about a whole-metre origin near it; other coordinates are
    taken as metres (see :func:`_project`); a ``crs`` member naming no CRS bgr can use is an
    error.  East is +x, north is -z.  Each lot's ``site`` says where its metres are on Earth.
    Each outline and hole is cleaned by :func:`clean_ring`; a feature that cannot be used is
    reported to ``warnings`` (one line naming it; an error when strict) and skipped, a hole that
    cannot be used is dropped so.  A file with no usable footprint at all is an error.

    ``options`` (:class:`LotOptions`) choose each lot's front edge and the properties that
    ``--map`` gives attrs: those are coerced here, into ``Lot.mapped``, and a value that cannot
    be is reported as a warning naming the feature.
    """
    shown = str(path)
    warnings = warnings if warnings is not None else Warnings()
    options = options if options is not None else LotOptions()
    data = read_json(path, "lot file", "--lot takes W,D (or WxD) in metres, or a GeoJSON file")
    features = _features(data, shown, "lot file")
    crs = _legacy_crs(data, shown, "lot file")

    skipped: list[str] = []  # why, for the error when no feature is usable
    held = HeldWarnings(warnings)  # the two passes below report in feature order

    def skip(i: int, name: str, why: str) -> None:
        skipped.append(f"{name} skipped: {why}")
        hint = "without --strict it is skipped with a warning"
        held.at(i).warn(Diagnostic(shown, 0, 0, f"{name} skipped: {why}", hint))

    items = []  # (name, [outer, *holes] as (k, 2) arrays, properties, id, feature's name, index)
    polygons = geometries = 0  # features with a Polygon or MultiPolygon geometry, with any
    for i, feature in enumerate(features):
        feature = feature if isinstance(feature, dict) else {}
        name = feature_name(i, feature)
        ident = feature_id(feature)
        properties = feature.get("properties")
        properties = properties if isinstance(properties, dict) else {}
        geometry = feature.get("geometry")
        geometries += isinstance(geometry, dict)
        polygons += isinstance(geometry, dict) and geometry.get("type") in _POLYGONS
        try:
            parts = _polygons(feature)
        except FootprintError as e:
            skip(i, name, str(e))
            continue
        for part, rings in enumerate(parts):
            part_name = f"{name}, part {part}" if len(parts) > 1 else name
            part_id = f"{ident}-{part}" if ident is not None and len(parts) > 1 else ident
            if isinstance(rings, FootprintError):
                skip(i, part_name, str(rings))
            else:
                items.append((part_name, rings, properties, part_id, name, i))

    projected, site, to_local = _project(items, crs)
    streets = None
    if options.front == "street" and to_local is not None:
        streets = read_streets(Path(str(options.streets)), to_local, crs, site, warnings)
    lots = []
    mapped: dict[str, dict] = {}  # feature name -> its mapped attrs (a MultiPolygon's parts share)
    for name, rings, properties, ident, whose, i in projected:
        if isinstance(rings[0], FootprintError):
            skip(i, name, str(rings[0]))
            continue
        try:
            outline, note = clean_ring(rings[0])
        except FootprintError as e:
            skip(i, name, str(e))
            continue
        if note:
            repaired = Diagnostic(shown, 0, 0, f"{name}: {note}", "without --strict it is repaired")
            held.at(i).warn(repaired)
        holes = _clean_holes(outline, rings[1:], name, shown, held.at(i))
        front = front_edge(outline, options.front, streets)
        outline = np.roll(outline, -front, axis=0)
        lot = footprint([tuple(p) for p in outline], properties, name, holes)
        lot.source = shown
        lot.feature_id, lot.feature, lot.site = ident, i, site
        if options.mapping:
            if whose not in mapped:
                mapped[whose] = map_properties(
                    properties, options.mapping, whose, shown, held.at(i)
                )
            lot.mapped = dict(mapped[whose])
        lots.append(lot)
    held.flush()
    if not lots:
        hint = None
        if not features:
            message = "the lot file has no features"
            hint = "a lot file holds footprints: features with a Polygon or MultiPolygon geometry"
        elif not geometries:
            message = (
                f"none of the lot file's {len(features)} features has a geometry"
                if len(features) > 1
                else "the lot file's only feature has no geometry"
            )
            hint = "a footprint is a feature with a Polygon or MultiPolygon geometry"
        else:
            what = "no usable footprint" if polygons else "no Polygon features"
            if skipped:
                more = f" (and {len(skipped) - 1} more)" if len(skipped) > 1 else ""
                what += f": {skipped[0]}{more}"
            message = f"the lot file has {what}"
        raise BgrError(Diagnostic(shown, 0, 0, message, hint))
    return lots


_POLYGONS = ("Polygon", "MultiPolygon")
_GEOMETRIES = ("Point", "MultiPoint", "LineString", "MultiLineString", *_POLYGONS)


def _features(data, shown: str, what: str) -> list:
    """The features of a GeoJSON FeatureCollection (or a single Feature), or a BgrError that
    says what the file is instead."""
    if isinstance(data, dict) and data.get("type") == "Feature":
        return [data]
    features = data.get("features") if isinstance(data, dict) else None
    if isinstance(features, list):
        return features
    kind = data.get("type") if isinstance(data, dict) else None
    hint = "convert it to GeoJSON features, e.g. ogr2ogr -f GeoJSON out.geojson INPUT"
    if kind == "FeatureCollection":
        found = 'a FeatureCollection whose "features" is ' + (
            "missing" if "features" not in data else f"not a list but {_shown(features)}"
        )
    elif kind in _GEOMETRIES or kind == "GeometryCollection":
        found = f"a bare {kind} geometry"
        hint = 'wrap it in a Feature: {"type": "Feature", "properties": {}, "geometry": ...}'
    elif isinstance(kind, str):
        found = f"a JSON object of type {_shown(kind)}"
    elif isinstance(data, dict):
        found = 'a JSON object without a "type" member'
    elif isinstance(data, list):
        found = "a JSON array"
    else:
        found = {type(None): "JSON null", bool: "a JSON boolean", str: "a JSON string"}.get(
            type(data), "a JSON number"
        )
    raise BgrError(
        Diagnostic(
            shown,
            0,
            0,
            f"a {what} must be a GeoJSON FeatureCollection or Feature; this one is {found}",
            hint,
        )
    )


def feature_id(feature: dict) -> str | None:
    """A feature's id as a string (GeoJSON's ``id`` member, else an ``id`` property, as
    OpenStreetMap exports have); None without one.  Output files name buildings by it."""
    ident = feature.get("id")
    if ident is None and isinstance(feature.get("properties"), dict):
        ident = feature["properties"].get("id")
    if ident is None or isinstance(ident, (dict, list)):
        return None
    return ident if isinstance(ident, str) else _shown(ident)


def feature_name(index: int, feature: dict) -> str:
    """How messages name a feature: its index in the file and its id (GeoJSON's ``id`` member,
    else an ``id`` property, as OpenStreetMap exports have)."""
    ident = feature.get("id")
    if ident is None and isinstance(feature.get("properties"), dict):
        ident = feature["properties"].get("id")
    if ident is None:
        return f"feature {index} (no id)"
    shown = ident if isinstance(ident, str) else _shown(ident)
    return f"feature {index} (id {shown[:40]}{'...' if len(shown) > 40 else ''})"


def _polygons(feature: dict) -> list:
    """The rings of each polygon of a feature, ``[outer, *holes]`` as (k, 2) float arrays; a
    polygon of a MultiPolygon that is malformed is a FootprintError in its place, so the others
    still count, and so is a malformed hole in its place (it is dropped, the polygon kept)."""
    geometry = feature.get("geometry")
    if not isinstance(geometry, dict):
        raise FootprintError("it has no geometry")
    kind, coords = geometry.get("type"), geometry.get("coordinates")
    if kind == "Polygon":
        return [_rings(coords)]
    if kind == "MultiPolygon":
        if not isinstance(coords, list) or not coords:
            raise FootprintError("malformed MultiPolygon coordinates")
        out = []
        for poly in coords:
            try:
                out.append(_rings(poly))
            except FootprintError as e:
                out.append(e)
        return out
    if not kind:
        raise FootprintError("its geometry has no type")
    shown = kind[:40] if isinstance(kind, str) else _shown(kind)[:40]
    raise FootprintError(f"a {shown} is not a footprint")


def _rings(polygon) -> list:
    """The outer ring of GeoJSON Polygon coordinates and its holes (a hole that is malformed is
    a FootprintError in its place)."""
    if not isinstance(polygon, list) or not polygon or not isinstance(polygon[0], list):
        raise FootprintError("malformed Polygon coordinates")
    out: list = [_ring(polygon[0], "outline")]
    for hole in polygon[1:]:
        try:
            out.append(_ring(hole, "outline"))
        except FootprintError as e:
            out.append(e)
    return out


def _ring(corners, what: str = "outline", least: int = 3) -> np.ndarray:
    """One ring (or line) of GeoJSON coordinates as a (k, 2) float array."""
    if not isinstance(corners, list):
        raise FootprintError("malformed Polygon coordinates")
    if len(corners) < least:
        raise FootprintError(f"its {what} has fewer than {('two', 'three')[least - 2]} corners")
    if not all(
        isinstance(c, list) and len(c) >= 2 and is_number(c[0]) and is_number(c[1]) for c in corners
    ):
        raise FootprintError("its coordinates are not [x, y] numbers")
    try:
        ring = np.array([(float(c[0]), float(c[1])) for c in corners], dtype=np.float64)
    except OverflowError:  # an int of more than about 309 digits
        raise FootprintError("its coordinates are not all finite") from None
    if not np.isfinite(ring).all():
        raise FootprintError("its coordinates are not all finite")
    if np.abs(ring).max() > MAX_COORDINATE:
        raise FootprintError(
            f"its coordinates are out of range (at most {MAX_COORDINATE:.0e} in size)".replace(
                "e+0", "e"
            )
        )
    return ring


def _clean_holes(outline: np.ndarray, holes: list, name: str, shown: str, warnings) -> list:
    """The usable holes of a cleaned outline, cleaned as outlines are (:func:`clean_ring`): a
    hole that cannot be cleaned, is not inside the outline clear of its edges, or touches or
    overlaps a hole kept before it is dropped with a warning (the courtyard is built over)."""
    if not holes:
        return []
    outer = Polygon(outline)
    kept: list[Polygon] = []
    out = []
    for j, hole in enumerate(holes, start=1):
        label = f"{name}: hole {j}"
        try:
            if isinstance(hole, FootprintError):
                raise hole
            ring, note = clean_ring(hole)
            shape = Polygon(ring)
            if not outer.contains(shape) or outer.exterior.distance(shape) <= CLEAN_TOL:
                raise FootprintError("it is not inside the outline, clear of its edges")
            if any(shape.distance(other) <= CLEAN_TOL for other in kept):
                raise FootprintError("it touches or overlaps another hole")
        except FootprintError as e:
            warnings.warn(
                Diagnostic(
                    shown,
                    0,
                    0,
                    f"{label} dropped: {e}",
                    "without --strict it is dropped with a warning and the courtyard built over",
                )
            )
            continue
        if note:
            warnings.warn(
                Diagnostic(shown, 0, 0, f"{label}: {note}", "without --strict it is repaired")
            )
        kept.append(shape)
        out.append([tuple(p) for p in ring])
    return out


def front_edge(outline: np.ndarray, how: str = "first", streets=None) -> int:
    """The index of the edge (``outline[i] -> outline[i + 1]``) that is the lot's front:
    ``first`` 0, ``longest`` the longest (the first of equals), ``street`` the one whose midpoint
    is nearest to a line of ``streets`` (an STRtree of them; on a tie within STREET_TIE, the
    longer edge)."""
    if how == "first":
        return 0
    lengths = _lengths(outline)
    if how == "longest" or streets is None:
        return int(np.argmax(lengths))
    mid = (outline + np.roll(outline, -1, axis=0)) / 2.0
    found, distance = streets.query_nearest(
        shapely.points(mid), return_distance=True, all_matches=False
    )
    near = np.full(len(outline), np.inf)
    near[found[0]] = distance
    candidates = np.flatnonzero(near <= near.min() + STREET_TIE)
    return int(candidates[np.argmax(lengths[candidates])])


def read_streets(path: Path, to_local: Callable, crs, site: dict | None, warnings: Warnings):
    """The LineString and MultiLineString features of a GeoJSON street file, projected as the
    lots were (``to_local``), as an STRtree of shapely lines.  The file must be in the lots' CRS
    (its ``crs`` member, if it has one, must say so); a line that cannot be used is skipped with
    a warning; a file without any usable line is an error."""
    shown = str(path)
    hint = (
        "give --front street:LINES.geojson, a GeoJSON file of LineString streets in the lots' CRS"
    )
    data = read_json(path, "street file", hint)
    features = _features(data, shown, "street file")
    own = _legacy_crs(data, shown, "street file")
    if own is not None:
        # with no crs member, the lots have a site only when they were longitude/latitude
        lonlat = crs.is_geographic if crs is not None else site is not None
        if own.is_geographic or lonlat:
            same = own.is_geographic and lonlat
        else:  # metres: the same CRS, or lots that do not say theirs
            same = crs is None or own.equals(crs, ignore_axis_order=True)
        if not same:
            raise BgrError(
                Diagnostic(
                    shown,
                    0,
                    0,
                    f"the street file is in {_crs_name(own) or own.name}, not in the lot file's "
                    "CRS",
                    "reproject the streets to the lot file's CRS, e.g. ogr2ogr -t_srs EPSG:4326 "
                    "out.geojson in.geojson",
                )
            )
    lines: list[tuple[str, np.ndarray]] = []
    for i, feature in enumerate(features):
        feature = feature if isinstance(feature, dict) else {}
        geometry = feature.get("geometry")
        geometry = geometry if isinstance(geometry, dict) else {}
        kind, coords = geometry.get("type"), geometry.get("coordinates")
        if kind not in ("LineString", "MultiLineString"):
            continue
        parts = [coords] if kind == "LineString" else coords
        name = feature_name(i, feature)
        for part in parts if isinstance(parts, list) else [None]:
            try:
                if not isinstance(part, list):
                    raise FootprintError("malformed LineString coordinates")
                lines.append((name, _ring(part, "line", least=2)))
            except FootprintError as e:
                warnings.warn(
                    Diagnostic(
                        shown,
                        0,
                        0,
                        f"street {name} skipped: {e}",
                        "without --strict it is skipped with a warning",
                    )
                )
    if not lines:
        raise BgrError(
            Diagnostic(shown, 0, 0, "the street file has no LineString or MultiLineString", hint)
        )
    metres = to_local(np.concatenate([line for _, line in lines]))
    geoms, at = [], 0
    for name, line in lines:
        part = metres[at : at + len(line)]
        at += len(line)
        if np.isfinite(part).all():
            geoms.append(shapely.linestrings(part))
        else:
            warnings.warn(
                Diagnostic(
                    shown,
                    0,
                    0,
                    f"street {name} skipped: its coordinates do not project to metres",
                    "without --strict it is skipped with a warning",
                )
            )
    if not geoms:
        raise BgrError(Diagnostic(shown, 0, 0, "the street file has no line in metres", hint))
    return shapely.STRtree(geoms)


def map_properties(
    properties: dict, mapping: tuple, name: str, shown: str, warnings: Warnings | HeldWarnings
) -> dict:
    """The attrs ``mapping`` (PropertyMap items) gives a feature of ``properties``: each value
    coerced (:func:`coerce`); a property that is missing or null gives nothing, silently; one
    that cannot be coerced gives nothing, with a warning naming the feature."""
    out = {}
    for item in mapping:
        value = properties.get(item.prop)
        if value is None:
            continue
        fitted, why = coerce(value, item.type)
        if why is None:
            out[item.attr] = fitted
            continue
        warnings.warn(
            Diagnostic(
                shown,
                0,
                0,
                f"{name}: property '{item.prop}' is {_shown(value)}, {why} (--map {item}); "
                f"the attr '{item.attr}' keeps its value",
                "without --strict the property is ignored with a warning",
            )
        )
    return out


def _legacy_crs(data: dict, shown: str, what: str = "lot file"):
    """The pyproj CRS a file's legacy ``crs`` member names (GeoJSON 2008: ``{"type": "name",
    "properties": {"name": "urn:ogc:def:crs:EPSG::3067"}}``, or ``{"type": "EPSG",
    "properties": {"code": 3067}}``), or None without one.  RFC 7946 dropped the member, but
    exports from GIS tools still carry it.  One that names no CRS pyproj knows, or one that is
    neither geographic nor projected, is an error: read as metres, the coordinates would be
    misplaced."""
    member = data.get("crs") if isinstance(data, dict) else None
    if member is None:
        return None
    props = member.get("properties") if isinstance(member, dict) else None
    props = props if isinstance(props, dict) else {}
    name, code = props.get("name"), props.get("code")
    if name is None and isinstance(code, int) and not isinstance(code, bool) and 0 < code < 10**9:
        name = f"EPSG:{code}"
    from pyproj import CRS
    from pyproj.exceptions import CRSError

    crs = None
    if isinstance(name, str) and len(name) <= 200:
        try:
            crs = CRS.from_user_input(name)
        except CRSError:
            crs = None
        if crs is not None and (crs.is_geographic or crs.is_projected):
            return crs
    named = f"'{name[:80]}'" if isinstance(name, str) else _shown(member)
    message = (
        f"the {what}'s crs member names no CRS bgr knows ({named})"
        if crs is None
        else f"the {what}'s crs member names {named}, a CRS that is neither longitude/latitude "
        "nor projected"
    )
    raise BgrError(
        Diagnostic(
            shown,
            0,
            0,
            message,
            "reproject the file to longitude/latitude (EPSG:4326, e.g. ogr2ogr -t_srs EPSG:4326 "
            "out.geojson in.geojson) or to a projected CRS in metres",
        )
    )


def utm_zone(longitude: float, latitude: float) -> str:
    """The EPSG code of the WGS84 UTM zone a point lies in: EPSG:326NN north of the equator,
    EPSG:327NN south (zone NN = 1..60, six degrees of longitude each from 180 W; the Norway and
    Svalbard exceptions are not made)."""
    zone = min(max(int(math.floor((longitude + 180.0) / 6.0)) + 1, 1), 60)
    return f"EPSG:{(32600 if latitude >= 0 else 32700) + zone}"


def _project(items: list, crs=None) -> tuple[list, dict | None, Callable | None]:
    """Each (name, rings, ...) item with its rings in local metres (east +x, north -z), the site
    those metres are in (:func:`_projection`), and the function that projects more points so
    (a street file's); a ring that does not project to finite metres is a FootprintError in its
    place.  One projection call for every ring of the file."""
    if not items:
        return [], None, None
    to_local, site = _projection(np.concatenate([item[1][0] for item in items]), crs)
    arrays = [ring for item in items for ring in item[1] if isinstance(ring, np.ndarray)]
    metres = to_local(np.concatenate(arrays))
    out, at = [], 0
    for name, rings, *rest in items:
        local: list = []
        for ring in rings:
            if not isinstance(ring, np.ndarray):
                local.append(ring)
                continue
            part = metres[at : at + len(ring)]
            at += len(ring)
            local.append(
                part
                if np.isfinite(part).all()
                else FootprintError("its coordinates do not project to metres")
            )
        out.append((name, local, *rest))
    return out, site, to_local


def _projection(outlines: np.ndarray, crs=None) -> tuple[Callable, dict | None]:
    """The function taking points (N, 2) of a file to local metres (east +x, north -z;
    non-finite where they do not project), and the site those metres are in:
    ``{"crs": "EPSG:NNNN", "origin": [E0, N0, 0.0]}`` (local x = E - E0, local -z = N - N0), or
    None.  ``outlines`` are the points of every outer ring of the file.

    - Geographic coordinates (``crs`` geographic, or, with no ``crs``, longitude/latitude as
      read_geojson tells them) are projected with pyproj to the UTM zone of the centre of their
      bounding box (:func:`utm_zone`); the origin is the centre of the projected bounding box,
      rounded to whole metres.  Lengths are true to the zone's scale (within 4 parts in 10,000
      inside the zone), and the output files can name the CRS.
    - A projected ``crs`` in metres keeps the coordinates as they are (origin 0, 0, 0) and is
      recorded as the site; one in other units is taken as metres and not recorded.
    - Otherwise the coordinates are metres as they are, with no site.
    """
    lo, hi = outlines.min(axis=0), outlines.max(axis=0)
    if crs is None:
        geographic = (
            bool((np.abs(outlines[:, 0]) <= 180).all() and (np.abs(outlines[:, 1]) <= 90).all())
            and hi[0] - lo[0] < 1.0
            and hi[1] - lo[1] < 1.0
        )
        source = CRS84 if geographic else None
    elif crs.is_geographic:
        source = crs
    else:
        source = None
    scale = np.array([1.0, -1.0])  # east +x, north -z
    if source is None:
        site = None
        name = _crs_name(crs) if crs is not None else None
        if name and crs.axis_info and crs.axis_info[0].unit_name == "metre":
            site = {"crs": name, "origin": [0.0, 0.0, 0.0]}
        return (lambda points: points * scale), site

    from pyproj import Transformer

    centre = (lo + hi) / 2.0
    target = utm_zone(float(centre[0]), float(centre[1]))
    to_utm = Transformer.from_crs(source, target, always_xy=True)

    def to_metres(points: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            east, north = to_utm.transform(points[:, 0], points[:, 1], errcheck=False)
        return np.column_stack([east, north])

    metres = to_metres(outlines)
    finite = np.isfinite(metres).all(axis=1)
    good = metres[finite] if finite.any() else np.zeros((1, 2))
    origin = np.round((good.min(axis=0) + good.max(axis=0)) / 2.0)
    site = {"crs": target, "origin": [float(origin[0]), float(origin[1]), 0.0]}
    return (lambda points: (to_metres(points) - origin) * scale), site


def _crs_name(crs) -> str | None:
    """``AUTHORITY:CODE`` of a pyproj CRS (EPSG:3067); None for one no authority names, which
    no output file could name either."""
    authority = crs.to_authority()
    return f"{authority[0]}:{authority[1]}" if authority else None


# --------------------------------------------------------------------------------------------
# properties


def attr_overrides(lot: Lot, attrs: dict, warnings: Warnings) -> dict:
    """The attr values a lot gives: first its properties, each overriding the attr of its name,
    then ``lot.mapped`` (the values ``--map`` took from its properties) over those.  A value is
    used when it fits the attr's type (the run's value of the attr): a number attr takes a
    finite number or a string that is one (:func:`number_of`), a string attr a string, a
    boolean attr a boolean.  ``null`` and properties that name no attr are ignored; a value that
    does not fit is reported (naming the lot) and the attr keeps its value.  A mapped attr that
    is no attr of the grammar is an error (:func:`check_mapping` says so before a run).

    A pure function of its arguments: runs that derive lots in other processes call it there."""
    out = {}
    for key, value in lot.properties.items():
        if key not in attrs or value is None:
            continue
        fitted = _fit(value, attrs[key])
        if isinstance(fitted, _Misfit):
            _misfit(lot, f"property '{key}' is {_shown(value)}", key, fitted.why, warnings)
        else:
            out[key] = fitted
    for key, value in lot.mapped.items():
        if key not in attrs:
            check_mapping(LotOptions(mapping=(PropertyMap(key, "?"),)), attrs, lot.source)
        fitted = _fit(value, attrs[key])
        if isinstance(fitted, _Misfit):
            _misfit(lot, f"--map gives '{key}' {_shown(value)}", key, fitted.why, warnings)
        else:
            out[key] = fitted
    return out


@dataclass(frozen=True)
class _Misfit:
    why: str


def _fit(value, current):
    """``value`` as the attr whose run value is ``current`` takes it, or a _Misfit saying why
    it does not fit."""
    if is_number(current):
        fitted = number_of(value) if isinstance(value, str) else value
        ok, need = is_number(fitted), "a number"
    elif isinstance(current, bool):
        fitted, ok, need = value, isinstance(value, bool), "true or false"
    elif isinstance(current, str):
        fitted, ok, need = value, isinstance(value, str), "a string"
    else:
        fitted, ok, need = value, isinstance(value, (int, float, str, bool)), "a value"
    # a number must be finite and in range, whichever attr it is for
    problem = number_problem(fitted) if ok and is_number(fitted) else None
    if ok and problem is None:
        return fitted
    return _Misfit(problem or f"not {need}")


def _misfit(lot: Lot, what: str, key: str, why: str, warnings: Warnings) -> None:
    warnings.warn(
        Diagnostic(
            lot.source,
            0,
            0,
            f"{lot.name}: {what}, {why}; the attr '{key}' keeps its value",
            "without --strict the property is ignored with a warning",
        )
    )


def _shown(value) -> str:
    import json

    try:
        return json.dumps(value, ensure_ascii=False, allow_nan=True)[:60]
    except (TypeError, ValueError):  # not JSON; or an int of more digits than str() converts
        try:
            return repr(value)[:60]
        except ValueError:
            return "a number of thousands of digits"
