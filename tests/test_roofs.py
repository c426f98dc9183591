"""Roof meshes (interpreter/geometry/roofs.py) and the straight skeleton under them.

The footprints are metric, in a face-local xy plane; roofs rise along +z.  The rectangle, L, T, U
and hexagon are checked for hip and gable against the properties that define a straight-skeleton
roof: every vertex on its edge's plane, eaves exactly the footprint, sloped faces tiling the
footprint without overlap, a closed surface once capped, and the expected top height.
"""

from __future__ import annotations

import math
import warnings
from collections import Counter

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Polygon

from bgr.interpreter.geometry.earclip import triangulate
from bgr.interpreter.geometry.roofs import (
    KINDS,
    MANSARD_BREAK,
    MITRE_LIMIT,
    RoofMesh,
    mansard_lower_pitch,
    roof_mesh,
)
from bgr.interpreter.geometry.skeleton import offset_outward, straight_skeleton

trimesh = pytest.importorskip("trimesh")

# name: (footprint, largest inset distance = radius of the largest inscribed circle)
SHAPES = {
    "rectangle": ([(0, 0), (10, 0), (10, 6), (0, 6)], 3.0),
    "L": ([(0, 0), (12, 0), (12, 5), (5, 5), (5, 10), (0, 10)], 2.5),
    "T": ([(4, 0), (8, 0), (8, 6), (12, 6), (12, 10), (0, 10), (0, 6), (4, 6)], 2.0),
    "U": ([(0, 0), (12, 0), (12, 9), (8, 9), (8, 4), (4, 4), (4, 9), (0, 9)], 2.0),
    "hexagon": ([(0, 0), (8, 0), (10, 2), (8, 4), (0, 4), (-2, 2)], 2.0),
}
PITCH = 35.0
TAN = math.tan(math.radians(PITCH))
TOL = 1e-6


def footprint(name: str) -> np.ndarray:
    return np.array(SHAPES[name][0], dtype=np.float64)


def edge_frame(poly: np.ndarray, i: int):
    """Start point and inward unit normal of edge i of a counter-clockwise polygon."""
    a, b = poly[i], poly[(i + 1) % len(poly)]
    d = (b - a) / np.linalg.norm(b - a)
    return a, np.array([-d[1], d[0]])


def capped(mesh: RoofMesh) -> trimesh.Trimesh:
    """The roof closed with a downward cap on its eave outline."""
    cap = triangulate(mesh.eave[:, :2])[:, ::-1] + len(mesh.vertices)
    return trimesh.Trimesh(
        np.vstack([mesh.vertices, mesh.eave]), np.vstack([mesh.faces, cap]), process=True
    )


def boundary_edges(mesh: RoofMesh) -> list[tuple[int, int]]:
    count = Counter(
        tuple(sorted((int(f[i]), int(f[(i + 1) % 3])))) for f in mesh.faces for i in range(3)
    )
    return [e for e, n in count.items() if n == 1]


def sloped(mesh: RoofMesh) -> np.ndarray:
    return np.array([mesh.planes[p].kind == "slope" for p in mesh.face_plane])


# ---------------------------------------------------------------------------------------------
# hip and gable on the five footprints


