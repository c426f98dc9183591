"""Capture geometry of style sheets (issue 27; Zhang et al. sections 4.1-4.3.1): the standard
view, floors, outlines, blocks and walls, against hand-computed expectations."""

from __future__ import annotations

import re
import time

import numpy as np
import pytest
import trimesh
from conftest import SHARED

from bgr.formats.textured_model import TexturedMesh
from bgr.grammar.errors import BgrError
from bgr.inverse.style.frame import standard_frame
from bgr.inverse.style.remesh import (
    blocks,
    capture_geometry,
    contours,
    cut_floors,
    floors,
)

PLATEAU = SHARED / "data/textured/plateau_tokyo/53392633_bldg_6697_2_op.gml"


def _mesh(parts: list[tuple[np.ndarray, np.ndarray]], up: str = "z", ids=("b1",)) -> TexturedMesh:
    """An untextured TexturedMesh of (vertices, faces) parts, all of building ids[0]."""
    vertices = np.concatenate([v for v, _ in parts])
    offsets = np.cumsum([0] + [len(v) for v, _ in parts])
    faces = np.concatenate([f + o for (_, f), o in zip(parts, offsets, strict=False)])
    n = len(faces)
    zeros = np.zeros(n, dtype=np.int64)
    return TexturedMesh(
        vertices.astype(float), faces.astype(np.int64), np.zeros((n, 3, 2)), zeros - 1, [],
        zeros, [""], zeros, list(ids), zeros, [""], up=up, source="mem.gml",
    )  # fmt: skip


def _box(extents, centre, transform=None) -> tuple[np.ndarray, np.ndarray]:
    box = trimesh.creation.box(extents=extents)
    box.apply_translation(centre)
    if transform is not None:
        box.apply_transform(transform)
    return np.asarray(box.vertices), np.asarray(box.faces)


# -- 1. a two-block stepped box, rotated and moved -------------------------------------------


def _stepped(degrees: float = 30.0):
    """z up: a 10 x 6 x 8 base (x along 10) and a 6 x 4 x 12 tower on it centred at (1, 0.5),
    turned ``degrees`` about up and moved to (100, 200, 5)."""
    turn = trimesh.transformations.rotation_matrix(np.radians(degrees), [0, 0, 1])
    turn[:3, 3] = [100.0, 200.0, 5.0]
    parts = [_box((10, 6, 8), (0, 0, 4), turn), _box((6, 4, 12), (1, 0.5, 14), turn)]
    return _mesh(parts), turn


def test_stepped_box_standard_frame_undoes_the_rotation():
    mesh, turn = _stepped()
    capture, frame = capture_geometry(mesh, None)
    assert frame.scale == pytest.approx(20.0)
    assert np.linalg.det(frame.rotation) == pytest.approx(1.0)
    # the base's own axes: +x (its 10 m side) becomes standard +x, +y (z up: north) becomes -z
    local = np.array([[0, 0, 0], [5, 0, 0], [0, 3, 0], [0, 0, 20]], dtype=float)
    std = frame.apply((turn[:3, :3] @ local.T).T + turn[:3, 3])
    np.testing.assert_allclose(std, [[0, 0, 0], [0.25, 0, 0], [0, 0, -0.15], [0, 1, 0]], atol=1e-12)
    points = np.random.default_rng(1).normal(size=(20, 3)) * 50
    np.testing.assert_allclose(frame.unapply(frame.apply(points)), points, atol=1e-9)


def test_the_axis_sign_points_within_90_degrees_of_the_input_x():
    """Turned 240 degrees, the base's own +x points away from the input's +x: standard +x is
    then the base's -x, and the tower (centred at +1 m, +0.5 m north of the base's centre)
    lands at -0.05, +0.025: the stepped box seen from the other side."""
    mesh, turn = _stepped(240.0)
    capture, frame = capture_geometry(mesh, None)
    assert np.linalg.det(frame.rotation) == pytest.approx(1.0)
    end = frame.apply(turn[:3, :3] @ [5.0, 0.0, 0.0] + turn[:3, 3])
    np.testing.assert_allclose(end, [[-0.25, 0.0, 0.0]], atol=1e-12)
    np.testing.assert_allclose(capture.blocks[1].box, (-0.2, 0.1, -0.075, 0.125), atol=1e-9)


