"""Syntax errors: what a user sees for text that is not a .bgr file.

Each test feeds one bad input to ``bgr.load`` and checks the first diagnostic: a message in the
language's own words, its exact 1-based line and column, and the hint when there is one.
Tests marked xfail(strict=True) describe the right behaviour where the implementation is wrong.
"""

from __future__ import annotations

import pytest
from errors_helpers import check, first_error

import bgr

# Words that must never reach a user: Lark's terminal names and Python internals.
LARK_WORDS = (
    "__ANON",
    "LPAR",
    "RPAR",
    "LBRACE",
    "RBRACE",
    "LSQB",
    "RSQB",
    "$END",
    "RULE_NAME",
    "PERCENT",
    "COLON",
    "Token(",
    "Traceback",
    "lark",
)


# (source, line, column, message substring, hint substring or None)
CASES = [
    # ---- missing or wrong arrow --------------------------------------------------------------
    pytest.param(
        "Lot extrude(3)\n", 1, 1, "unexpected name 'Lot'", "Lot --> body", id="missing-arrow"
    ),
    pytest.param(
        "Floor(i) NIL\n", 1, 1, "unexpected name 'Floor'", "-->", id="missing-arrow-with-params"
    ),
    pytest.param(
        "extrude(3)\n",
        1,
        1,
        "unexpected name 'extrude'",
        "operations belong in a rule body",
        id="operation-outside-a-rule",
    ),
    # ---- unclosed brackets ------------------------------------------------------------------
    pytest.param(
        "Lot --> extrude(3\n",
        1,
        18,
        "unexpected end of file; expected ')'",
        "a bracket is not closed",
        id="unclosed-paren-at-eof",
    ),
    pytest.param(
        "Lot --> extrude(3 Mass\n",
        1,
        19,
        "unexpected name 'Mass'",
        None,
        id="unclosed-paren-then-name",
    ),
    pytest.param(
        "A --> extrude(3\nB --> NIL\n",
        2,
        1,
        "expected ')'",
        None,
        id="unclosed-paren-then-next-rule",
    ),
    pytest.param(
        "Lot --> split(x) { 1: A | 2: B\n",
        1,
        31,
        "expected '|' or '}'",
        "a bracket is not closed",
        id="unclosed-brace-at-eof",
    ),
    pytest.param(
        "A --> split(x) { 1: B\nB --> NIL\n",
        2,
        1,
        "expected '|' or '}'",
        None,
        id="unclosed-brace-then-next-rule",
    ),
    pytest.param(
        "Lot --> [ t(0, 0, 0) A\n",
        1,
        23,
        "expected an operation or a successor or ']'",
        "a bracket is not closed",
        id="unclosed-square-bracket",
    ),
    pytest.param("A --> B }\n", 1, 9, "unexpected '}'", None, id="stray-closing-brace"),
    # ---- strings ----------------------------------------------------------------------------
    pytest.param(
        'Lot --> color("#ffffff)\n',
        1,
        15,
        "unterminated string",
        'close the string with "',
        id="unterminated-string",
    ),
    pytest.param(
        'A --> color("#fff\nB --> NIL\n',
        1,
        13,
        "unterminated string",
        None,
        id="unterminated-string-before-more-lines",
    ),
    pytest.param(
        'Lot --> material("a\\qb")\n',
        1,
        20,
        "unknown escape '\\q' in a string",
        "\\\\",
        id="bad-escape",
    ),
    # ---- characters -------------------------------------------------------------------------
    pytest.param(
        "Lot --> extrude(3) $ A\n",
        1,
        20,
        "unexpected character '$'",
        None,
        id="unknown-character-dollar",
    ),
    pytest.param("A --> B;\n", 1, 8, "unexpected character ';'", None, id="semicolon"),
    pytest.param("A --> B é\n", 1, 9, "unexpected character 'é'", None, id="non-ascii-character"),
    pytest.param("A --> `B`\n", 1, 7, "unexpected character '`'", None, id="backtick"),
    pytest.param("Lot -> extrude(3)\n", 1, 5, "'->'", "'-->'", id="single-dash-arrow-first-rule"),
    pytest.param(
        "A --> B\nC -> D\n",
        2,
        3,
        "'->' is not the rule arrow",
        "'-->'",
        id="single-dash-arrow-later-rule",
    ),
    # ---- alternatives -----------------------------------------------------------------------
    pytest.param(
        "A --> else: B | 50%: C\n",
        1,
        7,
        "'else' must be the last alternative",
        None,
        id="else-not-last",
    ),
    pytest.param(
        "A --> 50%: B | else: C | else: D\n",
        1,
        16,
        "'else' must be the last alternative",
        None,
        id="else-twice",
    ),
    pytest.param(
        "A --> 50%: B | case 1 < 2: C\n",
        1,
        16,
        "mixes percentages and 'case'",
        "use either '60%: A | else: B' or 'case cond: A | else: B'",
        id="mix-percent-then-case",
    ),
    pytest.param(
        "A --> case 1 < 2: B | 30%: C\n",
        1,
        23,
        "mixes percentages and 'case'",
        "use either",
        id="mix-case-then-percent",
    ),
    pytest.param(
        "A --> else: B\n",
        1,
        7,
        "a body cannot be only an 'else' branch",
        "without 'else:'",
        id="body-only-else",
    ),
    pytest.param(
        "A --> 50%: B |\n", 1, 15, "unexpected end of file", None, id="trailing-bar-at-eof"
    ),
    pytest.param(
        "A --> 50%: B |\nC --> NIL\n",
        2,
        1,
        "unexpected name 'C'",
        None,
        id="trailing-bar-then-next-rule",
    ),
    pytest.param("A --> |\n", 1, 7, "unexpected '|'", None, id="leading-bar"),
    pytest.param(
        "A --> 50: B | else: C\n",
        1,
        9,
        "expected '%'",
        "a stochastic choice is written '60%: A'",
        id="percent-sign-missing",
    ),
    pytest.param(
        "A --> case 1 < 2 B | else: C\n",
        1,
        18,
        "expected an operator, ':'",
        None,
        id="case-without-colon",
    ),
    # ---- expressions ------------------------------------------------------------------------
    pytest.param(
        "A --> case 1 < 2 < 3: B | else: C\n",
        1,
        18,
        "comparisons cannot be chained: '<' then '<'",
        "write 'a < b and b < c'",
        id="chained-less-than",
    ),
    pytest.param(
        "attr c = 1 == 2 != 3\nA --> NIL\n",
        1,
        17,
        "comparisons cannot be chained",
        "and",
        id="chained-equality",
    ),
    pytest.param(
        "A --> case 1 = 2: B | else: C\n",
        1,
        14,
        "unexpected '='",
        "compare with '=='",
        id="single-equals-comparison",
    ),
    pytest.param(
        "A --> ()\n", 1, 8, "unexpected ')'; expected an expression", None, id="empty-parens-body"
    ),
    pytest.param(
        "attr x = ()\nA --> NIL\n",
        1,
        11,
        "unexpected ')'; expected an expression",
        None,
        id="empty-parens-expression",
    ),
    pytest.param(
        "A --> t(1,, 2)\n", 1, 11, "unexpected ','; expected an expression", None, id="double-comma"
    ),
    pytest.param(
        "attr c = 1 ? 2\nA --> NIL\n", 2, 1, "expected ':'", None, id="ternary-without-colon"
    ),
    pytest.param("A --> win.\n", 1, 11, "expected a name", None, id="dotted-name-cut-short"),
    pytest.param(
        'version "1"\n',
        1,
        9,
        'unexpected string "1"; expected a number',
        None,
        id="version-not-a-number",
    ),
    # ---- numbers ----------------------------------------------------------------------------
    pytest.param(
        "attr h = 1e999\nA --> NIL\n",
        1,
        10,
        "number 1e999 is too large",
        None,
        id="number-too-large-exponent",
    ),
    pytest.param(
        "attr h = " + "9" * 400 + "\nA --> NIL\n",
        1,
        10,
        "is too large",
        None,
        id="number-too-large-digits",
    ),
    # ---- relative and floating sizes outside split blocks -----------------------------------
    pytest.param(
        "attr h = '0.5\nA --> NIL\n", 1, 10, "unexpected", "relative", id="relative-size-in-attr"
    ),
    # ---- blocks -----------------------------------------------------------------------------
    pytest.param(
        "A --> Foo(1) { 1: B }\n",
        1,
        7,
        "unknown operation 'Foo' with a { } block",
        "only split, comp and offset take a { } block",
        id="block-on-non-operation",
    ),
    pytest.param("A --> B { 1: C }\n", 1, 9, "unexpected '{'", None, id="block-on-bare-successor"),
    pytest.param("A --> split(x) { }\n", 1, 18, "unexpected '}'", None, id="empty-split-block"),
    pytest.param(
        "A --> split(x) { 1: B } * *\nB --> NIL\n", 1, 27, "unexpected '*'", None, id="second-star"
    ),
    # ---- empty bodies -----------------------------------------------------------------------
    pytest.param("A -->\n", 1, 6, "unexpected end of file", None, id="empty-body-at-eof"),
    pytest.param(
        "A -->\nB --> NIL\n",
        1,
        6,
        "empty rule body (the next line starts the rule 'B')",
        "NIL",
        id="empty-body-then-next-rule",
    ),
]


