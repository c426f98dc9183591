"""From a GeoJSON document to the rings of its footprints, checked and cleaned.

:func:`_features` finds the features of a FeatureCollection (or a single Feature), or says what
the file is instead; :func:`_polygons` gives each polygon of a feature as its outer ring and its
holes, each a (k, 2) float array checked to be finite numbers in range (:func:`_ring`), or a
FootprintError in its place that says why it cannot be used.  :func:`_clean_holes` cleans a
polygon's holes against its cleaned outline.  :func:`feature_name` and :func:`feature_id` name
a feature in messages and output files.
"""

from __future__ import annotations

import numpy as np
from shapely.geometry import Polygon

from bgr.grammar.errors import BgrError, Diagnostic

from .lot_options import _shown
from .outline import CLEAN_TOL, FootprintError, clean_ring
from .values import MAX_COORDINATE, is_number

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
