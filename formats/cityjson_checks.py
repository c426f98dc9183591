"""What CityJSON's boundaries and vertices must be before the reader computes with them.

A boundary index of -1 or 10**12 either wraps round to another vertex (numpy counts negative
indices from the end) or fails deep in numpy with a message that names no object; a vertex of
NaN or 1e308 would reach earcut (C++) and the Newell normals.  Bad indices raise
ValueError (read_cityjson names the city object); a surface with a bad vertex is fanned without
arithmetic, and the city reader's coordinate check (inverse/city/coordinates.py) then names
the vertex and its city object, as it does for every format.
"""

from __future__ import annotations

import numpy as np

from bgr.interpreter.limits import MAX_INPUT_COORDINATE


def check_indices(index: np.ndarray, count: int) -> None:
    """ValueError for a boundary index that names no vertex (negative, or ``count`` or more)."""
    bad = (index < 0) | (index >= count)
    if bad.any():
        raise ValueError(
            f"a boundary names vertex {int(index[np.argmax(bad)])}, but the file has "
            f"{count:,} vertices (counted from 0)"
        )


def usable(points: np.ndarray) -> bool:
    """Whether every point is finite and within MAX_INPUT_COORDINATE (NaN compares false)."""
    return bool((np.abs(points) <= MAX_INPUT_COORDINATE).all())


def fan(ring: np.ndarray) -> np.ndarray:
    """(n - 2, 3) triangles fanned from a ring's first corner: no arithmetic on its points."""
    if len(ring) < 3:
        return np.zeros((0, 3), dtype=np.int64)
    return np.stack([np.full(len(ring) - 2, ring[0]), ring[1:-1], ring[2:]], axis=1)
