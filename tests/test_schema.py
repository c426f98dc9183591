"""bgr infer --kind schema (issue 5): Build-by-Number face, floor and model schemas.

Round trips (derive -> infer -> derive at the source size gives the same labels in the same order
and sizes within 1e-6 m), retargeting against a direct computation of the paper's application
rule, floor configurations the source lacked, and the command line."""

from __future__ import annotations

import io
import json
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import bgr
from bgr.cli import main
from bgr.formats import write_json
from bgr.inverse.schema import faces as fs
from bgr.inverse.schema import infer, read_model

DATA = ROOT / "tests" / "data" / "schema"
SOURCES = sorted(DATA.glob("*.bgr"))


def terminals(result) -> list[dict]:
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=0, attrs={})
    return json.loads(buffer.getvalue())["terminals"]


def source(path: Path):
    return bgr.derive(bgr.load(path.read_text(encoding="utf-8"), path=path))


def style(result) -> bgr.Grammar:
    return bgr.load(bgr.format_module(infer(result)))


def lot_of(model, tmp_path: Path):
    """The lot that re-creates the source: its rectangle, or its footprint as GeoJSON."""
    block = model.sorted_blocks()[0]
    if len(block.footprint) == 4:
        return (block.width, block.depth)
    ring = [[x, -z] for x, z in block.footprint]
    geo = {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "properties": {},
                "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]},
            }
        ],
    }
    path = tmp_path / "lot.geojson"
    path.write_text(json.dumps(geo))
    return str(path)


def by_face(terms: list[dict]) -> dict:
    """Terminals grouped by the plane they lie in, each group in derivation order."""
    out: dict = {}
    for t in terms:
        normal = np.round(t["axes"][2], 6)
        key = (tuple(normal), round(float(np.dot(t["origin"], normal)), 6))
        out.setdefault(key, []).append(t)
    return out


# ---- round trips -----------------------------------------------------------------------------


def test_there_are_at_least_ten_varied_sources():
    assert len(SOURCES) >= 10


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: p.stem)
def test_round_trip_at_the_source_size(path, tmp_path):
    src = source(path)
    model = read_model(src)
    assert len(model.blocks) == 1, "one mass per source"
    a = terminals(src)
    b = terminals(bgr.derive(style(src), lot=lot_of(model, tmp_path)))
    assert len(a) == len(b)
    if len(model.blocks[0].footprint) == 4:  # a rectangle: the same terminals in the same order
        assert [t["label"] for t in a] == [t["label"] for t in b]
        np.testing.assert_allclose([t["size"] for t in a], [t["size"] for t in b], atol=1e-6)
        np.testing.assert_allclose([t["origin"] for t in a], [t["origin"] for t in b], atol=1e-6)
    else:  # a footprint lot starts its faces elsewhere: the same faces, each the same inside
        fa, fb = by_face(a), by_face(b)
        assert set(fa) == set(fb)
        for key in fa:
            assert [t["label"] for t in fa[key]] == [t["label"] for t in fb[key]]
            np.testing.assert_allclose(
                [t["size"] for t in fa[key]], [t["size"] for t in fb[key]], atol=1e-6
            )


def test_inferred_grammar_is_canonical_and_checks():
    src = source(DATA / "shopfront.bgr")
    text = bgr.format_module(infer(src))
    assert bgr.format_source(text) == text
    grammar = bgr.load(text)
    assert "height" in grammar.attrs


# ---- retargeting -----------------------------------------------------------------------------

PIERS = """\
attr W = 20
terminal Pier, Wall, Window
Lot --> s(W, 0, 10) extrude(6) comp(f) { front: Front | side: Pier | top: NIL | bottom: NIL }
Front --> split(x) { 1.5: Pier | { ~2: Wall | 1.2: Window }* | ~2: Wall | 1.5: Pier }
"""

PAIRS = """\
attr W = 8.4
terminal Wall, Window, Pier
Lot --> s(W, 0, 10) extrude(6) comp(f) { front: Front | side: Pier | top: NIL | bottom: NIL }
Front --> split(x) {
    ~1: Wall | ~1: Wall | 1.2: Window | ~1: Wall | ~1: Wall | 1.2: Window | ~1: Wall | ~1: Wall
}
"""


