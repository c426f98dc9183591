"""Scope frames after extrude, as CGA sets them (docs/language.md, "extrude and its frame").

y points along the extrusion, x keeps its old direction as far as it can, z completes a
right-handed frame.  Each case is checked on the JSON terminal list, as a user would see it.
"""

from __future__ import annotations

import io
import json

import numpy as np
import pytest

import bgr
from bgr.formats import write_json


def terminals(src: str, **kw) -> list[dict]:
    result = bgr.derive(bgr.load(src), **kw)
    buf = io.StringIO()
    write_json(result.terminals, buf, seed=0, attrs={})
    return json.loads(buf.getvalue())["terminals"]


def box(t: dict) -> tuple[np.ndarray, np.ndarray]:
    """World-space bounding box (lo, hi) of a terminal's scope."""
    o, a, s = np.array(t["origin"]), np.array(t["axes"]), np.array(t["size"])
    corners = np.array(
        [o + a.T @ (s * np.array([i, j, k])) for i in (0, 1) for j in (0, 1) for k in (0, 1)]
    )
    return corners.min(axis=0), corners.max(axis=0)


def by_label(ts: list[dict], label: str) -> list[dict]:
    return [t for t in ts if t["label"] == label]


SETBACKS = """\
terminal Wall, Top
attr h = 10
Lot --> extrude(h) comp(f) { top: [ Top ] T1 | side: Wall | bottom: NIL }
T1 --> s('0.7, '0.7, '1) center(xy) extrude(h * 0.8) comp(f) {
    top: [ Top ] T2 | side: Wall1 | bottom: NIL
}
T2 --> s('0.6, '0.6, '1) center(xy) extrude(h * 0.5) comp(f) {
    top: Top | side: Wall2 | bottom: NIL
}
Wall1 --> label("Wall1") Wall
Wall2 --> label("Wall2") Wall
"""


def test_stacked_setbacks_stand_on_the_tier_below_inside_its_footprint():
    ts = terminals(SETBACKS, lot=(20, 16))
    tiers = [by_label(ts, name) for name in ("Wall", "Wall1", "Wall2")]
    boxes = []
    for walls in tiers:
        assert len(walls) == 4, "each tier has four walls"
        lo = np.min([box(w)[0] for w in walls], axis=0)
        hi = np.max([box(w)[1] for w in walls], axis=0)
        boxes.append((lo, hi))
    (lo0, hi0), (lo1, hi1), (lo2, hi2) = boxes
    # heights: 0..10, 10..18, 18..23: each tier's bottom on the previous tier's top
    assert lo0[1] == pytest.approx(0.0) and hi0[1] == pytest.approx(10.0)
    assert lo1[1] == pytest.approx(hi0[1]) and hi1[1] == pytest.approx(18.0)
    assert lo2[1] == pytest.approx(hi1[1]) and hi2[1] == pytest.approx(23.0)
    # footprints nested and centred: 20 x 16, 14 x 11.2, 8.4 x 6.72
    for (lo_a, hi_a), (lo_b, hi_b) in [(boxes[0], boxes[1]), (boxes[1], boxes[2])]:
        assert np.all(lo_b[[0, 2]] >= lo_a[[0, 2]] - 1e-9)
        assert np.all(hi_b[[0, 2]] <= hi_a[[0, 2]] + 1e-9)
    assert hi1[0] - lo1[0] == pytest.approx(14.0) and hi1[2] - lo1[2] == pytest.approx(11.2)
    assert hi2[0] - lo2[0] == pytest.approx(8.4) and hi2[2] - lo2[2] == pytest.approx(6.72)
    # every wall of every tier is vertical: its z axis (normal) is horizontal
    for walls in tiers:
        for w in walls:
            assert abs(w["axes"][2][1]) < 1e-9
            assert w["axes"][1] == pytest.approx([0.0, 1.0, 0.0])  # and its y points up
    tops = by_label(ts, "Top")
    assert sorted(round(box(t)[0][1], 9) for t in tops) == [10.0, 18.0, 23.0]
    for t in tops:
        assert t["axes"][2] == pytest.approx([0.0, 1.0, 0.0])  # the caps face up


