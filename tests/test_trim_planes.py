"""CGA's trim planes: an inserted mesh is cut where its façade meets the next one.

As in CityEngine's trim-plane examples: a ledge inserted longer than its façade (Candler's
s('1.4, ...) center(x) i(ledge)) meets the next façade's ledge in a mitre at the corner instead
of running on past it.
"""

from __future__ import annotations

import numpy as np
import pytest

import bgr

LEDGES = """version 1
terminal Ledge
Lot --> set(trim.vertical, true) extrude(3) comp(f) { side: Ledges }
Ledges --> s('1.4, 0.5, 0.5) center(x) i(cube) Ledge
"""


def test_ledges_meet_in_a_mitre_at_the_corners():
    result = bgr.derive(bgr.load(LEDGES), lot=(10.0, 10.0))
    bounds = result.mesh.bounds
    # without trim planes each ledge would run 2 m past both corners
    assert np.allclose(bounds[0][[0, 2]], [-0.5, -0.5], atol=1e-9)
    assert np.allclose(bounds[1][[0, 2]], [10.5, 10.5], atol=1e-9)
    # each ledge is cut at 45 degrees: its outer edge is 11 m long, its inner one 10 m
    for k in range(len(result)):
        size = result.terminals.size[k]
        assert size[0] == pytest.approx(14.0)  # the scope keeps its size; the mesh is cut


def test_a_mesh_wholly_past_the_corner_is_gone_and_inside_ones_are_untouched():
    text = """version 1
terminal Out, In
Lot --> set(trim.vertical, true) extrude(3) comp(f) {
    front: [ t(-3, 0, 0) s(1, 1, 1) i(cube) Out ] s(1, 1, 1) i(cube) In
}
"""
    result = bgr.derive(bgr.load(text), lot=(10.0, 10.0))
    assert list(result.terminals.label) == ["In"]
    assert len(result.mesh.faces) == 12  # the box inside the façade is whole


def test_trims_follow_the_subtree_and_the_reuse_keeps_them_apart():
    # every floor of a façade carries its corner planes down to the inserts of its tiles;
    # identical floors are derived once and replayed, tiles at the corners are cut
    text = """version 1
terminal Bar
Lot --> set(trim.vertical, true) extrude(9) comp(f) { side: Facade }
Facade --> split(y) { ~3: Floor }*
Floor --> split(x) { ~2.5: Tile }*
Tile --> s('1.6, 0.2, 0.3) center(x) i(cube) Bar
"""
    grammar = bgr.load(text)
    result = bgr.derive(grammar, lot=(10.0, 10.0))
    bounds = result.mesh.bounds
    assert np.allclose(bounds[0][[0, 2]], [-0.3, -0.3], atol=1e-9)
    assert np.allclose(bounds[1][[0, 2]], [10.3, 10.3], atol=1e-9)
    # cut bars (at the corners) have more triangles than whole ones (12)
    per_row = [len(result.terminals.library.meshes[m].faces) for m in result.terminals.mesh]
    assert sorted(set(per_row))[0] == 12 and max(per_row) > 12


def test_without_reuse_the_same_bytes(tmp_path, monkeypatch):
    text = LEDGES.replace("i(cube) Ledge", "i(cube) Ledge") + "\n"
    a = tmp_path / "a.glb"
    b = tmp_path / "b.glb"
    bgr.derive(bgr.load(text), lot=(10.0, 10.0)).save(a)
    monkeypatch.setenv("BGR_REUSE", "0")
    bgr.derive(bgr.load(text), lot=(10.0, 10.0)).save(b)
    assert a.read_bytes() == b.read_bytes()


def test_trimming_is_off_until_set_and_set_false_turns_it_off():
    # complexpatterns' railing: set(trim.vertical, false) so that the corner bars are not cut;
    # a grammar written for bgr has trimming off unless it turns it on
    for text in (
        LEDGES.replace("Ledges --> s(", "Ledges --> set(trim.vertical, false) s("),
        LEDGES.replace("set(trim.vertical, true) ", ""),
    ):
        result = bgr.derive(bgr.load(text), lot=(10.0, 10.0))
        assert np.allclose(result.mesh.bounds[0][[0, 2]], [-2.0, -2.0], atol=1e-9)
        assert len(result.mesh.faces) == 4 * 12


