"""Lark's parse errors in the language's own words: "expected '-->'", never terminal names.

:func:`_translate` turns an ``UnexpectedInput`` into a :class:`BgrSyntaxError`, and recognises a
few slips the grammar alone reports badly (``->`` for ``-->``, an empty rule body, rule defaults
nested too deeply for the lexer's look-ahead).
"""

from __future__ import annotations

from lark import Token
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput

from .errors import BgrSyntaxError, Diagnostic, source_line, source_lines
from .lark_parser import _lark
from .registry import OPERATIONS

_TERMINAL_WORDS = {
    "NAME": "a name",
    "RULE_NAME": "a rule ('Name --> ...')",
    "AT": "an annotation ('@Name')",
    "NUMBER": "a number",
    "STRING": 'a string ("...")',
    "ARROW": "'-->'",
    "STAR": "'*'",
    "COMPARE": "a comparison",
    "BINOP": "an operator",
    "PREFIX": "'-'",
    "AND": "'and'",
    "OR": "'or'",
    "NOT": "'not'",
    "CASE": "'case'",
    "ELSE": "'else'",
    "NIL": "NIL",
    "TRUE": "'true'",
    "FALSE": "'false'",
    "RBRACE": "'}'",
    "LSQB": "'['",
    "RSQB": "']'",
    "$END": "the end of the file",
}
_EXPRESSION_START = {"NUMBER", "STRING", "NAME", "LPAR", "PREFIX", "TRUE", "FALSE", "NOT"}
_STEP_START = {"NAME", "LSQB", "NIL"}
_DECLARATIONS = {
    "VERSION",
    "IMPORT",
    "ATTR",
    "CONST",
    "FUNC",
    "ASSET",
    "TERMINAL",
    "START",
    "RULE_NAME",
    "AT",
}


def _describe_expected(expected: set[str]) -> list[str]:
    expected = set(expected)
    words = []
    if expected >= _DECLARATIONS:
        words.append("a declaration or a rule")
        expected -= _DECLARATIONS
    if expected >= _EXPRESSION_START:
        words.append("an expression")
        expected -= _EXPRESSION_START | {"QUOTE"}
    if expected >= _STEP_START:
        words.append("an operation or a successor")
        expected -= _STEP_START
    parser = _lark()
    for name in sorted(expected):
        if name in _TERMINAL_WORDS:
            words.append(_TERMINAL_WORDS[name])
            continue
        try:
            pattern = parser.get_terminal(name).pattern
        except KeyError:
            continue
        words.append(f"'{pattern.value}'" if pattern.type == "str" else name.lower())
    return sorted(set(words), key=lambda w: (w.startswith("'"), w))


def _describe_token(tok: Token) -> str:
    if tok == "'":
        return '"\'"'
    if tok.type == "$END":
        return "end of file"
    if tok.type in ("NAME", "RULE_NAME"):
        return f"name '{tok}'"
    if tok.type == "NUMBER":
        return f"number {tok}"
    if tok.type == "STRING":
        return f"string {tok}"
    return f"'{tok}'"


def _hint(tok: Token | None, expected: set[str]) -> str | None:
    if tok is None:
        return None
    if tok.type in ("NAME", "RULE_NAME") and "RULE_NAME" in expected:
        if tok in OPERATIONS:
            return "operations belong in a rule body: 'Name --> op(...)'"
        return f"a rule is written '{tok} --> body'"
    if "ARROW" in expected:
        return "a rule is written 'Name --> body' or 'Name(p1, p2) --> body'"
    if tok.type == "$END" and expected & {"RPAR", "RBRACE", "RSQB"}:
        return "a bracket is not closed"
    if tok.type in ("QUOTE", "TILDE"):
        return (
            "relative sizes ('0.5) go in s(), t(), split blocks and texture sizes; "
            "floating sizes (~2) in split blocks and texture sizes"
        )
    if tok.type == "COLON" and "PERCENT" in expected:
        return "a stochastic choice is written '60%: A'"
    if tok.type == "EQUAL" and ("BINOP" in expected or expected == {"COLON"}):
        return "compare with '=='"  # `case a = 1:` (the expression already ended at '=')
    return None


