"""The front edge of a lot (``--front``): its first edge, its longest, or the one nearest a
street.

``--front street:LINES.geojson`` reads a GeoJSON file of street lines in the lots' CRS
(:func:`read_streets`), projected as the lots were; :func:`front_edge` picks each outline's
edge whose midpoint is nearest to one of them.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import shapely

from bgr.grammar.errors import BgrError, Diagnostic, Warnings
from bgr.grammar.paths import read_json

from .lot_features import _features, _ring, feature_name
from .lot_projection import _crs_name, _legacy_crs
from .outline import CLEAN_TOL, FootprintError
from .outline import lengths as _lengths

STREET_TIE = CLEAN_TOL  # metres: edges whose midpoints are this close to equally near tie


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
