"""Parameter defaults, keyword arguments, rules handed to parameters, and footprint()
(docs/language.md sections 4 and 8): parsing, layout, checks and derivation."""

import numpy as np
import pytest
from errors_helpers import check

import bgr
from bgr import format_source
from bgr.interpreter.terminals import color_hex


def derive(src, **kw):
    return bgr.derive(bgr.load(src), **kw).terminals


# ---- defaults and keywords -------------------------------------------------------------------


def test_defaults_fill_left_out_parameters_in_order():
    src = (
        "Lot --> A(5) A(5, b = 2) A(a = 1, c = 7)\n"
        "A(a, b = a * 2, c = b + 1) --> s(a, b, c) X\nterminal X\n"
    )
    t = derive(src)
    np.testing.assert_allclose(t.size, [[5, 10, 11], [5, 2, 3], [1, 2, 7]])


def test_default_is_evaluated_on_the_shape_the_rule_receives():
    src = "Lot --> s(6, 0, 4) Half\nHalf(w = scope.sx / 2) --> s(w, 1, 1) X\nterminal X\n"
    np.testing.assert_allclose(derive(src).size[0], [3, 1, 1])


def test_default_uses_its_own_modules_consts(tmp_path):
    (tmp_path / "lib.bgr").write_text("const k = 4\nterminal X\nA(h = k) --> s(1, h, 1) X\n")
    src = 'import "lib.bgr" as lib\nconst k = 99\nLot --> lib.A\n'
    t = bgr.derive(bgr.load(src, path=tmp_path / "main.bgr")).terminals
    np.testing.assert_allclose(t.size[0], [1, 4, 1])


def test_start_rule_with_all_defaults_takes_the_lot():
    t = derive("Lot(h = 7) --> extrude(h) X\nterminal X\n")
    assert t.size[0][1] == pytest.approx(7)


def test_start_rule_with_a_required_parameter_is_a_runtime_error():
    with pytest.raises(bgr.BgrError, match="needs a value for h"):
        derive("Lot(h) --> extrude(h)\n")


def test_keyword_arguments_are_independent_of_order():
    a = derive("Lot --> A(c = 3, a = 1)\nA(a = 0, b = 2, c = 0) --> s(a, b, c) X\nterminal X\n")
    np.testing.assert_allclose(a.size[0], [1, 2, 3])


@pytest.mark.parametrize(
    "src",
    [
        'A(w = 3, d = max(w, 2), c = "#ffffff") --> B(1, x = 2) C\nB(p, x) --> NIL\nterminal C\n',
        "A(w = -1, k = 2 > 1 ? 3 : 4) --> NIL\n",
        "A --> B(x = 1, y = C)\nB(x = 0, y = C) --> y\nterminal C\n",
    ],
)
def test_layout_round_trip(src):
    out = format_source(src)
    assert bgr.parse(out) == bgr.parse(src)
    assert format_source(out) == out


