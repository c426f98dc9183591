"""Text -> syntax tree: :func:`parse`, the entry point of the language front end.

It runs the Lark parser (:mod:`lark_parser`), whose inline tree builder (:mod:`tree_builder`)
makes the nodes as it reduces, collects the comments, and turns every failure into a
:class:`BgrSyntaxError`: a construct the builder refuses, Lark's own errors (in the language's
words, by :mod:`syntax_errors`), and nesting deeper than :mod:`limits` allows.
"""

from __future__ import annotations

import contextlib
import gc
import threading
from collections.abc import Iterator
from typing import cast

from lark.exceptions import UnexpectedInput

from . import nodes as n
from .errors import (
    BgrSyntaxError,
    Diagnostic,
    normalise_newlines,
    source_line,
    source_lines,
)
from .lark_parser import GRAMMAR_FILE as GRAMMAR_FILE
from .lark_parser import _comments, _lark
from .limits import nesting_problem
from .syntax_errors import _translate
from .tree_builder import MAX_STRING as MAX_STRING
from .tree_builder import _Problem, _token_line_col

_lock = threading.Lock()


@contextlib.contextmanager
def no_gc() -> Iterator[None]:
    """Pause the cyclic collector for work that makes millions of small objects and no cycles
    (it would only rescan them): parsing (1.9 s -> 1.0 s for bench/parse_check.py's 5,000
    lines), a terminal list written as JSON, a city's axiom (6.1 s -> 1.5 s for 100,000
    buildings)."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def parse(text: str, path: str = "<text>") -> n.Module:
    """Parse .bgr source text into a :class:`nodes.Module`; raise :class:`BgrSyntaxError`.

    Text that is not a ``str`` is a TypeError (a programmer's error, not a user's).  A line ends
    at LF, CRLF or a lone CR; the module's ``source`` has them all as LF.
    """
    if not isinstance(text, str):
        raise TypeError(f"bgr.parse takes the text of a grammar (str), not {type(text).__name__}")
    text = normalise_newlines(text)
    if "\x00" in text:
        line = text.count("\n", 0, text.index("\x00")) + 1
        col = text.index("\x00") - (text.rfind("\n", 0, text.index("\x00")) + 1) + 1
        raise BgrSyntaxError(
            Diagnostic(
                path,
                line,
                col,
                "the file contains a NUL character",
                "is this a binary file?",
                source_line(text, line),
            )
        )
    with _lock, no_gc():
        _comments.tokens = []
        try:
            # the inline transformer builds the module items: a list, though Lark types a Tree
            items = cast("list[n.Item]", _lark().parse(text))
        except RecursionError:
            raise BgrSyntaxError(
                Diagnostic(
                    path,
                    0,
                    0,
                    "the file nests expressions or blocks too deeply",
                    "split deep nesting into separate rules",
                )
            ) from None
        except _Problem as p:
            raise BgrSyntaxError(
                Diagnostic(
                    path,
                    p.pos.line,
                    p.pos.column,
                    p.message,
                    p.hint,
                    source_line(text, p.pos.line),
                    p.length,
                )
            ) from None
        except UnexpectedInput as e:
            raise _translate(e, text, path) from None
        tokens = _comments.tokens
        _comments.tokens = []
    _check_nesting(items, text, path)
    comments = []
    lines = source_lines(text)
    for tok in tokens:
        line, column = _token_line_col(tok)
        before = lines[line - 1][: column - 1] if line <= len(lines) else ""
        comments.append(n.Comment(str(tok).rstrip(), line, column, not before.strip()))
    return n.Module(items, path=path, comments=comments, source=text)


def _check_nesting(items: list[n.Item], text: str, path: str) -> None:
    """Nesting deeper than :mod:`limits` allows is a syntax error, so that check, fmt and derive
    all stop at the same place before anything walks the tree recursively."""
    for item in items:
        problem = nesting_problem(item)
        if problem is not None:
            pos, message, hint = problem
            raise BgrSyntaxError(
                Diagnostic(path, pos.line, pos.column, message, hint, source_line(text, pos.line))
            )
