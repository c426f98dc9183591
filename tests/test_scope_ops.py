"""rotateScope, alignScopeToAxes and alignScopeToGeometry: the scope turns, the geometry stays.

The cases follow the examples of CityEngine's reference pages for the three operations.
"""

from __future__ import annotations

import numpy as np
import pytest

import bgr


def _derive(text: str, lot=(10.0, 20.0)):
    return bgr.derive(bgr.load("version 1\n" + text), lot=lot)


def _same_place(a, b) -> None:
    """Two results with the same geometry in the world: bounds, area and volume."""
    ma, mb = a.mesh, b.mesh
    assert np.allclose(ma.bounds, mb.bounds, atol=1e-9)
    assert ma.area == pytest.approx(mb.area)
    if ma.is_watertight:  # a solid: the same volume too
        assert abs(ma.volume) == pytest.approx(abs(mb.volume))


def _axes(result, k: int = 0) -> np.ndarray:
    return np.asarray(result.terminals.axes[k], dtype=float).reshape(3, 3)


def test_align_scope_to_axes_removes_the_scopes_rotation():
    # the reference's example: a turned scope back on the world's axes, the geometry in place
    turned = _derive("terminal Box\nLot --> extrude(3) r(0, 30, 0) Box")
    aligned = _derive("terminal Box\nLot --> extrude(3) r(0, 30, 0) alignScopeToAxes() Box")
    _same_place(turned, aligned)
    assert np.allclose(_axes(aligned), np.eye(3), atol=1e-9)
    size = aligned.terminals.size[0]
    bounds = aligned.mesh.bounds
    assert np.allclose(size, bounds[1] - bounds[0], atol=1e-9)  # the bounding box


def test_align_scope_to_axes_y_lays_x_level_and_keeps_a_lot_flat():
    # a face of the front wall turned to world y: x stays level, the face is still a face
    plain = _derive("terminal F\nLot --> extrude(6) comp(f) { front: r(0, 0, 30) F }")
    result = _derive(
        "terminal F\nLot --> extrude(6) comp(f) { front: r(0, 0, 30) alignScopeToAxes(y) F }"
    )
    _same_place(plain, result)
    axes = _axes(result)
    assert np.allclose(axes[1], [0, 1, 0], atol=1e-9)
    assert abs(axes[0][1]) < 1e-9
    # a lot turned about y and aligned back can still be split and extruded
    lot = _derive(
        "terminal P\nLot --> r(0, 40, 0) alignScopeToAxes(y) split(x) { ~1: extrude(2) P }*"
    )
    assert len(lot) > 1 and lot.mesh.volume == pytest.approx(10 * 20 * 2)


def test_align_scope_to_geometry_puts_x_on_the_longest_edge():
    # Building_From_Footprint's first step: a 10 x 20 lot aligned to its longest edge
    result = _derive("terminal A\nLot --> alignScopeToGeometry(yUp, 0, longest) A")
    assert result.terminals.size[0] == pytest.approx([20.0, 0.0, 10.0])
    axes = _axes(result)
    assert np.allclose(axes[1], [0, 1, 0]) and np.allclose(np.abs(axes[0]), [0, 0, 1])
    # and the aligned lot is still a 2D shape: it splits and extrudes
    mass = _derive("Lot --> alignScopeToGeometry(yUp, 0, longest) split(x) { ~4: extrude(3) }*")
    assert len(mass) == 5 and mass.mesh.volume == pytest.approx(10 * 20 * 3)


def test_align_scope_to_geometry_on_roof_faces_points_y_up_the_slope():
    # the reference's example: after comp(f), zUp with the lowest edge turns a roof face's
    # y up its slope (useful to lay tiles); the face itself does not move
    text = "terminal F\nLot --> roof(gable, 30) comp(f) { aslant: ALIGN F }"
    plain = _derive(text.replace("ALIGN", ""))
    result = _derive(text.replace("ALIGN", "alignScopeToGeometry(zUp, any, world.lowest)"))
    _same_place(plain, result)
    for k in range(len(result)):
        x, y, z = _axes(result, k)
        assert abs(x[1]) < 1e-9  # the lowest edge, the eave, is level
        assert y[1] > 0.4  # up the slope
        assert z[1] > 0.4  # the face's normal, up and out


def test_align_scope_to_geometry_yup_makes_the_normal_y():
    result = _derive(
        "terminal F\nLot --> extrude(4) comp(f) { front: alignScopeToGeometry(yUp, 0, 0) F }"
    )
    x, y, _ = _axes(result)
    assert np.allclose(y, [0, 0, -1], atol=1e-9)  # the front face looks to -z
    assert result.terminals.size[0][1] == pytest.approx(0.0)
    # an asset or a round primitive has no faces to align to
    with pytest.raises(bgr.BgrError, match="alignScopeToGeometry\\(\\) of a 'sphere'"):
        _derive("terminal A\nLot --> i(sphere) alignScopeToGeometry(yUp, 0, 0) A")


