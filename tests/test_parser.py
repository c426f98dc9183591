"""The parser builds the syntax tree the language reference describes."""

import pytest

import bgr
from bgr.grammar import nodes as n
from bgr.grammar.parser import parse


def body(src: str):
    """The body of the only rule of ``src``."""
    return parse(src).rules()[0].body


def expr(text: str):
    return parse(f"attr a = {text}\n").items[0].value


def test_declarations_of_every_kind():
    m = parse("""version 1
import "lib/w.bgr" as w
import stdlib.palette as pal
attr height = 18
attr style = "brick"
const floor_h = 3.2
func storeys(h) = floor(h / floor_h)
asset column = "assets/column.glb"
terminal Wall, Glass
start Lot
Lot --> NIL
""")
    assert m.items[:10] == [
        n.Version(1),
        n.Import("w", path="lib/w.bgr"),
        n.Import("pal", module="stdlib.palette"),
        n.Attr("height", n.Number(18)),
        n.Attr("style", n.String("brick")),
        n.Const("floor_h", n.Number(3.2)),
        n.Func("storeys", ["h"], n.Call("floor", [n.Binary("/", n.Name("h"), n.Name("floor_h"))])),
        n.Asset("column", "assets/column.glb"),
        n.TerminalDecl(["Wall", "Glass"]),
        n.Start("Lot"),
    ]


def test_rules_need_no_terminator_and_may_span_lines():
    m = parse("A --> B C\nB --> extrude(3)\n   C\nC(x, y) --> NIL")
    assert [r.name for r in m.rules()] == ["A", "B", "C"]
    assert m.rules()[1].body.steps == [n.Operation("extrude", [n.Number(3)]), n.Successor("C")]
    assert m.rules()[2].params == ["x", "y"]


def test_operations_and_successors_are_told_apart_by_the_registry():
    steps = body("A --> extrude(3) Floor(1, 'x) fac.Window NIL [ t(0, 1, 0) B ]").steps
    assert steps == [
        n.Operation("extrude", [n.Number(3)]),
        n.Successor("Floor", [n.Number(1), n.Relative(n.Name("x"))]),
        n.Successor("fac.Window"),
        n.Nil(),
        n.Push([n.Operation("t", [n.Number(0), n.Number(1), n.Number(0)]), n.Successor("B")]),
    ]


def test_split_sizes_groups_and_the_repeat_shorthand():
    op = body("A --> split(x) { 1: E | { ~2: W | '0.1: X }* | 3: E }").steps[0]
    assert op.block == n.Block(
        [
            n.Entry("abs", n.Number(1), n.Sequence([n.Successor("E")])),
            n.Group(
                [
                    n.Entry("float", n.Number(2), n.Sequence([n.Successor("W")])),
                    n.Entry("rel", n.Number(0.1), n.Sequence([n.Successor("X")])),
                ]
            ),
            n.Entry("abs", n.Number(3), n.Sequence([n.Successor("E")])),
        ]
    )
    short = body("A --> split(x) { ~2: W }*").steps[0].block
    assert short.repeat and short.entries == [
        n.Entry("float", n.Number(2), n.Sequence([n.Successor("W")]))
    ]


def test_nested_repeat_groups():
    op = body("A --> split(x) { { 1: B | { ~1: C }* }* }").steps[0]
    outer = op.block.entries[0]
    assert isinstance(outer, n.Group) and isinstance(outer.entries[1], n.Group)


def test_comp_selectors_and_offset_are_entries():
    op = body("A --> comp(f) { front: F | face(2): G | side: S }").steps[0]
    assert [e.key for e in op.block.entries] == [
        n.Name("front"),
        n.Call("face", [n.Number(2)]),
        n.Name("side"),
    ]
    off = body("A --> offset(-0.2) { inside: I | border: B }").steps[0]
    assert off.args == [n.Number(-0.2)] and [e.key.name for e in off.block.entries] == [
        "inside",
        "border",
    ]


