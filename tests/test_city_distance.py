"""inverse/city/distance.py: exact sampled distances between triangle meshes (issue 12).

The expected values are worked out by hand: a cube and the cube scaled 1.1 about its centre are
0.05 apart face to face and 0.05 * sqrt(3) corner to corner; a cube without its top is 0.5 from
the top's centre (the nearest walls are half a side away).  The point-triangle distance and the
grid search are checked against slow references on random triangles, degenerate ones included.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bgr.inverse.city import distance
from bgr.inverse.city.distance import (
    mesh_distances,
    point_triangle_distance,
    surface_distances,
    surface_samples,
)

CUBE_V = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
CUBE_F = np.array(
    [
        [0, 1, 3],
        [0, 3, 2],  # x = 0
        [4, 6, 7],
        [4, 7, 5],  # x = 1
        [0, 4, 5],
        [0, 5, 1],  # y = 0
        [2, 3, 7],
        [2, 7, 6],  # y = 1 (the top)
        [0, 2, 6],
        [0, 6, 4],  # z = 0
        [1, 5, 7],
        [1, 7, 3],  # z = 1
    ]
)


def grid_quads(n: int, flip: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """An n x n grid of unit squares in the plane z = 0, each cut along one diagonal or the
    other (``flip``, one boolean per square)."""
    v = np.array([[x, y, 0.0] for y in range(n + 1) for x in range(n + 1)])
    faces = []
    for k, (y, x) in enumerate(np.ndindex(n, n)):
        a, b = y * (n + 1) + x, y * (n + 1) + x + 1
        c, d = b + n + 1, a + n + 1
        faces += [[a, b, c], [a, c, d]] if flip.ravel()[k] else [[a, b, d], [b, c, d]]
    return v, np.array(faces)


# --------------------------------------------------------------------------------------------
# surface_distances on shapes with known answers


def test_identical_meshes_are_at_zero():
    d = surface_distances(CUBE_V, CUBE_F, CUBE_V, CUBE_F)
    assert d.hausdorff < 1e-12 and d.chamfer < 1e-12
    rng = np.random.default_rng(5)
    v = rng.uniform(-50, 50, (300, 3))
    f = rng.integers(0, 300, (400, 3))
    d = surface_distances(v, f, v, f, max_samples=2000)  # a soup of big crossing triangles
    assert d.hausdorff < 1e-9


@pytest.mark.parametrize("direction", [(1, 0, 0), (0, 0, -1), (1, 1, 1)])
def test_a_translation_of_half_a_millimetre(direction):
    """The cube moved 0.5 mm: every point moves at most 0.5 mm, and a face (or, moved along
    the diagonal, a corner) that leads is exactly that far from the moved cube."""
    step = 0.0005 * np.array(direction) / np.linalg.norm(direction)
    d = surface_distances(CUBE_V, CUBE_F, CUBE_V + step, CUBE_F)
    assert d.hausdorff == pytest.approx(0.0005, abs=1e-9)
    assert d.a_to_b_max == pytest.approx(0.0005, abs=1e-9)
    assert d.b_to_a_max == pytest.approx(0.0005, abs=1e-9)
    assert 0 < d.chamfer < 0.0005


def test_large_coordinates_keep_their_millimetres():
    """A cube at projected coordinates of millions of metres, moved 0.5 mm."""
    far = CUBE_V * 20 + [512_345.25, 87.5, -6_012_345.75]
    d = surface_distances(far, CUBE_F, far + [0.0005, 0, 0], CUBE_F)
    assert d.hausdorff == pytest.approx(0.0005, abs=1e-6)
    assert d.worst is not None and np.abs(d.worst - far.mean(axis=0)).max() < 20


def test_a_cube_scaled_about_its_centre():
    """Scaled 1.1 about (0.5, 0.5, 0.5): the big cube's faces are 0.05 outside the unit cube's,
    so every point of the unit cube is exactly 0.05 from the big one, while the big cube's
    corners are 0.05 * sqrt(3) from the unit cube's corners."""
    big = (CUBE_V - 0.5) * 1.1 + 0.5
    d = surface_distances(CUBE_V, CUBE_F, big, CUBE_F)
    assert d.a_to_b_max == pytest.approx(0.05, abs=1e-12)
    assert d.a_to_b_mean == pytest.approx(0.05, abs=1e-12)
    assert d.b_to_a_max == pytest.approx(0.05 * math.sqrt(3), abs=1e-12)
    assert d.hausdorff == pytest.approx(0.05 * math.sqrt(3), abs=1e-12)
    np.testing.assert_allclose(np.abs(d.worst - 0.5), 0.55, atol=1e-12)  # a big cube's corner
    assert 0.05 < d.b_to_a_mean < 0.05 * math.sqrt(3)
    assert d.chamfer == pytest.approx((d.a_to_b_mean + d.b_to_a_mean) / 2)


