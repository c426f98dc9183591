"""CGA source text -> a Lark tree with positions, and the comments it holds.

CGA writes comments three ways (``#``, ``//`` and ``/* ... */``); bgr knows ``#`` only, so each
comment comes back as bgr :class:`~bgr.grammar.nodes.Comment` lines at the line it was on, for
the formatter to put back beside the translated code.
"""

from __future__ import annotations

import re
import threading
from pathlib import Path

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken

from ..grammar import nodes as n
from ..grammar.errors import BgrSyntaxError, Diagnostic, normalise_newlines, source_line

GRAMMAR_FILE = Path(__file__).with_name("cga.lark")

_lock = threading.Lock()
_parser: Lark | None = None
_comments: list[Token] = []


def _lark() -> Lark:
    global _parser
    if _parser is None:
        _parser = Lark(
            GRAMMAR_FILE.read_text(encoding="utf-8"),
            parser="lalr",
            lexer="contextual",
            propagate_positions=True,
            maybe_placeholders=True,
            lexer_callbacks={"COMMENT": _comments.append},
        )
    return _parser


def parse(text: str, path: str = "<text>") -> tuple[Tree, list[n.Comment]]:
    """Parse CGA text; raise :class:`BgrSyntaxError` (path, line, column, what was expected)."""
    text = normalise_newlines(text)
    if "\x00" in text:
        raise BgrSyntaxError(
            Diagnostic(path, 0, 0, "the file contains a NUL character", "is this a binary file?")
        )
    with _lock:
        _comments.clear()
        try:
            tree = _lark().parse(text)
        except UnexpectedInput as e:
            raise _syntax_error(e, text, path) from None
        except RecursionError:
            raise BgrSyntaxError(
                Diagnostic(path, 0, 0, "the file nests expressions or blocks too deeply")
            ) from None
        tokens = list(_comments)
        _comments.clear()
    return tree, _bgr_comments(tokens, text)


def _bgr_comments(tokens: list[Token], text: str) -> list[n.Comment]:
    lines = text.split("\n")
    out = []
    for tok in tokens:
        line, column = tok.line or 1, tok.column or 1
        own = not lines[line - 1][: column - 1].strip() if line <= len(lines) else True
        body = str(tok)
        if body.startswith("//"):
            out.append(n.Comment("#" + body[2:].rstrip(), line, column, own))
        elif body.startswith("/*"):
            for k, part in enumerate(body[2:-2].split("\n")):
                part = part.strip().lstrip("*").rstrip()
                if part:
                    out.append(n.Comment(("# " + part.strip()).rstrip(), line + k, 1, own or k > 0))
        else:
            out.append(n.Comment(body.rstrip(), line, column, own))
    # a block comment's empty last lines and a `/**` line of stars say nothing
    return [c for c in out if c.text.strip("# *")]


def _syntax_error(e: UnexpectedInput, text: str, path: str) -> BgrSyntaxError:
    line, column = getattr(e, "line", 0) or 0, getattr(e, "column", 0) or 0
    if isinstance(e, UnexpectedToken):
        tok = e.token
        what = "end of the file" if tok.type == "$END" else f"'{tok}'"
        expected = sorted(e.accepts or e.expected)
        hint = "expected one of: " + ", ".join(_describe(x) for x in expected[:8])
        message = f"unexpected {what}"
    elif isinstance(e, UnexpectedCharacters):
        at = e.pos_in_stream or 0
        message = f"unexpected character {text[at : at + 1]!r}"
        hint = "CGA strings use double quotes; comments start with #, // or /*"
    elif isinstance(e, UnexpectedEOF):
        message, hint = "the file ends in the middle of a rule", None
    else:  # pragma: no cover - Lark's three kinds above are all it raises
        message, hint = "the text does not parse as CGA", None
    return BgrSyntaxError(Diagnostic(path, line, column, message, hint, source_line(text, line)))


_WORDS = {
    "ARROW": "'-->'",
    "LBRACE": "'{'",
    "RBRACE": "'}'",
    "STAR": "'*'",
    "PCT": "'%:'",
    "NAME": "a name",
    "RULE_NAME": "a rule",
    "FUNC_NAME": "a function",
    "NUMBER": "a number",
    "STRING": "a string",
    "LEAF": "a leaf name",
    "COLON": "':'",
    "COMMA": "','",
    "LPAR": "'('",
    "RPAR": "')'",
    "LSQB": "'['",
    "RSQB": "']'",
    "VBAR": "'|'",
    "EQUAL": "'='",
    "CASE": "'case'",
    "ELSE": "'else'",
    "NIL": "'NIL'",
    "AT": "'@'",
}


def _describe(terminal: str) -> str:
    return _WORDS.get(terminal, terminal.lower())


_ITEM_START = re.compile(r"[^\s#/@*]")  # a line that starts an item: not indented, no comment


def parse_lenient(text: str, path: str = "<text>"):
    """Parse CGA text, leaving out each top-level item (a rule, an attr, a function) that does
    not parse: its lines are blanked and a warning says where and why.  Returns (tree, comments,
    warnings); a file in which no item can be read at all raises the first syntax error."""
    text = normalise_newlines(text)
    lines = text.split("\n")
    warnings: list[Diagnostic] = []
    first_error: BgrSyntaxError | None = None
    for _ in range(200):
        try:
            tree, comments = parse("\n".join(lines), path)
            if first_error is not None and not tree.children:
                raise first_error  # nothing could be read
            return tree, comments, warnings
        except BgrSyntaxError as e:
            first_error = first_error or e
            d = e.diagnostics[0]
            span = _item_span(lines, d.line)
            if span is None:
                raise first_error from None
            start, end = span
            warnings.append(
                Diagnostic(
                    path,
                    d.line,
                    d.column,
                    f"{d.message}: the item on lines {start + 1}-{end + 1} is left out",
                    d.hint,
                    source_line(text, d.line),
                    severity="warning",
                )
            )
            for k in range(start, end + 1):
                lines[k] = ""
    raise first_error or BgrSyntaxError(Diagnostic(path, 0, 0, "the file does not parse"))


def _item_span(lines: list[str], line: int) -> tuple[int, int] | None:
    """The (first, last) 0-based lines of the top-level item around 1-based ``line``: from the
    last line at or above it that starts an item, to the line before the next one."""
    at = min(max(line, 1), len(lines)) - 1
    start = at
    while start > 0 and not _ITEM_START.match(lines[start]):
        start -= 1
    if not lines[start].strip():
        return None
    end = at + 1
    while end < len(lines) and not (
        _ITEM_START.match(lines[end]) and not lines[end].startswith(("}", "|", ")", "]"))
    ):
        end += 1
    return start, max(start, end - 1)
