"""CGA's math, probability, conversion and string functions, with the examples of CityEngine's
reference pages where they give some (count, find)."""

import pytest

import bgr


def attrs(**exprs: str) -> dict:
    source = "".join(f"attr {k} = {v}\n" for k, v in exprs.items()) + "Lot --> NIL\n"
    return bgr.derive(source).attrs


def test_the_reference_examples_of_count_and_find():
    text = '"cityengine rocks my world; cityengine should rock yours too"'
    got = attrs(
        a='count("cityengine", "e")',
        b=f'count({text}, "cityengine")',
        c='find("CE_Zero CE_One CE_Two", "CE", 0)',
        d='find("CE_Zero CE_One CE_Two", "CE", 1)',
        e=f'find({text}, "cityengine", 0)',
        f=f'find({text}, "cityengine", 1)',
        g='find("CE_Zero CE_One CE_Two", "asdf", 1)',
    )
    assert got == {"a": 2, "b": 2, "c": 0, "d": 8, "e": 0, "f": 27, "g": -1}


def test_substring_and_len():
    got = attrs(a='substring("cityengine", 4, 10)', b='substring("abc", 2, 99)', c='len("abc")')
    assert got == {"a": "engine", "b": "c", "c": 3}


def test_math_answers_in_degrees_as_the_trigonometry_takes_them():
    got = attrs(
        a="acos(0)", b="asin(1)", c="atan(1)", d="atan2(1, -1)", e="exp(0) + ln(1)",
        f="log10(1000)", g="rint(2.5) + rint(3.5)", h="isinf(1e308 * 10)", i="isnan(1)",
    )  # fmt: skip
    assert got == {"a": 90, "b": 90, "c": 45, "d": 135, "e": 1, "f": 3, "g": 6, "h": True,
                   "i": False}  # fmt: skip
    with pytest.raises(bgr.BgrError, match=r"acos\(\) of 2"):
        attrs(a="acos(2)")


def test_conversions():
    got = attrs(a='float("1.5")', b="float(true)", c='bool("true")', d="bool(0)", e='bool("no")')
    assert got == {"a": 1.5, "b": 1.0, "c": True, "d": False, "e": False}
    with pytest.raises(bgr.BgrError, match='float\\(\\) of the string "storey": not a number'):
        attrs(a='float("storey")')


def test_p_draws_from_the_shapes_stream_and_is_not_replayed():
    source = (
        "Lot --> extrude(30) comp(f) { side: Facade }\n"
        "Facade --> split(y) { 3: Floor }*\n"
        "Floor --> split(x) { ~2: Tile }*\n"
        "Tile --> case p(0.5): Lit | else: Dark\n"
        "terminal Lit, Dark\n"
    )
    labels = list(bgr.derive(source, lot=(20, 10), seed=4).terminals.label)
    assert 0.3 < labels.count("Lit") / len(labels) < 0.7  # every tile its own draw
    assert labels == list(bgr.derive(source, lot=(20, 10), seed=4).terminals.label)


def test_a_string_function_needs_a_string():
    with pytest.raises(bgr.BgrError, match=r"len\(\) needs a string, got 3"):
        attrs(a="len(3)")