@pytest.mark.parametrize("kind", ["hip", "gable"])
@pytest.mark.parametrize("name", list(SHAPES))
class TestSkeletonRoofs:
    def test_vertices_lie_on_their_edge_planes(self, name, kind):
        poly = footprint(name)
        mesh = roof_mesh(poly, kind, PITCH)
        for face, p in zip(mesh.faces, mesh.face_plane, strict=True):
            plane = mesh.planes[p]
            a, n = edge_frame(poly, plane.edge)
            dist = (mesh.vertices[face, :2] - a) @ n
            if plane.kind == "slope":
                assert np.allclose(mesh.vertices[face, 2], TAN * dist, atol=TOL)
            else:  # a gable wall stands on its edge
                assert plane.kind == "gable" and kind == "gable"
                assert np.allclose(dist, 0.0, atol=TOL)
            assert np.allclose(mesh.vertices[face] @ plane.normal, plane.offset, atol=TOL)

    def test_eaves_are_the_footprint(self, name, kind):
        poly = footprint(name)
        mesh = roof_mesh(poly, kind, PITCH)
        edges = boundary_edges(mesh)
        assert np.allclose(mesh.vertices[np.array(edges).ravel(), 2], 0.0, atol=TOL)
        eaves = shapely.union_all([LineString(mesh.vertices[list(e), :2]) for e in edges])
        outline = Polygon(poly).exterior
        assert eaves.symmetric_difference(outline).length < TOL
        assert abs(eaves.length - outline.length) < TOL

    def test_slopes_tile_the_footprint(self, name, kind):
        poly = footprint(name)
        mesh = roof_mesh(poly, kind, PITCH)
        tiles = [Polygon(mesh.vertices[f, :2]) for f in mesh.faces[sloped(mesh)]]
        total = sum(t.area for t in tiles)
        assert total == pytest.approx(Polygon(poly).area, abs=TOL)
        assert shapely.union_all(tiles).area == pytest.approx(total, abs=TOL)

    def test_closed_with_the_footprint_as_bottom(self, name, kind):
        mesh = roof_mesh(footprint(name), kind, PITCH)
        solid = capped(mesh)
        assert solid.is_watertight and solid.is_winding_consistent
        assert solid.volume > 0  # counter-clockwise seen from outside

    def test_heights(self, name, kind):
        mesh = roof_mesh(footprint(name), kind, PITCH)
        z = mesh.vertices[:, 2]
        assert z.min() == pytest.approx(0.0, abs=TOL)
        inner = np.setdiff1d(np.arange(len(z)), np.array(boundary_edges(mesh)).ravel())
        assert (z[inner] > TOL).all()
        assert z.max() == pytest.approx(TAN * SHAPES[name][1], abs=TOL)

    def test_faces_are_proper_triangles(self, name, kind):
        mesh = roof_mesh(footprint(name), kind, PITCH)
        assert mesh.vertices.dtype == np.float64 and mesh.faces.dtype == np.int32
        assert len(mesh.face_plane) == len(mesh.faces)
        tri = mesh.vertices[mesh.faces]
        normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        assert (np.linalg.norm(normals, axis=1) > 1e-6).all()
        own = np.array([mesh.planes[p].normal for p in mesh.face_plane])
        assert (np.einsum("ij,ij->i", normals, own) > 0).all()  # outward, like the plane


def test_gable_ends_are_the_wing_ends():
    expected = {"rectangle": {1, 3}, "L": {1, 4}, "T": {0, 3, 5}, "U": {2, 6}, "hexagon": set()}
    for name, ends in expected.items():
        mesh = roof_mesh(footprint(name), "gable", PITCH)
        assert {p.edge for p in mesh.planes if p.kind == "gable"} == ends, name


def test_gable_rectangle_ridge_runs_wall_to_wall():
    mesh = roof_mesh(footprint("rectangle"), "gable", PITCH)
    top = mesh.vertices[np.isclose(mesh.vertices[:, 2], 3 * TAN)]
    assert sorted(map(tuple, top[:, :2].round(9))) == [(0.0, 3.0), (10.0, 3.0)]
    walls = [p for p in mesh.planes if p.kind == "gable"]
    assert all(p.pitch == 90.0 and abs(p.normal[2]) < 1e-12 for p in walls)
    assert len(mesh.faces) == 6  # two slopes of two triangles, two wall triangles


def test_gable_square_ridge_parallel_to_the_front():
    square = np.array([(0, 0), (8, 0), (8, 8), (0, 8)], dtype=float)
    for start in range(4):  # the front is polygon[0] -> polygon[1], wherever it is
        poly = np.roll(square, -start, axis=0)
        mesh = roof_mesh(poly, "gable", PITCH)
        assert {p.edge for p in mesh.planes if p.kind == "gable"} == {1, 3}


def test_hip_square_is_a_pyramid_of_four_triangles():
    mesh = roof_mesh(np.array([(0, 0), (8, 0), (8, 8), (0, 8)], dtype=float), "hip", PITCH)
    assert len(mesh.faces) == 4 and len(mesh.vertices) == 5
    assert mesh.vertices[:, 2].max() == pytest.approx(4 * TAN)


# ---------------------------------------------------------------------------------------------
# overhang


