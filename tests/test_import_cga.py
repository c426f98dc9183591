"""bgr import-cga: CityEngine CGA rule files translated into grammars that check and derive.

The CGA snippets here are written for these tests in CGA's documented syntax; the real rule
files from Esri's public rule packages are read from ../shared/data/cga when it is there.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import bgr
from bgr.cga.files import translate_file
from bgr.cga.parse import parse
from bgr.grammar.errors import BgrError

SHARED_CGA = Path(__file__).resolve().parents[2] / "shared" / "data" / "cga"


def _import(tmp_path: Path, text: str, name: str = "rules.cga"):
    src = tmp_path / name
    src.write_text(text, encoding="utf-8")
    out = tmp_path / "out" / (src.stem + ".bgr")
    out.parent.mkdir(exist_ok=True)
    result = translate_file(src, out)
    for path, body in result.outputs.items():
        path.write_text(body, encoding="utf-8")
    return out, result


def _derive(out: Path, **kw):
    grammar = bgr.load(out)
    return bgr.derive(grammar, lot=kw.pop("lot", (40.0, 30.0)), **kw)


def _labels(result) -> dict[str, int]:
    counts: dict[str, int] = {}
    for label in result.terminals.label:
        counts[label] = counts.get(label, 0) + 1
    return counts


def test_rules_cases_and_choices_translate_and_derive(tmp_path):
    out, result = _import(
        tmp_path,
        """version "2014.0"
attr height = 12
const floorH = case height > 10: 3 else: 4
@StartRule
Lot --> extrude(height) comp(f) { top: Roof | side: Facade }
Facade --> split(y) { ~floorH: Floor }*
Floor -->
    case split.index == 0 && !(scope.sx < 1): Ground
    case split.index > 0 || false: 50%: Upper else: Upper
    else: NIL
Ground --> color("#aa0000")
Upper --> color(pow(0.5, 1), 0.5, 0.5)
Roof --> Roof.
""",
    )
    assert result.warnings == []
    text = out.read_text()
    assert "start Lot" in text and "terminal RoofLeaf" in text
    assert "and not scope.sx < 1" in text and "0.5 ** 1" in text
    assert "height > 10 ? 3 : 4" in text
    # the case branch that is a stochastic choice became a rule of its own
    assert "Floor_1 -->" in text and "50%: Upper" in text
    labels = _labels(_derive(out))
    assert labels["Ground"] == 4  # one ground floor per side
    assert labels["Upper"] == 4 * 3  # 12 m of 3 m floors: three more per side
    assert labels["RoofLeaf"] == 1


def test_overloaded_rules_get_a_name_each(tmp_path):
    out, result = _import(
        tmp_path,
        """Lot --> Box(3) Box
Box(h) --> extrude(h) Solid
Box --> extrude(1) Solid
Solid --> color(0, 0, 1)
""",
    )
    assert result.warnings == []
    text = out.read_text()
    assert "Box --> extrude(1) Solid" in text and "Box_1(h) --> extrude(h) Solid" in text
    assert "Lot --> Box_1(3) Box" in text
    heights = sorted(float(h) for h in _derive(out).terminals.size[:, 1])
    assert heights == pytest.approx([1.0, 3.0])


def test_offset_sign_and_selectors(tmp_path):
    out, result = _import(
        tmp_path,
        """Lot --> offset(-2) comp(f) { inside: Inner | border: Frame }
Inner --> offset(-1, inside) Core
Core --> color(1, 1, 1)
Frame --> color(0, 0, 0)
""",
    )
    assert result.warnings == []
    text = out.read_text()
    assert "offset(2) { inside: Inner | border: Frame }" in text
    assert "offset(1) { inside: Core }" in text
    derived = _derive(out)
    core = [k for k, label in enumerate(derived.terminals.label) if label == "Core"]
    assert len(core) == 1
    assert derived.terminals.size[core[0], 0] == pytest.approx(40 - 2 * 3)


def test_an_attr_that_reads_the_shape_is_set_when_the_start_rule_begins(tmp_path):
    out, result = _import(
        tmp_path,
        """attr area = geometry.area