def test_stepped_box_floors_blocks_and_walls():
    capture, _ = capture_geometry(_stepped()[0], None)
    np.testing.assert_allclose(capture.floors, [0.0, 0.4, 1.0], atol=1e-12)
    assert capture.building == "b1" and capture.source == "mem.gml"
    assert len(capture.blocks) == 2
    base, tower = capture.blocks
    assert base.levels == [0] and tower.levels == [1]
    np.testing.assert_allclose(base.box, (-0.25, 0.25, -0.15, 0.15), atol=1e-9)
    np.testing.assert_allclose(base.size, (0.5, 0.4, 0.3), atol=1e-9)
    # the tower's centre (1, 0.5) m in the base's (x, north) is (0.05, -0.025) standard units
    np.testing.assert_allclose(tower.box, (-0.1, 0.2, -0.125, 0.075), atol=1e-9)
    np.testing.assert_allclose(tower.size, (0.3, 0.6, 0.2), atol=1e-9)
    for block, (w, d) in ((base, (0.5, 0.3)), (tower, (0.3, 0.2))):
        assert [len(wall) for wall in block.walls] == [1, 1, 1, 1]
        widths = [wall[0].width for wall in block.walls]
        np.testing.assert_allclose(widths, [w, d, w, d], atol=1e-9)
        front, right, back, left = (wall[0] for wall in block.walls)
        assert [f.wall for f in (front, right, back, left)] == [0, 1, 2, 3]
        # left to right seen from outside: front -x, right -z, back +x, left +z
        assert front.start[0] > front.end[0] and front.start[1] == front.end[1] == block.box[2]
        assert right.start[1] > right.end[1] and right.start[0] == block.box[1]
        assert back.start[0] < back.end[0] and back.start[1] == block.box[3]
        assert left.start[1] < left.end[1] and left.start[0] == block.box[0]
        assert (front.bottom, front.top) == (block.bottom, block.top)
        assert all(f.texture is None for wall in block.walls for f in wall)


# -- 2. an L-shaped extrusion, meshed as CityGML would -------------------------------------

L_RING = np.array([(0, 0), (12, 0), (12, 4), (4, 4), (4, 8), (0, 8)], dtype=float)  # (x, z)


def _l_shape() -> TexturedMesh:
    """y up (an OBJ): the L above, 10 high, every wall a separate quad (not welded) and the
    front wall split at x = 5 (a collinear vertex the contour must drop); caps by earcut."""
    ring = list(L_RING)
    ring.insert(1, np.array([5.0, 0.0]))
    parts = []
    for p, q in zip(ring, ring[1:] + ring[:1], strict=True):
        v = np.array([[p[0], 0, p[1]], [q[0], 0, q[1]], [q[0], 10, q[1]], [p[0], 10, p[1]]])
        parts.append((v, np.array([[0, 1, 2], [0, 2, 3]])))
    import mapbox_earcut

    cap = mapbox_earcut.triangulate_float64(L_RING, np.array([len(L_RING)], dtype=np.uint32))
    cap = cap.reshape(-1, 3)
    for height in (0.0, 10.0):
        v = np.column_stack([L_RING[:, 0], np.full(len(L_RING), height), L_RING[:, 1]])
        parts.append((v, cap))
    return _mesh(parts, up="y")