@pytest.mark.parametrize("kind", ["hip", "gable", "mansard", "gambrel", "shed", "pyramid"])
@pytest.mark.parametrize("name", ["rectangle", "L", "T", "U"])
def test_overhang_keeps_the_planes(name, kind):
    poly, over = footprint(name), 0.6
    base = roof_mesh(poly, kind, PITCH)
    mesh = roof_mesh(poly, kind, PITCH, over)
    if mesh.kind != kind:  # a U cannot carry a pyramid: both are hips
        assert base.kind == mesh.kind == "hip"
    key = lambda p: (p.kind, p.edge, round(p.pitch, 9), tuple(np.round(p.normal, 9)))  # noqa: E731
    planes = {key(p): p.offset for p in base.planes}
    for p in mesh.planes:
        if p.kind == "wall":  # a shed's walls follow the eave
            continue
        assert p.offset == pytest.approx(planes[key(p)], abs=TOL)
    for face, p in zip(mesh.faces, mesh.face_plane, strict=True):
        plane = mesh.planes[p]
        assert np.allclose(mesh.vertices[face] @ plane.normal, plane.offset, atol=TOL)
    solid = capped(mesh)
    assert solid.is_watertight and solid.is_winding_consistent and solid.volume > 0


@pytest.mark.parametrize("name", list(SHAPES))
def test_overhang_extends_the_eaves(name):
    poly, over = footprint(name), 0.6
    mesh = roof_mesh(poly, "hip", PITCH, over)
    assert mesh.overhang == over
    assert np.allclose(mesh.eave[:, 2], -over * TAN)
    grown = Polygon(poly).buffer(over, join_style="mitre", mitre_limit=10.0)
    assert Polygon(mesh.eave[:, :2]).symmetric_difference(grown).area < TOL
    # every eave edge is a footprint edge moved out by the overhang
    for i in range(len(mesh.eave)):
        a, b = mesh.eave[i, :2], mesh.eave[(i + 1) % len(mesh.eave), :2]
        mid = (a + b) / 2
        assert LineString(poly.tolist() + [poly[0].tolist()]).distance(
            shapely.Point(mid)
        ) == pytest.approx(over, abs=TOL)
    tiles = [Polygon(mesh.vertices[f, :2]) for f in mesh.faces[sloped(mesh)]]
    assert sum(t.area for t in tiles) == pytest.approx(grown.area, abs=TOL)


def test_overhang_of_a_gable_keeps_the_wall_plane():
    poly = footprint("rectangle")
    mesh = roof_mesh(poly, "gable", PITCH, 0.5)
    walls = mesh.faces[np.array([mesh.planes[p].kind == "gable" for p in mesh.face_plane])]
    xs = mesh.vertices[walls.ravel(), 0]
    assert set(np.round(xs, 9)) == {0.0, 10.0}  # the walls stay in x = 0 and x = 10
    assert Polygon(mesh.eave[:, :2]).area == pytest.approx(10 * 7)


def test_overhang_wider_than_a_notch_closes_it():
    # a U whose courtyard is 1 m wide: 0.6 m eaves from both sides meet and cover it
    poly = np.array([(0, 0), (9, 0), (9, 8), (5, 8), (5, 3), (4, 3), (4, 8), (0, 8)], dtype=float)
    mesh = roof_mesh(poly, "hip", PITCH, 0.6)
    assert len(mesh.eave) == 4
    assert Polygon(mesh.eave[:, :2]).area == pytest.approx(10.2 * 9.2)
    solid = capped(mesh)
    assert solid.is_watertight and solid.volume > 0


# ---------------------------------------------------------------------------------------------
# the other kinds


def test_mansard_break_and_top():
    poly = footprint("rectangle")
    mesh = roof_mesh(poly, "mansard", 30.0)
    lower = math.tan(math.radians(mansard_lower_pitch(30.0)))
    inset = MANSARD_BREAK * 3.0
    heights = sorted(set(np.round(mesh.vertices[:, 2], 9)))
    top = lower * inset + math.tan(math.radians(30)) * (3 - inset)
    assert heights == pytest.approx([0.0, lower * inset, top])
    pitches = sorted({round(p.pitch, 9) for p in mesh.planes})
    assert pitches == pytest.approx([30.0, mansard_lower_pitch(30.0)])
    assert len(mesh.planes) == 8


