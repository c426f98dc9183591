"""Where an output lands: bgr's local frame, or the site's (grammar/site.py).

A run whose tables carry a site (a grammar's ``site`` declaration, or GeoJSON lots placed on
Earth) is written back in the input's frame, so that the output overlays the data it came
from with no offset applied by hand:

- OBJ and PLY: positions (float64, full precision) and normals in the input's axes, plus the
  origin: with ``up z``, local (x, y, z) is written (x, -z, y) + origin.
- CityJSON: always z up; its ``transform`` carries the origin (formats/cityjson.py).
- glTF: positions stay local float32; the root node's translation carries the origin in glTF's
  own y-up axes (:func:`gltf_translation`), as readers that apply node transforms expect.

The rotation taking y up to z up is proper (determinant 1), so faces keep their winding.
"""

from __future__ import annotations

import numpy as np


def up_of(site: dict | None) -> str:
    """The site's up axis: GeoJSON lots' sites say none and are z up."""
    return str(site.get("up", "z")) if site else "y"


def to_site(points: np.ndarray, site: dict | None) -> np.ndarray:
    """(n, 3) local points in the site's frame (a copy, float64); unchanged without a site."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if not site:
        return p
    east, north, height = (float(v) for v in site["origin"])
    if up_of(site) == "z":
        return np.column_stack([p[:, 0] + east, north - p[:, 2], p[:, 1] + height])
    return np.column_stack([p[:, 0] + east, p[:, 1] + height, p[:, 2] - north])


def gltf_translation(site: dict | None) -> np.ndarray:
    """The site's origin in glTF's axes (x east, y up, z south): what a root node adds so that
    a reader applying it sees the input's coordinates, in glTF's frame."""
    if not site:
        return np.zeros(3)
    east, north, height = (float(v) for v in site["origin"])
    return np.array([east, height, -north])
