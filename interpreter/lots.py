"""Lots: the shapes the axiom receives — a W x D rectangle, or footprints from GeoJSON.

A lot is a 2D shape in the xz plane (y up, sy = 0) whose scope has x along the footprint's front
edge (the street side: its first edge, or the one :class:`LotOptions` chooses) and z pointing into
the lot (LANGUAGE.md section 4).  A footprint's inner rings (courtyards) are holes of its shape.

Footprints from real data (OpenStreetMap, cadastres) are rarely clean: rings that cross
themselves, repeated and collinear corners, slivers of no width, coordinates as longitude and
latitude, numbers written as strings.  :func:`read_geojson` makes each feature a usable lot or
skips it with one warning naming it (docs/cli.md, "Lots", states the rules), so that one bad
feature among thousands does not stop a run.

This module holds the lot itself (:class:`Lot`, :func:`rectangle`, :func:`footprint`), the
``--lot`` option, the reading of a lot file, which puts the parts below together, and the attr
values a lot's properties give (:func:`attr_overrides`).  The parts, each importable from here
as before: lot_features.py (a GeoJSON document's features and rings), lot_projection.py (CRS
and projection to local metres), lot_fronts.py (the front edge, ``--front``), lot_options.py
(``--front`` and ``--map`` and the coercion of mapped properties); outline.py cleans a ring.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic, HeldWarnings, Warnings
from bgr.grammar.paths import read_json

from .geometry.polygons import RECT, is_unit_square, normalise, signed_area
from .lot_features import _POLYGONS, _clean_holes, _features, _polygons, feature_id, feature_name
from .lot_fronts import STREET_TIE as STREET_TIE
from .lot_fronts import front_edge, read_streets
from .lot_options import FRONTS as FRONTS
from .lot_options import MAP_TYPES as MAP_TYPES
from .lot_options import LotOptions, PropertyMap, _shown, check_mapping, map_properties
from .lot_options import coerce as coerce
from .lot_options import parse_front as parse_front
from .lot_options import parse_map as parse_map
from .lot_projection import CRS84 as CRS84
from .lot_projection import _legacy_crs, _project
from .lot_projection import utm_zone as utm_zone
from .outline import CLEAN_TOL as CLEAN_TOL
from .outline import FootprintError, clean_ring
from .shapes import IDENTITY, Flat, Shape
from .values import MAX_COORDINATE, is_number, number_of, number_problem

DEFAULT_LOT = (20.0, 20.0)


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