def test_gambrel_has_gable_walls_over_two_slopes():
    mesh = roof_mesh(footprint("rectangle"), "gambrel", 30.0)
    kinds = Counter(p.kind for p in mesh.planes)
    assert kinds == {"slope": 4, "gable": 2}
    for name in SHAPES:
        solid = capped(roof_mesh(footprint(name), "gambrel", 30.0))
        assert solid.is_watertight and solid.volume > 0


def test_pyramid_apex():
    mesh = roof_mesh(footprint("rectangle"), "pyramid", PITCH)
    apex = mesh.vertices[np.argmax(mesh.vertices[:, 2])]
    assert apex == pytest.approx([5.0, 3.0, 3 * TAN])
    assert len(mesh.faces) == 4
    assert max(p.pitch for p in mesh.planes) == pytest.approx(PITCH)
    # an L sees its edges from the corner square: the apex goes there
    mesh = roof_mesh(footprint("L"), "pyramid", PITCH)
    assert mesh.kind == "pyramid" and len(mesh.faces) == 6
    apex = mesh.vertices[np.argmax(mesh.vertices[:, 2])]
    assert Polygon(footprint("L")).exterior.distance(
        shapely.Point(apex[:2])
    ) * TAN == pytest.approx(apex[2])
    # a U has no point that sees all its edges: it gets a hip roof
    assert roof_mesh(footprint("U"), "pyramid", PITCH).kind == "hip"


def test_shed_rises_from_the_first_edge():
    poly = footprint("rectangle")[[2, 3, 0, 1]]  # front edge (10,6) -> (0,6)
    mesh = roof_mesh(poly, "shed", PITCH)
    top = mesh.planes[0]
    assert top.kind == "slope" and top.edge == 0
    assert np.allclose(mesh.vertices[np.isclose(mesh.vertices[:, 1], 6.0), 2], 0.0)
    assert mesh.vertices[:, 2].max() == pytest.approx(6 * TAN)
    assert Counter(p.kind for p in mesh.planes) == {"slope": 1, "wall": 3}
    solid = capped(mesh)
    assert solid.is_watertight and solid.volume == pytest.approx(0.5 * 6 * 6 * TAN * 10)


def test_flat_is_the_footprint():
    poly = footprint("U")
    mesh = roof_mesh(poly, "flat", 0)
    assert np.allclose(mesh.vertices[:, 2], 0.0)
    assert sum(Polygon(mesh.vertices[f, :2]).area for f in mesh.faces) == pytest.approx(88.0)
    grown = roof_mesh(poly, "flat", 0, overhang=0.5)
    area = sum(Polygon(grown.vertices[f, :2]).area for f in grown.faces)
    assert area == pytest.approx(Polygon(poly).buffer(0.5, join_style="mitre").area)


def test_flat_leaves_holes_open():
    """A courtyard stays open under a flat roof, shrunk by the overhang (the eaves reach into
    it); the skeleton kinds are built on the outline alone (see roofs.py, "Holes")."""
    outer = np.array([[0, 0], [30, 0], [30, 20], [0, 20]], dtype=float)
    hole = np.array([[10, 5], [10, 15], [20, 15], [20, 5]], dtype=float)  # clockwise
    for overhang in (0.0, 0.5):
        mesh = roof_mesh(outer, "flat", 0, overhang=overhang, holes=[hole])
        tris = [Polygon(mesh.vertices[f, :2]) for f in mesh.faces]
        assert all(t.exterior.is_ccw for t in tris)  # facing up
        expected = Polygon(outer).buffer(overhang, join_style="mitre").area - (
            10 - 2 * overhang
        ) * (10 - 2 * overhang)
        assert sum(t.area for t in tris) == pytest.approx(expected)
        assert not any(t.contains(shapely.Point(15, 10)) for t in tris)
    hip = roof_mesh(outer, "hip", PITCH, holes=[hole])
    assert hip.vertices[:, 2].max() == pytest.approx(10 * TAN)  # over the whole block


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("name", list(SHAPES))
@pytest.mark.parametrize("overhang", [0.0, 0.4])
def test_every_kind_is_finite_and_consistent(name, kind, overhang):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mesh = roof_mesh(footprint(name), kind, 40.0, overhang)
    assert np.isfinite(mesh.vertices).all() and len(mesh.faces)
    assert mesh.faces.min() >= 0 and mesh.faces.max() < len(mesh.vertices)
    tri = mesh.vertices[mesh.faces]
    doubled_areas = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    assert (doubled_areas > 1e-9).all()
    for face, p in zip(mesh.faces, mesh.face_plane, strict=True):
        plane = mesh.planes[p]
        assert np.allclose(mesh.vertices[face] @ plane.normal, plane.offset, atol=TOL)
    if kind != "flat":
        solid = capped(mesh)
        assert solid.is_watertight and solid.is_winding_consistent and solid.volume > 0


