"""Where a lot file's coordinates are on Earth, and how they become local metres.

A GeoJSON lot file is in longitude and latitude (RFC 7946), or, in exports from GIS tools, in the
CRS its legacy ``crs`` member names (:func:`_legacy_crs`).  :func:`_project` takes every ring of
a file to local metres (east +x, north -z) in one pyproj call: geographic coordinates to the UTM
zone of their centre (:func:`utm_zone`) about a whole-metre origin, metres as they are, and
records the site those metres are in, which output files name.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic

from .lot_options import _shown
from .outline import FootprintError

# GeoJSON's own CRS (RFC 7946): longitude, latitude on WGS84
CRS84 = "OGC:CRS84"


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