attr height = area / 100
Lot --> extrude(height) report("h", height)
""",
    )
    assert [w.line for w in result.warnings] == [1, 2]
    assert all("reads the shape" in w.message for w in result.warnings)
    derived = _derive(out)
    assert derived.reports[0]["reports"]["h"]["sum"] == pytest.approx(40 * 30 / 100)


def test_what_bgr_lacks_is_reported_at_its_place_and_left_out(tmp_path):
    out, result = _import(
        tmp_path,
        """Lot --> setPivot(xyz, 0)
    extrude(10)
    comp(f) { front: Front | side: Side }
Front --> comp(h) { all: Edge }
Side --> softenNormals(30) color(case inside(all): 1 else: 0, 0, 0)
Edge --> color(1, 0, 0)
""",
    )
    found = {(w.line, w.column): w.message for w in result.warnings}
    assert "setPivot" in found[(1, 9)]
    assert "comp(h)" in found[(4, 11)]
    assert "softenNormals" in found[(5, 10)]
    labels = _labels(_derive(out))
    assert "Edge" not in labels and labels["Side"] == 3  # comp(h) stood as NIL


def test_assets_beside_the_file_and_missing_ones(tmp_path):
    assets = tmp_path / "assets" / "parts"
    assets.mkdir(parents=True)
    (assets / "post.obj").write_text(
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 1\nf 1 2 3\nf 1 3 4\n", encoding="utf-8"
    )
    (tmp_path / "rules").mkdir()
    out, result = _import(
        tmp_path,
        """Lot --> [ i("parts/post.obj") Post ] [ t(5, 0, 0) i("parts/gone.obj") Gone ]
    i("builtin:cube") Cube
""",
        name="rules/posts.cga",
    )
    assert [w.message for w in result.warnings if "gone.obj" in w.message]
    text = out.read_text()
    assert 'asset post = "../assets/parts/post.obj"' in text
    assert "i(post) Post" in text and "i(cube) Gone" in text
    grammar = bgr.load(out, allow_paths=[tmp_path / "assets"])
    labels = _labels(bgr.derive(grammar, lot=(4.0, 4.0)))
    assert labels == {"Post": 1, "Gone": 1, "Cube": 1}


def test_comments_are_kept(tmp_path):
    out, _ = _import(
        tmp_path,
        """/* A file header,
 * two lines. */
// the start
Lot --> extrude(3) # and a trailing note
""",
    )
    text = out.read_text()
    assert "# A file header," in text and "# two lines." in text
    assert "# the start" in text and "# and a trailing note" in text
    assert text.index("# the start") < text.index("Lot -->")


def test_a_floating_repeat_may_vanish_where_a_floating_piece_fills_the_scope(tmp_path):
    # Candler's Windows(1): the group of window and divider gets no repetition, one window
    out, _ = _import(
        tmp_path,
        """Lot --> extrude(5) comp(f) { front: Windows(1) }
Windows(n) --> split(x) { { ~scope.sx/n: Window | 0.25: Wall }* | ~scope.sx/n: Window }
Window --> color(0, 0, 1)
Wall --> color(1, 1, 1)
""",
    )
    assert _labels(_derive(out)) == {"Window": 1}
    # a group with nothing else floating beside it keeps its one repetition
    g = bgr.load("version 1\nterminal A\nLot --> split(x) { { ~30: A }* }")
    assert len(bgr.derive(g, lot=(4.0, 4.0)).terminals) == 1


def test_an_item_that_does_not_parse_is_left_out_and_named(tmp_path):
    # syntax this reader does not know (scatter's block of one sequence): that rule is left out
    # with a warning at its line, the rest is translated and derives; its successor a leaf
    out, result = _import(
        tmp_path,
        """Lot --> extrude(3) comp(f) { top: Trees | side: Wall }
Trees -->
    scatter(surface, 10, uniform) { Tree }