@pytest.mark.parametrize("src, line, column, message, hint", CASES)
def test_syntax_error(src, line, column, message, hint):
    check(src, line, column, message, hint)


_CLEAN_CASES = [c for c in CASES if not c.marks]


@pytest.mark.parametrize("src, line, column, message, hint", _CLEAN_CASES)
def test_syntax_error_is_rendered_in_the_languages_words(src, line, column, message, hint):
    err = first_error(src)
    text = err.render()
    for word in LARK_WORDS:
        assert word not in text, text
    assert isinstance(err, bgr.BgrSyntaxError)
    assert text.startswith(f"<text>:{line}:{column}: error: ")


@pytest.mark.parametrize(
    "keyword",
    [
        "version",
        "import",
        "as",
        "attr",
        "const",
        "func",
        "start",
        "asset",
        "terminal",
        "case",
        "else",
        "NIL",
        "true",
        "false",
        "and",
        "or",
        "not",
    ],
)
def test_keyword_as_rule_name(keyword):
    check(
        f"A --> NIL\n{keyword} --> NIL\n",
        2,
        1,
        f"'{keyword}' is a keyword and cannot name a rule",
        "choose another name",
    )


# ---- bytes that are not text ----------------------------------------------------------------


def test_nul_byte():
    check("A --> B\x00\n", 1, 8, "NUL character", "binary file")