def _front_columns(model):
    face = next(f for f in model.faces() if f.name == "Front")
    return face.root.parts


@pytest.mark.parametrize(
    "src, pattern", [(PIERS, "A(BC)*BA"), (PAIRS, "A(AB)*A(AB)*AA")], ids=["piers", "pairs"]
)
@pytest.mark.parametrize("factor", [1.5, 0.7, 2.3])
def test_retargeting_follows_the_papers_application_rule(src, pattern, factor):
    """The inferred schema on a face `factor` times as wide repeats each group and scales the
    stretchable columns exactly as a direct computation of the paper's rule says."""
    result = bgr.derive(bgr.load(src))
    model = read_model(result)
    columns = _front_columns(model)
    keys = [f"{c.key()}@{round(c.size, 4)}" for c in columns]
    symbols = fs.symbols(keys)
    items = fs.rewrite(symbols)
    assert fs.to_text(items, symbols) == pattern
    width = sum(c.size for c in columns)
    # the paper's rule with the interpreter's floor (docs/inverse-schema.md)
    counts, scale = fs.retarget(
        items,
        [c.size for c in columns],
        [c.fixed for c in columns],
        width * factor,
        minimum=_floor(items, columns),
    )

    grammar = style(result)
    target = terminals(bgr.derive(grammar, lot=(width * factor, 10)))
    front = [t for t in target if "FrontFacade" in t["path"]]
    assert sum(t["label"] == "Window" for t in front) == sum(
        c
        for c, st in zip(counts, fs.stars(items), strict=True)
        if "Window" in (columns[st.first_index].label, columns[st.second_index].label)
    ) + sum(1 for it in items if isinstance(it, fs.Sym) and columns[it.index].label == "Window")
    stretched = [
        (t["size"][0], c)
        for t, c in zip(front, _expanded(items, counts, columns), strict=True)
        if not c.fixed
    ]
    for got, column in stretched:
        assert got == pytest.approx(column.size * scale, abs=1e-6)
    assert sum(t["size"][0] for t in front) == pytest.approx(width * factor, abs=1e-6)


def _expanded(items, counts, columns):
    return [columns[i] for i in fs.expand(items, counts)]


# ---- floor configurations the source lacked ------------------------------------------------------

L_LOT = [[0, 0], [24, 0], [24, -10], [10, -10], [10, -20], [0, -20]]
U_LOT = [[0, 0], [30, 0], [30, -20], [22, -20], [22, -8], [8, -8], [8, -20], [0, -20]]


@pytest.mark.parametrize("ring", [L_LOT, U_LOT], ids=["L", "U-double-inner-corner"])
def test_a_box_schema_styles_every_face_of_an_l_and_a_u(ring, tmp_path):
    src = source(DATA / "shopfront.bgr")
    model = read_model(src)
    assert {f.category for f in model.faces()} == {("outer", "outer")}
    geo = {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "properties": {},
                "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]},
            }
        ],
    }
    lot = tmp_path / "lot.geojson"
    lot.write_text(json.dumps(geo))
    out = terminals(bgr.derive(style(src), lot=str(lot)))
    faces = by_face(out)
    vertical = {k: v for k, v in faces.items() if abs(k[0][1]) < 0.5}
    planes = {
        (a[0] == b[0], a[0] if a[0] == b[0] else a[1])
        for a, b in zip(ring, ring[1:] + ring[:1], strict=True)
    }
    assert len(vertical) == len(
        planes
    )  # every side face got terminals (coplanar faces share a key)
    for key, terms in vertical.items():
        labels = Counter(t["label"] for t in terms)
        assert len(labels) >= 2, f"face {key} is not styled: {labels}"


# ---- command line ------------------------------------------------------------------------------


def test_cli_writes_a_grammar_that_derives(tmp_path, capsys):
    src = DATA / "palazzo.bgr"
    terms = tmp_path / "t.json"
    assert main(["derive", str(src), "-o", str(terms)]) == 0
    out = tmp_path / "style.bgr"
    assert main(["infer", str(terms), "--kind", "schema", "-o", str(out)]) == 0
    assert main(["check", str(out)]) == 0
    assert main(["derive", str(out), "--lot", "40,18", "-o", str(tmp_path / "x.glb")]) == 0
    # a .bgr input is derived first; standard output by default
    capsys.readouterr()
    assert main(["infer", str(src)]) == 0
    assert "\nversion 1\n" in capsys.readouterr().out