def test_rotate_scope_turns_the_scope_not_the_geometry():
    plain = _derive("terminal Box\nLot --> extrude(3) Box")
    turned = _derive("terminal Box\nLot --> extrude(3) rotateScope(0, 90, 0) Box")
    _same_place(plain, turned)
    assert turned.terminals.size[0] == pytest.approx([20.0, 3.0, 10.0])
    # about the extrusion axis it stays a prism: it can still be split
    split = _derive("Lot --> extrude(3) rotateScope(0, 90, 0) split(x) { ~5: A }*\nA --> NIL")
    assert len(split) == 0
    # r() turns both: the geometry moves
    moved = _derive("terminal Box\nLot --> extrude(3) r(0, 90, 0) Box")
    assert not np.allclose(moved.mesh.bounds, plain.mesh.bounds)
    # any angle: the scope is the geometry's bounding box along the turned axes
    skew = _derive("terminal Box\nLot --> extrude(3) rotateScope(0, 45, 0) Box")
    _same_place(plain, skew)
    assert skew.terminals.size[0][0] == pytest.approx((10 + 20) / np.sqrt(2))


def test_rotate_scope_then_insert_fits_the_turned_scope():
    # Candler's Ventilator: a scope turned before i() sets which way the asset lies; +90 about
    # y takes x to -z (right-handed, as r())
    result = _derive("terminal C\nLot --> s(4, 0, 1) rotateScope(0, 90, 0) i(cylinder) C")
    assert np.allclose(_axes(result)[0], [0, 0, -1], atol=1e-9)
    assert result.terminals.size[0] == pytest.approx([1.0, 2.5, 4.0])  # y: the mean of x and z
    assert np.allclose(result.mesh.bounds, [[0, 0, 0], [4, 2.5, 1]], atol=1e-9)


def test_mirror_flips_the_geometry_inside_its_scope():
    # the reference's example: mirror(true, false, false) flips an L left to right; the scope
    # stays where it was
    plain = _derive("terminal A\nLot --> footprint(L, 0.4, 0.5) extrude(3) A", lot=(10.0, 8.0))
    flipped = _derive(
        "terminal A\nLot --> footprint(L, 0.4, 0.5) mirror(true, false, false) extrude(3) A",
        lot=(10.0, 8.0),
    )
    assert np.allclose(plain.mesh.bounds, flipped.mesh.bounds)
    assert flipped.mesh.center_mass[0] == pytest.approx(10.0 - plain.mesh.center_mass[0])
    assert flipped.mesh.volume == pytest.approx(plain.mesh.volume)
    assert np.allclose(flipped.terminals.origin, plain.terminals.origin)
    # a mesh: mirrored along y, its triangles still face out (a positive volume)
    wedge = _derive("terminal W\nLot --> s(2, 2, 2) i(wedge) mirror(false, true, false) W")
    assert wedge.mesh.volume == pytest.approx(4.0)  # half the 2 m cube, facing out
    upright = _derive("terminal W\nLot --> s(2, 2, 2) i(wedge) W")
    assert wedge.mesh.center_mass[1] == pytest.approx(2.0 - upright.mesh.center_mass[1])
    with pytest.raises(bgr.BgrError, match="true or false"):
        _derive("Lot --> mirror(1, 0, 0)")


def test_cleanup_geometry_merges_near_points_and_leaves_exact_shapes_alone(tmp_path):
    # an outline with a point 1 cm from the next: cleanupGeometry(all, 0.05) drops it
    text = (
        "version 1\nterminal A\n"
        "Lot --> polygon(0, 0, 10, 0, 10.01, 0, 10, 8, 0, 8) CLEAN extrude(3) A"
    )
    plain = bgr.derive(bgr.load(text.replace("CLEAN ", "")), lot=(10.0, 8.0))
    clean = bgr.derive(
        bgr.load(text.replace("CLEAN", "cleanupGeometry(all, 0.05)")), lot=(10.0, 8.0)
    )
    assert len(clean.mesh.faces) < len(plain.mesh.faces)
    assert clean.mesh.volume == pytest.approx(plain.mesh.volume, rel=1e-3)
    # an inserted mesh with a duplicated corner 1 mm away: merged, its sliver face dropped
    obj = tmp_path / "sliver.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 1.001 1 0\nf 1 2 3\nf 2 4 3\n", encoding="utf-8")
    grammar = 'version 1\nasset s = "sliver.obj"\nterminal A\nLot --> s(1, 1, 1) i(s) CLEAN A'
    (tmp_path / "a.bgr").write_text(grammar.replace("CLEAN ", ""), encoding="utf-8")
    (tmp_path / "b.bgr").write_text(grammar.replace("CLEAN", "cleanupGeometry(all, 0.01)"))
    raw = bgr.derive(bgr.load(tmp_path / "a.bgr"))
    cleaned = bgr.derive(bgr.load(tmp_path / "b.bgr"))
    assert len(raw.mesh.faces) == 2 and len(cleaned.mesh.faces) == 1
    # exact shapes are left as they are
    box = "version 1\nterminal A\nLot --> extrude(3) CLEAN A"
    a = bgr.derive(bgr.load(box.replace("CLEAN ", "")))
    b = bgr.derive(bgr.load(box.replace("CLEAN", "cleanupGeometry(all, 0.1)")))
    assert np.array_equal(a.mesh.faces, b.mesh.faces)


