"""Text -> syntax tree: Lark's LALR parser with the contextual lexer, and a tree builder.

The tree builder runs inside the parser (Lark's ``transformer=`` option), so no intermediate
parse tree is built.  Lark's exceptions are translated into :class:`BgrSyntaxError` messages in
the language's own words ("expected '-->'"), never in terminal names.
"""

from __future__ import annotations

import contextlib
import gc
import math
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import cast

from lark import Lark, Token, Transformer
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput

from . import nodes as n
from .errors import (
    BgrSyntaxError,
    Diagnostic,
    normalise_newlines,
    source_line,
    source_lines,
    suggest,
)
from .limits import nesting_problem
from .registry import KEYWORDS, OPERATIONS

GRAMMAR_FILE = Path(__file__).with_name("bgr.lark")


def _first(x):
    """The first source position inside a child (a token, a node, or a list of them)."""
    if isinstance(x, Token):
        return (x.line, x.column)
    pos = x if isinstance(x, n.Pos) else getattr(x, "pos", None)
    if pos is not None and pos.line:
        return (pos.line, pos.column)
    if isinstance(x, (list, tuple)):
        for item in x:
            found = _first(item)
            if found:
                return found
    return None


def _last(x):
    if isinstance(x, Token):
        return (x.end_line, x.end_column)
    pos = x if isinstance(x, n.Pos) else getattr(x, "pos", None)
    if pos is not None and pos.line:
        return (pos.end_line, pos.end_column)
    if isinstance(x, (list, tuple)):
        for item in reversed(x):
            found = _last(item)
            if found:
                return found
    return None


def _span(*children) -> n.Pos:
    """The span of a node from its children: Lark cannot hand positions to an inline builder."""
    start, end = _first(children), _last(children)
    if start is None:
        return n.NOWHERE
    return n.Pos(start[0], start[1], *(end or start))


def _token_line_col(tok: Token) -> tuple[int, int]:
    """A token's line and column; Lark types them optional, but every lexed token has them."""
    return tok.line or 0, tok.column or 0


def _tok_pos(tok: Token) -> n.Pos:
    line, column = _token_line_col(tok)
    return n.Pos(line, column, tok.end_line or line, tok.end_column or column)


def _keywords_last(args: list) -> None:
    """``R(a = 1, 2)``: a positional argument after a keyword one is ambiguous, as in Python."""
    seen_keyword = False
    for arg in args:
        if isinstance(arg, n.Keyword):
            seen_keyword = True
        elif seen_keyword:
            raise _Problem(
                arg.pos,
                "a positional argument follows a keyword argument",
                "put the positional arguments first",
            )


def _no_keywords(args: list, what: str) -> None:
    """Keyword arguments name rule parameters; operations and functions take positions only."""
    for arg in args:
        if isinstance(arg, n.Keyword):
            raise _Problem(
                arg.pos,
                f"{what} takes no keyword arguments",
                f"write the value alone, without '{arg.name} ='",
                len(arg.name),
            )


class _Problem(Exception):
    """Raised by the tree builder for a construct the grammar accepts but the language does not."""

    def __init__(self, pos: n.Pos, message: str, hint: str | None = None, length: int = 1):
        super().__init__(message)
        self.pos, self.message, self.hint, self.length = pos, message, hint, length


def _unescape(tok: Token) -> str:
    body = tok[1:-1]
    out, i = [], 0
    # \r too: a raw CR ends a line (normalise_newlines), so a string holds one only escaped
    escapes = {'"': '"', "\\": "\\", "n": "\n", "r": "\r", "t": "\t"}
    while i < len(body):
        c = body[i]
        if c == "\\":
            nxt = body[i + 1]
            if nxt not in escapes:
                line, column = _token_line_col(tok)
                pos = n.Pos(line, column + i + 1, line, column + i + 2)
                raise _Problem(
                    pos,
                    f"unknown escape '\\{nxt}' in a string",
                    'strings know \\" \\\\ \\n \\r and \\t; write \\\\ for a backslash',
                    2,
                )
            out.append(escapes[nxt])
            i += 2
        else:
            out.append(c)
            i += 1
    return "".join(out)


