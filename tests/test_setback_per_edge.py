"""setbackPerEdge(distance): CGA's setback with its distance evaluated once per edge, the edge
as the current shape (its scope.sx the edge's length, comp.sel its selector word, comp.index
its number round the outline), and import-cga's setback(comp(fe) { ... }) written as one."""

import io
import json
from pathlib import Path

import pytest

import bgr
from bgr.cga.files import translate_file
from bgr.formats import write_json


def rows(src: str, lot=(20, 10), seed: int = 0) -> list[dict]:
    result = bgr.derive(bgr.load(src), lot=lot, seed=seed)
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=result.seed, attrs=result.attrs)
    return json.loads(buffer.getvalue())["terminals"]


def areas(terminals: list[dict]) -> dict[str, float]:
    out: dict[str, float] = {}
    for t in terminals:
        out[t["label"]] = out.get(t["label"], 0.0) + t["size"][0] * t["size"][2]
    return out


HEAD = "terminal Yard, Building\n"


def test_each_edge_its_own_distance_by_its_selector():
    src = HEAD + (
        'Lot --> setbackPerEdge(comp.sel == "front" ? 5 : 2) { all: Yard | remainder: Building }'
    )
    (building,) = [t for t in rows(src) if t["label"] == "Building"]
    assert building["origin"] == [2.0, 0.0, 5.0] and building["size"] == [16.0, 0.0, 3.0]
    assert areas(rows(src))["Yard"] == pytest.approx(20 * 10 - 16 * 3)


def test_the_edge_is_the_current_shape():
    """Only the long edges (scope.sx 20 m) are set back."""
    src = HEAD + "Lot --> setbackPerEdge(scope.sx > 15 ? 3 : 0) { all: Yard | remainder: Building }"
    (building,) = [t for t in rows(src) if t["label"] == "Building"]
    assert building["origin"] == [0.0, 0.0, 3.0] and building["size"] == [20.0, 0.0, 4.0]


def test_one_distance_for_every_edge_is_setback():
    per_edge = HEAD + "Lot --> setbackPerEdge(2) { front: Yard | remainder: Building }"
    plain = HEAD + "Lot --> setback(2) { front: Yard | remainder: Building }"
    assert rows(per_edge) == rows(plain)


def test_a_random_distance_is_drawn_per_edge():
    """The reference's "setback vs. setbackPerEdge": rand(5) once for all edges, or once for
    each."""
    src = (
        "terminal Red, Blue, Green\n"
        "Lot --> {op}(rand(5)) {{ front: Red | back: Blue | left: Green }}"
    )
    depth = {}
    for op in ("setback", "setbackPerEdge"):
        strips = rows(src.format(op=op), seed=3)
        front = next(t for t in strips if t["label"] == "Red")["size"][2]
        back = next(t for t in strips if t["label"] == "Blue")["size"][2]
        depth[op] = (front, back)
    assert depth["setback"][0] == pytest.approx(depth["setback"][1])
    assert depth["setbackPerEdge"][0] != pytest.approx(depth["setbackPerEdge"][1])


def test_a_negative_distance_is_an_error_at_its_place():
    with pytest.raises(bgr.BgrError, match="distance -1 is negative"):
        rows(HEAD + "Lot --> setbackPerEdge(comp.index - 1) { all: Yard | remainder: Building }")


def test_a_string_distance_is_a_check_error():
    with pytest.raises(bgr.BgrError, match="must be a number"):
        bgr.load(HEAD + 'Lot --> setbackPerEdge("far") { all: Yard | remainder: Building }')


def test_import_cga_writes_comp_fe_distances_as_setback_per_edge(tmp_path: Path):
    src = tmp_path / "lot.cga"
    src.write_text(
        'version "2014.0"\n'
        "Lot --> setback(comp(fe) { front = 5 | side = 3 | all = 1 }) "
        "{ all = Yard | remainder: Building }\n"
    )
    out = tmp_path / "lot.bgr"
    result = translate_file(src, out)
    text = result.outputs[out]
    assert "setbackPerEdge(" in text and "NIL" not in text
    (building,) = [t for t in rows(text) if t["label"] == "Building"]
    # front 5, left and right 3, back 1 on the 20 x 10 lot
    assert building["origin"] == [3.0, 0.0, 5.0] and building["size"] == [14.0, 0.0, 4.0]
