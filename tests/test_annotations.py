"""CGA's annotations above attrs and rules (grammar/annotations.py): parsed, printed back by
the formatter, held to the forms CityEngine's reference gives them, handed to tools as plain
values, and without any effect on what is derived."""

from pathlib import Path

import pytest
from conftest import ROOT

import bgr
from bgr.grammar.annotations import SPECS
from bgr.grammar.errors import BgrCheckError, BgrSyntaxError

ANNOTATED = """\
version 1
# storeys
@Range(min = 1, max = 20, stepsize = 1)  # a slider
@Group("Mass", 1)
@Description("storeys above the ground")
attr floors = 4
@Enum("tin", "felt", restricted = false)
attr roofing = "tin"
@Hidden
attr secret = 2
@Range(5, 50)
attr height = 20
@Range(Low = 0, Mid = 1, High = 2)
attr lod = 0
@Color
attr wall = "#a05030"

@StartRule
@Description("the lot")
Lot --> extrude(floors * 3) color(wall) Box
terminal Box
"""


def test_annotations_are_printed_back_as_written():
    assert bgr.format_source(ANNOTATED) == ANNOTATED
    messy = ANNOTATED.replace("min = 1, max = 20", "min=1,max =20").replace(
        '("Mass", 1)', '( "Mass",1 )'
    )
    assert bgr.format_source(messy) == ANNOTATED


def test_the_metadata_tools_read(tmp_path):
    path = tmp_path / "a.bgr"
    path.write_text(ANNOTATED)
    meta = bgr.attr_metadata(bgr.load(path))
    assert list(meta) == ["floors", "roofing", "secret", "height", "lod", "wall"]
    assert meta["floors"] == {
        "default": 4.0,
        "range": {"min": 1.0, "max": 20.0, "stepsize": 1.0},
        "group": ["Mass"],
        "groupOrder": 1.0,
        "description": "storeys above the ground",
    }
    assert meta["roofing"]["enum"] == {"values": ["tin", "felt"], "restricted": False}
    assert meta["secret"]["hidden"] is True and meta["wall"]["color"] is True
    assert meta["height"]["range"] == {"min": 5.0, "max": 50.0}
    assert meta["lod"]["enum"] == {"values": [0.0, 1.0, 2.0], "labels": ["Low", "Mid", "High"]}


def test_annotations_change_nothing_that_is_derived(tmp_path):
    plain = "\n".join(line for line in ANNOTATED.splitlines() if not line.startswith("@"))
    one, two = tmp_path / "one.glb", tmp_path / "two.glb"
    bgr.derive(ANNOTATED, seed=3).save(one)
    bgr.derive(plain, seed=3).save(two)
    assert one.read_bytes() == two.read_bytes()


@pytest.mark.parametrize(
    ("source", "message"),
    [
        ("@Range(min = 10, max = 2)\nattr a = 4\n", "@Range has its min (10) above its max (2)"),
        ("@Range(min = 1, max = 9, stepsize = -1)\nattr a = 4\n", "stepsize is 0 (none) or more"),
        ("@Range(1, 2, 3)\nattr a = 1\n", "@Range takes min = NUMBER"),
        ("@StartRule\nattr b = 1\n", "@StartRule annotates rules, not attrs"),
        ("@Color\nLot --> NIL\n", "@Color annotates attrs, not rules"),
        ('@Order("first")\nattr c = 1\n', "@Order takes one number"),
        ("@Order(1)\n@Order(2)\nattr c = 1\n", "@Order is given twice for attr 'c'"),
        ("@Enum()\nattr d = 1\n", "@Enum takes its values"),
        ("@Enum(1, 2, restricted = 3)\nattr d = 1\n", "restricted is true or false"),
        ("@Description(1)\nattr e = 1\n", "@Description takes one string"),
        ('@Group(1, "a")\nattr f = 1\n', "@Group takes one or more group names"),
        ("@Out(granularity = whole)\nLot --> NIL\n", "separatedShapes or combinedShape"),
        ("@Hidden(1)\nattr g = 1\n", "@Hidden takes nothing, or the names"),
    ],
)
def test_a_wrong_annotation_is_an_error_at_its_line(source, message):
    with pytest.raises(BgrCheckError) as info:
        bgr.load(source + "Start --> NIL\n")
    d = info.value.diagnostics[0]
    assert message in d.message and d.hint.startswith("CGA writes it @")
    assert source.splitlines()[d.line - 1].startswith("@") and d.column == 1


def test_unknown_annotations_and_defaults_outside_the_range_are_warnings():
    grammar = bgr.load("@Foo(1)\nattr a = 1\n@Range(5, 50)\nattr b = 60\n@Enum(1, 2)\nattr c = 3\n"
                       "Lot --> NIL\n")  # fmt: skip
    messages = [w.message for w in grammar.warnings]
    assert messages == [
        "unknown annotation @Foo: kept as metadata, no effect",
        "the default 60 is outside @Range(5, 50)",
        "the default 3.0 is not one of the @Enum values",
    ]
    assert all(w.severity == "warning" for w in grammar.warnings)
    # unrestricted choices let an editor type anything
    assert not bgr.load(
        "@Range(min = 5, max = 50, restricted = false)\nattr b = 60\nLot --> NIL\n"
    ).warnings


def test_an_annotation_stands_above_an_attr_or_a_rule_only():
    with pytest.raises(BgrSyntaxError) as info:
        bgr.load("@Hidden\nconst y = 2\n")
    assert info.value.diagnostics[0].line == 2


def test_every_annotation_is_documented():
    text = (ROOT / "docs" / "language.md").read_text()
    section = text.split("### Annotations", 1)[1].split("\n### ", 1)[0]
    assert [name for name in SPECS if f"@{name}" not in section] == []


def test_real_cga_annotations_parse():
    """Every annotation line of the CGA files in ../shared/data/cga parses in bgr's syntax."""
    folder = ROOT.parent / "shared" / "data" / "cga"
    if not folder.is_dir():
        pytest.skip("../shared/data/cga is not here")
    lines = [
        line.strip()
        for path in sorted(Path(folder).glob("*.cga"))
        for line in path.read_text(errors="replace").splitlines()
        if line.strip().startswith("@")
    ]
    assert lines, "no annotations found"
    for line in lines:
        module = bgr.parse(f"{line}\nattr x = 1\n")
        assert module.items[0].annotations[0].name == line[1:].split("(")[0].strip()
