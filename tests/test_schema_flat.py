"""bgr infer --kind schema on flat façades (issue 9, section 3): faces of any orientation.

A façade derived directly on the lot rectangle (``Lot --> split(x)`` or ``split(z)``, no extrude)
is a face; its schema is written as a grammar that splits the lot itself.  Round trips at the
source size give the same terminals; at other sizes the columns follow the paper's application
rule (computed directly with ``faces.retarget``) and the floors the model schema's one group.
Zero-size faces are skipped, and what is written always derives."""

from __future__ import annotations

import io
import json

import numpy as np
import pytest
from conftest import ROOT

import bgr
from bgr.cli import main
from bgr.formats import write_json
from bgr.inverse.schema import check_derives, infer, read_model, source_lot
from bgr.inverse.schema import faces as fs

DATA = ROOT / "tests" / "data" / "schema"
# (a) bays with fixed trims, (b) shop fronts, (c) floors of bays; trims are fixed by --fixed
FLAT = {
    "flat_bays": {"Trim": True},
    "flat_shopfronts": {},
    "flat_floors": {"Trim": True},
}


def terminals(result) -> list[dict]:
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=0, attrs={})
    return json.loads(buffer.getvalue())["terminals"]


def source(name: str):
    path = DATA / f"{name}.bgr"
    return bgr.derive(bgr.load(path.read_text(encoding="utf-8"), path=path))


def style_text(result, fixed=None) -> str:
    return bgr.format_module(infer(result, fixed=fixed))


def same_terminals(a: list[dict], b: list[dict]) -> None:
    assert [t["label"] for t in a] == [t["label"] for t in b]
    np.testing.assert_allclose([t["size"] for t in a], [t["size"] for t in b], atol=1e-6)
    np.testing.assert_allclose([t["origin"] for t in a], [t["origin"] for t in b], atol=1e-6)


# ---- round trips at the source size ----------------------------------------------------------


@pytest.mark.parametrize("name", FLAT)
def test_flat_facade_round_trips_at_the_source_size(name):
    src = source(name)
    model = read_model(src, fixed=FLAT[name])
    assert model.flat_axes == ("x", "z")  # columns along the lot's x, floors along its z
    assert len(model.faces()) == 1 and model.skipped == 0
    text = style_text(src, FLAT[name])
    assert "extrude" not in text and "attr height" not in text and "comp(" not in text
    assert "\nLot --> split(" in text  # the lot itself is the face
    assert bgr.format_source(text) == text
    same_terminals(terminals(src), terminals(bgr.derive(bgr.load(text), lot=source_lot(model))))


def test_flat_floors_keep_their_floor_structure():
    """Floors split first and bays inside each floor: the floors come back as the lot's rows,
    the middle floors as one repeat group (the model schema), each floor a split of bays."""
    src = source("flat_floors")
    face = read_model(src).faces()[0]
    assert face.root.axis == "y"
    assert [p.label for p in face.root.parts] == [
        "Ground",
        "Trim",
        "Floor",
        "Floor",
        "Floor",
        "Cornice",
    ]
    assert all(p.axis == "x" for p in face.root.parts if p.label in ("Ground", "Floor"))
    text = style_text(src, FLAT["flat_floors"])
    lot = next(line for line in text.splitlines() if line.startswith("Lot -->"))
    assert lot.startswith("Lot --> split(z) {") and "{ ~3.633333333: Floor }*" in lot


def test_flat_facades_of_several_lots_round_trip(tmp_path):
    """Each lot of a GeoJSON source is a façade of its own (lots in one plane are not merged);
    the grammar chooses between their schemas by the lot's width."""
    rings = [[[0, 0], [14, 0], [14, 9], [0, 9]], [[20, 0], [42, 0], [42, 9], [20, 9]]]
    geo = {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "properties": {},
                "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]},
            }
            for ring in rings
        ],
    }
    lots = tmp_path / "lots.geojson"
    lots.write_text(json.dumps(geo))
    src = bgr.derive(bgr.load(FLOORS_FIRST), lot=str(lots))
    model = read_model(src)
    assert len(model.faces()) == 2
    text = style_text(src)
    assert "Lot --> case scope.sx < 18:" in text
    same_terminals(terminals(src), terminals(bgr.derive(bgr.load(text), lot=str(lots))))


