"""The ``site`` declaration: where a grammar's metres are on Earth.

A city that ``bgr infer --kind city`` reads lies far from the origin (a Swiss LV95 tile sits
at 2,682,812 m east, 1,247,000 m north), where float32 positions lose metres.  The inferred
grammar works in local metres and declares the exact offset back to the input's frame::

    site "EPSG:2056" origin (2682812.125, 1247000.5, 400) up z

Local bgr coordinates are glTF's (y up); the input's are ``origin`` plus the local point in
the input's axes: with ``up z``, local (x, y, z) is input (x, -z, y) - origin, i.e. east, up,
-north; with ``up y`` the axes are the same.  The writers put their output back in the input's
frame (formats/placement.py).  The run's tables carry the site as a dict (TerminalTable.site),
the form GeoJSON lots give too: ``{"crs": ..., "origin": [east, north, height], "up": ...}``,
the origin always z up, as CityJSON stores it.
"""

from __future__ import annotations

import math

from . import nodes as n

MAX_ORIGIN = 1e8  # metres, as the city readers bound their input (interpreter/limits.py)
UP_AXES = ("y", "z")


def problems(site: n.Site) -> list[tuple[n.Pos, str, str | None]]:
    """What is wrong with a site declaration: (where, message, hint) for each problem."""
    out: list[tuple[n.Pos, str, str | None]] = []
    if site.up not in UP_AXES:
        out.append(
            (
                site.up_pos if site.up_pos.line else site.pos,
                f"'up {site.up}' is not an up axis",
                "write 'up z' (GIS data: x east, y north, z up) or 'up y' (glTF, most games)",
            )
        )
    for axis, value in zip("xyz", site.origin, strict=True):
        if not math.isfinite(value) or abs(value) > MAX_ORIGIN:
            out.append(
                (
                    site.pos,
                    f"the site's origin {axis} = {value:g} is beyond {MAX_ORIGIN:.0e} m",
                    "a projected CRS reaches 2e7 m: give the origin in metres",
                )
            )
    if site.crs is not None and crs_problem(site.crs):
        out.append((site.pos, crs_problem(site.crs) or "", "name it as EPSG:NNNN, e.g. EPSG:28992"))
    return out


def crs_problem(crs: str) -> str | None:
    """Why pyproj cannot read ``crs`` (None: it can)."""
    from pyproj import CRS
    from pyproj.exceptions import CRSError

    try:
        CRS.from_user_input(crs)
    except (CRSError, ValueError, TypeError):
        shown = crs if len(crs) <= 40 else crs[:37] + "..."
        return f"the site's CRS {shown!r} is not one pyproj knows"
    return None


def crs_name(text: str) -> str | None:
    """How a site names a CRS an input gave (a CityJSON URL, a GML URN, EPSG:NNNN): EPSG:NNNN
    where pyproj can name it so, the text itself where pyproj reads it otherwise, None where
    pyproj cannot read it."""
    from pyproj import CRS
    from pyproj.exceptions import CRSError

    try:
        crs = CRS.from_user_input(text)
    except (CRSError, ValueError, TypeError):
        return None
    authority = crs.to_authority()
    return f"{authority[0]}:{authority[1]}" if authority and authority[0] == "EPSG" else text


def table_site(site: n.Site) -> dict:
    """The declaration as the run's tables carry it (TerminalTable.site): origin z up."""
    x, y, z = site.origin
    origin = [x, y, z] if site.up == "z" else [x, -z, y]
    return {"crs": site.crs, "origin": origin, "up": site.up}
