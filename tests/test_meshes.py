"""The unit meshes of interpreter/geometry/meshes.py: ``prism_mesh`` builds the side walls of all
edges at once (issue 24) and must give, bit for bit and in the same order, the vertices and
triangles that the edge-by-edge loop it replaced gave: that loop is kept below as the reference,
and both run on the unit square, the primitives, the interpreter's footprints and insets,
generated simple polygons with and without holes in both ring orientations, and degenerate rings.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely.geometry import Polygon

import bgr
from bgr.interpreter.geometry import meshes
from bgr.interpreter.geometry.meshes import flat_mesh, primitive, prism_mesh
from bgr.interpreter.geometry.polygons import (
    RECT,
    UNIT_SQUARE,
    from_shapely,
    inset,
    named_footprint,
    triangulate,
)

# ---- the reference: prism_mesh as it was, one edge at a time ------------------------------------


def _old_orient(verts, faces, outward):
    if len(faces) == 0:
        return faces
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    normals = np.cross(b - a, c - a)
    want = outward((a + b + c) / 3.0)
    flip = np.einsum("ij,ij->i", normals, want) < 0
    faces = faces.copy()
    faces[flip] = faces[flip][:, ::-1]
    return faces


def _old_lift(pts2, k, level):
    a, b = meshes.PLANE_AXES[k]
    out = np.zeros((len(pts2), 3))
    out[:, a], out[:, b], out[:, k] = pts2[:, 0], pts2[:, 1], level
    return out


def _old_inside(pt, ext, holes) -> bool:
    def in_ring(ring):
        x, y, inside = pt[0], pt[1], False
        n = len(ring)
        for i in range(n):
            (x0, y0), (x1, y1) = ring[i], ring[(i + 1) % n]
            if (y0 > y) != (y1 > y) and x < (x1 - x0) * (y - y0) / (y1 - y0) + x0:
                inside = not inside
        return inside

    return in_ring(ext) and not any(in_ring(h) for h in holes)


def old_flat_mesh(polys, k):
    pts2, tris = triangulate([(UNIT_SQUARE, ())] if polys == RECT else polys)
    verts = _old_lift(pts2, k, 0.0)
    normal = np.eye(3)[k]
    return verts, _old_orient(verts, tris, lambda c: np.broadcast_to(normal, c.shape))


def old_prism_mesh(polys, k):
    polys = [(UNIT_SQUARE, ())] if polys == RECT else polys
    pts2, tris = triangulate(polys)
    bottom, top = _old_lift(pts2, k, 0.0), _old_lift(pts2, k, 1.0)
    normal = np.eye(3)[k]
    verts = [bottom, top]
    faces = [
        _old_orient(bottom, tris, lambda c: np.broadcast_to(-normal, c.shape)),
        _old_orient(top, tris, lambda c: np.broadcast_to(normal, c.shape)) + len(bottom),
    ]
    base = len(bottom) + len(top)
    for ext, holes in polys:
        for ring, is_hole in [(ext, False)] + [(h, True) for h in holes]:
            ring = np.asarray(ring, dtype=np.float64)
            nxt = np.roll(ring, -1, axis=0)
            for p, q in zip(ring, nxt, strict=True):
                quad = np.vstack(
                    [_old_lift(np.array([p, q]), k, 0.0), _old_lift(np.array([q, p]), k, 1.0)]
                )
                edge = q - p
                n2 = np.array([edge[1], -edge[0]])
                mid = (p + q) / 2
                inside_probe = mid - 1e-6 * n2
                if _old_inside(inside_probe, ext, holes) == is_hole:
                    n2 = -n2
                n3 = _old_lift(n2[None, :], k, 0.0)[0]
                tri = _old_orient(
                    quad,
                    np.array([[0, 1, 2], [0, 2, 3]]),
                    lambda c, n3=n3: np.broadcast_to(n3, c.shape),
                )
                verts.append(quad)
                faces.append(tri + base)
                base += 4
    return np.vstack(verts), np.vstack(faces)


def same(new, old) -> None:
    (v1, f1), (v0, f0) = new, old
    assert v1.dtype == v0.dtype and f1.dtype == f0.dtype
    assert v1.shape == v0.shape and f1.shape == f0.shape
    # bit for bit: equal values and equal signs of zero
    assert np.array_equal(v1, v0) and np.array_equal(np.signbit(v1), np.signbit(v0))
    assert np.array_equal(f1, f0)


def check(polys) -> None:
    for k in range(3):
        same(prism_mesh(polys, k), old_prism_mesh(polys, k))
        same(flat_mesh(polys, k), old_flat_mesh(polys, k))


# ---- fixed cases ------------------------------------------------------------------------------


def square_with_hole(ccw_ext: bool = True, ccw_hole: bool = False):
    ext = UNIT_SQUARE if ccw_ext else UNIT_SQUARE[::-1]
    hole = ((0.3, 0.3), (0.3, 0.7), (0.7, 0.7), (0.7, 0.3))
    return [(ext, (hole[::-1] if ccw_hole else hole,))]


FIXED = {
    "rect": RECT,
    "unit square": [(UNIT_SQUARE, ())],
    "unit square, clockwise": [(UNIT_SQUARE[::-1], ())],
    "wedge": [(((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)), ())],
    "cylinder": [
        (
            tuple(
                (
                    0.5 + 0.5 * math.cos(2 * math.pi * i / 24),
                    0.5 + 0.5 * math.sin(2 * math.pi * i / 24),
                )
                for i in range(24)
            ),
            (),
        )
    ],
    **{
        f"hole, exterior {'ccw' if e else 'cw'}, hole {'ccw' if h else 'cw'}": square_with_hole(
            e, h
        )
        for e in (True, False)
        for h in (True, False)
    },
    "two polygons": [
        (((0.0, 0.0), (0.4, 0.0), (0.4, 1.0), (0.0, 1.0)), ()),
        (((0.6, 1.0), (1.0, 1.0), (1.0, 0.0), (0.6, 0.0)), ()),
    ],
    "two holes": [
        (
            UNIT_SQUARE,
            (
                ((0.1, 0.1), (0.1, 0.4), (0.4, 0.4), (0.4, 0.1)),
                ((0.6, 0.6), (0.9, 0.6), (0.9, 0.9), (0.6, 0.9)),
            ),
        )
    ],
    "zero-length edge": [(((0.0, 0.0), (1.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)), ())],
    "closed ring (first point repeated)": [((*UNIT_SQUARE, UNIT_SQUARE[0]), ())],
    "collinear points": [
        (((0.0, 0.0), (0.25, 0.0), (0.5, 0.0), (1.0, 0.0), (1.0, 0.5), (1.0, 1.0), (0.0, 1.0)), ())
    ],
    "tiny edge": [(((0.0, 0.0), (0.5, 0.0), (0.5 + 1e-13, 1e-13), (1.0, 0.0), (0.5, 1.0)), ())],
    "spike": [(((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.5, 1.0), (0.5, 0.5), (0.5, 1.0)), ())],
    "integer corners": [(((0, 0), (1, 0), (1, 1), (0, 1)), ())],
    "no polygons": [],
}


@pytest.mark.parametrize("name", list(FIXED))
def test_same_mesh_as_the_edge_by_edge_loop(name):
    check(FIXED[name])


@pytest.mark.parametrize("kind", ["rect", "L", "U", "T", "cross", "circle"])
@pytest.mark.parametrize("a, b", [(0.3, 0.4), (0.5, 0.25), (7, 0.5), (3, 0.5), (32, 0.5)])
def test_same_mesh_on_the_named_footprints_and_their_insets(kind, a, b):
    if kind == "circle" and a < 3 or kind != "circle" and a >= 1:
        return
    polys = named_footprint(kind, a, b)
    check(polys)
    for distance in (0.05, -0.05, 0.2):
        inner, border = inset(polys, 10.0, 8.0, distance)
        check(inner)
        check(border)  # a ring with a hole, from shapely: exterior ccw, hole cw


def test_the_primitives_are_as_before():
    for name, polys, k in [
        ("cube", RECT, 1),
        ("wedge", FIXED["wedge"], 0),
        ("cylinder", FIXED["cylinder"], 1),
    ]:
        same(primitive(name), old_prism_mesh(polys, k))
    same(primitive("quad"), old_flat_mesh(RECT, 2))


def test_same_meshes_for_the_stdlib_masses(monkeypatch):
    """Every prism the interpreter asks for while deriving a few masses (courtyards included)."""
    seen = []
    real = meshes.prism_mesh

    def record(polys, k):
        seen.append((polys, k))
        return real(polys, k)

    monkeypatch.setattr(meshes, "prism_mesh", record)
    grammar = bgr.load(meshes.__file__.replace("interpreter/geometry/meshes.py", "stdlib/mass.bgr"))
    for start in ("UBlock", "CrossBlock", "RoundTower"):
        bgr.derive(grammar, seed=1, lot=(20, 15), start=start)
    assert seen
    for polys, k in seen:
        same(real(polys, k), old_prism_mesh(polys, k))


# ---- generated simple polygons ----------------------------------------------------------------


@st.composite
def star_ring(draw, cx: float, cy: float, r: float, min_n: int = 3):
    """A simple ring: corners at increasing angles round (cx, cy), radii up to r."""
    n = draw(st.integers(min_n, 12))
    turns = st.floats(0, 2 * math.pi, exclude_max=True)
    angles = sorted(draw(st.lists(turns, min_size=n, max_size=n, unique=True)))
    radii = draw(st.lists(st.floats(0.2 * r, r), min_size=len(angles), max_size=len(angles)))
    ring = tuple(
        (cx + rad * math.cos(t), cy + rad * math.sin(t))
        for t, rad in zip(angles, radii, strict=True)
    )
    if draw(st.booleans()):
        ring = ring[::-1]
    if draw(st.booleans()) and len(ring) > 2:  # a collinear corner, or a repeated one
        i = draw(st.integers(0, len(ring) - 1))
        (x0, y0), (x1, y1) = ring[i], ring[(i + 1) % len(ring)]
        extra = draw(st.sampled_from([0.0, 0.5, 0.25]))
        ring = (*ring[: i + 1], (x0 + extra * (x1 - x0), y0 + extra * (y1 - y0)), *ring[i + 1 :])
    return ring


@st.composite
def polygon(draw):
    ext = draw(star_ring(0.5, 0.5, 0.5))
    holes = []
    for _ in range(draw(st.integers(0, 2))):
        cx, cy = draw(st.floats(0.3, 0.7)), draw(st.floats(0.3, 0.7))
        holes.append(draw(star_ring(cx, cy, 0.12)))
    shape = Polygon(ext, holes)
    if not shape.is_valid or shape.area < 1e-6:
        fixed = from_shapely(shape.buffer(0))[:1] or [(UNIT_SQUARE, ())]
        (ext, holes) = fixed[0]  # exterior ccw, holes cw: turn each round or not
        turn = draw(st.lists(st.booleans(), min_size=1 + len(holes), max_size=1 + len(holes)))
        rings = [r[::-1] if t else r for r, t in zip([ext, *holes], turn, strict=True)]
        return [(rings[0], tuple(rings[1:]))]
    return [(ext, tuple(holes))]


@settings(max_examples=150, suppress_health_check=[HealthCheck.too_slow])
@given(polygon(), st.integers(0, 2))
def test_same_mesh_on_generated_polygons(polys, k):
    same(prism_mesh(polys, k), old_prism_mesh(polys, k))
    same(flat_mesh(polys, k), old_flat_mesh(polys, k))
