"""Rule overriding across imports (``alias.Name --> ...``, CGA's rule overriding): the imported
module's own calls to Name run the importer's rule, for that import only; and its translation
from CGA (bgr import-cga), with the rules an imported CGA file calls without defining."""

import io
import json
from collections import Counter

import pytest

import bgr
from bgr.cga.files import translate_file
from bgr.formats import write_json

LIB = """terminal Window, Wall
Facade --> split(x) { ~3: Tile }*
Tile --> split(y) { ~1: Wall | 1.5: Window | ~1: Wall }
Sill(depth) --> s('1, 0.1, depth) i(cube) SillStone
terminal SillStone
"""


def labels(path, lot=(9, 6), **kw) -> Counter:
    result = bgr.derive(bgr.load(path), lot=lot, **kw)
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=result.seed, attrs=result.attrs)
    return Counter(t["label"] for t in json.loads(buffer.getvalue())["terminals"])


def test_an_override_replaces_the_imported_rule_for_that_import_only(tmp_path):
    (tmp_path / "lib.bgr").write_text(LIB)
    main = tmp_path / "main.bgr"
    main.write_text(
        'import "lib.bgr" as lib\nimport "lib.bgr" as plain\nterminal Glass\n'
        "Lot --> extrude(6) comp(f) { front: lib.Facade | back: plain.Facade }\n"
        'lib.Window --> color("#3355aa") Glass\n'
    )
    # the front's windows are the override's Glass; the back (another import) keeps Window
    assert labels(main) == {"Wall": 12, "Glass": 3, "Window": 3}


def test_an_override_of_a_rule_takes_its_parameters(tmp_path):
    (tmp_path / "lib.bgr").write_text(LIB + "Ledge --> Sill(0.3)\n")
    main = tmp_path / "main.bgr"
    main.write_text(
        'import "lib.bgr" as lib\nterminal Deep\n'
        "Lot --> extrude(6) comp(f) { front: lib.Ledge }\n"
        "lib.Sill(depth) --> s('1, 0.2, depth * 2) i(cube) Deep\n"
    )
    result = bgr.derive(bgr.load(main), lot=(9, 6))
    table = result.terminals.freeze()
    assert list(table.label) == ["Deep"]
    assert table.size[0][2] == pytest.approx(0.6)  # the override ran with the caller's 0.3


@pytest.mark.parametrize(
    "rule, message",
    [
        ("lib.Door --> Glass", "'lib' has no rule or terminal 'Door' to override"),
        ("nope.Tile --> Glass", "'nope.Tile' overrides a rule of 'nope', which is not an import"),
        ("lib.Sill --> Glass", "'lib.Sill' takes 0 parameters, but the rule it overrides takes 1"),
    ],
)
def test_bad_overrides_are_located_errors(tmp_path, rule, message):
    (tmp_path / "lib.bgr").write_text(LIB)
    main = tmp_path / "main.bgr"
    main.write_text(f'import "lib.bgr" as lib\nterminal Glass\nLot --> lib.Facade\n{rule}\n')
    with pytest.raises(bgr.BgrError, match=message.replace("(", r"\(").replace(")", r"\)")):
        bgr.load(main)


def test_formatter_keeps_an_override(tmp_path):
    text = 'import "lib.bgr" as lib\n\nterminal Glass\n\nLot --> lib.Facade\nlib.Window --> Glass\n'
    assert bgr.format_source(text) == text


def test_cga_overrides_and_rules_called_but_not_defined(tmp_path):
    rules = tmp_path / "rules"
    rules.mkdir()
    (rules / "volume.cga").write_text(
        "Mass --> extrude(6) comp(f) { side: Side }\n"
        "Side --> split(x) { ~3: Glazing(1.5) }*\n"  # Glazing is the importer's to give
    )
    (rules / "main.cga").write_text(
        'import volume : "volume.cga"\n'
        "@StartRule\nLot --> volume.Mass\n"
        "volume.Glazing(dist) --> case dist > 1 : color(0,0,1) Glass. else : NIL\n"
    )
    out = tmp_path / "out" / "main.bgr"
    out.parent.mkdir()
    result = translate_file(rules / "main.cga", out)
    for path, text in result.outputs.items():
        path.write_text(text, encoding="utf-8")
    messages = [w.message for w in result.warnings]
    assert any("rule 'Glazing' is not defined in this file" in m for m in messages)
    assert not any("overriding" in m for m in messages)
    # every glazing tile of the four walls runs the override: three on each
    assert labels(out, lot=(10, 8)) == {"Glass": 12}
    # without the override the tiles stay leaves labelled Glazing
    assert labels(out.parent / "volume.bgr", lot=(10, 8)) == {"Glazing": 12}
