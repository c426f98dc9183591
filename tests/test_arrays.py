"""CGA's arrays: literals, items, size/index/splitString, str() as CityEngine prints them,
errors at their place, the formatter's round trip, and import-cga of Esri's array packages."""

import io
import json

import pytest

import bgr
from bgr.cga.files import translate_file
from bgr.formats import write_json
from bgr.grammar.formatter import format_module
from bgr.grammar.parser import parse


def value(expr: str, prelude: str = ""):
    """What ``expr`` is, reported by a one-rule grammar."""
    grammar = bgr.load(f'{prelude}Lot --> report("v", {expr}) NIL\n')
    (lot,) = bgr.derive(grammar, lot=(4, 4)).reports
    entry = lot["reports"]["v"]
    return entry["sum"] if "sum" in entry else next(iter(entry["values"]))


@pytest.mark.parametrize(
    "expr, expected",
    [
        ("[1, 2, 3][1]", 2),
        ('["brick", "stone"][0]', "brick"),
        ("[true, false][1]", "false"),
        ("size([4, 5, 6])", 3),
        ("size([])", 0),
        ('size("abc")', 3),
        ("index([4, 5, 6], 6)", 2),
        ("index([4, 5, 6], 7)", -1),
        ('splitString("a;b;c", ";")[2]', "c"),
        ('size(splitString("a;b;c;", ";"))', 3),
        ("str([1, 2.5, 3])", "(3)[1,2.5,3]"),
        ("a[a[0]]", 3),
    ],
)
def test_array_expressions(expr, expected):
    assert value(expr, prelude="attr a = [2, 0, 3]\n") == expected


@pytest.mark.parametrize(
    "expr, message",
    [
        ('[1, "a"]', "one kind of value, not numbers and strings"),
        ("[1, 2][2]", "index 2 is outside the array's 2 items"),
        ("[1, 2][-1]", "index -1 is outside"),
        ("[1, 2][0.5]", "index 0.5 is outside"),
        ("3[0]", "only an array has items"),
        ('splitString("a", "")', "non-empty separator"),
    ],
)
def test_what_is_wrong_is_an_error_at_its_place(expr, message):
    with pytest.raises(bgr.BgrError, match=message) as e:
        value(expr)
    assert e.value.diagnostics[0].line == 1


def test_an_array_where_a_number_goes_is_an_error_not_a_crash():
    with pytest.raises(bgr.BgrError, match=r"extrude\(\) needs a finite number, got an array"):
        bgr.derive(bgr.load("attr h = [3, 4]\nLot --> extrude(h) A\nterminal A\n"), lot=(4, 4))


@pytest.mark.parametrize(
    "step, message",
    [
        # an array is a tuple, as a relative size is ("rel", f): neither may pass for the other
        ("setback(h) { all: A | remainder: A }", r"setback\(\) needs a finite number"),
        ("s(h, 1, 1)", r"s\(\) needs a finite number"),
        ("s('h, 1, 1)", r"s\(\) needs a finite number"),
        ("roof(gable, h)", r"roof\(\) needs a finite number"),
        ("i(cube) r(0, h, 0)", r"r\(\) needs a finite number"),
        ("color(h)", r"color\(\) takes one value, got an array"),
        ("label(h)", r"label\(\) takes one value, got an array"),
        ("material(h)", r"material\(\) takes one value, got an array"),
    ],
)
def test_an_array_is_no_operations_single_value(step, message):
    src = f"attr h = [3, 4]\nLot --> {step} A\nterminal A\n"
    with pytest.raises(bgr.BgrError, match=message):
        bgr.derive(bgr.load(src), lot=(4, 4))


def test_arrays_pick_sizes_and_reach_the_terminal_lists_attrs():
    src = """attr heights = [3, 4.5, 6]
terminal A
Lot --> split(x) { 4: extrude(heights[split.index % size(heights)]) A }*
"""
    result = bgr.derive(bgr.load(src), lot=(16, 4))
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=result.seed, attrs=result.attrs)
    doc = json.loads(buffer.getvalue())
    assert [t["size"][1] for t in doc["terminals"]] == [3.0, 4.5, 6.0, 3.0]
    assert doc["attrs"]["heights"] == [3.0, 4.5, 6.0]


def test_the_formatter_writes_them_back():
    text = "attr a = [1, 2, 3]\nattr b = (a[0] + 1) * [2][0]\nLot --> extrude(a[size(a) - 1]) A\n"
    once = format_module(parse(text))
    assert "[1, 2, 3]" in once and "a[size(a) - 1]" in once
    assert format_module(parse(once)) == once


def test_set_back_per_edge_takes_an_array_item_by_item():
    src = """terminal Yard, Building
Lot --> setbackPerEdge([5, 1, 3]) { all: Yard | remainder: Building }
"""
    result = bgr.derive(bgr.load(src), lot=(20, 10))
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=result.seed, attrs=result.attrs)
    (building,) = [
        t for t in json.loads(buffer.getvalue())["terminals"] if t["label"] == "Building"
    ]
    # front 5, right 1, back 3, and the fourth edge (left) past the array's end: none
    assert building["origin"] == [0.0, 0.0, 5.0] and building["size"] == [19.0, 0.0, 2.0]


def test_import_cga_translates_arrays_and_prints_as_cityengine(tmp_path, capsys):
    """Esri's arrayAttrs package (PyPRT's tests): CityEngine prints these three lines."""
    src = tmp_path / "arrays.cga"
    src.write_text(
        'version "2023.0"\nattr f = [0]\nattr b = [false]\nattr s = ["uhm"]\nattr d = [5, 1]\n'
        'Init --> print("f = " + str(f)) print("b = " + str(b)) print("s = " + str(s))\n'
        "    setback(d) { all = Yard | remainder: Building }\n"
    )
    out = tmp_path / "arrays.bgr"
    result = translate_file(src, out)
    text = result.outputs[out]
    assert "attr f = [0]" in text and "setbackPerEdge(d)" in text
    assert not [w for w in result.warnings if "array" in w.message]
    (lot,) = bgr.derive(bgr.load(text), lot=(10, 10)).terminals.lots
    assert lot["prints"] == ["f = (1)[0]", "b = (1)[false]", "s = (1)[uhm]"]


def test_two_dimensional_arrays_are_reported_and_left_out(tmp_path):
    src = tmp_path / "two.cga"
    src.write_text('version "2023.0"\nattr a = [1, 2; 3, 4]\nInit --> print(a[0, 1])\n')
    result = translate_file(src, tmp_path / "two.bgr")
    assert [w.message for w in result.warnings] == [
        "arrays of two dimensions are not in bgr yet; 0 stands in",
        "an item of a two-dimensional array is not in bgr yet; 0 stands in",
    ]
