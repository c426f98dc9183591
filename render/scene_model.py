"""The renderer's :class:`Scene`: world triangles with a colour, a part and a label each (and,
for a textured source, an image and texture coordinates), and :func:`labels_index`, which
numbers the labels.

It is apart from the readers that make scenes (:mod:`.scene`, :mod:`.textured`) so that both
can build one without importing each other; :mod:`.scene` says what ``part`` and ``label`` hold
for each source.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

NO_LABEL = "(none)"


@dataclass(eq=False)
class Scene:
    """Triangles in world space (y up) and, per triangle, its colour, part and label."""

    triangles: np.ndarray  # (T, 3, 3) float64, corners counter-clockwise seen from outside
    colors: np.ndarray  # (T, 3) uint8 sRGB
    part: np.ndarray  # (T,) int64
    label: np.ndarray  # (T,) int64 index into labels
    labels: list[str]
    # a derived grammar's warnings (footprints skipped or repaired, ...): bgr.Result.warnings
    warnings: list = field(default_factory=list)
    # the direction the lots' fronts face (a unit world vector in the x-z plane, see
    # lots_front), which the front/iso/top views look at; None: bgr's default front, -z
    front: np.ndarray | None = None
    # textures (render/textured.py, drawn by render/texturing.py): per triangle the index of its
    # image in ``textures`` (-1: none, its colour alone) and its corners' texture coordinates,
    # (0, 0) at the image's lower-left, v up; None: an untextured scene
    texture: np.ndarray | None = None  # (T,) int64
    uv: np.ndarray | None = None  # (T, 3, 2) float64
    textures: list = field(default_factory=list)  # textured.Texture

    def textured(self) -> bool:
        """Whether any triangle shows an image."""
        if self.texture is None or not self.textures:
            return False
        return bool((self.texture >= 0).any())

    def __len__(self) -> int:
        return len(self.triangles)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) corners of the axis-aligned bounding box (a unit box at 0 when empty)."""
        if len(self) == 0:
            return np.full(3, -0.5), np.full(3, 0.5)
        flat = self.triangles.reshape(-1, 3)
        return flat.min(axis=0), flat.max(axis=0)

    def normals(self) -> np.ndarray:
        """(T, 3) unit face normals (degenerate triangles get +y)."""
        t = self.triangles
        n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
        length = np.linalg.norm(n, axis=1)
        bad = ~(length > 0)
        n[bad], length[bad] = (0.0, 1.0, 0.0), 1.0
        return n / length[:, None]


def labels_index(names) -> tuple[np.ndarray, list[str]]:
    """(index of each name into the sorted distinct names, those names)."""
    labels, index = np.unique(
        np.asarray(list(names), dtype=object).astype(str), return_inverse=True
    )
    return index.reshape(-1).astype(np.int64), [str(s) for s in labels]
