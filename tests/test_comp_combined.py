"""comp(f) { side = A }: CGA's '=' operator, the faces a selector takes as one shape, which a
later comp(f) gives back one by one (the Parthenon's cornice: `top = comp(f) { 0: .. | 1: .. }`)."""

import io
import json

import pytest

import bgr
from bgr.cga.files import translate_file
from bgr.formats import write_json
from bgr.grammar.formatter import format_module
from bgr.grammar.parser import parse

SIDES = """terminal Wall, Top
Lot --> extrude(10) comp(f) { side = Facade | top: Top }
Facade --> comp(f) { face(0): color("#ff0000") Wall | face(1): color("#00ff00") Wall | all: Wall }
"""


def rows(src: str, lot=(10, 6)) -> list[dict]:
    result = bgr.derive(bgr.load(src), lot=lot)
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=result.seed, attrs=result.attrs)
    return json.loads(buffer.getvalue())["terminals"]


def test_the_side_faces_are_one_shape_whose_faces_come_back_in_order():
    walls = [t for t in rows(SIDES) if t["label"] == "Wall"]
    assert len(walls) == 4
    # face(0) and face(1) of the combined shape: the first two sides, in the solid's order
    one_by_one = rows(SIDES.replace("side = Facade", "side: Facade"))
    assert [t["color"] for t in walls] == ["#ff0000", "#00ff00", "#cccccc", "#cccccc"]
    assert [t["color"] for t in one_by_one].count("#ff0000") == 4  # each side its own face(0)
    by_origin = {tuple(t["origin"]): t["size"] for t in one_by_one if t["label"] == "Wall"}
    assert {tuple(t["origin"]): t["size"] for t in walls} == by_origin  # the same faces


def test_the_combined_shape_is_its_faces_box_in_the_solids_axes():
    src = "terminal S\nLot --> extrude(10) comp(f) { side = S }\n"
    (shape,) = rows(src)
    assert shape["geometry"] == "polygon" and shape["size"] == [10.0, 10.0, 6.0]
    assert bgr.derive(bgr.load(src), lot=(10, 6)).mesh.area == pytest.approx(2 * (10 + 6) * 10)


def test_equals_outside_comp_f_is_a_check_error():
    with pytest.raises(bgr.BgrError, match="belongs in comp\\(f\\) blocks"):
        bgr.load("Lot --> split(x) { 2 = A }*\nterminal A\n")


def test_the_formatter_keeps_it():
    text = format_module(parse(SIDES))
    assert "side = Facade" in text and format_module(parse(text)) == text


def test_import_cga_writes_equals_in_comp_f(tmp_path):
    src = tmp_path / "c.cga"
    src.write_text('version "2014.0"\nLot --> extrude(10) comp(f) { side = Facade | top : Top }\n')
    result = translate_file(src, tmp_path / "c.bgr")
    assert "side = Facade" in result.outputs[tmp_path / "c.bgr"]
    assert result.warnings == []