Wall --> color(1, 1, 1)
""",
    )
    (warning,) = result.warnings
    assert (warning.line, warning.column) == (3, 42)
    assert "the item on lines 2-3 is left out" in warning.message
    assert _labels(_derive(out)) == {"Trees": 1, "Wall": 4}


def test_a_file_that_does_not_parse_at_all_is_an_error_at_its_place(tmp_path):
    src = tmp_path / "bad.cga"
    src.write_text("  Lot --> extrude(3\n", encoding="utf-8")
    with pytest.raises(BgrError) as e:
        translate_file(src, tmp_path / "bad.bgr")
    d = e.value.diagnostics[0]
    assert (d.path, d.line, d.column) == (str(src), 1, 19)
    assert d.message == "unexpected end of the file"


def test_cli_writes_the_grammar_and_strict_writes_nothing(tmp_path):
    src = tmp_path / "box.cga"
    src.write_text("Lot --> extrude(3) softenNormals(30) Box\nBox --> color(1,0,0)\n")
    out = tmp_path / "box.bgr"
    cmd = [sys.executable, "-m", "bgr", "import-cga", str(src)]
    strict = subprocess.run([*cmd, "-o", str(out), "--strict"], capture_output=True, text=True)
    assert strict.returncode == 1 and not out.exists()
    assert f"{src}:1:20: error: softenNormals() is not in bgr yet" in strict.stderr
    done = subprocess.run([*cmd, "-o", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert f"{src}:1:20: warning:" in done.stderr and "1 construct not translated" in done.stderr
    assert "Traceback" not in done.stderr + strict.stderr
    check = subprocess.run([sys.executable, "-m", "bgr", "check", str(out)], capture_output=True)
    assert check.returncode == 0
    refused = subprocess.run([*cmd[:-1], str(out)], capture_output=True, text=True)
    assert refused.returncode == 1 and "not a .cga file" in refused.stderr


@settings(max_examples=150, deadline=None)
@given(
    st.text(
        alphabet=st.sampled_from(list("Lot-->(){}[]|:~'*%=\"#/ \n.,@!&1x_caseelsNIL")), max_size=80
    )
)
def test_any_text_parses_or_is_a_located_error(text):
    try:
        parse(text, "fuzz.cga")
    except BgrError as e:
        assert e.diagnostics[0].path == "fuzz.cga"


@pytest.mark.skipif(not SHARED_CGA.is_dir(), reason="needs ../shared/data/cga")
@pytest.mark.parametrize(
    "name", sorted(p.name for p in SHARED_CGA.glob("*.cga")) if SHARED_CGA.is_dir() else []
)
def test_esri_rule_files_import_and_derive_on_a_40_by_30_lot(tmp_path, name):
    out = tmp_path / (Path(name).stem.split("__")[-1] + ".bgr")
    result = translate_file(SHARED_CGA / name, out)
    for path, body in result.outputs.items():
        path.write_text(body, encoding="utf-8")
    grammar = bgr.load(out)
    derived = bgr.derive(grammar, lot=(40.0, 30.0))
    assert len(derived) > 0, name
    json.dumps([w.message for w in result.warnings])  # the report is plain text


def test_comp_sel_names_the_selector_that_took_the_face(tmp_path):
    # CGA's comp.sel, as Candler's SubLedge reads it: the ledge is widened toward its corner
    out, result = _import(
        tmp_path,
        """Lot --> extrude(3) comp(f) { front: Face | left: Face | right: Face | top: Face }
Face --> case comp.sel == "left": L
    case comp.sel == "right": R
    else: Other
