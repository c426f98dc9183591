"""The formatter: canonical layout, comments kept, idempotent, meaning unchanged."""

import pytest
from conftest import SHARED, shipped_grammars

from bgr import format_module, format_source, parse
from bgr.grammar import nodes as n


@pytest.mark.parametrize("path", shipped_grammars(), ids=lambda p: p.name)
def test_every_shipped_grammar_is_formatted(path):
    text = path.read_text(encoding="utf-8")
    assert format_source(text) == text, f"run: bgr fmt -w {path}"


@pytest.mark.parametrize(
    "path", shipped_grammars() + sorted(SHARED.glob("bench/*.bgr")), ids=lambda p: p.name
)
def test_round_trip_and_idempotence_on_real_grammars(path):
    text = path.read_text(encoding="utf-8")
    once = format_source(text)
    assert parse(once) == parse(text)
    assert format_source(once) == once


def test_spacing_is_canonical():
    ugly = (
        "attr   a=1+2*  3\nA-->extrude( a )split(x){3:B|~1 :C}*   [t(0,0,1)B]\n"
        "B-->60 % : C|else:NIL\nC-->NIL"
    )
    assert format_source(ugly) == (
        "attr a = 1 + 2 * 3\n"
        "A --> extrude(a) split(x) { 3: B | ~1: C }* [ t(0, 0, 1) B ]\n"
        "B --> 60%: C | else: NIL\n"
        "C --> NIL\n"
    )


def test_comments_stay_where_they_belong():
    src = (
        "# file header\n"
        "\n"
        "\n"
        "attr h = 3   # metres\n"
        "// the lot\n"
        "Lot --> split(x) {\n"
        "  1: A # left edge\n"
        "  | ~2: B\n"
        "}\n"
        "A --> NIL\n"
        "B --> NIL\n"
        "# end\n"
    )
    assert format_source(src) == (
        "# file header\n"
        "\n"
        "attr h = 3  # metres\n"
        "// the lot\n"
        "Lot --> split(x) {\n"
        "    1: A  # left edge\n"
        "    | ~2: B\n"
        "}\n"
        "A --> NIL\n"
        "B --> NIL\n"
        "# end\n"
    )


def test_long_rules_break_into_one_entry_per_line():
    rule = (
        "Floor --> split(x) { 0.5: WallPieceLeft | { ~3: TileWithWindowAndBalcony }* "
        "| 0.5: WallPieceRight | 0.25: Pilaster }"
    )
    assert format_source(rule) == (
        "Floor --> split(x) {\n"
        "    0.5: WallPieceLeft\n"
        "    | { ~3: TileWithWindowAndBalcony }*\n"
        "    | 0.5: WallPieceRight\n"
        "    | 0.25: Pilaster\n"
        "}\n"
    )
    choice = (
        "Window --> 40%: ArchedWindowWithShutters | 30%: PlainWindowWithSill "
        "| 20%: BalconyDoorWindow | else: NIL"
    )
    assert format_source(choice) == (
        "Window -->\n"
        "    40%: ArchedWindowWithShutters\n"
        "    | 30%: PlainWindowWithSill\n"
        "    | 20%: BalconyDoorWindow\n"
        "    | else: NIL\n"
    )


@pytest.mark.parametrize(
    "text",
    [
        "a - (b - c)",
        "(a - b) - c",
        "a / (b * c)",
        "(-a) ** 2",
        "-a ** 2",
        "2 ** -1",
        "(a or b) and c",
        "not (a and b)",
        "(not a) == b",
        "a + (not b)",
        "(a ? b : c) + 1",
        "(a ? b : c) ? d : e",
        "a ? b : c ? d : e",
        "-(a + b)",
        "-(-a)",
        "x % 2 == 0",
        "(2 ** 3) ** 2",
        "f(-1, 'x)",
    ],
)
def test_expressions_keep_their_meaning(text):
    src = (
        f"attr x = 1\nfunc f(a, b) = a\nattr a = {text}\n"
        if "'" not in text
        else f"A --> s({text[2:-1]}, 0)\n"
    )
    assert parse(format_source(src)) == parse(src)


def test_trees_built_in_code_print_and_parse_back():
    """The inverse modules build trees, not text: the formatter is how they write .bgr."""
    tree = n.Module(
        [
            n.Attr("w", n.Number(-0.25)),
            n.Rule(
                "Facade",
                [],
                n.Sequence(
                    [
                        n.Operation(
                            "split",
                            [n.Name("y")],
                            n.Block(
                                [
                                    n.Entry("abs", n.Number(4), n.Sequence([n.Successor("Shop")])),
                                    n.Group(
                                        [
                                            n.Entry(
                                                "float",
                                                n.Number(3.2),
                                                n.Sequence(
                                                    [n.Successor("Floor", [n.Name("split.index")])]
                                                ),
                                            )
                                        ]
                                    ),
                                ]
                            ),
                        )
                    ]
                ),
            ),
            n.Rule(
                "Shop",
                [],
                n.Stochastic(
                    [
                        n.Choice(n.Number(50), n.Sequence([n.Nil()])),
                        n.Choice(None, n.Sequence([n.Successor("Floor", [n.Number(0)])])),
                    ]
                ),
            ),
            n.Rule("Floor", ["i"], n.Sequence([n.Operation("color", [n.String("#aabbcc")])])),
        ]
    )
    text = format_module(tree)
    assert text == (
        "attr w = -0.25\n"
        "Facade --> split(y) { 4: Shop | { ~3.2: Floor(split.index) }* }\n"
        "Shop --> 50%: NIL | else: Floor(0)\n"
        'Floor(i) --> color("#aabbcc")\n'
    )
    assert parse(text) == tree


def test_numbers_print_exactly():
    for value in [0.1, 1 / 3, 1e-7, 123456789.125, 3.0, -2.5]:
        text = format_module(n.Module([n.Attr("v", n.Number(value))]))
        assert parse(text).items[0].value.value == value


def test_strings_are_escaped():
    tree = n.Module([n.Attr("s", n.String('say "hi"\\\n\t'))])
    assert parse(format_module(tree)) == tree
