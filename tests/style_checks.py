"""What a user of ``bgr restyle`` relies on, measured on the written models (issue 27): the styled
model keeps the mass's shape, its walls carry images on every side, and the images keep the
density they were photographed at.  Shared by tests/test_style_plateau.py and
tests/test_style_masses.py."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import shapely

from bgr.formats.gltf_textured import read_gltf_textured
from bgr.formats.textured_model import TexturedMesh

SIDES = {"front": (0, 0, -1), "right": (1, 0, 0), "back": (0, 0, 1), "left": (-1, 0, 0)}
"""Outward normal of each wall of a mass, as comp(f) names them (y up, the front to -z)."""


def _normals(mesh: TexturedMesh) -> tuple[np.ndarray, np.ndarray]:
    """(corners (T, 3, 3), unit normals (T, 3)) of the mesh's triangles (zero for degenerate)."""
    c = mesh.vertices[mesh.faces]
    n = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    length = np.linalg.norm(n, axis=1)
    return c, n / np.where(length > 0, length, 1.0)[:, None]


def _facing(corners: np.ndarray, normals: np.ndarray, side: str) -> shapely.Geometry:
    """The union of the triangles facing ``side`` (within 8 degrees), drawn in the wall's plane:
    (horizontal coordinate along the wall, height)."""
    d = np.array(SIDES[side], float)
    on = normals @ d > 0.99
    u = 2 if d[0] else 0  # a wall facing x runs along z, one facing z along x
    flat = corners[on][:, :, [u, 1]]
    if not len(flat):
        return shapely.Polygon()
    return shapely.union_all(shapely.buffer(shapely.polygons(flat), 1e-6))


def wall_cover(mass: Path, styled: Path) -> dict[str, float]:
    """Per side: the fraction of the mass's wall area facing it that the styled model's textured
    triangles facing the same way cover (recessed faces project onto the wall they belong to)."""
    plain, out = read_gltf_textured(mass), read_gltf_textured(styled)
    pc, pn = _normals(plain)
    oc, on = _normals(out)
    textured = out.textured()
    cover = {}
    for side in SIDES:
        wall = _facing(pc, pn, side)
        images = _facing(oc[textured], on[textured], side)
        cover[side] = float(wall.intersection(images).area / wall.area) if wall.area else 1.0
    return cover


def outside(mass: Path, styled: Path, tol: float = 0.05) -> np.ndarray:
    """(k, 3) vertices of the styled model that lie outside the mass by more than ``tol`` metres:
    at each height the mass's plan is the union of its upward faces at that height or above."""
    plain, out = read_gltf_textured(mass), read_gltf_textured(styled)
    pc, pn = _normals(plain)
    up = pn[:, 1] > 0.99
    heights, roofs = pc[up][:, 0, 1], shapely.polygons(pc[up][:, :, [0, 2]])
    points = out.vertices[np.unique(out.faces)]
    bad = np.zeros(len(points), dtype=bool)
    levels = np.round(points[:, 1], 3)
    for y in np.unique(levels):
        at = levels == y
        plan = shapely.union_all(roofs[heights >= y - 1e-3])
        bad[at] = ~shapely.contains_xy(plan.buffer(tol), points[at, 0], points[at, 2])
    return points[bad]


def bounds(path: Path) -> np.ndarray:
    """(2, 3) lowest and highest corner of a model's triangles."""
    mesh = read_gltf_textured(path)
    points = mesh.vertices[np.unique(mesh.faces)]
    return np.array([points.min(axis=0), points.max(axis=0)])


def texel_density(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(px per metre along each textured triangle's most stretched direction, its area): the
    smaller singular value of the map from the triangle's plane (metres) to its image's pixels."""
    mesh = read_gltf_textured(path)
    keep = np.flatnonzero(mesh.textured())
    corners, uv = mesh.vertices[mesh.faces[keep]], mesh.uv[keep]
    size = np.array([m.image_size() if m.has_image() else (1, 1) for m in mesh.materials], float)
    pixels = size[mesh.material[keep]][:, None, :]  # (T, 1, 2) width, height
    e = corners[:, 1:] - corners[:, :1]  # (T, 2, 3) two edges
    n = np.cross(e[:, 0], e[:, 1])
    area = np.linalg.norm(n, axis=1) / 2
    ok = area > 1e-9
    e, n, area, uv, pixels = e[ok], n[ok], area[ok], uv[ok], pixels[ok]
    ax = e[:, 0] / np.linalg.norm(e[:, 0], axis=1)[:, None]
    ay = np.cross(n / (2 * area)[:, None], ax)
    plane = np.stack([(e * ax[:, None]).sum(-1), (e * ay[:, None]).sum(-1)], axis=-1)  # (T, 2, 2)
    texels = (uv[:, 1:] - uv[:, :1]) * pixels  # (T, 2, 2): the edges in pixels
    jacobian = np.linalg.solve(plane, texels)  # plane @ J = texels: metres to pixels
    return np.linalg.svd(jacobian, compute_uv=False)[:, 1], area


def share_below(path: Path, density: float) -> float:
    """The fraction of the textured area whose image is stretched below ``density`` px/m."""
    low, area = texel_density(path)
    return float(area[low < density].sum() / area.sum())