@pytest.mark.parametrize("kind", ["hip", "gable", "mansard", "shed"])
def test_orientation_and_placement_do_not_matter(kind):
    poly = footprint("L")
    angle = math.radians(33.0)
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    moved = poly @ rot.T + [250.0, -40.0]
    a = roof_mesh(poly, kind, PITCH)
    b = roof_mesh(moved, kind, PITCH)
    c = roof_mesh(np.roll(moved[::-1], 2, axis=0), kind, PITCH)  # clockwise, same front edge
    for other in (b, c):
        assert len(other.faces) == len(a.faces)
        assert other.vertices[:, 2].max() == pytest.approx(a.vertices[:, 2].max(), abs=TOL)
        assert capped(other).volume == pytest.approx(capped(a).volume, rel=1e-9)
    assert {p.edge for p in b.planes} == {p.edge for p in a.planes}


def test_collinear_and_repeated_points_are_merged():
    poly = [(0, 0), (5, 0), (10, 0), (10, 6), (10, 6), (0, 6), (0, 0)]
    mesh = roof_mesh(poly, "hip", PITCH)
    assert len(mesh.planes) == 4 and len(mesh.faces) == 6
    front = next(p for p in mesh.planes if 0 in p.edges)
    assert front.edges == (0, 1, 6) and front.edge in (0, 1)  # 6 is the closing repeat


@pytest.mark.parametrize(
    "args, message",
    [
        (([(0, 0), (1, 0), (1, 1)], "dome", 30), "unknown roof kind"),
        (([(0, 0), (1, 0), (1, 1)], "hip", 0), "pitch"),
        (([(0, 0), (1, 0), (1, 1)], "hip", 90), "pitch"),
        (([(0, 0), (1, 0), (1, 1)], "hip", 30, -1), "overhang"),
        (([(0, 0), (2, 2), (2, 0), (0, 2)], "hip", 30), "simple polygon"),
        (([(0, 0), (1, 0)], "hip", 30), "K >= 3"),
        (([(0, 0), (1, 0), (2, 0)], "flat", 0), "simple polygon"),
    ],
)
def test_bad_arguments(args, message):
    with pytest.raises(ValueError, match=message):
        roof_mesh(*args)


# ---------------------------------------------------------------------------------------------
# the straight skeleton itself


def skeleton_checks(poly: np.ndarray, weights=None):
    """Faces tile the polygon, and every node of a face is at offset t from the face's edge."""
    sk = straight_skeleton(poly, weights)
    tiles = []
    for k, cycles in enumerate(sk.faces[0]):
        assert cycles, f"edge {k} has no face"
        a, n = edge_frame(poly, k)
        for cycle in cycles:
            nodes = sk.nodes[cycle]
            w = 1.0 if weights is None else weights[k]
            assert np.allclose((nodes[:, :2] - a) @ n, w * nodes[:, 2], atol=1e-9)
            tiles.append(Polygon(nodes[:, :2]))
    area = sum(t.area for t in tiles)
    assert area == pytest.approx(Polygon(poly).area, abs=1e-9)
    assert shapely.union_all(tiles).area == pytest.approx(area, abs=1e-9)
    return sk


