"""The tree builder: Lark's parse-tree callbacks that make :mod:`nodes` dataclasses.

The builder runs inside the parser (Lark's ``transformer=`` option), so no intermediate parse
tree is built.  Besides the callbacks it holds what they need: source spans from tokens and child
nodes, string unescaping, operator precedence (an operator chain is ordered here, not by the
grammar), and :class:`_Problem`, raised for a construct the grammar accepts but the language does
not; :mod:`parser` turns it into a :class:`BgrSyntaxError`.
"""

from __future__ import annotations

import math

from lark import Token, Transformer

from . import nodes as n
from .errors import suggest
from .registry import KEYWORDS, OPERATIONS


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

    def combined(self, c):
        kind, key, start = c[0]
        return n.Entry(kind, key, c[1], pos=_span(start, c[1]), combine=True)

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

    def array(self, c):
        items = [x for x in c[1:-1] if x is not None]
        return n.Array(items, pos=_tok_pos(c[0]))

    def index(self, c):
        return n.Index(c[0], c[2], pos=_tok_pos(c[1]))

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
