"""Nesting limits (docs/language.md, "Limits"): any depth the parser accepts is either handled or
reported with a place, the same way by check, fmt and derive; nothing reaches RecursionError.

Issue 10, item 5: deep expressions passed `bgr check` and then crashed `derive`.
"""

from __future__ import annotations

import pytest

import bgr
from bgr import BgrError
from bgr.cli import main
from bgr.grammar.formatter import format_source
from bgr.grammar.limits import MAX_BLOCK_NESTING, MAX_NESTING

LOT = "Lot --> extrude({})\n"


def derive(text: str):
    return bgr.derive(bgr.load(text), lot=(10, 10), max_shapes=100_000)


def attr_value(text: str, name: str = "a"):
    return derive(text).attrs[name]


def all_stages(text: str) -> None:
    """check, fmt (and check of fmt's output) and derive all accept the text."""
    bgr.load(text)
    formatted = format_source(text)
    assert format_source(formatted) == formatted
    derive(formatted)


def rejected(text: str, message: str) -> BgrError:
    """check, fmt and derive all stop with the same located error."""
    with pytest.raises(BgrError) as checked:
        bgr.load(text)
    assert message in checked.value.message
    assert checked.value.line >= 1
    if "funcs it calls" not in message:  # fmt only parses; call depth is the checker's
        with pytest.raises(BgrError) as formatted:
            format_source(text)
        assert formatted.value.message == checked.value.message
    return checked.value


# ---- flat chains have no depth --------------------------------------------------------------


@pytest.mark.parametrize("terms", [500, 30_000])
def test_long_sum_derives(terms):
    text = "attr a = " + " + ".join(["1"] * terms) + "\n" + LOT.format("a")
    assert attr_value(text) == terms


def test_long_sum_is_formatted_as_it_is_written():
    text = "attr a = " + " - ".join(["1"] * 20_000) + "\n"
    assert format_source(text) == text


def test_long_chains_of_every_operator_kind():
    ops = ["+ 1", "- 1", "* 1", "/ 1", "% 7", "and true", "or false"]
    chain = "7 " + " ".join(ops * 2000)
    all_stages(f"attr a = {chain}\n" + LOT.format("1"))


def test_long_else_if_chain_of_ternaries():
    text = "attr a = " + "".join(f"a0 == {i} ? {i} : " for i in range(5000)) + "1\nattr a0 = 3\n"
    assert attr_value(text + LOT.format("a")) == 3
    assert format_source(text) == text


def test_short_circuit_in_a_chain():
    assert attr_value("attr a = 0 == 1 and 1 / 0 > 0 and 1\n" + LOT.format("1")) is False
    assert attr_value("attr a = false or 1 == 1 or 1 / 0\n" + LOT.format("1")) is True


def test_a_thousand_attrs_in_any_order():
    chain = [f"attr a{i} = a{i - 1} + 1" for i in range(1, 1000)]
    text = "\n".join(["attr a0 = 1", *reversed(chain), LOT.format("a999")])
    assert attr_value(text, "a999") == 1000


def test_ten_thousand_nested_parentheses_are_no_nesting():
    for depth in (10_000, 100_000):
        text = "attr a = " + "(" * depth + "1" + ")" * depth + "\n" + LOT.format("a")
        assert attr_value(text) == 1


def test_long_successor_sequence_and_case_chain():
    all_stages("Lot --> extrude(1)" + " t(0, 0, 0.001)" * 2000 + "\n")
    cases = " | ".join(f"case scope.sx > {i}: extrude({i + 1})" for i in range(1000))
    all_stages(f"Lot --> {cases} | else: NIL\n")


# ---- real nesting: reported where it starts --------------------------------------------------


@pytest.mark.parametrize(
    "text",
    [
        "attr a = " + "true ? " * 1000 + "1" + " : 2" * 1000 + "\n",
        "attr a = " + "(1 + " * 1000 + "1" + ")" * 1000 + "\n",
        "attr a = " + "- " * 1000 + "seed\n",
        "attr a = " + "not " * 1000 + "true\n",
        "attr a = " + " ** ".join(["1"] * 1000) + "\n",
        "func f(x) = x\nattr a = " + "f(" * 1000 + "1" + ")" * 1000 + "\n",
        "attr a = " + "(1 + " * 20_000 + "1" + ")" * 20_000 + "\n",
        "Lot --> extrude(" + "-" * 1000 + "scope.sx)\n",
        "Lot --> split(x) { " + "(1 + " * 200 + "1" + ")" * 200 + ": NIL }\n",
    ],
    ids=["ternary", "parentheses", "minus", "not", "power", "calls", "20k", "argument", "key"],
)
def test_deep_expression_is_a_located_error(text):
    e = rejected(text + LOT.format("1"), "expression nested too deeply")
    assert f"at most {MAX_NESTING}" in e.message