class _TreeBuilder(Transformer):
    """Parse-tree callbacks -> :mod:`nodes` dataclasses, run by the parser as it reduces."""

    # ---- declarations ---------------------------------------------------------------------
    def start(self, items):
        return list(items)

    def version_decl(self, c):
        return n.Version(_number(c[0]), pos=_span(c))

    def import_file(self, c):
        return n.Import(str(c[1]), path=_unescape(c[0]), pos=_span(c), alias_pos=_tok_pos(c[1]))

    def import_module(self, c):
        return n.Import(str(c[1]), module=str(c[0]), pos=_span(c), alias_pos=_tok_pos(c[1]))

    def attr_decl(self, c):
        notes, name, value = c
        return n.Attr(str(name), value, pos=_span(c[1:]), annotations=notes or [])

    def annotations(self, c):
        return list(c)

    def annotation(self, c):
        _at, name, args = c
        return n.Annotation(str(name), args or [], pos=_span(c))

    def const_decl(self, c):
        return n.Const(str(c[0]), c[1], pos=_span(c))

    def func_decl(self, c):
        params = c[1] or []
        return n.Func(
            str(c[0]),
            [str(p) for p in params],
            c[2],
            pos=_span(c),
            param_pos=[_tok_pos(p) for p in params],
        )

    def asset_decl(self, c):
        return n.Asset(str(c[0]), _unescape(c[1]), pos=_span(c))

    def terminal_decl(self, c):
        return n.TerminalDecl([str(t) for t in c[0]], pos=_span(c))

    def start_decl(self, c):
        return n.Start(str(c[0]), pos=_span(c))

    def site_decl(self, c):
        crs, *origin, up = c
        return n.Site(
            None if crs is None else _unescape(crs),
            (origin[0], origin[1], origin[2]),
            str(up),
            pos=_span(c),
            up_pos=_tok_pos(up),
        )

    def coordinate(self, c):
        value = _number(c[1])
        return -value if c[0] == "-" else value

    def names(self, c):
        return list(c)

    def dotted(self, c):
        return Token(
            "NAME",
            ".".join(c),
            line=c[0].line,
            column=c[0].column,
            end_line=c[-1].end_line,
            end_column=c[-1].end_column,
        )

    # ---- rules ----------------------------------------------------------------------------
    def rule(self, c):
        notes, name_tok, params, _arrow, body = c
        if str(name_tok) in KEYWORDS:
            raise _Problem(
                _tok_pos(name_tok),
                f"'{name_tok}' is a keyword and cannot name a rule",
                "choose another name, e.g. a capitalised one",
                len(name_tok),
            )
        return n.Rule(
            str(name_tok),
            [str(p) for p, _ in params],
            body,
            pos=_span(c[1:]),  # the rule's own text: its annotations have their own places
            param_pos=[_tok_pos(p) for p, _ in params],
            defaults=[d for _, d in params] if any(d is not None for _, d in params) else [],
            annotations=notes or [],
        )

    def rule_params(self, c):
        return c[0] if c and c[0] else []

    def params(self, c):
        return list(c)

    def param(self, c):
        return (c[0], c[1] if len(c) > 1 else None)

    def alternatives(self, alts):
        kinds = [kind for kind, *_ in alts]
        for i, (kind, _, _, pos) in enumerate(alts):
            if kind == "else" and i != len(alts) - 1:
                raise _Problem(pos, "'else' must be the last alternative", length=4)
        if set(kinds) == {"else"}:
            raise _Problem(
                alts[0][3],
                "a body cannot be only an 'else' branch",
                "write the sequence without 'else:'",
                4,
            )
        if "choice" in kinds and "case" in kinds:
            second = alts[kinds.index("case" if kinds[0] == "choice" else "choice")]
            raise _Problem(
                second[3],
                "a body mixes percentages and 'case' conditions",
                "use either '60%: A | else: B' or 'case cond: A | else: B'",
            )
        if "choice" in kinds:
            return n.Stochastic(
                [n.Choice(test, body, pos=pos) for _, test, body, pos in alts],
                pos=_span(alts[0][3], alts[-1][3]),
            )
        return n.Conditional(
            [n.Case(test, body, pos=pos) for _, test, body, pos in alts],
            pos=_span(alts[0][3], alts[-1][3]),
        )

    def choice(self, c):
        return ("choice", c[0], c[1], _span(c))

    def case(self, c):
        return ("case", c[1], c[2], _span(c))

    def else_alt(self, c):
        return ("else", None, c[1], _span(c))

    def sequence(self, c):
        return n.Sequence(list(c), pos=_span(c))

    def nil(self, c):
        return n.Nil(pos=_span(c))

    def push(self, c):
        return n.Push(list(c[1:-1]), pos=_span(c))

    def successor(self, c):
        return n.Successor(str(c[0]), [], pos=_span(c))

    def call(self, c):
        name, args, block = str(c[0]), c[1] or [], c[2]
        _keywords_last(args)
        keywords = any(isinstance(a, n.Keyword) for a in args)
        if name in OPERATIONS and not (keywords and block is None):
            return n.Operation(name, args, block, pos=_span(c))
        if block is not None:
            hint = suggest(name, [op for op, spec in OPERATIONS.items() if spec.block])
            raise _Problem(
                _tok_pos(c[0]),
                f"unknown operation '{name}' with a {{ }} block",
                hint or "only split, comp and offset take a { } block",
                len(name),
            )
        # keyword arguments make it a rule application (operations take none): a parameter named
        # like an operation (`roof(pitch = 20)` with a parameter `roof`); the checker decides
        return n.Successor(name, args, pos=_span(c))

    def block(self, c):
        return n.Block(c[1], repeat=c[3] is not None, pos=_span(c))

    def entries(self, c):
        return list(c)

    def keyed(self, c):
        kind, key, start = c[0]
        return n.Entry(kind, key, c[1], pos=_span(start, c[1]))

    def group(self, c):
        return n.Group(c[1], pos=_span(c))

    def key_abs(self, c):
        return ("abs", c[0], c[0])

    def key_rel(self, c):
        return ("rel", c[1], c[0])

    def key_float(self, c):
        return ("float", c[1], c[0])

    def args(self, c):
        return list(c)

    def rel_arg(self, c):
        return n.Relative(c[1], pos=_span(c))

    def float_arg(self, c):
        return n.Relative(c[1], pos=_span(c), floating=True)

    def keyword_arg(self, c):
        return n.Keyword(str(c[0]), c[1], pos=_tok_pos(c[0]))

    # ---- expressions ----------------------------------------------------------------------
    def number(self, c):
        return n.Number(_number(c[0]), pos=_tok_pos(c[0]))

    def signed_number(self, c):
        value = _number(c[1])
        return n.Number(-value if c[0] == "-" else value, pos=_span(c))

    def string(self, c):
        if len(c[0]) > MAX_STRING + 2:
            raise _Problem(
                _tok_pos(c[0]),
                f"a string of {len(c[0]) - 2:,} characters is too long (at most {MAX_STRING:,})",
                "keep long text out of the grammar",
                length=1,
            )
        return n.String(_unescape(c[0]), pos=_tok_pos(c[0]))

    def true(self, c):
        return n.Bool(True, pos=_tok_pos(c[0]))

    def false(self, c):
        return n.Bool(False, pos=_tok_pos(c[0]))

    def name(self, c):
        return n.Name(str(c[0]), pos=_tok_pos(c[0]))

    def fcall(self, c):
        args = c[1] or []
        _no_keywords(args, f"function '{c[0]}'")
        return n.Call(str(c[0]), args, pos=_span(c))

    def ternary(self, c):
        return n.Ternary(c[0], c[1], c[2], pos=_span(c))

    def term(self, c):
        return c  # prefix operator tokens, then the operand; ordered by chain()

    def chain(self, c):
        stream = []
        for i, part in enumerate(c):
            if i % 2:
                stream.append(part)  # a binary operator token
            else:
                stream.extend(part)
        if len(stream) == 1:
            return stream[0]
        return _order(stream)


