"""CGA's resetMaterial() and deleteHoles(), from their reference pages: a material undone
back to a new shape's, and a courtyard filled."""

import io
import json

import pytest

import bgr
from bgr.formats import write_json
from bgr.interpreter.lots import footprint


def rows(src: str, lot=(10, 10)) -> list[dict]:
    result = bgr.derive(bgr.load(src), lot=lot)
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=result.seed, attrs=result.attrs)
    return json.loads(buffer.getvalue())["terminals"]


TEXTURED = """terminal A
Lot --> color("#aa2200") material("brick") set(material.opacity, 0.5) label("Wall")
    setupProjection(0, scope.xz, 2, 2) texture("stdlib/textures/brick.png") projectUV(0) RESET A
"""


def test_reset_material_undoes_colour_material_values_and_textures():
    (row,) = rows(TEXTURED.replace("RESET", "resetMaterial()"))
    assert row["color"] == "#cccccc" and row["material"] is None and "surface" not in row
    assert row["label"] == "Wall"
    (plain,) = rows("terminal A\nLot --> A\n")
    assert row["color"] == plain["color"]
    textured = bgr.derive(bgr.load(TEXTURED.replace("RESET", "")), lot=(10, 10))
    reset = bgr.derive(bgr.load(TEXTURED.replace("RESET", "resetMaterial()")), lot=(10, 10))
    assert len(textured.terminals.tex_rows) == 1 and len(reset.terminals.tex_rows) == 0


COURTYARD = [[(0, 0), (20, 0), (20, 20), (0, 20)]]
HOLE = [(5, 5), (5, 15), (15, 15), (15, 5)]


@pytest.mark.parametrize("fill, area", [("", 400 - 100), ("deleteHoles()", 400)])
def test_delete_holes_fills_a_courtyard(fill, area):
    lot = footprint(COURTYARD[0], holes=[HOLE])
    result = bgr.derive(bgr.load(f"terminal A\nLot --> {fill} A\n"), lot=[lot])
    assert result.mesh.area == pytest.approx(area)


def test_a_solid_without_holes_is_unchanged_and_a_courtyard_block_is_an_error():
    assert rows("terminal A\nLot --> extrude(3) deleteHoles() A\n") == rows(
        "terminal A\nLot --> extrude(3) A\n"
    )
    lot = footprint(COURTYARD[0], holes=[HOLE])
    with pytest.raises(bgr.BgrError, match="of an extrusion with holes is not in bgr yet"):
        bgr.derive(bgr.load("terminal A\nLot --> extrude(3) deleteHoles() A\n"), lot=[lot])
