"""CGA's rotate(mode, coordSystem, x, y, z) and translate(mode, coordSystem, x, y, z), from the
examples of their reference pages: a box turned to a world orientation, and a grid of cubes
whose copies move along the world's or the object's x axis."""

import io
import json
import math

import pytest

import bgr
from bgr.cga.files import translate_file
from bgr.formats import write_json
from bgr.interpreter.lots import footprint


def rows(src: str, lot=(20, 10), seed: int = 0) -> list[dict]:
    result = bgr.derive(bgr.load(src), lot=lot, seed=seed)
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=result.seed, attrs=result.attrs)
    return json.loads(buffer.getvalue())["terminals"]


def close(a, b, tol=1e-9) -> bool:
    return all(math.isclose(x, y, abs_tol=tol) for x, y in zip(a, b, strict=True))


def test_rotate_abs_world_sets_the_scope_to_the_world_angles():
    """The reference's "set scope orientation to world coordinate system angles": whatever
    the lot's orientation, the box ends turned 90 degrees about world y, in place."""
    src = """Init --> r(0, 30, 0) extrude(10) t('0.2, 0, '0.3) s('0.5, '1, '0.5)
    rotate(abs, world, 0, 90, 0) Box
Box --> i(cube)
"""
    (box,) = rows(src)
    x, y, z = box["axes"]
    assert close(x, (0, 0, -1)) and close(y, (0, 1, 0)) and close(z, (1, 0, 0))
    (before,) = rows(src.replace("rotate(abs, world, 0, 90, 0)", ""))
    assert close(box["origin"], before["origin"]) and box["size"] == before["size"]


def test_rotate_rel_scope_is_r_and_abs_world_zero_undoes_any_turn():
    turned = rows("Lot --> r(10, 20, 30) i(cube)")[0]
    same = rows("Lot --> rotate(rel, scope, 10, 20, 30) i(cube)")[0]
    assert turned["axes"] == same["axes"] and turned["origin"] == same["origin"]
    (back,) = rows("Lot --> r(10, 20, 30) rotate(abs, world, 0, 0, 0) i(cube)")
    assert close(back["axes"][0], (1, 0, 0)) and close(back["axes"][1], (0, 1, 0))


def test_rotate_rel_world_turns_about_the_world_axis_not_the_scopes():
    """A scope lying on its side (its y along world x) turned 90 degrees about world y: its y
    goes to world -z; about its own y (r) it would not move."""
    (shape,) = rows("Lot --> r(0, 0, -90) rotate(rel, world, 0, 90, 0) i(cube)")
    assert close(shape["axes"][1], (0, 0, -1))
    (own,) = rows("Lot --> r(0, 0, -90) r(0, 90, 0) i(cube)")
    assert close(own["axes"][1], (1, 0, 0))


GRID = """terminal X
Init --> split(x) { '0.2: split(z) { '0.2: PP }* }*
PP --> 43%: i(cube) s(1, 1, 1) X MOVE color("#ff0000") X
     | else: NIL
"""


@pytest.mark.parametrize("system", ["world", "object"])
def test_translate_rel_moves_copies_along_the_systems_x(system):
    """The reference's grid of cubes: each red copy is its white cube moved 2 m along the
    world's x, or the object's (the lot's scope, turned 30 degrees here)."""
    src = GRID.replace("MOVE", f"translate(rel, {system}, 2, 0, 0)")
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    # a 10 m square whose front edge (the scope's x) runs 30 degrees off world x
    corners = [(0, 0), (10 * c, -10 * s), (10 * c + 10 * s, 10 * c - 10 * s), (10 * s, 10 * c)]
    cubes = rows(src, lot=[footprint(corners)], seed=4)
    white = [c for c in cubes if c["color"] != "#ff0000"]
    red = [c for c in cubes if c["color"] == "#ff0000"]
    assert white and len(white) == len(red) < 25  # the 43 % chance left some cells empty
    step = (2, 0, 0) if system == "world" else (2 * c, 0, -2 * s)
    for w, r in zip(white, red, strict=True):
        moved = [a + b for a, b in zip(w["origin"], step, strict=True)]
        assert close(r["origin"], moved), (w["origin"], r["origin"])
        assert r["axes"] == w["axes"]


def test_translate_abs_puts_the_origin_at_the_point():
    (world,) = rows("Lot --> t(3, 4, 5) translate(abs, world, 1, 2, 3) i(cube)")
    assert close(world["origin"], (1, 2, 3))
    # in the object's system: the lot's scope as the start rule received it, not turned
    (obj,) = rows(
        "Start --> r(0, 90, 0) Lot\nLot --> t(3, 4, 5) translate(abs, object, 1, 0, 0) i(cube)"
    )
    assert close(obj["origin"], (1, 0, 0))  # the start rule received the unturned lot


def test_placed_translates_are_not_replayed_from_another_place():
    """A rule that puts its shape at an absolute place gives the same point for every shape
    that reaches it; a reused subtree would move it with the shape."""
    src = """Lot --> split(x) { 2: Mark }*
Mark --> s(1, 1, 1) translate(abs, world, 0, 5, 0) i(cube)
"""
    marks = rows(src, lot=(10, 4))
    assert len(marks) == 5 and all(close(m["origin"], (0, 5, 0)) for m in marks)


def test_a_bad_word_is_a_check_error_at_its_place():
    with pytest.raises(bgr.BgrError) as e:
        bgr.load("Lot --> rotate(absolute, world, 0, 0, 0) i(cube)")
    assert "absolute" in str(e.value) and "abs" in str(e.value)


def test_import_cga_translates_rotate_and_translate(tmp_path):
    cga = tmp_path / "r.cga"
    cga.write_text(
        'version "2014.0"\nLot --> extrude(5) rotate(rel, world, 0, 45, 0) '
        "translate(rel, object, 1, 0, 0) Mass\n"
    )
    result = translate_file(cga, tmp_path / "r.bgr")
    text = result.outputs[tmp_path / "r.bgr"]
    assert "rotate(rel, world, 0, 45, 0)" in text and "translate(rel, object, 1, 0, 0)" in text
    assert not [w for w in result.warnings if "rotate" in w.message or "translate" in w.message]
    assert rows(text)


def test_r_about_the_scope_centre_keeps_the_centre():
    (box,) = rows("Lot --> s(4, 4, 2) r(scopeCenter, 0, 90, 0) i(cube)")
    x, y, z = box["axes"]
    centre = [box["origin"][k] + 2 * x[k] + 2 * y[k] + 1 * z[k] for k in range(3)]
    assert close(centre, (2, 2, 1)) and close(x, (0, 0, -1))
    (plain,) = rows("Lot --> s(4, 4, 2) r(scopeOrigin, 0, 90, 0) i(cube)")
    assert close(plain["origin"], (0, 0, 0)) and plain["axes"] == box["axes"]


def test_a_bad_pivot_word_is_a_check_error():
    with pytest.raises(bgr.BgrError, match="scopeCenter"):
        bgr.load("Lot --> r(scopeMiddle, 0, 90, 0) i(cube)")
