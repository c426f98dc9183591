"""The standard view of a textured building (section 4.1 of Zhang et al.): y up, metres, the
principal horizontal axis along x, the lowest point at y = 0, centred in x and z, unit height.

The paper aligns each model by hand ("manually aligning the front of the building with the xy
plane") and remarks that an automatic alignment could replace that step; :func:`standard_frame`
is that replacement.  How each step is made:

1. **Up.** A z-up file (CityGML, CityJSON) is turned y up by the proper rotation
   (x, y, z) -> (x, z, -y); a y-up file (glTF, OBJ) is kept.
2. **Metres.** A geographic CRS (a PLATEAU file is EPSG:6697: latitude, longitude, height) is
   projected with pyproj to the UTM zone of the building's centre (``interpreter.lots.utm_zone``),
   horizontally only: heights are kept as the file gives them.  A projected CRS, or none, is taken
   as metres already.
3. **Axes.** The wall directions of a Manhattan-world building are found as the area-weighted
   circular mean of the vertical triangles' normal angles *modulo 90 degrees* (the mean of
   exp(4i alpha)).  Deviation from a plain PCA of positions, with the reason: the principal axes
   of an L or a cross whose arms are equal lie on the diagonal, 45 degrees off every wall, which
   would break the four-walls decomposition of section 4.3.1.  PCA still decides which of the two
   wall directions is x: the one along which the wall area's second moment (its exact
   area-weighted covariance, triangle by triangle) is larger, i.e. the building's longer axis.
4. **Sign.** Of the two opposite directions of that axis, x is the one within 90 degrees of the
   input's own +x (east, for a geographic file); ties (exactly north-south) take the one along
   the y-up frame's +z (the input's +z for a y-up file, its -y for a z-up one).  The rotation is
   about y, so it is proper (det +1, no mirror), and z follows: the *front* wall (outward -z) is
   the long side that faces the input's -z for a y-up file, its +y for a z-up one (north, for a
   geographic file).
5. **Scale.** The lowest point goes to y = 0, the bounding box is centred in x and z, and the
   model is divided by its height (``Frame.scale`` metres a unit).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from bgr.formats.textured_model import TexturedMesh
from bgr.grammar.errors import BgrError, Diagnostic

VERTICAL = 0.1
"""A triangle is vertical (a wall) when its unit normal's up component is below this (within
about 5.7 degrees of vertical).  Our choice: the paper's walls are exactly vertical; real
models (PLATEAU) tilt walls by a few tenths of a degree."""


@dataclass
class Frame:
    """The map from a file's frame to the standard view, and back.

    ``apply`` = scale down . shift . rotate about y . to y up . project; ``unapply`` inverts it.
    """

    up: str  # "z" or "y": the file's up axis
    source_crs: str | None  # the geographic CRS projected from (as the file names it), or None
    utm: str | None  # the EPSG code projected to (EPSG:326NN), or None
    angle: float  # radians: the standard x axis is (cos, sin) in the y-up metric (x, z) plane
    centre: np.ndarray  # (3,) y-up metres: the point that becomes (0, 0, 0) before scaling
    scale: float  # metres a unit: the building's height

    @property
    def rotation(self) -> np.ndarray:
        """(3, 3): the rotation about y taking y-up metres (centred) to the standard axes."""
        c, s = np.cos(self.angle), np.sin(self.angle)
        return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])

    def metric(self, points: np.ndarray) -> np.ndarray:
        """(N, 3) file-frame points in y-up metres (steps 1 and 2), not yet centred."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if self.utm is not None and self.source_crs is not None:
            east, north = _transformer(self.source_crs, self.utm).transform(*_lonlat(p, self))
            p = np.column_stack([east, north, p[:, 2] if self.up == "z" else p[:, 1]])
            return np.column_stack([p[:, 0], p[:, 2], -p[:, 1]])
        if self.up == "z":
            return np.column_stack([p[:, 0], p[:, 2], -p[:, 1]])
        return p.copy()

    def apply(self, points: np.ndarray) -> np.ndarray:
        """(N, 3) points of the file's frame in the standard view."""
        return (self.metric(points) - self.centre) @ self.rotation.T / self.scale

    def unapply(self, points: np.ndarray) -> np.ndarray:
        """(N, 3) standard-view points back in the file's frame (and CRS)."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3) * self.scale
        p = p @ self.rotation + self.centre  # the rotation's inverse is its transpose
        if self.utm is not None and self.source_crs is not None:
            t = _transformer(self.source_crs, self.utm)
            lon, lat = t.transform(p[:, 0], -p[:, 2], direction="INVERSE")
            first, second = (lat, lon) if _lat_first(self.source_crs) else (lon, lat)
            if self.up == "z":
                return np.column_stack([first, second, p[:, 1]])
            return np.column_stack([first, p[:, 1], second])
        if self.up == "z":
            return np.column_stack([p[:, 0], -p[:, 2], p[:, 1]])  # y up -> z up
        return p


def standard_frame(mesh: TexturedMesh, faces: np.ndarray) -> Frame:
    """The standard view of the building made of the triangles ``faces`` ((F,) bool) of ``mesh``.

    Raises :class:`BgrError` (located at ``mesh.source``) for an empty selection, a building
    without vertical triangles, or one of zero height."""
    shown = mesh.source
    tris = mesh.faces[np.asarray(faces, dtype=bool)]
    if len(tris) == 0:
        raise BgrError(
            Diagnostic(shown, 0, 0, "the building has no triangles", "check the building's id")
        )
    up = "y" if mesh.up == "y" else "z"
    source, utm = _geographic(mesh, tris, up)
    frame = Frame(up, source, utm, 0.0, np.zeros(3), 1.0)
    used = np.unique(tris)
    metric = np.zeros((len(mesh.vertices), 3))
    metric[used] = frame.metric(mesh.vertices[used])
    if not np.isfinite(metric[used]).all():
        raise BgrError(
            Diagnostic(
                shown,
                0,
                0,
                "the building has coordinates that are not finite metres"
                + (f" once projected from {(source or '')[:200]} to {utm}" if utm else ""),
                "check the model's CRS and coordinates",
            )
        )
    corners = metric[tris]  # (F, 3, 3)
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    area = np.linalg.norm(cross, axis=1) / 2.0
    with np.errstate(invalid="ignore", divide="ignore"):
        normal = cross / (2.0 * area[:, None])
    wall = (area > 0) & (np.abs(normal[:, 1]) < VERTICAL)
    if not wall.any():
        raise BgrError(
            Diagnostic(
                shown,
                0,
                0,
                "the building has no vertical faces: a style sheet captures walls",
                "give a building with walls (a CityGML LoD2 solid, a textured mesh with façades)",
            )
        )
    height = float(np.ptp(metric[used, 1]))
    if not height > 0 or not np.isfinite(height):
        raise BgrError(
            Diagnostic(shown, 0, 0, "the building has zero height", "give a 3D building model")
        )
    frame.angle = _axis(corners[wall], normal[wall], area[wall])
    turned = metric[used] @ frame.rotation.T
    lo, hi = turned.min(axis=0), turned.max(axis=0)
    middle = np.array([(lo[0] + hi[0]) / 2.0, lo[1], (lo[2] + hi[2]) / 2.0])
    frame.centre = middle @ frame.rotation  # back in y-up metres (unrotated)
    frame.scale = height
    return frame


def _axis(corners: np.ndarray, normal: np.ndarray, area: np.ndarray) -> float:
    """The angle of the standard x axis in the (x, z) plane (module docstring, steps 3 and 4)."""
    alpha = np.arctan2(normal[:, 2], normal[:, 0])
    mean = np.angle(np.sum(area * np.exp(4j * alpha))) / 4.0  # a wall direction, mod 90 deg
    # the area-weighted second moment of the wall surface (exact for each triangle:
    # integral of p p^T over a triangle = A / 12 * (sum v v^T + s s^T), s the vertex sum)
    xz = corners[:, :, [0, 2]]  # (F, 3, 2)
    total = float(area.sum())
    centre = np.einsum("f,fvk->k", area, xz) / (3.0 * total)
    d = xz - centre
    s = d.sum(axis=1)
    moment = np.einsum("f,fvk,fvl->kl", area, d, d) + np.einsum("f,fk,fl->kl", area, s, s)
    best, spread = mean, -1.0
    for angle in (mean, mean + np.pi / 2.0):
        u = np.array([np.cos(angle), np.sin(angle)])
        along = float(u @ moment @ u)
        if along > spread * (1.0 + 1e-9):
            best, spread = angle, along
    u = np.array([np.cos(best), np.sin(best)])
    if u[0] < -1e-12 or (abs(u[0]) <= 1e-12 and u[1] < 0):
        best += np.pi
    return float(np.arctan2(np.sin(best), np.cos(best)))


def _geographic(mesh: TexturedMesh, tris: np.ndarray, up: str) -> tuple[str | None, str | None]:
    """(the file's geographic CRS, the UTM zone of the building's centre), or (None, None) for a
    file in metres (a projected CRS, or none named)."""
    if not mesh.crs:
        return None, None
    try:
        horizontal = _horizontal(mesh.crs)
    except Exception:  # pyproj.exceptions.CRSError: a CRS pyproj does not know
        raise BgrError(
            Diagnostic(
                mesh.source,
                0,
                0,
                f"unknown CRS {mesh.crs[:200]!r}",
                "give a file whose CRS pyproj knows (an EPSG code)",
            )
        ) from None
    if not horizontal.is_geographic:
        return None, None
    from bgr.interpreter.lots import utm_zone

    p = mesh.vertices[np.unique(tris)]
    a, b = (p[:, 0], p[:, 1]) if up == "z" else (p[:, 0], p[:, 2])
    lat, lon = (a, b) if _lat_first(mesh.crs) else (b, a)
    centre_lon = (float(lon.min()) + float(lon.max())) / 2.0
    centre_lat = (float(lat.min()) + float(lat.max())) / 2.0
    return mesh.crs, utm_zone(centre_lon, centre_lat)


def _lonlat(p: np.ndarray, frame: Frame) -> tuple[np.ndarray, np.ndarray]:
    """Longitude and latitude columns of file-frame points (the CRS's axis order decides)."""
    assert frame.source_crs is not None
    a, b = (p[:, 0], p[:, 1]) if frame.up == "z" else (p[:, 0], p[:, 2])
    return (b, a) if _lat_first(frame.source_crs) else (a, b)


@lru_cache(maxsize=16)
def _horizontal(crs: str) -> Any:
    """The horizontal part of a CRS (a compound CRS's first member: EPSG:6697 -> EPSG:6668)."""
    from pyproj import CRS

    parsed = CRS.from_user_input(crs)
    return parsed.sub_crs_list[0] if parsed.is_compound else parsed


@lru_cache(maxsize=16)
def _lat_first(crs: str) -> bool:
    """Whether the CRS's first axis is the latitude (EPSG:6697 and EPSG:4326 are; CRS84 is not)."""
    axes = _horizontal(crs).axis_info
    return bool(axes) and axes[0].direction.lower() in ("north", "south")


@lru_cache(maxsize=16)
def _transformer(source: str, target: str) -> Any:
    """pyproj Transformer from the CRS's horizontal part to UTM, longitude/latitude order."""
    from pyproj import Transformer

    return Transformer.from_crs(_horizontal(source), target, always_xy=True)