def test_the_same_quads_cut_along_the_other_diagonal():
    one = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
    d = surface_distances(one, [[0, 1, 2], [0, 2, 3]], one, [[0, 1, 3], [1, 2, 3]])
    assert d.hausdorff < 1e-9
    rng = np.random.default_rng(2)
    flip = rng.random((20, 20)) < 0.5
    va, fa = grid_quads(20, flip)
    vb, fb = grid_quads(20, ~flip)
    for offset in ([0.0, 0.0, 0.0], [500_000.0, 6_000_000.0, 40.0]):
        d = surface_distances(va + offset, fa, vb + offset, fb)
        assert d.hausdorff < 1e-9


def test_a_cube_without_its_top():
    """The top's centre is the point of the full cube farthest from the open box: 0.5 from the
    nearest walls (it is the midpoint of the top's diagonal edge, so it is sampled)."""
    open_box = np.delete(CUBE_F, [6, 7], axis=0)
    d = surface_distances(CUBE_V, CUBE_F, CUBE_V, open_box)
    assert d.hausdorff == pytest.approx(0.5, abs=1e-12)
    assert d.a_to_b_max == pytest.approx(0.5, abs=1e-12)
    assert d.b_to_a_max < 1e-12
    np.testing.assert_allclose(d.worst, [0.5, 1.0, 0.5], atol=1e-12)


def test_empty_meshes():
    none = np.zeros((0, 3), dtype=np.int64)
    d = surface_distances(CUBE_V, none, CUBE_V, none)
    assert d.hausdorff == 0 and d.chamfer == 0 and d.samples == 0 and d.worst is None
    d = surface_distances(CUBE_V, CUBE_F, CUBE_V, none)
    assert d.a_to_b_max == math.inf and d.hausdorff == math.inf and d.b_to_a_max == 0


def test_degenerate_triangles_do_not_crash():
    """Zero-area faces (a repeated corner, three corners on a line, one point thrice) count as
    the segments and points they are."""
    v = np.vstack([CUBE_V, [[0.5, 0.5, 2.0], [0.5, 0.5, 3.0], [0.5, 0.5, 4.0]]])
    extra = np.array([[8, 8, 9], [8, 9, 10], [10, 10, 10]])
    d = surface_distances(CUBE_V, CUBE_F, v, np.vstack([CUBE_F, extra]))
    assert np.isfinite(d.hausdorff) and np.isfinite(d.chamfer)
    assert d.b_to_a_max == pytest.approx(3.0)  # (0.5, 0.5, 4) is 3 from the face z = 1
    assert d.a_to_b_max < 1e-12
    only = surface_distances(v, extra, v, extra[:1])
    assert only.a_to_b_max == pytest.approx(1.0)  # (0.5, 0.5, 4) to the segment ending at z = 3


def test_samples():
    """8 corners, 12 centroids, 18 distinct edges (a face diagonal each), and 4 per m² of the
    cube's 6 m², also when every triangle has vertices of its own (a soup)."""
    points, random = surface_samples(CUBE_V, CUBE_F, 4.0, 0, 100)
    assert (len(points), random) == (8 + 12 + 18 + 24, 24)
    soup, _ = surface_samples(CUBE_V[CUBE_F].reshape(-1, 3), np.arange(36).reshape(-1, 3), 4, 0, 0)
    assert len(soup) == 8 + 12 + 18
    assert len(surface_samples(CUBE_V, CUBE_F, 4.0, 1000, 5000)[0]) == 38 + 1000
    assert len(surface_samples(CUBE_V, CUBE_F, 4.0, 10, 20)[0]) == 38 + 20
    # the random points lie on the surface: each on one of the six faces at least
    tail = points[-random:]
    assert (np.sum(np.isclose(tail, 0) | np.isclose(tail, 1), axis=1) >= 1).all()
    assert ((tail >= 0) & (tail <= 1)).all()


def test_the_same_seed_gives_the_same_answer():
    big = (CUBE_V - 0.5) * 1.3 + 0.5
    one = surface_distances(CUBE_V, CUBE_F, big, CUBE_F, seed=4)
    again = surface_distances(CUBE_V, CUBE_F, big, CUBE_F, seed=4)
    assert (again.chamfer, again.hausdorff, again.samples) == (
        one.chamfer,
        one.hausdorff,
        one.samples,
    )
    other = surface_distances(CUBE_V, CUBE_F, big, CUBE_F, seed=5)
    assert other.hausdorff == one.hausdorff  # reached at a corner, whatever the seed
    assert other.b_to_a_mean != one.b_to_a_mean


def test_bad_input():
    with pytest.raises(ValueError, match="index vertices"):
        surface_distances(CUBE_V, CUBE_F + 1, CUBE_V, CUBE_F)
    bad = CUBE_V.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match="finite"):
        surface_distances(CUBE_V, CUBE_F, bad, CUBE_F)
    with pytest.raises(ValueError, match="integers"):
        surface_distances(CUBE_V, CUBE_F.astype(float), CUBE_V, CUBE_F)


# --------------------------------------------------------------------------------------------
# against slow references