@pytest.mark.parametrize(
    "src, line, column, message, hint",
    [
        ("Lot --> A(b = 1)\nA(a = 0) --> NIL\n", 1, 11, "rule 'A' has no parameter 'b'", None),
        (
            "Lot --> A(wdth = 1)\nA(width = 0) --> NIL\n",
            1,
            11,
            "no parameter 'wdth'",
            "did you mean 'width'",
        ),
        (
            "Lot --> A(1, a = 2)\nA(a = 0) --> NIL\n",
            1,
            14,
            "parameter 'a' of rule 'A' is given twice",
            None,
        ),
        (
            "Lot --> A(b = 2)\nA(a, b = 0) --> NIL\n",
            1,
            9,
            "needs a value for parameter 'a'",
            "A(a, b = 0)",
        ),
        (
            "Lot --> A(1, 2, 3)\nA(a, b = 0) --> NIL\n",
            1,
            9,
            "rule 'A' takes 2 arguments, given 3",
            None,
        ),
        (
            "Lot --> A(a = 1, 2)\nA(a, b = 0) --> NIL\n",
            1,
            18,
            "a positional argument follows a keyword",
            None,
        ),
        ("A(a = 1, b) --> NIL\n", 1, 10, "parameter 'b' has no default but follows one", None),
        ("A(a = b, b = 1) --> NIL\n", 1, 7, "unknown name 'b'", None),
        ("Lot --> extrude(h = 3)\n", 1, 17, "operation 'extrude' takes no keyword arguments", None),
        (
            "Lot --> extrude(max(a = 1, 2))\n",
            1,
            21,
            "function 'max' takes no keyword arguments",
            None,
        ),
        ("Lot --> extrude(B)\nB --> NIL\n", 1, 17, "'B' is a rule, not a value", "R(part = Name)"),
        (
            "Lot --> A(x = B + 1)\nA(x = 0) --> NIL\nB --> NIL\n",
            1,
            15,
            "'B' is a rule, not a value",
            None,
        ),
        ("Lot --> footprint(Q)\n", 1, 19, "unknown footprint kind 'Q'", "rect, L, U"),
        (
            "import stdlib.palette as pal\nLot --> A\nA(c = pal.Brick) --> NIL\n",
            3,
            7,
            "module 'pal' has no rule 'Brick'",
            None,
        ),
    ],
)
def test_check_errors(src, line, column, message, hint):
    check(src, line, column, message, hint)


@pytest.mark.parametrize(
    "src, line, column",
    [
        ("A(x = max(0, min(1, 2))) --> NIL\n", 1, 1),
        ("terminal W\nLot --> W\nTile(\n    w = 1,\n    h = max(1, (2 + 3))\n) --> NIL\n", 3, 1),
    ],
)
def test_defaults_nested_too_deep_are_named(src, line, column):
    check(src, line, column, "nest parentheses more than one level deep", "func")


# ---- rules as parameters ---------------------------------------------------------------------


def test_a_parameter_applies_the_rule_it_holds():
    src = (
        "Lot --> Bay(Red) Bay(Blue) Bay\n"
        "Bay(part = Plain) --> part\n"
        'Red --> color("#ff0000") X\nBlue --> color("#0000ff") X\nPlain --> X\nterminal X\n'
    )
    t = derive(src)
    assert [color_hex(c) for c in t.color] == ["#ff0000", "#0000ff", "#cccccc"]


def test_a_rule_of_another_module_runs_in_its_own_module(tmp_path):
    (tmp_path / "win.bgr").write_text(
        "const w = 2\nterminal Glass\nArched(k = w) --> s(k, 1, 1) Glass\n"
    )
    (tmp_path / "fac.bgr").write_text("Facade(window = Own) --> window\nOwn --> NIL\n")
    src = (
        'import "win.bgr" as win\nimport "fac.bgr" as fac\n'
        "Lot --> fac.Facade(window = win.Arched) fac.Facade(window = Mine)\n"
        "Mine --> s(5, 1, 1) Glass\nterminal Glass\n"
    )
    t = bgr.derive(bgr.load(src, path=tmp_path / "main.bgr")).terminals
    assert t.label == ["Glass", "Glass"]
    np.testing.assert_allclose(t.size[:, 0], [2, 5])


def test_a_held_terminal_is_emitted_with_its_label():
    t = derive("Lot --> A(part = Door)\nA(part = Wall) --> part\nterminal Door, Wall\n")
    assert t.label == ["Door"]


def test_rule_values_pass_through_parameters():
    src = "Lot --> A(Red)\nA(p) --> B(p)\nB(q) --> q\nRed --> X\nterminal X\n"
    assert derive(src).label == ["X"]


def test_a_number_applied_as_a_rule_is_a_located_runtime_error():
    with pytest.raises(bgr.BgrError) as e:
        derive("Lot --> A(3)\nA(p) --> p\n")
    assert (e.value.line, e.value.column) == (2, 10)
    assert "parameter 'p' is applied as a rule but holds the value 3" in e.value.message