L --> color(1, 0, 0)
R --> color(0, 1, 0)
Other --> color(0, 0, 1)
""",
    )
    assert result.warnings == []
    assert _labels(_derive(out)) == {"L": 1, "R": 1, "Other": 2}
    grammar = bgr.load(
        "version 1\nLot --> extrude(3) comp(f) { side: A | face(5): A }\nA --> label(comp.sel)"
    )
    labels = list(bgr.derive(grammar, lot=(4.0, 4.0)).terminals.label)
    assert labels == ["side"] * 4 + ["face"]


_PIECES = st.sampled_from(
    [
        "Lot", "A", "B(1)", "-->", "extrude(3)", "split(x){", "}", "}*", "|", "~1:", "'0.5:",
        "2:", "comp(f){", "side:", "top:", "case", "else:", "30%:", "NIL", "[", "]",
        "color(1,0,0)", "attr h = 3", "const c = 2", "f(x) = x*2", "h", "f(h)",
        "geometry.area", "scope.sx", ">", "+", "(", ")", ",", "\n", "@Range(1,2)", "A.",
        'i("builtin:cube")', "offset(-1)", "inside:", "border:", "s('1,'1,0.2)", "t(0,0,1)",
        "roofHip(30)", "set(h, 2)", '"s"', "rand(1,2)", "&&", "!",
    ]
)  # fmt: skip


@settings(max_examples=60, deadline=None)
@given(st.lists(_PIECES, max_size=30))
def test_whatever_is_read_is_written_as_a_grammar_that_checks(tmp_path_factory, pieces):
    # CGA-like text from CGA's own words: it is an error at its place, or it becomes a grammar
    # that bgr checks without an error (and that derives, or stops with a located error)
    folder = tmp_path_factory.mktemp("fuzz")
    src = folder / "x.cga"
    src.write_text(" ".join(pieces), encoding="utf-8")
    try:
        result = translate_file(src, folder / "x.bgr")
    except BgrError as e:
        assert e.diagnostics[0].path == str(src)
        return
    for path, text in result.outputs.items():
        path.write_text(text, encoding="utf-8")
    grammar = bgr.load(folder / "x.bgr")
    try:
        bgr.derive(grammar, lot=(10.0, 10.0), max_shapes=2000)
    except BgrError as e:
        assert e.diagnostics[0].line > 0 or e.diagnostics[0].message


def test_imports_are_followed_and_translated_beside_the_grammar(tmp_path):
    (tmp_path / "windows.cga").write_text(
        "attr frame = 0.1\nWindow --> offset(-frame) comp(f) { inside: Glass | border: Frame }\n"
        'Glass --> report("frame", frame) color(0, 0, 1)\nFrame --> color(1, 1, 1)\n',
        encoding="utf-8",
    )
    out, result = _import(
        tmp_path,
        'import win : "windows.cga"\n'
        "Lot --> extrude(3) comp(f) { front: win.Window | side: Wall }\n"
        "Wall --> color(0.5, 0.5, 0.5)\n",
    )
    assert result.warnings == []
    assert 'import "windows.bgr" as win' in out.read_text()
    assert (out.parent / "windows.bgr").is_file()
    derived = _derive(out)
    assert _labels(derived) == {"Glass": 1, "Frame": 1, "Wall": 3}
    assert derived.reports[0]["reports"]["frame"]["sum"] == pytest.approx(0.1)
    # with an attribute binding: the imported attr takes the importer's value
    out3, result3 = _import(
        tmp_path,
        'attr border = 0.3\nimport win : "windows.cga" (frame = border * 2)\n'
        "Lot --> extrude(3) comp(f) { front: win.Window }\n",
        name="bound.cga",
    )
    assert result3.warnings == [] and "set(win.frame, border * 2)" in out3.read_text()
    assert _derive(out3).reports[0]["reports"]["frame"]["sum"] == pytest.approx(0.6)
    # a missing import: its rules become leaves, with a warning at the import's line
    out2, result2 = _import(
        tmp_path,
        'import roof : "/ESRI.lib/rules/Roofs/Roof_Textures.cga"\nLot --> roof.Generate\n',
        name="other.cga",
    )
    assert [w.line for w in result2.warnings] == [1]
    assert _labels(_derive(out2)) == {"roof_Generate": 1}


def test_find_with_two_arguments_finds_the_first(tmp_path):
    out, result = _import(
        tmp_path, 'attr zone = "Urban Corridor"\nLot --> report("at", find(zone, "Corridor"))\n'
    )
    assert result.warnings == [] and 'find(zone, "Corridor", 0)' in out.read_text()
    assert _derive(out).reports[0]["reports"]["at"]["sum"] == 6.0


def test_r_about_the_scope_centre_turns_in_place(tmp_path):
    # CGA's r(scopeCenter, 0, 90, 0): a 4 x 2 box turned about its centre keeps that centre
    out, result = _import(
        tmp_path, 'Lot --> s(4, 1, 2) i("builtin:cube") r(scopeCenter, 0, 90, 0) Box\n'
    )
    assert result.warnings == []
    bounds = _derive(out).mesh.bounds
    assert np.allclose(bounds.mean(axis=0)[[0, 2]], [2.0, 1.0])  # the centre stays
    assert np.allclose(bounds[1] - bounds[0], [2.0, 1.0, 4.0])  # turned a quarter


@pytest.mark.parametrize(
    "call, bounds",
    [  # the reference's example: 10 x 15 x 20 in the xz centre of the 40 x 30 lot, on y = 0
        ("primitiveCube(10, 15, 20)", [[15, 0, 5], [25, 15, 25]]),
        # sizes from attrs; a negative width spans the same, a negative height reaches down
        ("primitiveCube(w, -1, 3)", [[19, -1, 13.5], [21, 0, 16.5]]),
    ],
)
def test_a_sized_primitive_cube_stands_in_the_xz_centre_of_the_scope(tmp_path, call, bounds):
    out, result = _import(tmp_path, f"attr w = -2\nLot --> {call} Box\n")
    assert result.warnings == []
    assert np.allclose(_derive(out).mesh.bounds, bounds)


def test_a_style_becomes_a_grammar_that_sets_its_attrs_and_overrides_its_rules(tmp_path):
    out, result = _import(
        tmp_path,
        """attr wall = "#888888"
