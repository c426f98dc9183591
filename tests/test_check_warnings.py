"""Warnings of `bgr check` and `bgr.load`: rules that can never end in a terminal (issue 24).

A cycle of rules that only hand shapes to each other derives until a limit stops it, or ends
having made nothing: the check warns, at the cycle's first rule, and names the cycle.  Grammars
that can end in a terminal (a declared terminal, a sequence left unconsumed, a split piece with no
successor) must not be warned about.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import bgr
from bgr.cli import main

ROOT = Path(__file__).resolve().parent.parent

WARNED = [
    # (source, line, column, text in the message)
    pytest.param("Lot --> A\nA --> B\nB --> A\n", 2, 1, "(A -> B -> A)", id="two-rules"),
    pytest.param(
        "Lot --> split(x) { ~1: Lot | ~1: Lot }\n", 1, 1, "(Lot -> Lot)", id="binary-split"
    ),
    pytest.param("Lot --> Lot Lot\n", 1, 1, "(Lot -> Lot)", id="doubling"),
    pytest.param("Lot --> extrude(3) Lot\n", 1, 1, "(Lot -> Lot)", id="successor-consumes"),
    pytest.param("Lot --> [ Lot ] t(1, 0, 0)\n", 1, 1, "(Lot -> Lot)", id="child-made-no-end"),
    pytest.param(
        "Lot --> extrude(3) Mass\nMass --> case scope.sy > 1: Mass | else: NIL\n",
        2,
        1,
        "(Mass -> Mass)",
        id="case-recursion-ends-in-nil",
    ),
    pytest.param(
        "Lot --> [ A ] [ B ]\nA --> comp(f) { all: B }\nB --> 50%: A | else: NIL\n",
        2,
        1,
        "(A -> B -> A)",
        id="push-comp-stochastic",
    ),
    pytest.param(
        "terminal T\nLot --> T\nX --> offset(-1) { inside: Y | border: NIL }\nY --> X\n",
        3,
        1,
        "(X -> Y -> X)",
        id="unreachable-cycle",
    ),
]


@pytest.mark.parametrize(("source", "line", "column", "text"), WARNED)
def test_unproductive_cycle_is_warned(source, line, column, text):
    grammar = bgr.load(source, path="g.bgr")
    assert len(grammar.warnings) == 1, [w.render() for w in grammar.warnings]
    w = grammar.warnings[0]
    assert (w.severity, w.path, w.line, w.column) == ("warning", "g.bgr", line, column)
    assert "no terminal is reachable" in w.message and text in w.message
    assert w.hint and "terminal" in w.hint


CLEAN = [
    pytest.param(
        "Lot --> case scope.sx > 1: s('0.5, '1, '1) Lot | else: extrude(3)\n",
        id="unconsumed-end-emits",
    ),
    pytest.param("terminal T\nLot --> A\nA --> B T\nB --> A\n", id="terminal-in-cycle"),
    pytest.param(
        'Lot --> split(x) { ~1: Lot | 1: color("#ffffff") }\n', id="piece-without-successor"
    ),
    pytest.param('Lot --> 30%: [ t(1, 0, 0) Lot ] | else: color("#ffffff")\n', id="bracket-or-end"),
    pytest.param('Lot --> A\nA --> case depth > 9: color("#ffffff") | else: A\n', id="case-ends"),
    pytest.param("Lot --> Win(w = Lot)\nWin(w) --> w\n", id="rule-in-a-parameter"),
    pytest.param("import stdlib.facade as fac\nLot --> fac.Tripartite(3)\n", id="imported-rule"),
    pytest.param("Lot --> NIL\n", id="nil-is-no-cycle"),
]


@pytest.mark.parametrize("source", CLEAN)
def test_productive_grammar_is_not_warned(source):
    assert bgr.load(source, path="g.bgr").warnings == []


def test_start_rule_reaching_only_a_cycle_is_named():
    grammar = bgr.load("Lot --> extrude(3) A\nA --> B\nB --> split(y) { ~1: A }*\n", path="g.bgr")
    [w] = grammar.warnings
    assert "the start rule 'Lot' reaches no terminal either" in w.message


def test_shipped_grammars_are_not_warned():
    files = sorted(ROOT.glob("examples/*.bgr")) + sorted(ROOT.glob("examples/*/*.bgr"))
    files += sorted(ROOT.glob("stdlib/*.bgr"))
    assert files
    for path in files:
        assert bgr.load(path).warnings == [], path


def test_check_prints_the_warning_and_exits_0(tmp_path, capsys):
    path = tmp_path / "loop.bgr"
    path.write_text("# a loop\nLot --> A\nA --> B\nB --> A\n", encoding="utf-8")
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr()
    assert out.out == f"{path}: ok (1 warning)\n"
    assert out.err.startswith(f"{path}:3:1: warning: no terminal is reachable from rules 'A', 'B'")
    assert "    3 | A --> B\n" in out.err and "hint: give one of them" in out.err