def test_skeleton_of_degenerate_rectilinear_shapes():
    shapes = [
        [
            (3, 0),
            (6, 0),
            (6, 3),
            (9, 3),
            (9, 6),
            (6, 6),
            (6, 9),
            (3, 9),
            (3, 6),
            (0, 6),
            (0, 3),
            (3, 3),
        ],  # a plus
        [(2, 0), (4, 0), (4, 2), (6, 2), (6, 4), (0, 4), (0, 2), (2, 2)],  # every event at once
        [(0, 0), (2, 0), (2, 2), (4, 2), (4, 0), (6, 0), (6, 4), (0, 4)],  # an upside-down U
        [(0, 0), (10, 0), (10, 1), (6, 1), (6, 3), (4, 3), (4, 1), (0, 1)],  # a bump on a bar
    ]
    for shape in shapes:
        sk = skeleton_checks(np.array(shape, dtype=float))
        assert sk.t_max > 0


def test_skeleton_of_random_rectilinear_and_star_shapes():
    rng = np.random.default_rng(1234)
    done = 0
    while done < 60:
        if done % 2:
            k = int(rng.integers(3, 12))
            ang = np.sort(rng.uniform(0, 2 * np.pi, k))
            poly = np.column_stack([np.cos(ang), np.sin(ang)]) * rng.uniform(3, 10, k)[:, None]
            shape = Polygon(poly)
        else:
            corners = rng.integers(0, 8, (int(rng.integers(2, 6)), 2))
            sizes = rng.integers(1, 5, corners.shape)
            shape = shapely.union_all(
                [shapely.box(*c, *(c + s)) for c, s in zip(corners, sizes, strict=True)]
            )
        if shape.geom_type != "Polygon" or shape.interiors or not shape.is_valid:
            continue
        shape = shapely.geometry.polygon.orient(shapely.simplify(shape, 0), 1.0)
        skeleton_checks(np.array(shape.exterior.coords[:-1]))
        done += 1


def test_weighted_skeleton_holds_zero_weight_edges():
    rect = np.array([(0, 0), (10, 0), (10, 6), (0, 6)], dtype=float)
    sk = skeleton_checks(rect, np.array([1.0, 0.0, 1.0, 0.0]))
    assert set(map(tuple, sk.nodes[sk.nodes[:, 2] > 2.9][:, :2].round(9))) == {(0, 3), (10, 3)}


def test_skeleton_breaks_cut_every_face():
    rect = np.array([(0, 0), (10, 0), (10, 6), (0, 6)], dtype=float)
    sk = straight_skeleton(rect, breaks=(1.0,))
    assert len(sk.faces) == 2
    for k in range(4):
        (low,), (high,) = sk.faces[0][k], sk.faces[1][k]
        assert sk.nodes[low, 2].max() == pytest.approx(1.0)
        assert sk.nodes[high, 2].min() == pytest.approx(1.0)
    area = sum(Polygon(sk.nodes[c, :2]).area for stage in sk.faces for f in stage for c in f)
    assert area == pytest.approx(60)


def test_offset_outward_closes_a_narrow_notch():
    poly = np.array([(0, 0), (9, 0), (9, 8), (5, 8), (5, 3), (4, 3), (4, 8), (0, 8)], dtype=float)
    ring, source = offset_outward(poly, 0.2)
    assert len(ring) == 8 and list(source) == list(range(8))
    ring, source = offset_outward(poly, 0.6)  # the notch is gone; the arms' tops meet in line
    assert np.allclose(ring, [(-0.6, 8.6), (-0.6, -0.6), (9.6, -0.6), (9.6, 8.6), (4.5, 8.6)])
    assert list(source) == [7, 0, 1, 2, 6]


# ---------------------------------------------------------------------------------------------
# sharp corners: the eave is bevelled, not mitred to infinity