attr h = 6
Lot --> extrude(h) color(wall) Mass
Mass --> Block.
style Red
attr wall = "#cc0000"
attr h = h * 2
Mass --> case h > 10 : s('1, '0.5, '1) Half. else : NIL
Tower --> NIL
""",
    )
    styled = out.with_name("rules.Red.bgr")
    assert styled.is_file()
    text = styled.read_text()
    assert 'set(base.wall, "#cc0000")' in text and "set(base.h, base.h * 2)" in text
    assert "base.Mass --> case base.h > 10:" in text  # the style's rule overrides the file's
    # a rule the file does not have is left out, said where
    assert [w.line for w in result.warnings] == [9]
    plain, red = _derive(out), _derive(styled)
    assert list(plain.terminals.label) == ["Block"]
    assert np.allclose(plain.terminals.color[0], [0x88 / 255] * 3, atol=1e-3)
    assert list(red.terminals.label) == ["Half"]
    assert np.allclose(red.terminals.color[0], [0xCC / 255, 0, 0], atol=1e-3)
    assert red.terminals.size[0][1] == pytest.approx(6.0)  # 12 m, halved by the style's Mass


def test_same_distance_setbacks_shapes_and_edges_translate(tmp_path):
    # envelope2002's forms: setback(comp(fe) { all: d }) is setback(d); shapeL/U/O with their
    # blocks; comp(e) with roof selectors; envelope along world.up
    out, result = _import(
        tmp_path,
        """Lot --> shapeL(8, 6) { shape: Building | remainder: Yard }
Building --> setback(comp(fe) { all : 2 }) { all : Rim | remainder : Core }
Core --> extrude(9) comp(f) { top : Roof }
Roof --> roofHip(30) comp(e) { ridge : Bar Ridge. | eave : Bar Eave. }
Bar --> s('1, 0.2, 0.2) center(yz) primitiveCube()
Rim --> envelope(world.up, 3, 1, 45) Rim.
Yard --> color(0, 1, 0) Yard.
""",
    )
    assert [w.message for w in result.warnings] == []
    text = out.read_text()
    assert "setback(2) { all: Rim | remainder: Core }" in text
    assert "shapeL(8, 6) { shape: Building | remainder: Yard }" in text
    labels = _labels(_derive(out))
    # an L's hip roof: a bar on each of its two ridges and six eaves (the bare edges
    # themselves, Ridge. and Eave., make nothing, as in CityEngine); eight strips round the L
    assert labels["Bar"] == 2 + 6 and "Ridge" not in labels
    assert labels["RimLeaf"] == 8 and labels["YardLeaf"] == 1


def test_nil_in_the_middle_of_a_sequence_lets_the_rest_run(tmp_path):
    # CGA's NIL is a successor that makes nothing: envelope2002's
    # comp(f) { top: report(..) NIL report(..) NIL } reports twice
    out, _ = _import(
        tmp_path,
        'Lot --> extrude(3) comp(f) { top: report("a", 1) NIL report("b", 2) NIL }\n'
        'X --> NIL report("c", 3)\n',
    )
    text = out.read_text()
    assert 'report("a", 1) report("b", 2) NIL' in text
    assert 'X --> report("c", 3) NIL' in text
    (lot,) = _derive(out).reports
    assert {k: v["sum"] for k, v in lot["reports"].items()} == {"a": 1, "b": 2}


def test_an_asset_path_built_from_strings_picks_among_the_files_beside(tmp_path):
    assets = tmp_path / "assets"
    assets.mkdir()
    tri = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n"
    (assets / "tree1.obj").write_text(tri)
    (assets / "tree2.obj").write_text(tri + "v 0 1 0\nf 1 3 4\n")
    out, result = _import(tmp_path, 'attr n = 1\nLot --> i("assets/tree" + n + ".obj") Tree.\n')
    assert [w.message for w in result.warnings if "not found" in w.message] == []
    grammar = bgr.load(out, allow_paths=[tmp_path])
    for n, triangles in ((1, 1), (2, 2), (3, 12)):  # no tree3.obj: a box of the scope
        derived = bgr.derive(grammar, lot=(4.0, 4.0), attrs={"n": n})
        assert len(derived.mesh.faces) == triangles


@pytest.mark.parametrize(
    "args, height",
    [
        ("", 20.0),  # CGA propagates the importer's attr of the same name
        ("(height)", 10.0),  # a listed name is protected
        ("()", 10.0),  # empty brackets protect every attr
        ("(height = 7)", 7.0),  # a value given to it
        ("(floors)", 20.0),  # another attr listed: height still propagates
    ],
)
def test_import_propagates_attrs_of_the_same_name(tmp_path, args, height):
    rules = tmp_path / "rules"
    rules.mkdir()
    (rules / "imp.cga").write_text("attr height = 10\nattr floors = 2\nLot --> extrude(height)\n")
    (rules / "main.cga").write_text(
        f'import imp : "imp.cga" {args}\nattr height = 20\n@StartRule\nLot --> imp.Lot\n'
    )
    out = tmp_path / "out" / "main.bgr"
    out.parent.mkdir()
    result = translate_file(rules / "main.cga", out)
    for path, text in result.outputs.items():
        path.write_text(text, encoding="utf-8")
    derived = _derive(out, lot=(4.0, 4.0))
    assert derived.mesh.bounds[1][1] == pytest.approx(height)


@pytest.mark.parametrize(
    "call, origin, size",
    [  # the reference's example (radius 10, height 15), and a radius computed from an attr
        ("primitiveCylinder(8, 10, 15)", (10.0, 0.0, 5.0), (20.0, 15.0, 20.0)),
        ("primitiveCylinder(8, r + 1, 3)", (18.5, 0.0, 13.5), (3.0, 3.0, 3.0)),
    ],
)
def test_a_sized_cylinder_stands_in_the_xz_centre_of_the_scope(tmp_path, call, origin, size):
    out, result = _import(tmp_path, f'version "2014.0"\nattr r = 0.5\nLot --> {call}\n')
    assert not result.warnings
    derived = _derive(out)
    assert derived.terminals.origin[0].tolist() == pytest.approx(origin)
    assert derived.terminals.size[0].tolist() == pytest.approx(size)


def test_extrude_along_world_y_is_world_up_without_a_warning(tmp_path):
    out, result = _import(
        tmp_path, "Lot --> extrude(world.y, 3) Mass\nA --> extrude(world.x, 3) B\n"
    )
    assert "extrude(world.up, 3)" in out.read_text()
    assert [w.line for w in result.warnings] == [2]  # world.x is still erected along world.up
