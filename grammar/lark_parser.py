"""The one Lark parser of the language: ``bgr.lark``, LALR with the contextual lexer.

Built once, on first use, with the tree builder as its inline transformer and a callback that
collects comments (the lexer hands them over instead of dropping them).  Apart from
:mod:`parser` because the error translation (:mod:`syntax_errors`) asks it for terminal patterns.
"""

from __future__ import annotations

from pathlib import Path

from lark import Lark, Token

from .tree_builder import _TreeBuilder

GRAMMAR_FILE = Path(__file__).with_name("bgr.lark")


class _Comments:
    """Collects COMMENT tokens, which the lexer hands over instead of dropping them."""

    def __init__(self) -> None:
        self.tokens: list[Token] = []

    def __call__(self, tok: Token) -> Token:
        self.tokens.append(tok)
        return tok


_comments = _Comments()
_parser: Lark | None = None


def _lark() -> Lark:
    global _parser
    if _parser is None:
        _parser = Lark(
            GRAMMAR_FILE.read_text(encoding="utf-8"),
            parser="lalr",
            lexer="contextual",
            propagate_positions=True,
            maybe_placeholders=True,
            transformer=_TreeBuilder(),
            lexer_callbacks={"COMMENT": _comments},
        )
    return _parser