# Binding powers: (left, right).  Left-associative operators bind tighter on the right.
_INFIX = {
    "or": (1, 2),
    "and": (3, 4),
    "==": (7, 8),
    "!=": (7, 8),
    "<": (7, 8),
    "<=": (7, 8),
    ">": (7, 8),
    ">=": (7, 8),
    "+": (9, 10),
    "-": (9, 10),
    "*": (11, 12),
    "/": (11, 12),
    "%": (11, 12),
    "**": (15, 15),
}
_PREFIX = {"not": 5, "-": 13, "+": 13}  # right binding power of each prefix operator
_COMPARISONS = {"==", "!=", "<", "<=", ">", ">="}


def _order(stream: list) -> n.Expr:
    """Orders a flat operator chain by precedence, as Python does: ``or`` < ``and`` < ``not`` <
    comparisons < ``+ -`` < ``* / %`` < unary ``- +`` < ``**`` (right-associative).

    An operator-precedence (shunting-yard) loop with the binding powers above, not a recursive
    descent: a chain of a thousand prefix minuses or ``**`` must not exhaust Python's stack
    before the nesting limit (:mod:`limits`) can report it.
    """
    operands: list = []
    pending: list[tuple[Token, int, bool]] = []  # (operator, right binding power, is prefix)

    def reduce(incoming: Token | None) -> None:
        tok, _, prefix = pending.pop()
        op = str(tok)
        if prefix:
            operand = operands.pop()
            if op == "-" and isinstance(operand, n.Number):  # -0.25 is a number literal
                operands.append(n.Number(-operand.value, pos=_span(tok, operand)))
            else:
                operands.append(n.Unary(op, operand, pos=_span(tok, operand)))
            return
        if incoming is not None and op in _COMPARISONS and str(incoming) in _COMPARISONS:
            raise _Problem(
                _tok_pos(incoming),
                f"comparisons cannot be chained: '{op}' then '{incoming}'",
                "write 'a < b and b < c'",
                len(incoming),
            )
        right = operands.pop()
        left = operands.pop()
        operands.append(n.Binary(op, left, right, pos=_span(left, right)))

    want_operand = True
    for item in stream:
        if want_operand:
            if isinstance(item, Token):  # a prefix operator
                pending.append((item, _PREFIX[str(item)], True))
            else:
                operands.append(item)
                want_operand = False
            continue
        lbp, rbp = _INFIX[str(item)]
        while pending and pending[-1][1] > lbp:
            reduce(item)
        pending.append((item, rbp, False))
        want_operand = True
    while pending:
        reduce(None)
    return operands[0]


# a string literal's length: labels, colours and materials are short; a cap keeps a runaway (an
# unclosed quote in generated text, a pasted file) from costing memory in every later copy
MAX_STRING = 65_536


def _number(tok: Token) -> float:
    value = float(tok)
    if math.isinf(value):
        raise _Problem(_tok_pos(tok), f"number {tok} is too large", length=len(tok))
    return value


class _Comments:
    """Collects COMMENT tokens, which the lexer hands over instead of dropping them."""

    def __init__(self) -> None:
        self.tokens: list[Token] = []

    def __call__(self, tok: Token) -> Token:
        self.tokens.append(tok)
        return tok


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


# ---- error translation --------------------------------------------------------------------------

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
    if tok.type == "EQUAL" and "BINOP" in expected:
        return "compare with '=='"
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