def test_the_trim_operation_cuts_the_shapes_own_geometry():
    # CGA's trim(): a façade made 20 % wider than its wall is cut back at the corners' mitres,
    # with trimming on; with it off, or with no plane crossing the shape, nothing changes
    src = (
        "attr on = true\n"
        "Lot --> set(trim.vertical, on) extrude(6) comp(f) { front: Wide }\n"
        "Wide --> s('1.2, '1, '1) center(x) [ report(\"before\", geometry.area()) ] trim()\n"
        "    report(\"after\", geometry.area()) s('1.2, '1, '1) center(x) extrude(0.5) trim()\n"
        '    report("slab", geometry.area(top)) NIL\n'
    )
    grammar = bgr.load(src)
    (lot,) = bgr.derive(grammar, lot=(10, 8)).reports
    got = {k: v["sum"] for k, v in lot["reports"].items()}
    assert got["before"] == pytest.approx(12 * 6)
    assert got["after"] == pytest.approx(10 * 6)
    # a slab as wide again pushed out 0.5 m from the wall, cut by the 45-degree mitres: 10 m
    # wide at the wall, 11 m at its outer face (the cuts stay open, as CGA's trims)
    assert got["slab"] == pytest.approx(11 * 6)
    (lot,) = bgr.derive(grammar, lot=(10, 8), attrs={"on": False}).reports
    got = {k: v["sum"] for k, v in lot["reports"].items()}
    assert got["after"] == pytest.approx(12 * 6)


@pytest.mark.parametrize("horizontal", [True, False])
def test_horizontal_planes_cut_a_hip_roofs_tiles_at_the_hips(horizontal):
    # CGA's trim.horizontal (off by default): comp(f) of a roof gives each slope planes at the
    # edges it shares with the others, and those rising less than 40 degrees (the hips of a
    # 30-degree roof, its ridge) are horizontal ones; with them on, tiles inserted over the
    # whole width of each row (a split's pieces keep the slab's scope) are cut at the hips
    switch = "set(trim.horizontal, true) " if horizontal else ""
    src = (
        "Lot --> set(trim.vertical, true) extrude(5) comp(f) { top: Roof }\n"
        'Roof --> roof(hip, 30) [ report("roof", geometry.area()) ] comp(f) { aslant: Plane }\n'
        f"Plane --> {switch}split(y) {{ ~1: split(x) {{ ~1: s('1, '1, 0.05) i(cube) "
        'report("tiles", geometry.area(back)) B }* }*\nterminal B\n'
    )
    (lot,) = bgr.derive(bgr.load(src), lot=(10, 8)).reports
    got = {k: v["sum"] for k, v in lot["reports"].items()}
    if horizontal:  # the tiles' outer faces cover the slopes (cut a little wider, 5 cm out)
        assert got["tiles"] == pytest.approx(got["roof"], rel=0.03)
    else:  # the end slopes' and the sides' rows keep their full width
        assert got["tiles"] > got["roof"] * 1.3


def test_planes_turned_off_and_on_again_still_cut():
    """CGA keeps a shape's trim planes while trimming is off: the Parthenon turns it off for a
    column's box and on for the capital, which the corner's plane then cuts."""
    again = LEDGES.replace(
        "Ledges --> s(", "Ledges --> set(trim.vertical, false) set(trim.vertical, true) s("
    )
    assert np.allclose(
        bgr.derive(bgr.load(again), lot=(10.0, 10.0)).mesh.bounds,
        bgr.derive(bgr.load(LEDGES), lot=(10.0, 10.0)).mesh.bounds,
    )
    off = LEDGES.replace("Ledges --> s(", "Ledges --> set(trim.vertical, false) s(")
    bounds = bgr.derive(bgr.load(off), lot=(10.0, 10.0)).mesh.bounds
    assert np.allclose(bounds[0][[0, 2]], [-2.0, -2.0], atol=1e-9)  # off: the ledges run past