def test_nul_byte_on_a_later_line():
    check(b"A --> B\nB -->\x00 NIL\n", 2, 6, "NUL character", "binary file")


def test_non_utf8_bytes():
    check(b"A --> B\nC --> \xff\n", 2, 7, "not UTF-8 text (byte 0xff)", "UTF-8")


def test_non_utf8_file(tmp_path):
    path = tmp_path / "latin1.bgr"
    path.write_bytes('attr s = "caf\u00e9"\nA --> NIL\n'.encode("latin-1"))
    err = check(path, 1, 14, "not UTF-8 text (byte 0xe9)", "save it as UTF-8")
    assert err.path == str(path)


# ---- positions count characters, not bytes or display columns -------------------------------


def test_column_after_a_tab_counts_one():
    err = check("A --> NIL\n\tC --> D(\n", 2, 10, "unexpected end of file", "not closed")
    caret = err.render().splitlines()[2]
    assert caret.endswith("\t        ^")  # the tab is kept, so the caret lines up in a terminal


def test_crlf_line_endings():
    check("A --> NIL\r\nB --> extrude(3 C\r\n", 2, 17, "unexpected name 'C'")


def test_byte_order_mark_does_not_shift_columns():
    check(b"\xef\xbb\xbfA --> B $\n", 1, 9, "unexpected character '$'")


def test_multibyte_character_counts_one_column():
    check('A --> color("\u00e9\u00e9") $\n', 1, 19, "unexpected character '$'")


def test_stray_quote_is_named_readably():
    err = first_error("attr h = '0.5\nA --> NIL\n")
    assert (err.line, err.column) == (1, 10)
    assert "'''" not in err.message
