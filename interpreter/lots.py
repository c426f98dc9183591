"""Lots: the shapes the axiom receives — a W x D rectangle, or footprints from GeoJSON.

A lot is a 2D shape in the xz plane (y up, sy = 0) whose scope has x along the footprint's first
edge (its front, the street side) and z pointing into the lot (LANGUAGE.md section 4).

Footprints from real data (OpenStreetMap, cadastres) are rarely clean: rings that cross
themselves, repeated and collinear corners, slivers of no width, coordinates as longitude and
latitude, numbers written as strings.  :func:`read_geojson` makes each feature a usable lot or
skips it with one warning naming it (docs/cli.md, "Lots", states the rules), so that one bad
feature among thousands does not stop a run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import shapely
from shapely.geometry import Polygon
from shapely.validation import make_valid

from bgr.grammar.errors import BgrError, Diagnostic, Warnings, read_json

from .geometry.earclip import signed_area as ring_area
from .geometry.polygons import RECT, is_unit_square, normalise, signed_area
from .shapes import IDENTITY, Flat, Shape
from .values import MAX_COORDINATE, is_number, number_of, number_problem

DEFAULT_LOT = (20.0, 20.0)
CLEAN_TOL = 1e-3  # metres: a corner this close to the previous one or to a straight line goes
MIN_WIDTH = 0.05  # metres: an outline whose mean width (2 area / perimeter) is less is skipped

# GeoJSON's own CRS (RFC 7946): longitude, latitude on WGS84
CRS84 = "OGC:CRS84"


@dataclass
class Lot:
    shape: Shape
    properties: dict = field(default_factory=dict)
    name: str = ""  # how messages name it, e.g. "feature 12 (id 4253124)"; "" for --lot W,D
    source: str = ""  # the file it came from, where property warnings point
    feature_id: str | None = None  # the GeoJSON feature's id (or "id" property), as a string
    # where its local metres are on Earth, for lots of a file with a known CRS (see _project):
    # {"crs": "EPSG:32635", "origin": [easting, northing, height]}; None for plain metres
    site: dict | None = None


class FootprintError(ValueError):
    """A feature's outline cannot be a lot; the message says why (it follows "skipped: ")."""


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
    points_xz: list[tuple[float, float]], properties: dict | None = None, name: str = ""
) -> Lot:
    """A lot on a polygon given in world (x, z), first edge = front."""
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
    # z must point into the lot: if the interior is on the other side, walk the ring backwards
    local = [
        ((x - x0) * xa[0] + (z - z0) * xa[2], (x - x0) * za[0] + (z - z0) * za[2]) for x, z in pts
    ]
    centroid_w = sum(w for _, w in local) / len(local)
    if centroid_w < 0:
        return footprint([pts[1], pts[0], *reversed(pts[2:])], properties, name)
    unit, (u0, w0, width, depth) = normalise([(tuple(local), ())])
    origin = (x0 + u0 * xa[0] + w0 * za[0], 0.0, z0 + u0 * xa[2] + w0 * za[2])
    axes = (xa, (0.0, 1.0, 0.0), za)
    geom = Flat(1, RECT if is_unit_square(unit) else [(tuple(unit[0][0]), ())])
    return Lot(Shape(origin, axes, (width, 0.0, depth), geom), dict(properties or {}), name)


def parse_lot_option(value: str, warnings: Warnings | None = None) -> list[Lot]:
    """``W,D`` or a GeoJSON file of footprints."""
    if "," in value and not value.lower().endswith((".json", ".geojson")):
        sides = [number_of(v) for v in value.split(",")]  # ASCII numbers only, as in .bgr
        if len(sides) != 2 or sides[0] is None or sides[1] is None:  # "nan", "1_0", "1e400"
            raise BgrError(
                f"--lot {value[:60]}: write the lot as WIDTH,DEPTH, two numbers in metres "
                "(e.g. 20,30), or give a GeoJSON file"
            )
        return [rectangle(sides[0], sides[1])]
    return read_geojson(Path(value), warnings)


