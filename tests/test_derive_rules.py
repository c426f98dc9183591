"""Rules, attrs, randomness and limits (LANGUAGE.md sections 3, 8, 9, 10)."""

import numpy as np
import pytest

import bgr


def labels(src, **kw):
    return bgr.derive(bgr.load(src), **kw).terminals.label


def test_stochastic_choice_frequencies_over_ten_thousand_shapes():
    src = "Lot --> split(x) { { 1: W }* }\nW --> 60%: A | 30%: B | else: C\nterminal A, B, C\n"
    t = labels(src, lot=(10_000, 1), seed=7)
    assert len(t) == 10_000
    for name, p in (("A", 0.6), ("B", 0.3), ("C", 0.1)):
        assert abs(t.count(name) / 10_000 - p) < 0.025


def test_without_else_the_rest_is_nil():
    t = labels("Lot --> split(x) { { 1: W }* }\nW --> 50%: A\nterminal A\n", lot=(2000, 1))
    assert 0.45 < len(t) / 2000 < 0.55


def test_same_seed_same_terminals_other_seed_other_draws():
    src = "Lot --> split(x) { { 1: W }* }\nW --> s('1, rand(1, 10), '1) X\nterminal X\n"
    a = bgr.derive(bgr.load(src), seed=3, lot=(50, 1)).terminals
    b = bgr.derive(bgr.load(src), seed=3, lot=(50, 1)).terminals
    c = bgr.derive(bgr.load(src), seed=4, lot=(50, 1)).terminals
    np.testing.assert_array_equal(a.size, b.size)
    assert not np.array_equal(a.size, c.size)


def test_editing_one_subtree_keeps_the_draws_of_the_others():
    before = (
        "Lot --> split(x) { 10: Left | 10: Right }\n"
        "Left --> split(x) { { 1: L }* }\nRight --> split(x) { { 1: R }* }\n"
        "L --> s('1, rand(1, 9), '1) X\nR --> s('1, rand(1, 9), '1) Y\nterminal X, Y\n"
    )
    after = before.replace(
        "L --> s('1, rand(1, 9), '1) X", "L --> 50%: s('1, rand(20, 30), '1) X | else: NIL"
    )
    a = bgr.derive(bgr.load(before), seed=11).terminals
    b = bgr.derive(bgr.load(after), seed=11).terminals
    ya = [s[1] for s, lab in zip(a.size, a.label, strict=True) if lab == "Y"]
    yb = [s[1] for s, lab in zip(b.size, b.label, strict=True) if lab == "Y"]
    assert ya == yb and len(ya) == 10
    xa = [s[1] for s, lab in zip(a.size, a.label, strict=True) if lab == "X"]
    xb = [s[1] for s, lab in zip(b.size, b.label, strict=True) if lab == "X"]
    assert xa != xb


def test_attrs_consts_funcs_params_and_set():
    src = (
        "attr h = 3\nconst k = 2\nfunc twice(x) = x * k\n"
        "Lot --> extrude(twice(h)) M(h + 1)\nM(p) --> s(p, '1, '1) X\nterminal X\n"
    )
    t = bgr.derive(bgr.load(src)).terminals
    assert tuple(t.size[0]) == (4.0, 6.0, 20.0)
    t = bgr.derive(bgr.load(src), attrs={"h": 5}).terminals
    assert tuple(t.size[0]) == (6.0, 10.0, 20.0)


def test_unknown_attr_in_set_is_an_error():
    with pytest.raises(bgr.BgrError, match="(?s)no attr 'hieght'.*did you mean 'height'"):
        bgr.derive(bgr.load("attr height = 1\nLot --> NIL\n"), attrs={"hieght": 3})


def test_conditional_rules_and_depth():
    src = (
        "Lot --> split(x) { { 2: P }* }\n"
        "P --> case split.index == 0: A | case split.index < 3: B | else: C\nterminal A, B, C\n"
    )
    assert labels(src, lot=(10, 1)) == ["A", "B", "B", "C", "C"]


def test_push_and_pop_place_several_children():
    src = "Lot --> [ t(5, 0, 0) A ] [ t(0, 0, 5) A ] A\nterminal A\n"
    t = bgr.derive(bgr.load(src)).terminals
    assert [tuple(o) for o in t.origin] == [(5, 0, 0), (0, 0, 5), (0, 0, 0)]


def test_center_on_the_received_scope():
    src = "Lot --> s(4, 0, 2) center(xz) A\nterminal A\n"
    t = bgr.derive(bgr.load(src), lot=(10, 10)).terminals
    assert tuple(t.origin[0]) == (3, 0, 4)