# ---- other sizes: the paper's application rule -------------------------------------------------


def _rows(face) -> list[tuple[int, object]]:
    """(row index, cell) of every split of columns: the face itself, or each floor of it."""
    if face.root.axis == "x":
        return [(-1, face.root)]
    return [(i, p) for i, p in enumerate(face.root.parts) if p.axis == "x"]


def _columns_out(out: list[dict], prefix_depth: int, row: int) -> list[tuple[float, float]]:
    """The output's column instances of one row, in order: (x0, x1) of the terminals that share
    a path prefix one level below the row."""
    spans: dict[str, list[float]] = {}
    for t in out:
        parts = t["path"].split("/")
        if row >= 0 and not parts[1].endswith(f".{row}"):
            continue
        key = "/".join(parts[: prefix_depth + 1])
        x0, x1 = t["origin"][0], t["origin"][0] + t["size"][0]
        span = spans.setdefault(key, [x0, x1])
        span[0], span[1] = min(span[0], x0), max(span[1], x1)
    return [tuple(s) for s in spans.values()]


@pytest.mark.parametrize("name", FLAT)
@pytest.mark.parametrize("factor", [1.5, 0.7, 2.3])
def test_flat_facade_retargets_by_the_papers_application_rule(name, factor):
    """On a lot `factor` times as wide, every row of columns repeats its groups and scales its
    stretchable columns exactly as a direct computation of the paper's rule says (with
    LANGUAGE.md's floor of one repetition per group, docs/inverse-schema.md)."""
    src = source(name)
    model = read_model(src, fixed=FLAT[name])
    face = model.faces()[0]
    width, height = source_lot(model)
    out = terminals(bgr.derive(bgr.load(style_text(src, FLAT[name])), lot=(width * factor, height)))
    for row, cell in _rows(face):
        columns = cell.parts
        symbols = fs.symbols(
            [f"{c.key()}@{round(c.size, 4)}{'!' if c.fixed else ''}" for c in columns]
        )
        items = fs.rewrite(symbols)
        assert fs.stars(items), (
            f"{name}: row {row} has no repeat group: {fs.to_text(items, symbols)}"
        )
        counts, scale = fs.retarget(
            items,
            [c.size for c in columns],
            [c.fixed for c in columns],
            width * factor,
            minimum=_floor(items, columns),
        )
        expected = [columns[i] for i in fs.expand(items, counts)]
        got = _columns_out(out, 1 if row < 0 else 2, row)
        assert len(got) == len(expected), (
            f"{name} row {row}: {len(got)} columns, not {len(expected)}"
        )
        x = 0.0
        for (x0, x1), column in zip(got, expected, strict=True):
            size = column.size if column.fixed else column.size * scale
            assert x0 == pytest.approx(x, abs=1e-6) and x1 - x0 == pytest.approx(size, abs=1e-6)
            x += size
        assert x == pytest.approx(width * factor, abs=1e-6)


def _one_group(fixed: float, floating: float, group: float, length: float) -> tuple[int, float]:
    """LANGUAGE.md section 6 rule 3 for one floating repeat group (the paper's rule with one
    group): the count whose scale of the floating sizes is closest to 1, ties to more, at
    least one."""
    best = None
    for count in range(1, 200):
        scale = (length - fixed) / (floating + count * group)
        if best is None or abs(scale - 1) <= abs(best[1] - 1) + 1e-12:
            best = (count, scale)
    return best