def test_a_held_rule_the_arguments_do_not_fit_is_a_runtime_error():
    with pytest.raises(bgr.BgrError, match="takes 1 argument, given 0 \\(held by parameter 'p'\\)"):
        derive("Lot --> A(B)\nA(p) --> p\nB(h) --> NIL\n")


def test_a_parameter_named_like_an_operation_applies_its_rule_with_keywords():
    """`roof(pitch = 30)` with a parameter `roof` is the held rule, `roof(hip, 30)` the op."""
    src = (
        "Lot(roof = Gable) --> extrude(5) comp(f) { top: roof(pitch = 30) | all: NIL }\n"
        "Gable(pitch = 10) --> s(1, pitch, 1) X\nterminal X\n"
    )
    t = derive(src)
    assert t.label == ["X"] and t.size[0][1] == pytest.approx(30)


def test_a_held_rule_takes_keyword_arguments():
    src = "Lot --> A(B)\nA(p) --> p(h = 4)\nB(w = 1, h = 1) --> s(w, h, 1) X\nterminal X\n"
    np.testing.assert_allclose(derive(src).size[0], [1, 4, 1])


# ---- footprint -------------------------------------------------------------------------------


def _area(src, lot=(20, 10)):
    r = bgr.derive(bgr.load(src), lot=lot)
    return r.mesh


@pytest.mark.parametrize(
    "kind, args, area",
    [
        ("rect", "", 1.0),
        ("L", ", 0.4, 0.5", 0.5 + 0.4 * 0.5),
        ("U", ", 0.25, 0.5", 0.5 + 2 * 0.25 * 0.5),
        ("T", ", 0.4, 0.3", 0.3 + 0.4 * 0.7),
        ("cross", ", 0.4, 0.2", 0.4 + 0.2 - 0.4 * 0.2),
        ("circle", ", 64", np.pi / 4 * (64 / (2 * np.pi)) * np.sin(2 * np.pi / 64)),
    ],
)
def test_footprint_areas_and_volumes(kind, args, area):
    """An extruded footprint is a closed prism whose volume is the outline's area x height."""
    mesh = _area(f"Lot --> footprint({kind}{args}) extrude(3) X\nterminal X\n")
    mesh.merge_vertices()
    assert mesh.is_watertight
    assert mesh.volume == pytest.approx(20 * 10 * area * 3, rel=1e-6)


def test_footprint_front_face_is_on_the_lot_front_edge():
    src = (
        "Lot --> footprint(L, 0.3, 0.4) extrude(5) comp(f) { front: F | side: S | top: NIL | "
        "bottom: NIL }\n"
        "terminal F, S\n"
    )
    t = derive(src, lot=(20, 10))
    assert t.label.count("F") == 1
    i = t.label.index("F")
    assert t.size[i][0] == pytest.approx(20)
    assert t.label.count("S") == 5


def test_footprint_takes_hip_roofs_on_l_shapes():
    mesh = _area("Lot --> footprint(L, 0.4, 0.4) comp(f) { all: roof(hip, 45) }\n", lot=(20, 20))
    assert mesh.bounds[1][1] == pytest.approx(0.4 * 20 / 2, rel=1e-6)


@pytest.mark.parametrize(
    "src, message",
    [
        ("Lot --> footprint(U, 0.6)\n", "needs 0 < a < 0.5"),
        ("Lot --> footprint(L, 0.2, 1.5)\n", "needs 0 < b < 1"),
        ("Lot --> footprint(circle, 2)\n", "3 to 1024 sides"),
        ("Lot --> extrude(3) footprint(L)\n", "needs a 2D shape"),
    ],
)
def test_footprint_bad_values_are_runtime_errors(src, message):
    with pytest.raises(bgr.BgrError, match=message):
        derive(src)