def test_cli_fixed_and_stretch_change_the_schema(tmp_path, capsys):
    src = DATA / "palazzo.bgr"
    assert main(["infer", str(src), "--stretch", "Window"]) == 0
    stretched = capsys.readouterr().out
    assert main(["infer", str(src)]) == 0
    default = capsys.readouterr().out
    assert stretched != default
    assert main(["infer", str(src), "--fixed", "Wall", "--stretch", "Wall"]) == 2


@pytest.mark.parametrize(
    "content, message",
    [
        ("{", "not valid JSON"),
        ('{"x": 1}', "neither a terminal list nor a captured model"),
        ('{"terminals": [{"label": "A"}]}', "terminals[0].path"),
        ('{"terminals": []}', "empty"),
        (
            (
                '{"terminals": [{"label": "A", "path": "Lot", "origin": [0, 0, 0], '
                '"axes": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "size": [1, 1, "x"]}]}'
            ),
            "terminals[0].size",
        ),
    ],
)
def test_cli_bad_inputs_exit_1_with_the_element_named(tmp_path, capsys, content, message):
    bad = tmp_path / "bad.json"
    bad.write_text(content)
    out = tmp_path / "style.bgr"
    assert main(["infer", str(bad), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not out.exists()


def test_cli_kind_image_asks_for_the_outline_then_refuses_a_grammar(capsys, tmp_path):
    assert main(["infer", str(DATA / "palazzo.bgr"), "--kind", "image"]) == 1
    assert "--kind image needs the building's outline" in capsys.readouterr().err
    outline = tmp_path / "sil.json"
    outline.write_text("[[1, 1], [9, 1], [9, 9]]")
    args = ["infer", str(DATA / "palazzo.bgr"), "--kind", "image", "--silhouette", str(outline)]
    assert main(args) == 1
    err = capsys.readouterr().err
    assert "cannot read the photograph" in err and "Traceback" not in err


def test_cli_kind_style_refuses_a_grammar_saying_what_it_reads(capsys):
    assert main(["infer", str(DATA / "palazzo.bgr"), "--kind", "style"]) == 1
    err = capsys.readouterr().err
    assert "palazzo.bgr: error: bgr infer --kind style reads a textured model" in err
    assert "hint:" in err


# ---- fuzz: no input gives a traceback ----------------------------------------------------------


_JSON = st.recursive(
    st.none() | st.booleans() | st.floats(allow_nan=True) | st.integers() | st.text(max_size=5),
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=20,
)


def _only_bgr_errors(data) -> None:
    try:
        text = bgr.format_module(infer(data))
    except bgr.BgrError:
        return
    bgr.load(text)  # what is written always parses and checks


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_JSON)
def test_fuzz_random_json_raises_only_bgr_errors(data):
    _only_bgr_errors(data if isinstance(data, dict) else {"terminals": data})


_SMALL = terminals(
    bgr.derive(
        bgr.load(
            "terminal W, N\nLot --> s(6, 0, 4) extrude(3) comp(f) { side: split(x) { ~1: W | 1: N "
            "| ~1: W }* | all: NIL }\n"
        )
    )
)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_fuzz_mutated_terminal_lists_raise_only_bgr_errors(data):
    terms = json.loads(json.dumps(_SMALL))
    for _ in range(data.draw(st.integers(1, 4))):
        t = terms[data.draw(st.integers(0, len(terms) - 1))]
        key = data.draw(st.sampled_from(["label", "path", "origin", "axes", "size"]))
        t[key] = data.draw(
            st.one_of(
                _JSON,
                st.lists(st.floats(-1e9, 1e9), min_size=3, max_size=3),
                st.sampled_from(
                    [
                        "",
                        "Lot",
                        "Lot/A.0",
                        "Lot//",
                        "/",
                        "W",
                        "shop-window",
                        "split",
                        "NIL",
                        "1st",
                        "é",
                        [[0, 0, 0]] * 3,
                        [[1, 0, 0], [0, 0, 1], [0, 1, 0]],
                    ]
                ),
            )
        )
    _only_bgr_errors({"terminals": terms})


def test_captured_example_grammar_is_current_and_restyles_an_l_lot():
    """examples/captured/corner_shop.bgr is what bgr infer writes for corner_shop.json, and it
    derives on the example's L-shaped lot."""
    folder = ROOT / "examples" / "captured"
    text = bgr.format_module(infer(folder / "corner_shop.json"))
    committed = (folder / "corner_shop.bgr").read_text(encoding="utf-8")
    assert text.split("\n", 1)[1] == committed.split("\n", 1)[1], (
        "rerun: bgr infer examples/captured/corner_shop.json -o examples/captured/corner_shop.bgr"
    )
    result = bgr.derive(
        bgr.load(committed), lot=str(folder / "l_lot.geojson"), attrs={"height": 18.8}
    )
    assert len(result) > 200


def test_floor_schema_prefers_the_face_with_fewest_occluded_subfaces():
    """Third criterion: two schemas alike in corners, side and width -> the less occluded one."""
    from bgr.inverse.schema.emit import Emitter
    from bgr.inverse.schema.model import Block, Cell, Face, Model

    def face(label, occluded, x_axis, origin):
        leaf = Cell(4.0, label, occluded=occluded)
        root = Cell(10.0, axis="x", parts=[Cell(3.0, "Wall"), leaf, Cell(3.0, "Wall")])
        return Face(
            10.0,
            4.0,
            root,
            left="outer",
            right="outer",
            name=label,
            origin=origin,
            x_axis=x_axis,
            normal=(-x_axis[2], 0.0, x_axis[0]),
        )

    faces = [
        face("Hidden", True, (0.0, 0.0, 1.0), (10.0, 0.0, 0.0)),  # normal (-1, 0, 0): left
        face("Seen", False, (0.0, 0.0, -1.0), (0.0, 0.0, 10.0)),
    ]  # normal (1, 0, 0): right
    for f in faces:
        f.normal = (0.0, 0.0, 1.0)  # both face the back: same side, same corners, same width
    model = Model([Block("b", faces, 10, 10, 4)])
    text = bgr.format_module(Emitter(model).module())
    grammar = bgr.load(text)
    labels = bgr.derive(grammar, lot=(10, 10)).terminals.label
    assert "Seen" in labels and "Hidden" not in labels


@pytest.mark.parametrize(
    "name, blocks", [("house.bgr", 1), ("stdlib_street.bgr", 1), ("tower.bgr", 3)]
)
def test_grammars_with_3d_parts_give_one_face_per_wall(name, blocks):
    """Recessed glass, frames, sills and reveals at right angles belong to the wall they are set
    in: the shipped examples (3D windows, roofs, setbacks) give closed rings of whole walls."""
    model = read_model(ROOT / "examples" / name)
    assert len(model.blocks) == blocks
    for block in model.blocks:
        assert len(block.faces) == 4
        assert all(f.left != "free" and f.right != "free" for f in block.faces)
    grammar = bgr.load(bgr.format_module(infer(ROOT / "examples" / name)))
    assert len(bgr.derive(grammar, lot=(30, 16))) > 50


# ---- review cases: GeoJSON lots, gaps, touching lots, ties between groups -----------------------

FRONT_DOOR = """\
terminal Wall, Door, Window
Lot --> extrude(8) comp(f) { front: F | side: Wall | top: NIL | bottom: NIL }
F --> split(x) {
    ~1: Wall | 1.2: split(y) { 2.4: Door | ~1: Wall } | { ~1: Wall | 1.2: Window }* | ~1: Wall
}
"""


def _geojson(tmp_path, rings) -> str:
    geo = {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "properties": {},
                "geometry": {"type": "Polygon", "coordinates": [r + [r[0]]]},
            }
            for r in rings
        ],
    }
    path = tmp_path / "lots.geojson"
    path.write_text(json.dumps(geo))
    return str(path)