def test_stochastic_body():
    b = body("W --> 60%: A | (p * 10)%: B C | else: NIL")
    assert b == n.Stochastic(
        [
            n.Choice(n.Number(60), n.Sequence([n.Successor("A")])),
            n.Choice(
                n.Binary("*", n.Name("p"), n.Number(10)),
                n.Sequence([n.Successor("B"), n.Successor("C")]),
            ),
            n.Choice(None, n.Sequence([n.Nil()])),
        ]
    )


def test_conditional_body():
    b = body("B --> case scope.sx < 1.2: W | case split.index == 0: D | else: Win")
    assert isinstance(b, n.Conditional)
    assert b.cases[0].cond == n.Binary("<", n.Name("scope.sx"), n.Number(1.2))
    assert b.cases[2].cond is None


@pytest.mark.parametrize(
    "text, tree",
    [
        ("1 + 2 * 3", n.Binary("+", n.Number(1), n.Binary("*", n.Number(2), n.Number(3)))),
        ("(1 + 2) * 3", n.Binary("*", n.Binary("+", n.Number(1), n.Number(2)), n.Number(3))),
        ("1 - 2 - 3", n.Binary("-", n.Binary("-", n.Number(1), n.Number(2)), n.Number(3))),
        ("2 ** 3 ** 2", n.Binary("**", n.Number(2), n.Binary("**", n.Number(3), n.Number(2)))),
        ("-2 ** 2", n.Unary("-", n.Binary("**", n.Number(2), n.Number(2)))),
        ("-0.25", n.Number(-0.25)),
        ("a * -b", n.Binary("*", n.Name("a"), n.Unary("-", n.Name("b")))),
        ("not a == b", n.Unary("not", n.Binary("==", n.Name("a"), n.Name("b")))),
        (
            "not a and b or c",
            n.Binary("or", n.Binary("and", n.Unary("not", n.Name("a")), n.Name("b")), n.Name("c")),
        ),
        (
            "a < b and c >= d",
            n.Binary(
                "and",
                n.Binary("<", n.Name("a"), n.Name("b")),
                n.Binary(">=", n.Name("c"), n.Name("d")),
            ),
        ),
        (
            "a ? 1 : b ? 2 : 3",
            n.Ternary(n.Name("a"), n.Number(1), n.Ternary(n.Name("b"), n.Number(2), n.Number(3))),
        ),
        ("7 % 3 + 1e3", n.Binary("+", n.Binary("%", n.Number(7), n.Number(3)), n.Number(1000))),
        ('"a\\"b\\\\c"', n.String('a"b\\c')),
        ("true or false", n.Binary("or", n.Bool(True), n.Bool(False))),
        ("max(1, 2, rand())", n.Call("max", [n.Number(1), n.Number(2), n.Call("rand", [])])),
        (
            "andy + notx + order",
            n.Binary("+", n.Binary("+", n.Name("andy"), n.Name("notx")), n.Name("order")),
        ),
    ],
)
def test_expression_precedence(text, tree):
    assert expr(text) == tree


def test_comments_are_kept_with_their_places():
    m = parse("# head\nA --> B  // tail\nB --> NIL\n")
    assert [(c.text, c.line, c.own_line) for c in m.comments] == [
        ("# head", 1, True),
        ("// tail", 2, False),
    ]


def test_positions_are_recorded_but_do_not_compare():
    a, b = parse("A --> B\n"), parse("\n\n   A   -->\n B")
    assert a == b
    assert (a.rules()[0].pos.line, b.rules()[0].pos.line) == (1, 3)
    assert b.rules()[0].body.steps[0].pos.line == 4


def test_colour_strings_and_hash_comments_do_not_clash():
    m = parse('A --> color("#ff0000") # red\n')
    assert m.rules()[0].body.steps[0].args == [n.String("#ff0000")]
    assert m.comments[0].text == "# red"


def test_parse_and_check_a_large_generated_grammar():
    import importlib.util
    from pathlib import Path

    spec = importlib.util.spec_from_file_location(
        "parse_check", Path(__file__).parent.parent / "bench" / "parse_check.py"
    )
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    text = bench.generate(1000)
    assert len(text.splitlines()) >= 1000
    grammar = bgr.load(text)
    assert len(grammar.rules) > 900
