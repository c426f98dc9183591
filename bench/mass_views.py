"""Synthetic silhouettes of the 30 stdlib masses for the photograph stage (issue 28), drawn as
Nishida et al. 2018 section 4.3 draws theirs:

* parameters uniform over each family's ranges (bgr.inverse.image.masses) and the camera's
  (bgr.inverse.image.camera: the paper's ranges);
* a view is discarded when the camera sees the top or the bottom face of the mass's bounding
  box (it stands below the ground or above the roof: ``t_y`` is drawn where it does not, see
  :func:`_heights`), or when a vertex projects more than 3 % of the image outside it;
* the outline's corners are moved at random within +-1 % of the image's size (every projected
  vertex, consistently for the triangles that share it).

Not done: the paper's extra check that a roof face or the side of every stack is visible.

A view keeps its projected triangles in [0, 1] image coordinates, so that it can be drawn at
any resolution: the network's input (:func:`bgr.inverse.image.mass_fit.network_input`) or the
evaluation's finer masks.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bgr.inverse.image.camera import HIGH, LOW, PhotoCamera
from bgr.inverse.image.masses import FAMILIES, triangles

ASPECT = (4, 3)  # width : height of the synthetic photographs
OUTSIDE = 0.03  # a vertex may project this far (of the image's size) outside it
JITTER = 0.01  # outline corners move up to this much (of the image's size)
ATTEMPTS = 40  # camera draws per wanted view before the geometry is given up


@dataclass
class View:
    family: int  # index into FAMILIES
    mass: np.ndarray  # the mass's parameters in [0, 1]
    camera: np.ndarray  # the camera's parameters in [0, 1]
    corners: np.ndarray  # (n, 3, 2) projected triangles, x / width and y / height


def views_of(
    family: int, rng: np.random.Generator, count: int, jitter: float = JITTER
) -> list[View]:
    """Up to ``count`` accepted views of one random mass of a family, the outline's corners
    moved by up to ``jitter`` (0: a clean render of the same mass and camera)."""
    fam = FAMILIES[family]
    unit = rng.random(len(fam.params))
    tris = triangles(fam, fam.values(unit))
    points, inverse = np.unique(tris.reshape(-1, 3).round(5), axis=0, return_inverse=True)
    top = points[:, 1].max()
    width, height = ASPECT
    found: list[View] = []
    for _ in range(count * ATTEMPTS):
        if len(found) == count:
            break
        cam_unit = rng.random(8)
        span = _heights(cam_unit, top)
        if span is None:
            continue
        cam_unit[7] = rng.uniform(*span)
        camera = PhotoCamera.from_vector(LOW + cam_unit * (HIGH - LOW))
        pixels, front = camera.project(points, width, height)
        if not front.all():
            continue
        xy = pixels / np.array([width, height])
        if (xy < -OUTSIDE).any() or (xy > 1 + OUTSIDE).any():
            continue
        # drawn whatever the jitter, so that a clean set has the jittered set's masses and views
        moved = rng.uniform(-JITTER, JITTER, xy.shape)
        xy = xy + moved * (jitter / JITTER)
        found.append(View(family, unit, cam_unit, xy[inverse.reshape(-1)].reshape(-1, 3, 2)))
    return found


def _heights(cam_unit: np.ndarray, top: float) -> tuple[float, float] | None:
    """The range of ``t_y`` (in [0, 1]) that puts the camera between the ground and the top
    of the mass, the other parameters given; None when there is none.  Drawing ``t_y`` from it
    is the paper's rejection of views that see the top or bottom face, without the misses: the
    camera's height is linear in ``t_y``."""
    real = LOW + cam_unit * (HIGH - LOW)
    rotation = PhotoCamera.from_vector(real).rotation()
    t_z = PhotoCamera.from_vector(real).t_z
    # camera height = -(R^T t)_y = a + b * t_y
    a = -(rotation[0, 1] * real[6] + rotation[2, 1] * t_z)
    b = -rotation[1, 1]
    ends = sorted(((0.0 - a) / b, (top - a) / b))
    low = max(ends[0], LOW[7]) + 1e-6
    high = min(ends[1], HIGH[7]) - 1e-6
    if low >= high:
        return None
    return (low - LOW[7]) / (HIGH[7] - LOW[7]), (high - LOW[7]) / (HIGH[7] - LOW[7])


def draw_view(view: View, width: int, height: int) -> np.ndarray:
    """The view's silhouette as a (height, width) bool mask."""
    from bgr.inverse.image.outline import draw

    return draw(view.corners * np.array([width, height]), width, height)


def sample(seed: int, per_family: int, views: int, jitter: float = JITTER) -> list[View]:
    """``per_family`` masses of every family, ``views`` accepted views of each (fewer when the
    camera draws run out), from one seed."""
    rng = np.random.default_rng(seed)
    out: list[View] = []
    for family in range(len(FAMILIES)):
        for _ in range(per_family):
            out += views_of(family, rng, views, jitter)
    return out