def test_l_shape_one_block_six_corners_and_walls_broken_at_the_box_corners():
    capture, frame = capture_geometry(_l_shape(), None)
    assert frame.angle == pytest.approx(0.0, abs=1e-12) and frame.scale == pytest.approx(10.0)
    np.testing.assert_allclose(capture.floors, [0.0, 1.0])
    assert len(capture.blocks) == 1
    (ring,) = capture.contours
    expected = (L_RING - [6.0, 4.0]) / 10.0  # centred, unit height
    assert len(ring) == 6  # the collinear vertex at x = 5 is gone
    assert sorted(map(tuple, ring.round(9))) == sorted(map(tuple, expected.round(9)))
    x, z = ring[:, 0], ring[:, 1]
    assert np.dot(x, np.roll(z, -1)) - np.dot(z, np.roll(x, -1)) > 0  # counter-clockwise
    block = capture.blocks[0]
    np.testing.assert_allclose(block.box, (-0.6, 0.6, -0.4, 0.4))
    front, right, back, left = block.walls
    # the (12, 8) corner of the box is missing: its nearest vertex is (12, 4) (4 m away, against
    # 8 m for (4, 8)), so the right wall is the 4 m edge and the back takes the L's notch
    np.testing.assert_allclose([f.width for f in front], [1.2])
    np.testing.assert_allclose([f.width for f in right], [0.4])
    np.testing.assert_allclose([f.width for f in left], [0.8])
    # the back seen from outside (looking to -z) runs to +x: the 4 m top, the notch, the 8 m
    np.testing.assert_allclose([f.width for f in back], [0.4, 0.4, 0.8])
    np.testing.assert_allclose(
        [f.start for f in back], [(-0.6, 0.4), (-0.2, 0.4), (-0.2, 0.0)], atol=1e-12
    )
    np.testing.assert_allclose(
        [f.end for f in back], [(-0.2, 0.4), (-0.2, 0.0), (0.6, 0.0)], atol=1e-12
    )
    assert sum(len(w) for w in block.walls) == 6 and len(capture.faces) == 6


# -- 3. floors, cuts --------------------------------------------------------------------------


def _heights(*ys: float) -> np.ndarray:
    return np.column_stack([np.zeros(len(ys)), ys, np.zeros(len(ys))])


def test_floors_join_heights_closer_than_0_0005_of_the_height():
    np.testing.assert_allclose(floors(_heights(0, 0.5, 0.5003, 1)), [0, 0.50015, 1])
    np.testing.assert_allclose(floors(_heights(1, 0.5007, 0.5, 0)), [0, 0.5, 0.5007, 1])
    # the adjacency lists chain: 0.5 - 0.5004 - 0.5008 is one floor though its ends are 0.0008
    np.testing.assert_allclose(floors(_heights(0, 0.5, 0.5004, 0.5008, 1)), [0, 0.5004, 1])
    # relative to the building's height: 0.003 apart on a 10-high model is 0.0003 of it
    np.testing.assert_allclose(floors(_heights(0, 5, 5.003, 10)), [0, 5.0015, 10])
    # the ends keep the building's extremes
    np.testing.assert_allclose(floors(_heights(0, 0.0003, 0.9998, 1)), [0, 1])


def test_cuts_at_local_maxima_of_the_area_ratio():
    assert list(cut_floors(np.array([4.0, 4.0, 1.0, 1.0]))) == [2]
    assert list(cut_floors(np.array([4.0, 4.0, 4.0]))) == []
    assert list(cut_floors(np.array([4.0, 4.0 * (1 + 1e-12), 4.0]))) == []  # noise is no cut
    # r = 1.1, 3, 1.2: only the 3
    assert list(cut_floors(np.array([11.0, 10.0, 30.0, 36.0]))) == [2]
    # a ziggurat of equal steps: r = 2, 2, 2, a plateau above the ends (1): three cuts
    assert list(cut_floors(np.array([16.0, 8.0, 4.0, 2.0]))) == [1, 2, 3]