def test_convexify_cuts_a_concave_outline_into_convex_faces():
    # the reference's example: convexify(maxLength) comp(f) { all: SubShapes }; an L and a U
    def parts(text):
        result = _derive("terminal P\nLot --> " + text + " comp(f) { all: P }", lot=(20.0, 15.0))
        return result, len(result)

    whole = _derive("terminal P\nLot --> footprint(U, 0.3, 0.4) P", lot=(20.0, 15.0))
    u, count = parts("footprint(U, 0.3, 0.4) convexify()")
    assert count == 3 and u.mesh.area == pytest.approx(whole.mesh.area)
    # each part is convex: geometry.isConcave of each face says so
    flags = _derive(
        "terminal P\nLot --> footprint(U, 0.3, 0.4) convexify() comp(f) { all: "
        "label(str(geometry.isConcave())) P }",
        lot=(20.0, 15.0),
    )
    assert set(flags.terminals.label) == {"false"}
    _, l_count = parts("footprint(L, 0.3, 0.4) convexify()")
    assert l_count == 2
    # no cut is longer than 5 m here: the U stays one (concave) part
    _, kept = parts("footprint(U, 0.3, 0.4) convexify(5)")
    assert kept == 1
    _, box = parts("convexify()")  # a rectangle is convex already
    assert box == 1


def test_convexify_of_a_solid_cuts_its_concave_faces():
    # a U-shaped mass: its caps come out of comp(f) as three convex parts each, the walls
    # (rectangles) whole, the mesh itself unchanged
    def faces(text):
        return _derive(
            "terminal Cap, Wall\nLot --> footprint(U, 0.3, 0.4) extrude(6) "
            + text
            + " comp(f) { top: Cap | bottom: Cap | side: Wall }",
            lot=(20.0, 15.0),
        )

    plain, cut = faces(""), faces("convexify()")
    assert list(plain.terminals.label).count("Cap") == 2
    assert list(cut.terminals.label).count("Cap") == 6
    assert list(cut.terminals.label).count("Wall") == list(plain.terminals.label).count("Wall")
    assert cut.mesh.area == pytest.approx(plain.mesh.area)
    flags = _derive(
        "terminal F\nLot --> footprint(U, 0.3, 0.4) extrude(6) convexify() "
        "comp(f) { all: label(str(geometry.isConcave())) F }",
        lot=(20.0, 15.0),
    )
    assert len(flags) == 6 + 8 and set(flags.terminals.label) == {"false"}
    # no cut is 5 m or shorter here: the caps stay whole; a box has nothing to cut
    assert list(faces("convexify(5)").terminals.label).count("Cap") == 2
    box = _derive("terminal F\nLot --> extrude(3) convexify() comp(f) { all: F }")
    assert len(box) == 6
    # a hip roof on an L: every face comp(f) gives is convex
    roof = _derive(
        "terminal F\nLot --> footprint(L, 0.4, 0.4) roof(hip, 30) convexify() "
        "comp(f) { all: label(str(geometry.isConcave())) F }",
        lot=(20.0, 15.0),
    )
    assert set(roof.terminals.label) == {"false"}


def test_align_scope_to_geometry_of_a_solid_uses_its_faces():
    # CGA's roof-tile idiom on the roof itself: y along the largest slope's normal, x along
    # that slope's lowest edge (the eave); the roof stays where it was
    text = (
        "terminal R\nLot --> extrude(6) comp(f) { top: Roof }\nRoof --> roof(gable, 30) ALIGN R\n"
    )
    lot = (10.0, 8.0)  # the ridge along x
    turned = _derive(
        text.replace("ALIGN", "alignScopeToGeometry(yUp, largest, world.lowest)"), lot=lot
    )
    plain = _derive(text.replace("ALIGN", ""), lot=lot)
    _same_place(turned, plain)
    axes = np.asarray(turned.terminals.axes[0])
    assert abs(axes[0][1]) < 1e-9 and abs(abs(axes[0][0]) - 1) < 1e-9  # x along the eave
    assert axes[1][1] == pytest.approx(np.cos(np.radians(30)))  # y the slope's normal
    # zUp puts the normal on z instead; an edge picked by index works too
    up_z = _derive(text.replace("ALIGN", "alignScopeToGeometry(zUp, 0, 0)"), lot=lot)
    _same_place(up_z, plain)
