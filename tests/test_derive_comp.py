"""Component splits: the face frames of LANGUAGE.md section 7, selectors, comp.index/total."""

import io
import json

import numpy as np
import pytest

import bgr
from bgr.formats import write_json

BOX = """Lot --> extrude(4) comp(f) {
    front: F | back: B | left: L | right: R | top: T | bottom: Bo
}
terminal F, B, L, R, T, Bo
"""


def faces(src=BOX, lot=(10, 6)):
    """label -> (origin, axes, size) read from the JSON terminal list."""
    result = bgr.derive(bgr.load(src), lot=lot)
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=result.seed, attrs=result.attrs)
    return {
        t["label"]: (np.array(t["origin"]), np.array(t["axes"]), np.array(t["size"]))
        for t in json.loads(buffer.getvalue())["terminals"]
    }


@pytest.mark.parametrize(
    "label, origin, x, y, z, size",
    [
        ("F", (10, 0, 0), (-1, 0, 0), (0, 1, 0), (0, 0, -1), (10, 4, 0)),
        ("B", (0, 0, 6), (1, 0, 0), (0, 1, 0), (0, 0, 1), (10, 4, 0)),
        ("L", (0, 0, 0), (0, 0, 1), (0, 1, 0), (-1, 0, 0), (6, 4, 0)),
        ("R", (10, 0, 6), (0, 0, -1), (0, 1, 0), (1, 0, 0), (6, 4, 0)),
        ("T", (0, 4, 6), (1, 0, 0), (0, 0, -1), (0, 1, 0), (10, 6, 0)),
        ("Bo", (0, 0, 0), (1, 0, 0), (0, 0, 1), (0, -1, 0), (10, 6, 0)),
    ],
)
def test_face_frames(label, origin, x, y, z, size):
    o, axes, s = faces()[label]
    np.testing.assert_allclose(o, origin, atol=1e-9)
    np.testing.assert_allclose(axes, [x, y, z], atol=1e-9)
    np.testing.assert_allclose(s, size, atol=1e-9)
    assert np.linalg.det(axes) == pytest.approx(1.0)  # right-handed


def test_front_is_the_lots_first_edge_and_x_runs_left_to_right_from_outside():
    o, axes, s = faces()["F"]
    # seen from outside the front (from -z, looking at +z), x runs from the viewer's left to right
    viewer_right = np.cross([0, 0, 1], [0, 1, 0])
    assert np.dot(axes[0], viewer_right) > 0.99


def test_earlier_selectors_win_and_unmatched_faces_are_dropped():
    src = "Lot --> extrude(3) comp(f) { front: F | side: S | all: A }\nterminal F, S, A\n"
    t = bgr.derive(bgr.load(src)).terminals
    assert sorted(t.label) == ["A", "A", "F", "S", "S", "S"]
    src = "Lot --> extrude(3) comp(f) { top: T }\nterminal T\n"
    assert bgr.derive(bgr.load(src)).terminals.label == ["T"]


def test_face_index_selector_and_comp_index_total():
    src = (
        "Lot --> extrude(3) comp(f) { face(0): F | side: S(comp.index, comp.total) }\n"
        "terminal F\nS(i, n) --> s(i, n, 0)\n"
    )
    t = bgr.derive(bgr.load(src)).terminals
    assert t.label[0] == "F"
    assert [tuple(map(int, s[:2])) for s in t.size[1:]] == [(0, 3), (1, 3), (2, 3)]


def test_faces_of_an_l_shaped_footprint(tmp_path):
    geo = tmp_path / "l.geojson"
    geo.write_text(
        '{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {}, '
        '"geometry": {"type": "Polygon", "coordinates": '
        "[[[0, 0], [20, 0], [20, 10], [10, 10], [10, 20], [0, 20], [0, 0]]]}}]}"
    )
    src = "Lot --> extrude(5) comp(f) { side: S | top: T | bottom: Bo }\nterminal S, T, Bo\n"
    t = bgr.derive(bgr.load(src), lot=str(geo)).terminals
    sides = [i for i, lab in enumerate(t.label) if lab == "S"]
    assert len(sides) == 6
    assert sorted(round(float(t.size[i][0]), 6) for i in sides) == [10, 10, 10, 10, 20, 20]
    # every side face's outward normal points away from the footprint's inside
    for i in sides:
        centre = t.origin[i] + t.axes[i][0] * t.size[i][0] / 2
        probe = centre - t.axes[i][2] * 0.01  # just inside the wall
        x, z = probe[0], -probe[2]  # back to GeoJSON's (east, north)
        assert (0 < x < 20 and 0 < z < 10) or (0 < x < 10 and 0 < z < 20)


def test_comp_left_and_right_name_the_corners_of_each_side_face():
    """comp.left/comp.right: 90 at an outer corner, -90 at an inner one, seen from outside."""
    src = (
        "Lot --> footprint(L, 0.4, 0.5) extrude(5) comp(f) { side: F(comp.left, comp.right) | all: "
        "NIL }\n"
        'F(l, r) --> label(l == 90 ? (r == 90 ? "oo" : "oi") : (r == 90 ? "io" : "ii")) X\n'
        "terminal X\n"
    )
    t = bgr.derive(bgr.load(src), lot=(20, 20)).terminals
    # front, right end of the bar, back of the bar (inner corner on its left), the wing's side
    # (inner corner on its right), the wing's back, the long left side
    assert t.label == ["oo", "oo", "io", "oi", "oo", "oo"]
    box = bgr.derive(bgr.load(src.replace("footprint(L, 0.4, 0.5) ", ""))).terminals
    assert box.label == ["oo"] * 4