def _same(src_result, grammar, lot) -> None:
    a, b = terminals(src_result), terminals(bgr.derive(grammar, lot=lot))
    assert [t["label"] for t in a] == [t["label"] for t in b]
    np.testing.assert_allclose([t["size"] for t in a], [t["size"] for t in b], atol=1e-6)
    np.testing.assert_allclose([t["origin"] for t in a], [t["origin"] for t in b], atol=1e-6)


@pytest.mark.parametrize(
    "rings",
    [
        [
            [[0, 0], [16, 0], [16, 14], [0, 14]],
            [[20, 0], [34, 0], [34, 14], [20, 14]],
            [[38, 2], [52, 0], [54, 14], [38, 14]],
        ],  # three lots, one a trapezoid: fronts face south
        [
            [[0, 0], [10, 0], [10, 12], [0, 12]],
            [[10, 0], [20, 0], [20, 12], [10, 12]],
        ],  # touching lots
    ],
    ids=["geojson", "touching"],
)
def test_round_trip_on_geojson_lots_keeps_each_face_on_its_side(rings, tmp_path):
    """Sides are read in each lot's frame (a GeoJSON lot's front faces +z), and faces of two
    lots that touch are two buildings."""
    lot = _geojson(tmp_path, rings)
    src = bgr.derive(bgr.load(FRONT_DOOR), lot=lot)
    model = read_model(src)
    assert len(model.blocks) == len(rings)
    assert all(len(b.faces) == 4 for b in model.blocks)
    _same(src, style(src), lot)