@pytest.mark.parametrize(
    "body",
    [
        "split(x) { 1: " * 300 + "A" + " }" * 300,
        "[ " * 1000 + "A" + " ]" * 1000,
        "split(x) " + "{ " * 300 + "1: A" + " }*" * 300,
        "extrude(1) " + "comp(f) { all: " * 300 + "A" + " }" * 300,
        "offset(-1) { inside: " * 300 + "A" + " }" * 300,
    ],
    ids=["split", "push", "groups", "comp", "offset"],
)
def test_deep_blocks_are_a_located_error(body):
    e = rejected(f"Lot --> {body}\nterminal A\n", "blocks nested too deeply")
    assert f"at most {MAX_BLOCK_NESTING}" in e.message


def test_a_thousand_funcs_deep_is_a_check_error_not_a_recursion():
    funcs = ["func f0() = 1"] + [f"func f{i}() = f{i - 1}() + 1" for i in range(1, 1000)]
    e = rejected("\n".join(funcs) + "\n" + LOT.format("f999()"), "with the funcs it calls")
    assert len(e.diagnostics) == 1  # reported at the first func too deep, not at its callers
    assert "calls itself" not in e.message


def test_funcs_deep_through_an_imported_module(tmp_path):
    lib = tmp_path / "lib.bgr"
    lib.write_text("func f(x) = " + "-(" * 60 + "x" + ")" * 60 + "\n", encoding="utf-8")
    main_file = tmp_path / "main.bgr"
    body = "-" * 45 + "lib.f(1)"  # 45 levels, a call, and f's 61
    main_file.write_text('import "lib.bgr" as lib\n' + LOT.format(body), encoding="utf-8")
    with pytest.raises(BgrError, match="with the funcs it calls"):
        bgr.load(main_file)


def test_recursive_func_is_bounded_while_deriving():
    func = "func f(n) = n <= 0 ? 0 : 1 + f(n - 1)\n"
    assert derive(func + "attr a = f(100)\n" + LOT.format("a")).attrs["a"] == 100
    with pytest.raises(BgrError, match="calls itself too deeply") as e:
        derive(func + LOT.format("f(100000)"))
    assert e.value.line == 1


# ---- at the limits: every stage copes, even from pytest's deep stack -------------------------


def _nested_blocks(inner: str, levels: int = MAX_BLOCK_NESTING) -> str:
    half = levels // 2
    return (
        "[ " * half
        + "split(x) { 1: " * (levels - half)
        + inner
        + " }" * (levels - half)
        + (" ]" * half)
    )


@pytest.mark.parametrize(
    "expr",
    [
        "(scope.sx + " * (MAX_NESTING - 1) + "1" + ")" * (MAX_NESTING - 1),
        "min(" * (MAX_NESTING - 1) + "scope.sx" + ", 1)" * (MAX_NESTING - 1),
        "-" * (MAX_NESTING - 1) + "scope.sx",
        "g97(scope.sx)",
    ],
    ids=["sums", "min", "minus", "funcs"],
)
def test_deepest_accepted_expression_in_the_deepest_blocks(expr):
    # g0 is 2 levels deep (-x), each g(k) one more: g97(scope.sx) is 100 levels, as are the others
    funcs = "func g0(x) = -x\n" + "".join(f"func g{k}(x) = g{k - 1}(-x)\n" for k in range(1, 98))
    text = funcs + "Lot --> " + _nested_blocks(f"extrude({expr})") + "\n"
    all_stages(text)


def test_one_level_more_is_rejected():
    too_deep = "-" * MAX_NESTING + "scope.sx"
    rejected(LOT.format(too_deep), "expression nested too deeply")
    blocks = _nested_blocks("A", MAX_BLOCK_NESTING + 1)
    rejected(f"Lot --> {blocks}\nterminal A\n", "blocks nested too deeply")


@pytest.mark.parametrize("command", ["check", "fmt", "derive"])
def test_cli_reports_deep_input_without_internal_error(command, tmp_path, capsys):
    path = tmp_path / "deep.bgr"
    path.write_text("attr a = " + "true ? " * 1000 + "1" + " : 2" * 1000 + "\n" + LOT.format("a"))
    args = [command, str(path)] + (["-o", str(tmp_path / "out.glb")] if command == "derive" else [])
    assert main(args) == 1
    err = capsys.readouterr().err
    assert "deep.bgr:1:10: error: expression nested too deeply" in err
    assert "internal error" not in err