@pytest.mark.parametrize("factor", [0.6, 1.4, 2.5])
def test_flat_floors_grow_by_whole_floors(factor):
    """On a lot `factor` times as high the middle floors repeat, the others keep, and the
    floating rows scale alike: the model schema on the lot's rows."""
    src = source("flat_floors")
    model = read_model(src, fixed=FLAT["flat_floors"])
    rows = model.faces()[0].root.parts
    width, height = source_lot(model)
    floor = next(r for r in rows if r.label == "Floor")
    single = [r for r in rows if r.label != "Floor"]
    count, scale = _one_group(
        sum(r.size for r in single if r.fixed),
        sum(r.size for r in single if not r.fixed),
        floor.size,
        height * factor,
    )
    out = terminals(
        bgr.derive(bgr.load(style_text(src, FLAT["flat_floors"])), lot=(width, height * factor))
    )
    spans: dict[str, list[float]] = {}
    for t in out:
        key = "/".join(t["path"].split("/")[:2])
        z0, z1 = t["origin"][2], t["origin"][2] + t["size"][2]
        span = spans.setdefault(key, [z0, z1])
        span[0], span[1] = min(span[0], z0), max(span[1], z1)
    labels = [key.split("/")[1].rsplit(".", 1)[0] for key in spans]
    assert labels == ["Ground", "Trim"] + ["Floor"] * count + ["Cornice"]
    expected = [rows[0], rows[1]] + [floor] * count + [rows[-1]]
    z = 0.0
    for (z0, z1), row in zip(spans.values(), expected, strict=True):
        size = row.size if row.fixed else row.size * scale
        assert z0 == pytest.approx(z, abs=1e-6) and z1 - z0 == pytest.approx(size, abs=1e-6)
        z += size
    assert z == pytest.approx(height * factor, abs=1e-6)


# ---- the failures: floors first on a flat lot, zero-size faces ---------------------------

FLOORS_FIRST = """\
terminal Wall, Window, Pier
Lot --> split(z) { 3: A | ~4: B }
A --> split(x) { 1: Pier | { ~2: Wall | 1.2: Window }* | ~2: Wall | 1: Pier }
B --> split(x) { { ~2: Wall | 1.2: Window }* | ~2: Wall }
"""


def test_inferred_grammar_of_a_flat_lot_derives(tmp_path, capsys):
    """The issue's case: floors split first on the flat lot used to lose the floors and write
    `attr height = 0`, which crashed inside shapely.  Now the floors are the lot's rows and the
    grammar derives back to the source."""
    src_path = tmp_path / "floors.bgr"
    src_path.write_text(FLOORS_FIRST)
    terms = tmp_path / "t.json"
    assert main(["derive", str(src_path), "--lot", "12,9", "-o", str(terms)]) == 0
    out = tmp_path / "style.bgr"
    assert main(["infer", str(terms), "-o", str(out)]) == 0
    text = out.read_text()
    assert "attr height" not in text and "extrude" not in text
    assert "Lot --> split(z) { 3: A | 6: B }" in text
    again = tmp_path / "again.json"
    assert main(["derive", str(out), "--lot", "12,9", "-o", str(again)]) == 0
    capsys.readouterr()
    a = json.loads(terms.read_text())["terminals"]
    b = json.loads(again.read_text())["terminals"]
    same_terminals(a, b)


ZERO_FACE = """\
terminal Wall, Window, Line
Lot --> s(12, 0, 8) extrude(6) comp(f) {
    front: F | left: s('1, 0, 0) Line | side: Wall | top: NIL | bottom: NIL
}
F --> split(x) { 1: Wall | { ~2: Wall | 1.2: Window }* | ~2: Wall | 1: Wall }
"""


def test_a_zero_size_face_is_skipped_cleanly():
    """A face without area (here the left face, squashed to a line) is no face: it is left
    out of the schemas, counted in the header, and the grammar derives."""
    src = bgr.derive(bgr.load(ZERO_FACE))
    model = read_model(src)
    assert model.skipped == 1
    assert len(model.faces()) == 3 and all(f.height > 0 for f in model.faces())
    text = style_text(src)
    assert "Line" not in text.split("\n", 4)[-1]  # not in the grammar, only in the header note
    assert "(1 part of zero size" in text
    result = bgr.derive(bgr.load(text), lot=(12, 8))
    assert "Window" in result.terminals.label and "Line" not in result.terminals.label


