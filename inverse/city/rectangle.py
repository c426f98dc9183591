"""The angle of a component's minimum-area rectangle seen from above (paper, section IV.B).

:func:`angle` is trimesh's ``oriented_bounds_2D`` (a qhull hull, then every hull edge tried as
the rectangle's side), turned into the angle :mod:`.components` needs.  It costs ~0.2 ms a call,
which a city of 100,000 one-triangle objects pays 100,000 times, so triangles take
:func:`triangle_angles`: the same arithmetic on all of them at once, in the order qhull hands a
triangle's edges over: lo the first corner of least x, hi the first of greatest x, mid the
third, the edges are hi-lo, mid-lo, mid-hi, whichever way the triangle turns.  A triangle that
qhull could see otherwise (two corners of nearly but not exactly equal x, nearly no area) is
left to :func:`angle`;
tests/test_linear.py checks the two agree bit for bit.
"""

from __future__ import annotations

import numpy as np
from trimesh.bounds import _flip, oriented_bounds_2D

CLEAR = 1e-9  # relative to the triangle's size and place: closer x, or less area, goes to qhull


def angle(points: np.ndarray) -> float:
    """The angle (degrees) of the minimum rectangle of 2D ``points``; 0 where qhull finds no
    hull (collinear points: the world axes are kept)."""
    try:
        transform, _ = oriented_bounds_2D(points)
    except Exception:
        return 0.0
    return float(np.degrees(np.arctan2(transform[1, 0], transform[0, 0])))


def triangle_angles(tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`angle` of each triangle of ``tri`` (n, 3, 2) at once, and which of them it holds
    for (the others, close to degenerate, need :func:`angle`)."""
    n = len(tri)
    rows = np.arange(n)
    x = tri[:, :, 0]
    lo, hi = np.argmin(x, axis=1), np.argmax(x, axis=1)  # the first of equals, as qhull
    mid = (3 - lo - hi) % 3  # (all three x equal: no triangle seen from above, not clear)
    span = np.ptp(tri.reshape(n, -1), axis=1)
    size = np.abs(tri).max(axis=(1, 2)) + span
    gaps = np.abs(x[:, [0, 1, 2]] - x[:, [1, 2, 0]])
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    twice_area = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    apart = (gaps == 0) | (gaps > CLEAR * size[:, None])  # equal x, or clearly apart
    clear = apart.all(axis=1) & (twice_area > CLEAR * span**2) & (lo != hi)
    # qhull's edges of a triangle, each from its first point to its second (see the module)
    simplices = np.stack([np.stack(p, axis=1) for p in ((hi, lo), (mid, lo), (mid, hi))], axis=1)
    edges = tri[rows[:, None, None], simplices]  # (n, 3 edges, 2 ends, 2)
    # from here on trimesh's oriented_bounds_2D, one triangle per row
    vectors = edges[:, :, 1] - edges[:, :, 0]
    norm = np.sqrt((vectors**2) @ np.array([1.0, 1.0]))
    clear &= (norm > 1e-10).all(axis=1)
    vectors = vectors / np.where(norm > 0, norm, 1.0)[:, :, None]
    perp = vectors[:, :, ::-1] * np.array([-1.0, 1.0])
    corners = np.swapaxes(tri, 1, 2)  # (n, 2, 3): the hull is the triangle, in any order
    along, across = vectors @ corners, perp @ corners
    extents = np.stack([np.ptp(along, axis=2), np.ptp(across, axis=2)], axis=2)
    best = np.argmin(extents[:, :, 0] * extents[:, :, 1], axis=1)
    side, rectangle = vectors[rows, best], extents[rows, best]
    theta = np.arctan2(side[:, 1], side[:, 0])
    transform = np.zeros((n, 3, 3))
    sin, cos = np.sin(theta), np.cos(theta)
    transform[:, 0, 0], transform[:, 0, 1] = cos, sin
    transform[:, 1, 0], transform[:, 1, 1] = -sin, cos
    transform[:, 2, 2] = 1.0
    long_y = rectangle[:, 1] > rectangle[:, 0]  # trimesh turns the rectangle to be long in x
    transform[long_y] = _flip @ transform[long_y]
    return np.degrees(np.arctan2(transform[:, 1, 0], transform[:, 0, 0])), clear