def test_extrude_from_a_face_points_y_along_the_normal_and_keeps_x():
    src = (
        "Lot --> s(10, 0, 6) extrude(8) comp(f) { front: F | all: NIL }\n"
        "F --> extrude(0.5) P\n"
        "terminal P\n"
    )
    (p,) = terminals(src)
    x, y, z = (np.array(a) for a in p["axes"])
    assert x == pytest.approx([-1, 0, 0])  # the face's x: left to right seen from the street
    assert y == pytest.approx([0, 0, -1])  # the front face's outward normal
    assert z == pytest.approx(np.cross(x, y))  # right-handed
    assert p["size"] == pytest.approx([10.0, 0.5, 8.0])
    lo, hi = box(p)
    assert lo == pytest.approx([0, 0, -0.5]) and hi == pytest.approx([10, 8, 0])


def test_a_window_reveal_extruded_into_a_facade_lines_the_opening():
    """extrude(-d) goes into the wall; its side faces close the hole from the face to depth d."""
    src = (
        "Lot --> s(10, 0, 6) extrude(8) comp(f) { front: F | all: NIL }\n"
        "F --> split(x) { ~1: NIL | 2: split(y) { 1: NIL | 1.5: Hole | ~1: NIL } | ~1: NIL }\n"
        "Hole --> extrude(-0.3) comp(f) {\n"
        "    left: R | right: R | front: Head | back: Sill | all: NIL\n"
        "}\n"
        "terminal R, Head, Sill\n"
    )
    ts = terminals(src)
    assert len(by_label(ts, "R")) == 2 and len(by_label(ts, "Head")) == 1
    # the opening: x 4..6, y 1..2.5, in the front wall's plane z = 0, the wall goes back to +z
    for t in ts:
        lo, hi = box(t)
        assert lo[2] == pytest.approx(0.0) and hi[2] == pytest.approx(0.3)  # face to depth
    (head,), (sill,) = by_label(ts, "Head"), by_label(ts, "Sill")
    assert box(head)[0][1] == pytest.approx(2.5) and box(head)[1][1] == pytest.approx(2.5)
    assert box(sill)[0][1] == pytest.approx(1.0) and box(sill)[1][1] == pytest.approx(1.0)
    sides = sorted(box(t)[0][0] for t in by_label(ts, "R"))
    assert sides == pytest.approx([4.0, 6.0])
    for t in by_label(ts, "R"):  # the sides span the opening's height: no gap
        lo, hi = box(t)
        assert lo[1] == pytest.approx(1.0) and hi[1] == pytest.approx(2.5)


def test_a_roof_access_box_stands_on_a_roof_face():
    src = (
        "Lot --> extrude(12) comp(f) { top: [ Roof ] Access | all: NIL }\n"
        "Access --> s(3, 2, '1) center(xy) extrude(2.5) comp(f) {\n"
        "    top: Lid | side: Side | all: NIL\n"
        "}\n"
        "terminal Roof, Lid, Side\n"
    )
    ts = terminals(src, lot=(20, 14))
    (lid,) = by_label(ts, "Lid")
    lo, hi = box(lid)
    assert lo[1] == pytest.approx(14.5) and hi[1] == pytest.approx(14.5)  # 12 + 2.5, on top
    assert lid["axes"][2] == pytest.approx([0, 1, 0])
    for side in by_label(ts, "Side"):
        lo, hi = box(side)
        assert lo[1] == pytest.approx(12.0) and hi[1] == pytest.approx(14.5)
        assert np.all(lo[[0, 2]] >= [0, 0]) and np.all(hi[[0, 2]] <= [20, 14])
    assert len(by_label(ts, "Side")) == 4


def test_extrude_world_up_on_a_tilted_face_rises_vertically():
    src = (
        "Lot --> s(4, 0, 4) r(30, 0, 0) extrude(world.up, 2) P\n"  # a lot tilted 30 degrees
        "terminal P\n"
    )
    (p,) = terminals(src)
    assert p["axes"][1] == pytest.approx([0, 1, 0])
    assert p["geometry"] == "extrusion"
    mesh = bgr.derive(bgr.load(src)).mesh
    mesh.merge_vertices()
    heights = mesh.vertices[:, 1]
    # the tilted face spans 4 * sin(30) = 2 m of height; the top is 2 m above each point
    assert heights.max() - heights.min() == pytest.approx(2 + 4 * np.sin(np.radians(30)))
    assert mesh.is_watertight and mesh.volume == pytest.approx(4 * 4 * np.cos(np.radians(30)) * 2)


