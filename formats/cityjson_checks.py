"""What CityJSON's vertices and boundary indices must be before the reader computes with them.

A vertex of NaN or 1e308 reaches earcut (C++) and the Newell normals, and a boundary index of
-1 or 10**12 either wraps round to another vertex (numpy counts negative indices from the end)
or fails deep in numpy with a message that names no object (issue 25).  The reader raises
ValueError with these messages; read_cityjson turns them into one BgrError naming the file.
"""

from __future__ import annotations

import numpy as np

from bgr.interpreter.limits import MAX_INPUT_COORDINATE


def checked_vertices(vertices: np.ndarray) -> np.ndarray:
    """(N, 3) vertices, each finite and within MAX_INPUT_COORDINATE of the origin once the
    transform is applied; ValueError naming the first that is not."""
    if vertices.ndim != 2 and vertices.size:
        raise ValueError('"vertices" must be a list of [x, y, z] lists')
    vertices = vertices.reshape(-1, 3)
    bad = ~(np.abs(vertices) <= MAX_INPUT_COORDINATE).all(axis=1)  # NaN compares false
    if bad.any():
        k = int(np.argmax(bad))
        raise ValueError(
            f"vertex {k} (counted from 0) is {vertices[k].tolist()} after the transform: "
            f"coordinates must be finite and within ±{MAX_INPUT_COORDINATE:.0e} m".replace(
                "e+0", "e"
            )
        )
    return vertices


def check_indices(index: np.ndarray, count: int) -> None:
    """ValueError for a boundary index that names no vertex (negative, or ``count`` or more)."""
    bad = (index < 0) | (index >= count)
    if bad.any():
        raise ValueError(
            f"a boundary names vertex {int(index[np.argmax(bad)])}, but the file has "
            f"{count:,} vertices (counted from 0)"
        )