def test_every_setback_of_a_mass_is_a_cut():
    # an untextured mass of four blocks (tests/style_synth.py's four_stack, one face a wall):
    # its floors are its setbacks only, areas 30 x 18, 24 x 14, 18 x 10, 12 x 6, r = 1.61, 1.87,
    # 2.5 -- growing, so only the last is a local maximum; each is over remesh.SETBACK (1.25)
    assert list(cut_floors(np.array([540.0, 336.0, 180.0, 72.0]))) == [1, 2, 3]
    # a taper under SETBACK keeps the paper's rule: r = 1.1, 1.2, 1.15, one cut at the 1.2
    assert list(cut_floors(np.array([12.1, 11.0, 13.2, 15.18]))) == [2]


def test_blocks_take_the_box_of_their_cut_interval():
    square = np.array([(-1, -1), (1, -1), (1, 1), (-1, 1)], dtype=float)
    rings = [square * 0.4, square * 0.4, square * 0.2, square * 0.19]
    out = blocks(np.array([0, 0.2, 0.4, 0.6, 1.0]), rings)
    assert [b.levels for b in out] == [[0, 1], [2, 3]]
    assert [(b.bottom, b.top) for b in out] == [(0.0, 0.4), (0.4, 1.0)]
    np.testing.assert_allclose(out[1].box, (-0.2, 0.2, -0.2, 0.2))


def test_contours_cut_between_floors():
    vertices, faces = _box((2, 4, 1), (0, 0, 0))  # trimesh boxes are z up: height 1 here
    vertices = vertices[:, [0, 2, 1]] * [1, 1, -1] + [0, 0.5, 0]  # y up, from 0 to 1
    (ring,) = contours(vertices, faces, np.array([0.0, 1.0]))
    assert sorted(map(tuple, ring)) == [(-1, -2), (-1, 2), (1, -2), (1, 2)]


# -- errors -----------------------------------------------------------------------------------


def test_bad_buildings_are_located_errors():
    flat = _mesh([(np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0]]), np.array([[0, 1, 2]]))])
    with pytest.raises(BgrError, match="no vertical faces") as info:
        capture_geometry(flat, None)
    assert info.value.diagnostics[0].path == "mem.gml" and info.value.diagnostics[0].hint
    with pytest.raises(BgrError, match="no building 'nope'"):
        capture_geometry(_stepped()[0], "nope")
    mesh = _stepped()[0]
    mesh.object_ids.append("empty")
    with pytest.raises(BgrError, match="no triangles"):
        capture_geometry(mesh, "empty")
    with pytest.raises(BgrError, match="no triangles"):
        standard_frame(mesh, np.zeros(len(mesh.faces), dtype=bool))


# -- 4. the real PLATEAU buildings -------------------------------------------------------------


def test_plateau_buildings_capture():
    if not PLATEAU.exists():
        pytest.skip("the shared PLATEAU data is not here")
    from bgr.formats.citygml_read import read_citygml

    mesh = read_citygml(PLATEAU)
    text = PLATEAU.read_text(encoding="utf-8")
    measured = dict(
        re.findall(
            r'<bldg:Building gml:id="([^"]+)">.*?<bldg:measuredHeight uom="m">([0-9.]+)<',
            text,
            re.S,
        )
    )
    assert len(mesh.object_ids) == 10 and set(measured) == set(mesh.object_ids)
    start = time.perf_counter()
    for building in mesh.object_ids:
        capture, frame = capture_geometry(mesh, building)
        assert capture.building == building and len(capture.blocks) >= 1
        assert len(capture.faces) >= 4
        assert frame.scale == pytest.approx(float(measured[building]), abs=0.3)
        assert capture.floors[0] == 0 and capture.floors[-1] == 1
        assert np.all(np.diff(capture.floors) >= 0.0005)
        for block in capture.blocks:
            for level in block.levels:  # the four walls of a level are its whole outline
                ring = capture.contours[level]
                perimeter = np.hypot(*(np.roll(ring, -1, axis=0) - ring).T).sum()
                faces = [f for wall in block.walls for f in wall if f.level == level]
                assert sum(f.width for f in faces) == pytest.approx(perimeter)
        back = frame.unapply(frame.apply(mesh.vertices[:50]))
        np.testing.assert_allclose(back, mesh.vertices[:50], atol=1e-8)
    elapsed = time.perf_counter() - start
    assert elapsed < 30.0  # about 1.6 s on an idle core; generous on a loaded 2-core machine
    # the simplest (a 7 m box, 12 triangles): its walls lie along the standard axes
    capture, _ = capture_geometry(mesh, mesh.object_ids[-1])
    (block,) = capture.blocks
    front, right, back, left = (wall for wall in block.walls)
    assert all(abs(f.start[1] - f.end[1]) < 1e-3 * f.width for f in front + back)
    assert all(abs(f.start[0] - f.end[0]) < 1e-3 * f.width for f in right + left)