def reference_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
    """The distance from p to triangle abc the long way: the projection onto the plane when it
    falls inside (barycentric coordinates by least squares), else the nearest of the three
    edges; a degenerate triangle is its edges."""

    def segment(p, s, e):
        d = e - s
        length2 = float(d @ d)
        t = 0.0 if length2 == 0 else min(max(float((p - s) @ d) / length2, 0.0), 1.0)
        return float(np.linalg.norm(p - (s + t * d)))

    edges = min(segment(p, a, b), segment(p, b, c), segment(p, c, a))
    n = np.cross(b - a, c - a)
    longest = max(np.linalg.norm(b - a), np.linalg.norm(c - a), np.linalg.norm(c - b))
    if np.linalg.norm(n) <= 1e-9 * longest**2:
        return edges
    n = n / np.linalg.norm(n)
    q = p - float((p - a) @ n) * n
    (u, w), *_ = np.linalg.lstsq(np.column_stack([b - a, c - a]), q - a, rcond=None)
    if u >= 0 and w >= 0 and u + w <= 1:
        return min(abs(float((p - a) @ n)), edges)
    return edges


def random_triangles(rng: np.random.Generator, n: int) -> np.ndarray:
    """Triangles of every kind: ordinary, slivers, obtuse ones, segments, points."""
    tris = rng.normal(size=(n, 3, 3)) * rng.choice([0.01, 1.0, 100.0], (n, 1, 1))
    kind = rng.integers(0, 6, n)
    t = rng.random(n)[:, None]
    tris[kind == 1, 2] = tris[kind == 1, 0]  # a repeated corner
    line = kind == 2  # three corners on a line
    tris[line, 2] = tris[line, 0] + (tris[line, 1] - tris[line, 0]) * (1 + 2 * t[line])
    tris[kind == 3, 1:] = tris[kind == 3, :1]  # one point
    sliver = kind == 4
    tris[sliver, 2] = (tris[sliver, 0] + tris[sliver, 1]) / 2 + 1e-4 * rng.normal(
        size=(sliver.sum(), 3)
    )
    return tris


def test_point_triangle_distance_against_the_reference():
    rng = np.random.default_rng(0)
    n = 3000
    tris = random_triangles(rng, n)
    scale = np.abs(tris).max(axis=(1, 2))
    near = rng.random(n) < 0.3  # points on or next to the triangle's plane too
    w = rng.dirichlet([1, 1, 1], n)
    on_plane = np.einsum("ij,ijk->ik", w * 1.4 - 0.2, tris)
    points = np.where(near[:, None], on_plane, rng.normal(size=(n, 3)) * scale[:, None] * 2)
    got = point_triangle_distance(points, tris[:, 0], tris[:, 1], tris[:, 2])
    want = np.array([reference_distance(p, *t) for p, t in zip(points, tris, strict=True)])
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * scale.max())
    assert np.isfinite(got).all()


@pytest.mark.parametrize("chunk", [distance.CHUNK_PAIRS, 37])
def test_mesh_distances_against_brute_force(monkeypatch, chunk):
    """Triangles of mixed sizes (a few much larger than a grid cell, so that they are cut into
    pieces), degenerate ones, and points near the surface, far from it and off its grid; with a
    tiny chunk too, so that the pairs are cut at every place."""
    monkeypatch.setattr(distance, "CHUNK_PAIRS", chunk)
    monkeypatch.setattr(distance, "CHUNK_POINTS", min(chunk, distance.CHUNK_POINTS))
    rng = np.random.default_rng(1)
    small = rng.uniform(-20, 20, (300, 1, 3)) + rng.normal(size=(300, 3, 3))
    large = rng.uniform(-20, 20, (5, 1, 3)) + rng.normal(size=(5, 3, 3)) * 15
    tris = np.concatenate(
        [small, large, random_triangles(rng, 40) + rng.uniform(-20, 20, (40, 1, 3))]
    )
    on = tris[rng.integers(0, len(tris), 400)]
    w = rng.dirichlet([1, 1, 1], 400)
    points = np.concatenate(
        [
            np.einsum("ij,ijk->ik", w, on) + rng.normal(size=(400, 3)) * 0.01,
            rng.uniform(-30, 30, (300, 3)),
            rng.uniform(-300, 300, (100, 3)),
        ]
    )
    got = mesh_distances(points, tris)
    flat = tris.reshape(1, -1, 3, 3)
    all_pairs = point_triangle_distance(
        np.repeat(points, len(tris), axis=0),
        *(
            np.broadcast_to(flat[:, :, k], (len(points), len(tris), 3)).reshape(-1, 3)
            for k in range(3)
        ),
    ).reshape(len(points), len(tris))
    np.testing.assert_allclose(got, all_pairs.min(axis=1), rtol=1e-12, atol=1e-12)


def test_mesh_distances_of_a_single_point_and_no_triangle():
    tri = np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]])
    assert mesh_distances([[0.25, 0.25, 2.0]], tri)[0] == pytest.approx(2.0)
    assert mesh_distances([[3.0, 0.0, 0.0]], tri)[0] == pytest.approx(2.0)
    assert mesh_distances([[3.0, 0.0, 0.0]], np.zeros((0, 3, 3)))[0] == math.inf
    assert mesh_distances(np.zeros((0, 3)), tri).shape == (0,)