# --------------------------------------------------------------------------------------------
# GeoJSON


def read_geojson(path: Path, warnings: Warnings | None = None) -> list[Lot]:
    """Every Polygon / MultiPolygon feature becomes a lot (the outer ring of each polygon).

    Longitude/latitude (a legacy ``crs`` member naming a geographic CRS, or, without one, every
    coordinate within +-180, +-90 and the whole set within one degree) are projected to the UTM
    zone of the collection's centre, about a whole-metre origin near it; other coordinates are
    taken as metres (see :func:`_project`).  East is +x, north is -z.  Each lot's ``site`` says
    where its metres are on Earth.  Each outline is cleaned by :func:`clean_ring`; a feature
    that cannot be used is reported to ``warnings`` (one line naming it; an error when strict)
    and skipped.  A file with no usable footprint at all is an error.
    """
    shown = str(path)
    warnings = warnings if warnings is not None else Warnings()
    data = read_json(path, "lot file", "give W,D or a GeoJSON file")
    features = data.get("features") if isinstance(data, dict) else None
    if isinstance(data, dict) and data.get("type") == "Feature":
        features = [data]
    if not isinstance(features, list):
        raise BgrError(
            Diagnostic(shown, 0, 0, "a lot file must be a GeoJSON FeatureCollection or Feature")
        )

    skipped: list[str] = []  # why, for the error when no feature is usable

    def skip(name: str, why: str) -> None:
        skipped.append(f"{name} skipped: {why}")
        warnings.warn(
            Diagnostic(
                shown,
                0,
                0,
                f"{name} skipped: {why}",
                "without --strict it is skipped with a warning",
            )
        )

    rings = []  # (name, coordinates (k, 2), properties, feature id)
    polygons = 0  # features with a Polygon or MultiPolygon geometry
    for i, feature in enumerate(features):
        feature = feature if isinstance(feature, dict) else {}
        name = feature_name(i, feature)
        ident = feature_id(feature)
        properties = feature.get("properties")
        properties = properties if isinstance(properties, dict) else {}
        geometry = feature.get("geometry")
        polygons += isinstance(geometry, dict) and geometry.get("type") in _POLYGONS
        try:
            outlines = _outer_rings(feature)
        except FootprintError as e:
            skip(name, str(e))
            continue
        for part, ring in enumerate(outlines):
            part_name = f"{name}, part {part}" if len(outlines) > 1 else name
            part_id = f"{ident}-{part}" if ident is not None and len(outlines) > 1 else ident
            if isinstance(ring, FootprintError):
                skip(part_name, str(ring))
            else:
                rings.append((part_name, ring, properties, part_id))

    crs = _legacy_crs(data, shown, warnings)
    lots = []
    projected, site = _project(rings, crs)
    for name, ring, properties, ident in projected:
        if isinstance(ring, FootprintError):
            skip(name, str(ring))
            continue
        try:
            outline, note = clean_ring(ring)
        except FootprintError as e:
            skip(name, str(e))
            continue
        if note:
            warnings.warn(
                Diagnostic(shown, 0, 0, f"{name}: {note}", "without --strict it is repaired")
            )
        lot = footprint([tuple(p) for p in outline], properties, name)
        lot.source = shown
        lot.feature_id = ident
        lot.site = site
        lots.append(lot)
    if not lots:
        what = "no usable footprint" if polygons else "no Polygon features"
        if skipped:
            more = f" (and {len(skipped) - 1} more)" if len(skipped) > 1 else ""
            what += f": {skipped[0]}{more}"
        raise BgrError(Diagnostic(shown, 0, 0, f"the lot file has {what}"))
    return lots


_POLYGONS = ("Polygon", "MultiPolygon")


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