def test_coordinates_that_do_not_project_are_a_located_error():
    mesh, _ = _stepped()
    mesh.crs = "EPSG:4326"  # latitude, longitude: 100 and 200 degrees are nowhere
    with pytest.raises(BgrError, match="not finite metres") as info:
        capture_geometry(mesh, None)
    assert info.value.diagnostics[0].path == "mem.gml"


def test_a_geographic_building_is_measured_in_metres():
    """EPSG:6697 (latitude, longitude, height): a box 0.0002 degrees of latitude by 0.0001 of
    longitude at 35.5 N, from 3 to 13 m.  By the ellipsoid's series, a degree of latitude there
    is 110,949.8 m and one of longitude 90,729.9 m: 22.190 m by 9.073 m, times UTM zone 54's
    scale 0.99974 at 139.8 E."""
    v, f = _box((0.0002, 0.0001, 10.0), (35.5001, 139.80005, 8.0))
    mesh = _mesh([(v, f)])
    mesh.crs = "http://www.opengis.net/def/crs/EPSG/0/6697"
    capture, frame = capture_geometry(mesh, None)
    assert frame.utm == "EPSG:32654" and frame.scale == pytest.approx(10.0)
    (block,) = capture.blocks
    width, height, depth = block.size
    assert width * 10 == pytest.approx(22.190 * 0.99974, rel=3e-4)  # the long side is x
    assert depth * 10 == pytest.approx(9.073 * 0.99974, rel=3e-4)
    assert height == pytest.approx(1.0)
    np.testing.assert_allclose(frame.unapply(frame.apply(v)), v, rtol=0, atol=1e-9)


def test_a_courtyard_is_filled_and_the_largest_part_is_kept():
    import shapely

    ring = shapely.Polygon([(0, 0), (10, 0), (10, 10), (0, 10)], [[(3, 3), (7, 3), (7, 7), (3, 7)]])
    court = trimesh.creation.extrude_polygon(ring, 5.0)  # z up, 0 to 5
    capture, _ = capture_geometry(_mesh([(court.vertices, court.faces)]), None)
    (outline,) = capture.contours  # the outer ring only: 10 m / 5 m = 2 units a side
    assert sorted(map(tuple, outline.round(9))) == [(-1, -1), (-1, 1), (1, -1), (1, 1)]
    assert [len(w) for w in capture.blocks[0].walls] == [1, 1, 1, 1]
    # two towers 10 high, 6 x 4 at x = 0 and 2 x 2 at x = 10 (their box: x -3..11, centre 4)
    parts = [_box((6, 4, 10), (0, 0, 5)), _box((2, 2, 10), (10, 0, 5))]
    capture, _ = capture_geometry(_mesh(parts), None)
    (outline,) = capture.contours
    lo, hi = outline.min(axis=0), outline.max(axis=0)
    np.testing.assert_allclose([lo[0], hi[0], lo[1], hi[1]], [-0.7, -0.1, -0.2, 0.2], atol=1e-12)


