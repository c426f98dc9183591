"""CGA's str() and string concatenation: the reference page's examples, and "Floor" + 2."""

import pytest

import bgr


def attrs(**exprs: str) -> dict:
    source = "".join(f"attr {k} = {v}\n" for k, v in exprs.items()) + "Lot --> NIL\n"
    return bgr.derive(source).attrs


def test_the_reference_examples():
    # esri.github.io/cityengine-sdk cgaref func_str: each example and its documented result
    got = attrs(a="str(1.69)", b="str(1.69 - 69/100)", c="str(001)", d="str(true)", e='str("x")')
    assert got == {"a": "1.69", "b": "1", "c": "1", "d": "true", "e": "x"}


def test_a_string_joins_numbers_and_booleans_as_text():
    got = attrs(a='"Floor" + 2', b='1 + "x" + 0.5', c='"lit: " + (2 > 1)', d='"" + 1/3')
    assert got == {"a": "Floor2", "b": "1x0.5", "c": "lit: true", "d": "0.3333333333"}
    assert attrs(a="1 + 2")["a"] == 3  # numbers still add


def test_a_rule_has_no_text():
    source = 'Lot --> P(x = A)\nP(x) --> label("k" + x) A\nterminal A\n'
    with pytest.raises(bgr.BgrError, match="cannot join"):
        bgr.derive(source)