def _outer_rings(feature: dict) -> list:
    """The outer ring of each polygon of a feature, as (k, 2) float arrays; a polygon of a
    MultiPolygon that is malformed is a FootprintError in its place, so the others still count."""
    geometry = feature.get("geometry")
    if not isinstance(geometry, dict):
        raise FootprintError("it has no geometry")
    kind, coords = geometry.get("type"), geometry.get("coordinates")
    if kind == "Polygon":
        return [_ring(coords)]
    if kind == "MultiPolygon":
        if not isinstance(coords, list) or not coords:
            raise FootprintError("malformed MultiPolygon coordinates")
        out = []
        for poly in coords:
            try:
                out.append(_ring(poly))
            except FootprintError as e:
                out.append(e)
        return out
    if not kind:
        raise FootprintError("its geometry has no type")
    shown = kind[:40] if isinstance(kind, str) else _shown(kind)[:40]
    raise FootprintError(f"a {shown} is not a footprint")


def _ring(polygon) -> np.ndarray:
    """The outer ring of GeoJSON Polygon coordinates (holes are left out: see clean_ring)."""
    if not isinstance(polygon, list) or not polygon or not isinstance(polygon[0], list):
        raise FootprintError("malformed Polygon coordinates")
    corners = polygon[0]
    if len(corners) < 3:
        raise FootprintError("its outline has fewer than three corners")
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


def _legacy_crs(data: dict, shown: str, warnings: Warnings):
    """The pyproj CRS a file's legacy ``crs`` member names (GeoJSON 2008: ``{"type": "name",
    "properties": {"name": "urn:ogc:def:crs:EPSG::3067"}}``, or ``{"type": "EPSG",
    "properties": {"code": 3067}}``), or None without one.  RFC 7946 dropped the member, but
    exports from GIS tools still carry it; one that names no CRS pyproj knows is ignored with a
    warning, and the coordinates are read as if it were not there."""
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

    if isinstance(name, str) and len(name) <= 200:
        try:
            crs = CRS.from_user_input(name)
        except CRSError:
            crs = None
        if crs is not None and (crs.is_geographic or crs.is_projected):
            return crs
    warnings.warn(
        Diagnostic(
            shown,
            0,
            0,
            f"its crs member {_shown(member)} names no known geographic or projected CRS; it "
            "is ignored",
            "without --strict the coordinates are read as if it were not there",
        )
    )
    return None


def utm_zone(longitude: float, latitude: float) -> str:
    """The EPSG code of the WGS84 UTM zone a point lies in: EPSG:326NN north of the equator,
    EPSG:327NN south (zone NN = 1..60, six degrees of longitude each from 180 W; the Norway and
    Svalbard exceptions are not made)."""
    zone = min(max(int(math.floor((longitude + 180.0) / 6.0)) + 1, 1), 60)
    return f"EPSG:{(32600 if latitude >= 0 else 32700) + zone}"