SHARP = {
    "triangle": [(0, 0), (30, 0), (30, 10.9)],  # a 20-degree corner
    "flatiron": [(0, 0), (40, 0), (10, 12), (0, 12)],  # a 22-degree corner
    "kite": [(0, 0), (10, -1), (30, 0), (10, 1)],  # 6 and 11 degrees
    # a Helsinki building (OSM way 123412759) with a 0.07-degree needle: its mitred eave went
    # 670 m out, a pyramid's 2 km
    "needle": [
        (0, 1.0679),
        (22.6712, 0),
        (23.0133, 7.3577),
        (20.8704, 7.4571),
        (20.8094, 6.1859),
        (10.8256, 6.6391),
        (10.5487, 0.5816),
        (9.1477, 0.6479),
    ],
}


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("name", list(SHARP))
def test_sharp_corners_keep_the_eave_near(name, kind):
    poly, over = np.array(SHARP[name], dtype=float), 0.5
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mesh = roof_mesh(poly, kind, PITCH, over)
    assert np.isfinite(mesh.vertices).all() and not mesh.fallback
    area = Polygon(poly)
    reach = max(area.distance(shapely.Point(v)) for v in mesh.vertices[:, :2])
    assert reach <= MITRE_LIMIT * over + TOL
    for face, p in zip(mesh.faces, mesh.face_plane, strict=True):
        plane = mesh.planes[p]
        assert np.allclose(mesh.vertices[face] @ plane.normal, plane.offset, atol=TOL)
    if kind != "flat":
        solid = capped(mesh)
        assert solid.is_watertight and solid.is_winding_consistent and solid.volume > 0
    if kind in ("hip", "mansard"):  # the bevel's facet rises through the corner at z = 0
        corners = [p for p in mesh.planes if p.kind == "corner"]
        assert corners and all(p.pitch == pytest.approx(mesh.planes[0].pitch) for p in corners)
        for p in corners:
            assert min(abs(np.append(c, 0.0) @ p.normal - p.offset) for c in poly) < TOL
    assert not any(p.kind == "corner" for p in roof_mesh(poly, kind, PITCH).planes)


@pytest.mark.parametrize("angle, bevelled", [(61.0, False), (59.0, True)])
def test_corners_sharper_than_60_degrees_are_bevelled(angle, bevelled):
    # a fan: the corner at the origin, its bisector along +x; the arc's corners are blunt
    half = math.radians(angle / 2)
    arc = [(20 * math.cos(a), 20 * math.sin(a)) for a in np.linspace(-half, half, 5)]
    mesh = roof_mesh(np.array([(0.0, 0.0), *arc]), "hip", PITCH, 0.5)
    assert any(p.kind == "corner" for p in mesh.planes) == bevelled
    # a mitre reaches overhang / sin(angle / 2) along the bisector; a bevel the overhang
    tip = -mesh.eave[:, 0].min()
    assert tip == pytest.approx(0.5 if bevelled else 0.5 / math.sin(half), rel=1e-9)


def test_a_triangle_gets_no_gable():
    poly = np.array(SHARP["triangle"], dtype=float)
    mesh = roof_mesh(poly, "gable", PITCH)
    assert mesh.kind == "gable" and not mesh.fallback
    assert not any(p.kind == "gable" for p in mesh.planes)
    assert capped(mesh).volume == pytest.approx(capped(roof_mesh(poly, "hip", PITCH)).volume)


def test_pyramid_overhang_is_bounded_on_a_long_footprint():
    # a square: every eave overhang out, level (the pyramid grown about its apex)
    square = np.array([(0, 0), (8, 0), (8, 8), (0, 8)], dtype=float)
    mesh = roof_mesh(square, "pyramid", PITCH, 0.5)
    assert np.allclose(mesh.eave[:, 2], -0.5 * TAN)
    assert np.allclose(np.abs(mesh.eave[:, :2] - 4), 4.5)
    # 6 m x 70 m: the far corners stop at MITRE_LIMIT overhangs (carried on by the overhang
    # over the apex's clearance, they went 5.85 m out); the planes stay those without overhang
    long = np.array([(0, 0), (70, 0), (70, 6), (0, 6)], dtype=float)
    base, mesh = roof_mesh(long, "pyramid", PITCH), roof_mesh(long, "pyramid", PITCH, 0.5)
    moved = np.linalg.norm(mesh.eave[:, :2] - long, axis=1)
    assert moved == pytest.approx(np.full(4, MITRE_LIMIT * 0.5))
    for p, q in zip(base.planes, mesh.planes, strict=True):
        assert np.allclose(p.normal, q.normal) and p.offset == pytest.approx(q.offset)
    solid = capped(mesh)
    assert solid.is_watertight and solid.volume > capped(base).volume