def _translate(e: UnexpectedInput, text: str, path: str) -> BgrSyntaxError:
    line, column = getattr(e, "line", 0), getattr(e, "column", 0)
    if isinstance(e, UnexpectedCharacters):
        at = e.pos_in_stream or 0
        char = text[at] if at < len(text) else "?"
        if char == '"':
            message, hint = "unterminated string", 'close the string with " on the same line'
        elif char == "'" or char == "~":
            message, hint = (
                f"unexpected '{char}'",
                "relative ('0.5) and floating (~2) sizes go in split blocks",
            )
        else:
            message, hint = f"unexpected character {char!r}", None
            if char == "-" and text[at : at + 2] == "->":
                hint = "a rule arrow is '-->'"
        return BgrSyntaxError(
            Diagnostic(path, line, column, message, hint, source_line(text, line))
        )
    tok = getattr(e, "token", None)
    expected = set(getattr(e, "accepts", None) or getattr(e, "expected", None) or ())
    special = _deep_default(text, path)
    if special is None and tok is not None and tok.type != "$END":
        special = _arrow_mistake(tok, text, path)
    if special is not None:
        return special
    if isinstance(e, UnexpectedEOF) or (tok is not None and tok.type == "$END"):
        lines = source_lines(text) or [""]
        while len(lines) > 1 and not lines[-1].strip():
            lines.pop()
        line, column = len(lines), len(lines[-1]) + 1
        tok = Token("$END", "")
    words = _describe_expected(expected)
    message = f"unexpected {_describe_token(tok) if tok is not None else 'input'}"
    if words:
        message += "; expected " + (
            words[0] if len(words) == 1 else ", ".join(words[:-1]) + " or " + words[-1]
        )
    length = len(tok) if tok is not None and tok.type != "$END" and "\n" not in tok else 1
    return BgrSyntaxError(
        Diagnostic(
            path, line, column, message, _hint(tok, expected), source_line(text, line), length
        )
    )


def _line_col(text: str, index: int) -> tuple[int, int]:
    return text.count("\n", 0, index) + 1, index - (text.rfind("\n", 0, index) + 1) + 1


def _deep_default(text: str, path: str) -> BgrSyntaxError | None:
    """A rule head whose defaults nest parentheses two levels deep, `A(x = max(0, min(1, 2))) -->`:
    the lexer's rule-head look-ahead allows one level, so the head is not recognised and the error
    would otherwise land somewhere puzzling."""
    at = text.find("-->")
    while at != -1:
        if "#" in text[text.rfind("\n", 0, at) + 1 : at]:  # an arrow in a comment
            at = text.find("-->", at + 3)
            continue
        i = at - 1
        while i >= 0 and text[i] in " \t\r\n":
            i -= 1
        if i >= 0 and text[i] == ")":
            depth = deepest = 0
            while i >= 0:
                if text[i] == ")":
                    depth += 1
                    deepest = max(deepest, depth)
                elif text[i] == "(":
                    depth -= 1
                    if depth == 0:
                        break
                elif text[i] in "\n#" and depth == 0:
                    break
                i -= 1
            j = i - 1
            while j >= 0 and (text[j].isalnum() or text[j] == "_"):
                j -= 1
            if depth == 0 and deepest > 2 and j + 1 < i:
                line, col = _line_col(text, j + 1)
                return BgrSyntaxError(
                    Diagnostic(
                        path,
                        line,
                        col,
                        "the defaults of this rule nest parentheses more than one level deep",
                        "move the expression into a func (func f(x) = ...) and call that in the "
                        "default",
                        source_line(text, line),
                        i - j - 1,
                    )
                )
        at = text.find("-->", at + 3)
    return None


def _arrow_mistake(tok: Token, text: str, path: str) -> BgrSyntaxError | None:
    """Two slips the grammar alone reports badly: '->' for '-->', and a rule with an empty body
    (the next rule's name is then read as a successor, and its '-->' is what looks wrong)."""
    start = tok.start_pos if tok.start_pos is not None else 0
    after = start + len(tok)
    while after < len(text) and text[after] in " \t":
        after += 1
    for at in (start, after):
        if text.startswith("->", at) and not text.startswith("-->", at - 1):
            line, col = _line_col(text, at)
            return BgrSyntaxError(
                Diagnostic(
                    path,
                    line,
                    col,
                    "'->' is not the rule arrow",
                    "write '-->'",
                    source_line(text, line),
                    2,
                )
            )
    if not text.startswith("-->", start):
        return None
    # `A -->` then `B --> ...`: walk back over B (and its parameters) to the arrow before it
    j = start
    while j > 0 and text[j - 1].isspace():
        j -= 1
    if j > 0 and text[j - 1] == ")":
        j = max(text.rfind("(", 0, j), 0)
    name_end = j
    while j > 0 and (text[j - 1].isalnum() or text[j - 1] == "_"):
        j -= 1
    name = text[j:name_end]
    k = j
    while k > 0 and text[k - 1].isspace():
        k -= 1
    if name and text.endswith("-->", 0, k):
        line, col = _line_col(text, k)
        return BgrSyntaxError(
            Diagnostic(
                path,
                line,
                col,
                f"empty rule body (the next line starts the rule '{name}')",
                "a body needs at least one step: write NIL to delete the shape",
                source_line(text, line),
            )
        )
    line, col = _line_col(text, start)
    return BgrSyntaxError(
        Diagnostic(
            path,
            line,
            col,
            "unexpected '-->'",
            "a rule is written 'Name --> body', one arrow per rule",
            source_line(text, line),
            3,
        )
    )