def test_extrude_world_up_of_a_lot_is_extrude():
    a = terminals("Lot --> extrude(world.up, 3) P\nterminal P\n")
    b = terminals("Lot --> extrude(3) P\nterminal P\n")
    assert a == b


def test_negative_extrude_of_a_lot_goes_down():
    (p,) = terminals("Lot --> extrude(-3) P\nterminal P\n", lot=(4, 4))
    lo, hi = box(p)
    assert lo[1] == pytest.approx(-3.0) and hi[1] == pytest.approx(0.0)
    assert p["axes"][1] == pytest.approx([0, 1, 0])


def test_extrude_world_up_of_a_wall_is_an_error():
    src = "Lot --> extrude(3) comp(f) { front: extrude(world.up, 1) P | all: NIL }\nterminal P\n"
    with pytest.raises(bgr.BgrError, match="vertical face has no volume"):
        bgr.derive(bgr.load(src))


@pytest.mark.parametrize("primitive", ["cube", "cylinder", "sphere", "wedge"])
def test_a_primitive_inserted_into_a_face_is_not_flattened(primitive):
    """A face has z size 0; as for assets, the missing size is the mean of the other two."""
    src = (
        "Lot --> s(4, 0, 4) extrude(3) comp(f) {\n"
        f"    front: s(2, 1, 0) i({primitive}) P | all: NIL\n"
        "}\n"
        "terminal P\n"
    )
    (p,) = terminals(src)
    assert p["size"] == pytest.approx([2.0, 1.0, 1.5])


def test_a_primitive_keeps_a_scope_with_no_zero_size():
    (p,) = terminals("Lot --> s(2, 3, 4) i(cube) P\nterminal P\n")
    assert p["size"] == pytest.approx([2.0, 3.0, 4.0])
    (q,) = terminals("Lot --> s(2, 0, 0) i(cube) P\nterminal P\n")
    assert q["size"] == pytest.approx([2.0, 2.0, 2.0])  # two zero: uniform by the third
    (r,) = terminals("Lot --> s(0, 0, 0) i(quad) P\nterminal P\n")
    assert r["size"] == pytest.approx([1.0, 1.0, 0.0])  # all zero: the primitive's own size


# ---- geometry.isRectangular and the ridge trims (issue 9, visible defects) -------------------

RIDGE = """\
import stdlib.roof as rf
Lot --> extrude(6) comp(f) { top: rf.RidgeGable(chimney = true) | all: NIL }
"""


def _trapezoid(tmp_path):
    path = tmp_path / "trapezoid.geojson"
    ring = [[38, 2], [52, 0], [54, 14], [38, 14], [38, 2]]
    feature = {
        "type": "Feature",
        "properties": {},
        "geometry": {"type": "Polygon", "coordinates": [ring]},
    }
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    return str(path)


@pytest.mark.parametrize(
    "lot, expected",
    [((10, 8), "A"), ("trapezoid", "B"), ("l_lot", "B")],
)
def test_geometry_is_rectangular(tmp_path, lot, expected):
    from pathlib import Path

    if lot == "trapezoid":
        lot = _trapezoid(tmp_path)
    elif lot == "l_lot":
        lot = str(Path(__file__).resolve().parents[1] / "examples" / "l_lot.geojson")
    src = "Lot --> case geometry.isRectangular(1): A | else: B\nterminal A, B\n"
    assert [t["label"] for t in terminals(src, lot=lot)] == [expected]


def test_ridge_trims_sit_on_the_roof_of_a_rectangle():
    result = bgr.derive(bgr.load(RIDGE), lot=(12, 8))
    table = result.terminals
    roof_rows = [i for i, lab in enumerate(table.label) if lab == "Roof"]
    ridge_rows = [i for i, lab in enumerate(table.label) if lab == "Ridge"]
    assert roof_rows and ridge_rows
    mesh = result.mesh
    roof_top = 6 + 4 * np.tan(np.radians(40))  # the ridge of a 40-degree gable over 8 m
    ys = mesh.vertices[:, 1]
    # the highest vertex is the chimney's; the ridge cap straddles the ridge line: some of its
    # vertices below the ridge height, some above, none more than 0.3 m away
    cap = [t for t in terminals(RIDGE, lot=(12, 8)) if t["label"] == "Ridge"][0]
    lo, hi = box(cap)
    assert lo[1] < roof_top < hi[1] and hi[1] - roof_top < 0.3
    assert ys.max() > roof_top  # the chimney rises above the ridge