def _project(items: list, crs=None) -> tuple[list, dict | None]:
    """Each (name, ring, properties, id) item with its ring in local metres (east +x, north -z),
    and the site those metres are in: ``{"crs": "EPSG:NNNN", "origin": [E0, N0, 0.0]}`` (local
    x = E - E0, local -z = N - N0), or None.

    - Geographic coordinates (``crs`` geographic, or, with no ``crs``, longitude/latitude as
      read_geojson tells them) are projected with pyproj to the UTM zone of the centre of their
      bounding box (:func:`utm_zone`); the origin is the centre of the projected bounding box,
      rounded to whole metres.  Lengths are true to the zone's scale (within 4 parts in 10,000
      inside the zone), and the output files can name the CRS.
    - A projected ``crs`` in metres keeps the coordinates as they are (origin 0, 0, 0) and is
      recorded as the site; one in other units is taken as metres and not recorded.
    - Otherwise the coordinates are metres as they are, with no site.

    A ring that does not project to finite metres is a FootprintError in its place.
    """
    if not items:
        return [], None
    flat = np.concatenate([item[1] for item in items])
    lo, hi = flat.min(axis=0), flat.max(axis=0)
    if crs is None:
        geographic = (
            bool((np.abs(flat[:, 0]) <= 180).all() and (np.abs(flat[:, 1]) <= 90).all())
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
        return [(name, ring * scale, *rest) for (name, ring, *rest) in items], site

    from pyproj import Transformer

    centre = (lo + hi) / 2.0
    target = utm_zone(float(centre[0]), float(centre[1]))
    to_utm = Transformer.from_crs(source, target, always_xy=True)
    with np.errstate(all="ignore"):
        east, north = to_utm.transform(flat[:, 0], flat[:, 1], errcheck=False)
    metres = np.column_stack([east, north])
    finite = np.isfinite(metres).all(axis=1)
    good = metres[finite] if finite.any() else np.zeros((1, 2))
    origin = np.round((good.min(axis=0) + good.max(axis=0)) / 2.0)
    out, at = [], 0
    for name, ring, *rest in items:
        part = metres[at : at + len(ring)]
        at += len(ring)
        if not np.isfinite(part).all():
            out.append((name, FootprintError("its coordinates do not project to metres"), *rest))
        else:
            out.append((name, (part - origin) * scale, *rest))
    site = {"crs": target, "origin": [float(origin[0]), float(origin[1]), 0.0]}
    return out, site


def _crs_name(crs) -> str | None:
    """``AUTHORITY:CODE`` of a pyproj CRS (EPSG:3067); None for one no authority names, which
    no output file could name either."""
    authority = crs.to_authority()
    return f"{authority[0]}:{authority[1]}" if authority else None


# --------------------------------------------------------------------------------------------
# cleaning one outline


def clean_ring(ring) -> tuple[np.ndarray, str | None]:
    """A footprint outline (k, 2) in metres made fit to build on, and a note when that lost
    part of it; raises FootprintError when nothing usable is left.

    - the closing point and corners within CLEAN_TOL of the previous one are dropped;
    - an outline that crosses or touches itself is repaired with shapely's ``make_valid`` and
      the largest polygon it yields is kept (the note says how much was dropped); holes are not
      kept, here or in the input, so a courtyard is built over;
    - corners within CLEAN_TOL of the straight line through their neighbours are dropped;
    - an outline whose mean width (2 area / perimeter) is under MIN_WIDTH is not used.

    The first edge (the front) stays the one that carries the input's first edge; a repaired
    outline starts at its corner nearest the input's first corner and keeps its orientation.
    """
    pts = _drop_repeats(np.asarray(ring, dtype=np.float64))
    if len(pts) < 3:
        raise FootprintError("its outline has fewer than three distinct corners")
    note = None
    poly = Polygon(pts)
    if not poly.is_valid:
        pts, note = _repair(pts, poly)
    kept = _drop_straight(pts)
    if len(kept) >= 3 and Polygon(pts[kept]).is_valid:
        # the front edge is the kept edge that carries input edge 0: start at the last kept
        # corner at or before corner 0 (cyclically)
        start = kept.index(0) if 0 in kept else len(kept) - 1
        pts = pts[kept[start:] + kept[:start]]
    area, perimeter = abs(ring_area(pts)), float(_lengths(pts).sum())
    if area == 0 or 2 * area / perimeter < MIN_WIDTH:
        raise FootprintError(
            "its outline has no area"
            if area < 1e-6
            else f"its outline is thinner than {MIN_WIDTH * 100:g} cm ({area:.2g} m²)"
        )
    return pts, note


def _lengths(pts: np.ndarray) -> np.ndarray:
    return np.linalg.norm(np.roll(pts, -1, axis=0) - pts, axis=1)


def _drop_repeats(pts: np.ndarray) -> np.ndarray:
    """The ring without its closing point and without corners within CLEAN_TOL of the one
    before (a corner is compared with the last one kept, so a run of near-repeats is one)."""
    kept = [0]
    for i in range(1, len(pts)):
        if np.linalg.norm(pts[i] - pts[kept[-1]]) > CLEAN_TOL:
            kept.append(i)
    while len(kept) > 1 and np.linalg.norm(pts[kept[-1]] - pts[kept[0]]) <= CLEAN_TOL:
        kept.pop()
    return pts[kept]


def _drop_straight(pts: np.ndarray) -> list[int]:
    """Indices of the corners that are not within CLEAN_TOL of the straight line through their
    neighbours (lying between them); repeated until none is left, so a run of them goes."""
    keep = list(range(len(pts)))
    changed = True
    while changed and len(keep) > 3:
        changed = False
        a, b, c = pts[np.roll(keep, 1)], pts[keep], pts[np.roll(keep, -1)]
        ac = c - a
        span = np.linalg.norm(ac, axis=1)
        off = np.abs(ac[:, 0] * (b - a)[:, 1] - ac[:, 1] * (b - a)[:, 0]) / np.maximum(span, 1e-300)
        between = np.einsum("ij,ij->i", b - a, c - b) > 0
        straight = np.flatnonzero((span > CLEAN_TOL) & (off <= CLEAN_TOL) & between)
        if len(straight):
            del keep[int(straight[np.argmin(off[straight])])]  # the straightest first
            changed = True
    return keep


def _repair(pts: np.ndarray, poly: Polygon) -> tuple[np.ndarray, str | None]:
    """The largest polygon ``make_valid`` makes of a self-crossing outline, as a ring in the
    input's orientation starting at the corner nearest the input's first one."""
    fixed = make_valid(poly)
    parts = [
        g
        for g in shapely.get_parts(fixed)
        for g in (shapely.get_parts(g) if g.geom_type == "GeometryCollection" else [g])
        if g.geom_type in ("Polygon", "MultiPolygon")
    ]
    polygons = [p for g in parts for p in shapely.get_parts(g) if p.area > 0]
    if not polygons:
        raise FootprintError("its outline has no area")
    best = max(polygons, key=lambda p: p.area)
    ring = np.array(best.exterior.coords[:-1], dtype=np.float64)
    if (ring_area(ring) > 0) != (ring_area(pts) > 0):
        ring = ring[::-1]
    ring = np.roll(ring, -int(np.argmin(np.linalg.norm(ring - pts[0], axis=1))), axis=0)
    note = None
    if len(polygons) > 1:
        total = sum(p.area for p in polygons)
        note = (
            f"its outline crosses itself; repaired, keeping the largest of its {len(polygons)} "
            f"parts ({best.area:.3g} of {total:.3g} m²)"
        )
    return _drop_repeats(ring), note


# --------------------------------------------------------------------------------------------
# properties


def attr_overrides(lot: Lot, attrs: dict, warnings: Warnings) -> dict:
    """The attr values a lot's properties give: a property overrides the attr of its name when
    its value fits the attr's type (the run's value of the attr): a number attr takes a finite
    number or a string that is one (:func:`number_of`), a string attr a string, a boolean attr a
    boolean.  ``null`` and names that are no attr are ignored; a value that does not fit is
    reported (naming the lot) and the attr keeps its value."""
    out = {}
    for key, value in lot.properties.items():
        if key not in attrs or value is None:
            continue
        current = attrs[key]
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
            out[key] = fitted
            continue
        why = problem or f"not {need}"
        warnings.warn(
            Diagnostic(
                lot.source,
                0,
                0,
                f"{lot.name}: property '{key}' is {_shown(value)}, {why}; "
                f"the attr '{key}' keeps its value",
                "without --strict the property is ignored with a warning",
            )
        )
    return out


def _shown(value) -> str:
    import json

    try:
        return json.dumps(value, ensure_ascii=False, allow_nan=True)[:60]
    except (TypeError, ValueError):  # not JSON; or an int of more digits than str() converts
        try:
            return repr(value)[:60]
        except ValueError:
            return "a number of thousands of digits"