@pytest.mark.parametrize(
    "front",
    [
        # a door shorter than its column
        "split(x) { { ~1: Wall | 1.2: split(y) { 2.5: Door } | ~1: Wall }* }",
        (
            "split(x) { 1: Pier | 1.5: Window | 1: Pier | 1.5: Window | 1: Pier | 1.5: Window | 1: "
            "Pier | 2: Door "
            "| 1: Pier | 1.5: Window | 1: Pier | 1.5: Window | 1: Pier | ~1: Wall }"
        ),  # bays, a door, bays
    ],
)
def test_round_trip_of_nested_gaps_and_tied_groups(front):
    src_text = (
        "terminal Wall, Window, Door, Pier\n"
        "Lot --> s(17, 0, 10) extrude(4) comp(f) "
        f"{{ front: {front} | side: Wall | top: NIL | bottom: NIL }}\n"
    )
    src = bgr.derive(bgr.load(src_text))
    text = bgr.format_module(infer(src))
    _same(src, bgr.load(text), (17, 10))
    if "Pier" in front:
        assert "}*" in text  # the two groups of bays still repeat


def test_a_face_with_an_edge_gap_is_kept():
    """A gap at the edge of a face narrows it (its extent is its terminals'), but the face stays a
    face of the mass: its schema is not lost."""
    src = bgr.derive(
        bgr.load(
            "terminal Wall, Window\n"
            "Lot --> s(20, 0, 12) extrude(6) comp(f) { front: F | side: Wall | top: NIL | bottom: "
            "NIL }\n"
            "F --> split(x) { 1: Wall | 1: Wall | 1: Wall | 2: Window | 1: Wall | 1: Wall | 1.5: "
            "Wall }\n"
        )
    )
    model = read_model(src)
    assert model.dropped == 0 and len(model.faces()) == 4
    out = terminals(bgr.derive(style(src), lot=(20, 12)))
    assert any(t["label"] == "Window" for t in out)


def test_terminal_list_lists_each_lot_with_its_frame(tmp_path):
    """`lots` in the terminal list: the path each lot's terminals start with, and its axes."""
    rings = [[[0, 0], [10, 0], [10, 12], [0, 12]], [[10, 0], [20, 0], [20, 12], [10, 12]]]
    buffer = io.StringIO()
    write_json(
        bgr.derive(bgr.load(FRONT_DOOR), lot=_geojson(tmp_path, rings)).terminals,
        buffer,
        seed=0,
        attrs={},
    )
    data = json.loads(buffer.getvalue())
    lots = data["lots"]
    assert [lot["path"] for lot in lots] == ["Lot.0", "Lot.1"]
    assert {t["path"].split("/")[0] for t in data["terminals"]} == {"Lot.0", "Lot.1"}
    np.testing.assert_allclose(
        lots[0]["axes"][2], [0, 0, -1], atol=1e-12
    )  # into the lot: north is -z


def _floor(items, columns) -> int:
    """The split solver's least repetitions per group: 0 where a stretchable column outside the
    groups can take the length (as CGA), else 1 (docs/language.md, rule 3)."""
    outside = [it.index for it in items if isinstance(it, fs.Sym)]
    return 0 if any(not columns[i].fixed for i in outside) else 1
