"""Silhouettes of a mass seen by a :class:`~.camera.PhotoCamera`, and the distance between two of
them that the photograph stage minimises (Nishida et al. 2018, section 4.4).

A silhouette is a boolean mask (rows down): the union of the mass's projected triangles, drawn by
Pillow.  The distance is the paper's symmetric chamfer distance between the two outlines: the
mean, over the pixels of each outline, of the distance transform of the other outline.
"""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw
from scipy import ndimage

from .camera import PhotoCamera

AREA_WEIGHT = 20.0  # pixels of chamfer distance that a whole area mismatch is worth


def project_triangles(
    tris: np.ndarray, camera: PhotoCamera, width: int, height: int
) -> np.ndarray | None:
    """(n, 3, 2) pixel positions of the triangles' corners, or None when a corner lies behind
    the camera (the silhouette of such a view is not a projection)."""
    pixels, front = camera.project(tris.reshape(-1, 3), width, height)
    if not front.all():
        return None
    return pixels.reshape(-1, 3, 2)


def draw(projected: np.ndarray, width: int, height: int) -> np.ndarray:
    """The filled union of projected triangles as a (height, width) bool mask."""
    image = Image.new("1", (width, height), 0)
    pen = ImageDraw.Draw(image)
    for tri in np.round(projected - 0.5, 2).tolist():
        pen.polygon([tuple(p) for p in tri], fill=1, outline=1)
    return np.asarray(image, dtype=bool)


def silhouette(tris: np.ndarray, camera: PhotoCamera, width: int, height: int) -> np.ndarray | None:
    """The mass's silhouette in a width x height image, or None when it is behind the camera."""
    projected = project_triangles(tris, camera, width, height)
    return None if projected is None else draw(projected, width, height)


def boundary(mask: np.ndarray) -> np.ndarray:
    """The mask's outline: its pixels with a 4-neighbour outside it (the image's edge counts as
    outside, so that a building cut by the frame keeps that side)."""
    return mask & ~ndimage.binary_erosion(mask, border_value=0)


class Target:
    """The outline a fit is measured against, with its distance transform computed once."""

    def __init__(self, mask: np.ndarray) -> None:
        self.mask = mask
        self.outline = boundary(mask)
        self.distance = ndimage.distance_transform_edt(~self.outline)
        self.count = int(self.outline.sum())

    def score(self, other: np.ndarray) -> float:
        """What the fit minimises: the chamfer distance plus :data:`AREA_WEIGHT` pixels per
        unit of area mismatch (1 - IoU).  The chamfer distance alone has minima where a small
        part of the outline is matched well and the rest ignored; the area term sees the whole
        shape (see docs/inverse-image.md for both measured)."""
        union = np.logical_or(self.mask, other).sum()
        overlap = np.logical_and(self.mask, other).sum() / union if union else 1.0
        return self.chamfer(other) + AREA_WEIGHT * (1.0 - overlap)

    def chamfer(self, other: np.ndarray) -> float:
        """The paper's dist(S, S^) for the silhouette ``other`` (pixels; the image's diagonal
        when ``other`` is empty)."""
        line = boundary(other)
        n = int(line.sum())
        if n == 0 or self.count == 0:
            return float(np.hypot(*self.mask.shape))
        theirs = ndimage.distance_transform_edt(~line)
        total = self.distance[line].sum() + theirs[self.outline].sum()
        return float(total / (n + self.count))


def centre(mask: np.ndarray) -> np.ndarray | None:
    """(x, y) centre of the mask's bounding box in pixels, None when it is empty."""
    rows = np.flatnonzero(mask.any(axis=1))
    cols = np.flatnonzero(mask.any(axis=0))
    if len(rows) == 0:
        return None
    return np.array([(cols[0] + cols[-1] + 1) / 2, (rows[0] + rows[-1] + 1) / 2])


def iou(a: np.ndarray, b: np.ndarray) -> float:
    """Intersection over union of two masks (1.0 for two empty masks)."""
    union = np.logical_or(a, b).sum()
    return 1.0 if union == 0 else float(np.logical_and(a, b).sum() / union)