def test_ridge_trims_give_way_to_a_plain_gable_off_the_rectangle(tmp_path):
    labels = {t["label"] for t in terminals(RIDGE, lot=_trapezoid(tmp_path))}
    assert "Roof" in labels and not labels & {"Ridge", "Eave", "Chimney"}


def test_a_prism_of_zero_height_has_no_side_faces():
    src = (
        "Lot --> extrude(0) comp(f) { side: split(x) { ~1: W | ~1: W } | top: T | all: NIL }\n"
        "terminal W, T\n"
    )
    assert [t["label"] for t in terminals(src)] == ["T"]


@pytest.mark.parametrize("window", ["Plain", "Shop", "Arched"])
def test_stdlib_reveals_close_the_opening_and_face_into_it(window):
    """The four sides of a recessed window meet the wall's opening edge to edge (no see-through
    sliver) and face into the hole, so a one-sided renderer draws them."""
    src = (
        "import stdlib.window as win\n"
        "terminal Wall\n"
        "Lot --> s(4, 0, 4) extrude(3) comp(f) { front: F | all: NIL }\n"
        "F --> split(x) { ~1: Wall | 1.2: split(y) { 0.8: Wall | 1.5: O | ~1: Wall } | ~1: Wall }\n"
        f"O --> win.{window}\n"
    )
    ts = terminals(src)
    # the front wall is the plane z = 0 (facing -z); the opening x 1.4..2.6, y 0.8..2.3
    reveals = [t for t in ts if t["label"] == "Wall" and abs(t["axes"][2][2]) < 1e-9]
    assert reveals, "the window has reveal faces"
    centre = np.array([2.0, 1.55])
    lo_all = np.min([box(t)[0] for t in reveals], axis=0)
    hi_all = np.max([box(t)[1] for t in reveals], axis=0)
    assert lo_all[2] == pytest.approx(0.0, abs=1e-9)  # from the wall face ...
    assert lo_all[0] == pytest.approx(1.4) and hi_all[0] == pytest.approx(2.6)  # ... round the
    # opening, up to its head (an arch's head is a polygon: its highest vertex may sit a few
    # millimetres under the opening's top)
    assert hi_all[1] == pytest.approx(2.3, abs=0.01)
    for t in reveals:
        lo, hi = box(t)
        assert lo[2] == pytest.approx(0.0, abs=1e-9)  # every side starts at the wall face
        mid = (lo + hi) / 2
        normal = np.array(t["axes"][2])
        to_centre = np.array([centre[0] - mid[0], centre[1] - mid[1], 0.0])
        assert normal @ to_centre > 0, f"{t['path']} faces away from the hole"


def test_comp_of_a_roof_gives_its_slopes_and_upright_gable_ends():
    src = (
        "Lot --> extrude(6) comp(f) { top: roof(gable, 40, 0.4) R | all: NIL }\n"
        "R --> comp(f) { vertical: G | aslant: S | all: X }\n"
        "terminal G, S, X\n"
    )
    ts = terminals(src, lot=(12, 8))
    labels = sorted(t["label"] for t in ts)
    assert labels == ["G", "G", "S", "S"]
    # a gable end stands on the wall top (y = 6), not down at the eaves, where it would lie in
    # the wall's own plane and flicker against it: 8 m wide, 4 tan(40) high
    for g in by_label(ts, "G"):
        assert g["axes"][1] == pytest.approx([0, 1, 0])  # upright, y up
        assert g["size"] == pytest.approx([8.0, 4 * np.tan(np.radians(40)), 0.0])
        assert box(g)[0][1] == pytest.approx(6.0)
    for s in by_label(ts, "S"):
        assert abs(s["axes"][2][1]) == pytest.approx(np.cos(np.radians(40)))


def test_stdlib_gable_ends_are_wall_not_roof():
    src = "import stdlib.roof as rf\nLot --> extrude(6) comp(f) { top: rf.RidgeGable | all: NIL }\n"
    ts = terminals(src, lot=(12, 8))
    for t in ts:
        upright = abs(t["axes"][2][1]) < 1e-9 and t["geometry"] == "polygon"
        if t["label"] == "Roof":
            assert not upright, "a gable end drawn as roof"
    gables = [t for t in ts if t["label"] == "Wall"]
    assert len(gables) == 2 and all(t["color"] == "#d8c8a8" for t in gables)
