"""Lots: the shapes the axiom receives — a W x D rectangle, or footprints from GeoJSON.

A lot is a 2D shape in the xz plane (y up, sy = 0) whose scope has x along the footprint's first
edge (its front, the street side) and z pointing into the lot (LANGUAGE.md section 4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from bgr.grammar.errors import BgrError, Diagnostic, read_json

from .geometry.polygons import RECT, is_unit_square, normalise, signed_area
from .shapes import IDENTITY, Flat, Shape

DEFAULT_LOT = (20.0, 20.0)


@dataclass
class Lot:
    shape: Shape
    properties: dict = field(default_factory=dict)


def rectangle(width: float, depth: float) -> Lot:
    if not (width > 0 and depth > 0 and math.isfinite(width) and math.isfinite(depth)):
        raise BgrError(f"--lot {width:g},{depth:g}: a lot needs a positive width and depth")
    return Lot(Shape((0.0, 0.0, 0.0), IDENTITY, (width, 0.0, depth), Flat(1, RECT)))


def footprint(points_xz: list[tuple[float, float]], properties: dict | None = None) -> Lot:
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
        return footprint([pts[1], pts[0], *reversed(pts[2:])], properties)
    unit, (u0, w0, width, depth) = normalise([(tuple(local), ())])
    origin = (x0 + u0 * xa[0] + w0 * za[0], 0.0, z0 + u0 * xa[2] + w0 * za[2])
    axes = (xa, (0.0, 1.0, 0.0), za)
    geom = Flat(1, RECT if is_unit_square(unit) else [(tuple(unit[0][0]), ())])
    return Lot(Shape(origin, axes, (width, 0.0, depth), geom), dict(properties or {}))


def parse_lot_option(value: str) -> list[Lot]:
    """``W,D`` or a GeoJSON file of footprints."""
    if "," in value and not value.lower().endswith((".json", ".geojson")):
        try:
            width, depth = (float(v) for v in value.split(","))
        except ValueError:
            raise BgrError(
                f"--lot {value}: write the lot as WIDTH,DEPTH in metres (e.g. 20,30) "
                "or give a GeoJSON file"
            ) from None
        return [rectangle(width, depth)]
    return read_geojson(Path(value))


def read_geojson(path: Path) -> list[Lot]:
    """Every Polygon / MultiPolygon feature becomes a lot (its exterior ring).

    Longitude/latitude (every coordinate within +-180, +-90 and the whole set within one degree)
    are projected to metres around the collection's centre (equirectangular, good to a few
    centimetres over a city district); other coordinates are taken as metres.  East is +x,
    north is -z.
    """
    shown = str(path)
    data = read_json(path, "lot file", "give W,D or a GeoJSON file")
    features = data.get("features") if isinstance(data, dict) else None
    if isinstance(data, dict) and data.get("type") == "Feature":
        features = [data]
    if not isinstance(features, list):
        raise BgrError(
            Diagnostic(shown, 0, 0, "a lot file must be a GeoJSON FeatureCollection or Feature")
        )
    rings = []
    for i, feature in enumerate(features):
        geometry = (feature or {}).get("geometry") or {}
        kind, coords = geometry.get("type"), geometry.get("coordinates")
        try:
            if kind == "Polygon":
                rings.append((coords[0], feature.get("properties") or {}, i))
            elif kind == "MultiPolygon":
                rings += [(poly[0], feature.get("properties") or {}, i) for poly in coords]
        except (TypeError, IndexError):
            raise BgrError(
                Diagnostic(shown, 0, 0, f"feature {i}: malformed {kind} coordinates")
            ) from None
    if not rings:
        raise BgrError(Diagnostic(shown, 0, 0, "the lot file has no Polygon features"))
    try:
        flat = [(float(c[0]), float(c[1])) for ring, _, _ in rings for c in ring]
    except (TypeError, ValueError, IndexError):
        raise BgrError(Diagnostic(shown, 0, 0, "coordinates must be [x, y] numbers")) from None
    xs, ys = [x for x, _ in flat], [y for _, y in flat]
    geographic = (
        all(abs(x) <= 180 and abs(y) <= 90 for x, y in flat)
        and max(xs) - min(xs) < 1.0
        and max(ys) - min(ys) < 1.0
    )
    lon0 = sum(x for x, _ in flat) / len(flat)
    lat0 = sum(y for _, y in flat) / len(flat)
    kx, ky = (111_320.0 * math.cos(math.radians(lat0)), 110_540.0) if geographic else (1.0, 1.0)
    lots = []
    for ring, props, i in rings:
        pts = [
            (
                (float(c[0]) - (lon0 if geographic else 0)) * kx,
                -(float(c[1]) - (lat0 if geographic else 0)) * ky,
            )
            for c in ring
        ]
        try:
            lots.append(footprint(pts, props))
        except BgrError as e:
            raise BgrError(Diagnostic(shown, 0, 0, f"feature {i}: {e.message}")) from None
    return lots