@pytest.mark.parametrize(
    "grammar",
    [
        # four walls squashed to height 0 (a prism of height 0 has no side faces at all)
        "terminal W\nLot --> extrude(3) comp(f) { side: s('1, 0, 0) W | all: NIL }\n",
        "terminal W\nLot --> s('1, 0, 0) W\n",  # a lot squashed to a line
    ],
    ids=["squashed-walls", "line-lot"],
)
def test_only_zero_size_faces_is_a_located_error(grammar, tmp_path, capsys):
    terms = tmp_path / "t.json"
    bgr.derive(bgr.load(grammar)).save(terms)
    out = tmp_path / "style.bgr"
    assert main(["infer", str(terms), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "no face with an area" in err and "zero size" in err and "Traceback" not in err
    assert not out.exists()


# ---- what is written always derives -------------------------------------------------------------


def test_a_grammar_that_does_not_derive_is_a_bgr_error(monkeypatch):
    """check_derives turns any failure of the derivation (a BgrError, or a failure inside the
    geometry code) into one BgrError naming the source; infer runs it before returning."""
    src = bgr.derive(bgr.load(FLOORS_FIRST))
    model = read_model(src)
    model.source = "floors.json"
    looping = bgr.parse("Lot --> X\nX --> X\n")
    with pytest.raises(
        bgr.BgrError, match="floors.json: error: the inferred grammar does not derive"
    ):
        check_derives(looping, model)

    import bgr.interpreter.derive as derive_module

    def broken(*args, **kwargs):
        raise ValueError("a ring of three points")

    monkeypatch.setattr(derive_module, "derive", broken)
    with pytest.raises(bgr.BgrError, match="ValueError: a ring of three points"):
        infer(src)


# ---- frames, not axis conventions ------------------------------------------------------------

FRAMED = """\
terminal Wall, Glass, Frame, Sill
Lot --> s(12, 0, 8) extrude(6) comp(f) { front: F | side: Wall | top: NIL | bottom: NIL }
F --> split(y) { { ~3: Floor }* }
Floor --> split(x) { ~1: Wall | { 1.2: Win | ~1.5: Wall }* }
Win --> split(y) { ~1: Wall | 0.08: s('1, '1, 0.2) i(cube) Sill | 1.6: W | ~0.4: Wall }
W --> offset(0.06) { border: extrude(0.08) Frame | inside: t(0, 0, -0.15) Glass }
"""


def _depth_turned(data: dict) -> dict:
    """The same terminal list with every extruded part (a prism) in the other extrude frame:
    x kept, the depth moved from y to z (CGA's extrude, the interpreter's since it follows CGA,
    puts it along y; the interpreter before put it along z), the boxes unchanged."""
    out = json.loads(json.dumps(data))
    for t in out["terminals"]:
        if t["geometry"] != "prism":
            continue
        (x, y, z), (sx, sy, sz) = t["axes"], t["size"]
        t["axes"] = [x, z, [-v for v in y]]
        t["size"] = [sx, sz, sy]
        t["origin"] = [o + sy * v for o, v in zip(t["origin"], y, strict=True)]
    return out


def test_schemas_do_not_depend_on_how_extrude_sets_the_scope():
    """Frames extruded from a wall belong to it whether their depth is along their y (CGA's
    extrude) or along their z (how the interpreter extruded before): the reader reads each
    terminal's own frame, so both terminal lists give the same grammar."""
    buffer = io.StringIO()
    write_json(bgr.derive(bgr.load(FRAMED)).terminals, buffer, seed=0, attrs={})
    data = json.loads(buffer.getvalue())
    turned = _depth_turned(data)
    assert any(t["geometry"] == "prism" for t in data["terminals"])
    assert turned != data
    text = bgr.format_module(infer(data))
    assert bgr.format_module(infer(turned)) == text
    # the frame (and the glass it overlaps, one part) sits in the wall's window column
    assert "Win --> split(y) { ~0.942857143: Wall | ~0.08: Sill | ~1.6: W |" in text
    assert read_model(turned).dropped == 0


def _floor(items, columns) -> int:
    """The split solver's least repetitions per group: 0 where a stretchable column outside the
    groups can take the length (as CGA), else 1 (docs/language.md, rule 3)."""
    outside = [it.index for it in items if isinstance(it, fs.Sym)]
    return 0 if any(not columns[i].fixed for i in outside) else 1
