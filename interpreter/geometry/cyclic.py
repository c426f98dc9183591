"""A ring's points shifted by one place, for the per-corner arithmetic of small polygons.

``np.roll`` does the same, but through a general n-dimensional path whose fixed cost dominated
on the few-corner rings of roofs and ear clipping (1.3 % of deriving the Helsinki example).
These give the very same arrays, so every result computed from them is the same to the bit.
"""

from __future__ import annotations

import numpy as np


def following(points: np.ndarray) -> np.ndarray:
    """Each row's successor round the ring: ``np.roll(points, -1, axis=0)``."""
    return np.concatenate((points[1:], points[:1]))


def preceding(points: np.ndarray) -> np.ndarray:
    """Each row's predecessor round the ring: ``np.roll(points, 1, axis=0)``."""
    return np.concatenate((points[-1:], points[:-1]))