def test_area_noise_is_no_cut():
    # r = 1.001, 1, 4, 1: the 0.1 % step is noise (RATIO_NOISE), not a local maximum
    assert list(cut_floors(np.array([4.0, 4.004, 4.004, 1.0, 1.0]))) == [3]


def test_parts_sharing_a_wall_are_one_outline_among_many_small_ones():
    """A 6 x 6 and a 4 x 6 box side by side (one wall shared, meshed twice), 10 high, and a row
    of 20 sheds 0.3 m wide and 1 m high: the section at 0.5 m has 21 parts; its outline is the
    10 x 6 rectangle the two boxes make (4 corners: the shared wall is inside)."""
    parts = [_box((6, 6, 10), (-2, 0, 5)), _box((4, 6, 10), (3, 0, 5))]
    parts += [_box((0.3, 0.3, 1), (x, 8, 0.5)) for x in np.linspace(-4.5, 4.5, 20)]
    capture, _ = capture_geometry(_mesh(parts), None)
    # the sheds' 1 m slice is thinner than remesh.MIN_LEVEL (2 m): it joins the interval above
    np.testing.assert_allclose(capture.floors, [0.0, 1.0])
    assert len(capture.blocks) == 1
    for ring in capture.contours:
        assert len(ring) == 4
        np.testing.assert_allclose(np.ptp(ring, axis=0), [1.0, 0.6], atol=1e-12)


def test_an_l_with_equal_arms_is_aligned_with_its_walls():
    """The principal axes of an L whose arms are equal lie on its diagonal; the standard view
    still lines the walls up with x and z (frame.py, step 3): turned 20 degrees, every outline
    edge comes out axis-parallel and the box is 10 x 10 m."""
    import shapely

    ell = shapely.Polygon([(0, 0), (10, 0), (10, 4), (4, 4), (4, 10), (0, 10)])
    solid = trimesh.creation.extrude_polygon(ell, 5.0)
    solid.apply_transform(trimesh.transformations.rotation_matrix(np.radians(20.0), [0, 0, 1]))
    capture, frame = capture_geometry(_mesh([(solid.vertices, solid.faces)]), None)
    (ring,) = capture.contours
    edges = np.roll(ring, -1, axis=0) - ring
    assert len(ring) == 6 and np.all(np.min(np.abs(edges), axis=1) < 1e-9)
    np.testing.assert_allclose(capture.blocks[0].size, (2.0, 1.0, 2.0), atol=1e-9)


def test_a_thin_level_joins_the_neighbour_whose_outline_it_resembles():
    from bgr.inverse.style.remesh import thin_levels_merged

    def square(area: float) -> np.ndarray:
        s = np.sqrt(area) / 2
        return np.array([(-s, -s), (s, -s), (s, s), (-s, s)])

    # intervals 0-0.3 (area 4), 0.3-0.32 (area 4: a ledge's vertices), 0.32-0.6 and 0.6-1
    # (area 1); least 0.2: the thin one joins the interval below, whose area it shares, so
    # the floor at 0.3 goes and the cut at 0.32 stays
    floors = np.array([0.0, 0.3, 0.32, 0.6, 1.0])
    rings = [square(4), square(4), square(1), square(1)]
    np.testing.assert_allclose(thin_levels_merged(floors, rings, 0.2), [0.0, 0.32, 0.6, 1.0])
    # with the thin interval shaped like the one above, the floor at 0.32 goes instead
    rings = [square(4), square(1), square(1), square(1)]
    np.testing.assert_allclose(thin_levels_merged(floors, rings, 0.2), [0.0, 0.3, 0.6, 1.0])
    # nothing thinner than least: unchanged; everything thin: one interval is left
    np.testing.assert_allclose(thin_levels_merged(floors, rings, 0.01), floors)
    assert list(thin_levels_merged(floors, rings, 2.0)) == [0.0, 1.0]