def test_rotation_keeps_the_scope_right_handed():
    src = "Lot --> r(0, 90, 0) r(30, 0, 0) A\nterminal A\n"
    axes = bgr.derive(bgr.load(src)).terminals.axes[0]
    np.testing.assert_allclose(axes @ axes.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(axes) == pytest.approx(1)


def test_infinite_recursion_stops_with_a_clear_error():
    with pytest.raises(bgr.BgrError) as e:
        bgr.derive(bgr.load("A --> B\nB --> A\n", path="loop.bgr"), max_depth=50)
    assert "deeper than 50" in str(e.value) and e.value.line in (1, 2)


def test_shape_explosion_stops_at_the_budget():
    with pytest.raises(bgr.BgrError, match="more than 1,000 shapes"):
        bgr.derive(
            bgr.load("Lot --> split(x) { { 0.01: A }* }\nA --> B\nterminal B\n"),
            lot=(100, 1),
            max_shapes=1000,
        )


def test_division_by_zero_names_the_place():
    with pytest.raises(bgr.BgrError) as e:
        bgr.derive(bgr.load("attr n = 0\nLot --> extrude(1 / n)\n", path="div.bgr"))
    assert (e.value.line, e.value.column) == (2, 17) and "division by zero" in e.value.message


def test_tapering_a_3d_shape_and_negative_sizes_are_errors():
    # extrude() of a solid extrudes each face (test_derive_operations.py); taper() has no
    # such reading
    with pytest.raises(bgr.BgrError, match="already 3D"):
        bgr.derive(bgr.load("Lot --> extrude(1) taper(2, 0.5)\n"))
    # extrude(-1) is CGA's extrusion against the normal (tests/test_scope_frames.py), but a
    # taper is still a height
    with pytest.raises(bgr.BgrError, match="negative height"):
        bgr.derive(bgr.load("Lot --> taper(-1, 0.5)\n"))
    with pytest.raises(bgr.BgrError, match="negative size"):
        bgr.derive(bgr.load("Lot --> s(-1, 1, 1)\n"))


def test_missing_asset_is_reported_at_its_declaration(tmp_path):
    f = tmp_path / "a.bgr"
    f.write_text('asset col = "nope.glb"\nLot --> i(col)\n')
    with pytest.raises(bgr.BgrError, match="asset file 'nope.glb' not found") as e:
        bgr.derive(bgr.load(f))
    assert e.value.line == 1


def test_terminal_paths_follow_the_derivation():
    t = bgr.derive(
        bgr.load("Lot --> extrude(3) comp(f) { top: Roof | side: Wall }\nterminal Roof, Wall\n")
    ).terminals
    assert t.path[0] == "Lot/Roof.0" and t.path[1] == "Lot/Wall.1"


def test_scope_origin_is_read_in_the_frame_of_the_shape_it_was_cut_from():
    src = "Lot --> split(x) { { 2: P }* }\nP --> s(scope.x + 1, '1, '1) X\nterminal X\n"
    t = bgr.derive(bgr.load(src), lot=(6, 1)).terminals
    assert [s[0] for s in t.size] == [1, 3, 5]


def test_terminals_come_depth_first_in_child_order():
    src = "Lot --> [ t(1, 0, 0) A ] T\nA --> X Y\nterminal T, X, Y\n"
    assert bgr.derive(bgr.load(src)).terminals.label == ["X", "Y", "T"]


def test_a_rule_that_only_places_children_in_brackets_is_no_terminal():
    src = "Cluster --> [ t(0, 0, 0) Tower ] [ t(12, 0, 0) r(0, 90, 0) Tower ]\nterminal Tower\n"
    assert bgr.derive(bgr.load(src)).terminals.label == ["Tower", "Tower"]


def test_computed_percentages_are_checked_when_they_run():
    with pytest.raises(bgr.BgrError, match="over 100%"):
        bgr.derive(bgr.load("attr p = 70\nLot --> (p)%: A | (p)%: A\nterminal A\n"), seed=5)


def test_rand_in_an_attr_is_drawn_per_lot_and_not_per_path_spelling(tmp_path):
    f = tmp_path / "r.bgr"
    f.write_text("attr h = rand(1, 100)\nLot --> s('1, h, '1) X\nterminal X\n")
    a = bgr.derive(bgr.load(f), seed=2).terminals.size[0][1]
    b = bgr.derive(bgr.load(str(tmp_path / "." / "r.bgr")), seed=2).terminals.size[0][1]
    assert a == b
