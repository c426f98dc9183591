"""CGA's string lists ("a;b;c;": strings in one string, each followed by a semicolon) and the
utility functions that read and build them, from their reference pages' examples."""

import io
import json

import pytest

import bgr
from bgr.formats import write_json


def value(expr: str, seed: int = 0):
    """What ``expr`` is, reported by a one-rule grammar."""
    grammar = bgr.load(f'Lot --> report("v", {expr}) NIL\n')
    (lot,) = bgr.derive(grammar, lot=(4, 4), seed=seed).reports
    entry = lot["reports"]["v"]
    return entry["sum"] if "sum" in entry else next(iter(entry["values"]))


@pytest.mark.parametrize(
    "expr, expected",
    [
        ('listSize("rule;your;city;")', 3),
        ('listSize("")', 0),
        ('listSize("a;b")', 2),  # a last item without its semicolon still counts
        ('listItem("rule;your;city;", 1)', "your"),
        ('listItem("rule;your;city;", 5)', ""),
        ('listIndex("rule;your;city;", "city")', 2),
        ('listIndex("rule;your;city;", "town")', -1),
        ('listCount("a;b;a;", "a")', 2),
        ('listFirst("rule;your;city;")', "rule"),
        ('listLast("rule;your;city;")', "city"),
        ('listAdd("rule;your;", "city")', "rule;your;city;"),
        ('listRange("rule;your;city;", 1, 3)', "your;city;"),
        ('listTerminate("rule;your")', "rule;your;"),
    ],
)
def test_string_list_functions(expr, expected):
    assert value(expr) == expected


def test_list_random_draws_each_item_from_the_shapes_stream():
    drawn = {value('listRandom("rule;your;city;")', seed=s) for s in range(40)}
    assert drawn == {"rule", "your", "city"}
    assert value('listRandom("rule;your;city;")', seed=7) == value(
        'listRandom("rule;your;city;")', seed=7
    )


def test_a_list_picks_colours_by_split_index():
    src = """attr colours = "#aa3333;#33aa33;#3333aa;"
terminal A
Lot --> split(x) { 2: color(listItem(colours, split.index % listSize(colours))) A }*
"""
    result = bgr.derive(bgr.load(src), lot=(8, 4))
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=result.seed, attrs=result.attrs)
    colours = [t["color"] for t in json.loads(buffer.getvalue())["terminals"]]
    assert colours == ["#aa3333", "#33aa33", "#3333aa", "#aa3333"]
