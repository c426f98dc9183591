"""The syntax tree of a .bgr file: small dataclasses that carry their source positions.

Positions never take part in equality (``field(compare=False)``), so two trees that differ only in
layout compare equal: that is how the formatter's round trip ``parse(fmt(x)) == parse(x)`` is
stated and tested.  The parser builds these trees from text; the inverse modules build them
directly and print them with :mod:`bgr.grammar.formatter`.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Pos:
    """A span of source text: 1-based line and column of its first and last character."""

    line: int = 0
    column: int = 0
    end_line: int = 0
    end_column: int = 0


NOWHERE = Pos()


def _pos():
    return field(default=NOWHERE, compare=False, repr=False, kw_only=True)


# ---- expressions -----------------------------------------------------------------------------


@dataclass
class Number:
    value: float
    pos: Pos = _pos()


@dataclass
class String:
    value: str
    pos: Pos = _pos()


@dataclass
class Bool:
    value: bool
    pos: Pos = _pos()


@dataclass
class Name:
    """A name, possibly dotted: ``height``, ``scope.sx``, ``fac.floor_h``."""

    name: str
    pos: Pos = _pos()


@dataclass
class Call:
    """A function call inside an expression: a built-in (``rand``) or a ``func``."""

    name: str
    args: list[Expr]
    pos: Pos = _pos()


@dataclass
class Unary:
    op: str  # '-', '+', 'not'
    operand: Expr
    pos: Pos = _pos()


@dataclass
class Binary:
    op: str  # + - * / % ** == != < <= > >= and or
    left: Expr
    right: Expr
    pos: Pos = _pos()


@dataclass
class Ternary:
    cond: Expr
    then: Expr
    otherwise: Expr
    pos: Pos = _pos()


@dataclass
class Relative:
    """``'expr`` as an operation argument: a fraction of the scope size (``s('0.5, 0, 0)``);
    ``floating``: ``~expr``, a size rounded so that whole tiles span the scope
    (``setupProjection(0, scope.xy, ~1.5, 1)``)."""

    expr: Expr
    pos: Pos = _pos()
    floating: bool = False


@dataclass
class Keyword:
    """``name = expr`` as a successor argument: binds rule parameter ``name`` (``Tile(w = 2)``)."""

    name: str
    value: Expr
    pos: Pos = _pos()


@dataclass
class Array:
    """``[a, b, c]``: CGA's array, its items all numbers, all strings or all booleans."""

    items: list
    pos: Pos = _pos()


@dataclass
class Index:
    """``a[i]``: the i-th (0-based) item of an array."""

    target: Expr
    index: Expr
    pos: Pos = _pos()


Expr = Number | String | Bool | Name | Call | Unary | Binary | Ternary | Array | Index
Arg = Expr | Relative | Keyword


# ---- rule bodies -----------------------------------------------------------------------------


@dataclass
class Operation:
    """A shape operation from the registry: ``extrude(3)``, ``split(x) { ... }``."""

    name: str
    args: list[Arg]
    block: Block | None = None
    pos: Pos = _pos()


@dataclass
class Successor:
    """A rule application: ``Facade``, ``Floor(i)``, ``fac.Tripartite(3.2)``."""

    name: str
    args: list[Arg] = field(default_factory=list)
    pos: Pos = _pos()


@dataclass
class Push:
    """``[ ... ]``: the steps inside work on a copy of the shape state."""

    steps: list[Step]
    pos: Pos = _pos()


@dataclass
class Nil:
    pos: Pos = _pos()


Step = Operation | Successor | Push | Nil


@dataclass
class Sequence:
    steps: list[Step]
    pos: Pos = _pos()


@dataclass
class Entry:
    """One piece of a block: ``3: A``, ``'0.5: A``, ``~2: A``, ``front: A``, ``inside: A``.

    ``kind`` is ``abs``, ``rel`` or ``float`` (the prefix the size was written with).  For
    ``comp`` and ``offset`` blocks the key is a selector, held as an expression (``Name('front')``,
    ``Call('face', [Number(2)])``) with kind ``abs``.
    """

    kind: str
    key: Expr
    body: Sequence
    pos: Pos = _pos()
    combine: bool = False  # `side = A`: comp(f)'s faces taken as one shape (CGA's `=`)


@dataclass
class Group:
    """A repeat group ``{ ... }*`` inside a block: a Kleene star."""

    entries: list[Entry | Group]
    pos: Pos = _pos()


@dataclass
class Block:
    """The ``{ ... }`` of split, comp and offset.

    ``repeat`` is the ``split(x) { ... }*`` shorthand: the whole block is one repeat group.
    """

    entries: list[Entry | Group]
    repeat: bool = False
    pos: Pos = _pos()


@dataclass
class Choice:
    """One branch of a stochastic body; ``prob`` is ``None`` for ``else``."""

    prob: Expr | None
    body: Sequence
    pos: Pos = _pos()


@dataclass
class Stochastic:
    choices: list[Choice]
    pos: Pos = _pos()


@dataclass
class Case:
    """One branch of a conditional body; ``cond`` is ``None`` for ``else``."""

    cond: Expr | None
    body: Sequence
    pos: Pos = _pos()


@dataclass
class Conditional:
    cases: list[Case]
    pos: Pos = _pos()


Body = Sequence | Stochastic | Conditional


# ---- top-level items -------------------------------------------------------------------------


@dataclass
class Rule:
    """``Name(p1, p2 = default) --> body``; ``defaults`` holds one Expr or None per parameter."""

    name: str
    params: list[str]
    body: Body
    pos: Pos = _pos()
    param_pos: list[Pos] = field(default_factory=list, compare=False, repr=False, kw_only=True)
    defaults: list = field(default_factory=list, kw_only=True)
    annotations: list[Annotation] = field(default_factory=list, kw_only=True)

    def default(self, i: int):
        """The default expression of parameter ``i``, or None when it has none."""
        return self.defaults[i] if i < len(self.defaults) else None


@dataclass
class Version:
    number: float
    pos: Pos = _pos()


@dataclass
class Import:
    """An import: ``import "lib/w.bgr" as w`` (sets ``path``) or ``import stdlib.facade as fac``.

    The alias names the module in rule references (``w.Window``).
    """

    alias: str
    path: str | None = None
    module: str | None = None
    pos: Pos = _pos()
    alias_pos: Pos = _pos()


@dataclass
class Attr:
    name: str
    value: Expr
    pos: Pos = _pos()
    annotations: list[Annotation] = field(default_factory=list, kw_only=True)


@dataclass
class Annotation:
    """``@Name`` or ``@Name(args)`` before an attr or a rule (CGA's annotations): metadata for
    editors, checked by grammar/annotations.py; ``args`` holds expressions and Keywords."""

    name: str
    args: list = field(default_factory=list)
    pos: Pos = _pos()


@dataclass
class Const:
    name: str
    value: Expr
    pos: Pos = _pos()


@dataclass
class Func:
    name: str
    params: list[str]
    body: Expr
    pos: Pos = _pos()
    param_pos: list[Pos] = field(default_factory=list, compare=False, repr=False, kw_only=True)


@dataclass
class Asset:
    name: str
    path: str
    pos: Pos = _pos()


@dataclass
class TerminalDecl:
    names: list[str]
    pos: Pos = _pos()


@dataclass
class Start:
    name: str
    pos: Pos = _pos()


@dataclass
class Site:
    """Where the grammar's metres are on Earth: its coordinates are the input's (a city that
    ``bgr infer`` read) minus ``origin``, which is in the input's own axes, ``up`` its vertical
    axis ("y" or "z"), ``crs`` the coordinate reference system it names (None: plain metres).
    Writers put their output back there (docs/language.md, "Site")."""

    crs: str | None
    origin: tuple[float, float, float]
    up: str
    pos: Pos = _pos()
    up_pos: Pos = _pos()


Item = Version | Import | Attr | Const | Func | Asset | TerminalDecl | Start | Site | Rule


@dataclass
class Comment:
    """A source comment, kept so that the formatter can put it back."""

    text: str
    line: int
    column: int
    own_line: bool  # nothing but whitespace before it on its line


@dataclass
class Module:
    """A whole file.  ``comments`` and ``source`` are layout, not meaning: they do not compare."""

    items: list[Item]
    path: str = field(default="<text>", compare=False)
    comments: list[Comment] = field(default_factory=list, compare=False, repr=False)
    source: str = field(default="", compare=False, repr=False)

    def rules(self) -> list[Rule]:
        return [item for item in self.items if isinstance(item, Rule)]


def walk(expr) -> Iterator:
    """Every node of an expression, itself first, without recursion (chains can be long)."""
    stack = [expr]
    while stack:
        e = stack.pop()
        yield e
        if isinstance(e, Binary):
            stack += (e.left, e.right)
        elif isinstance(e, Unary):
            stack.append(e.operand)
        elif isinstance(e, Ternary):
            stack += (e.cond, e.then, e.otherwise)
        elif isinstance(e, Call):
            stack += e.args
        elif isinstance(e, (Relative, Keyword)):
            stack.append(e.expr if isinstance(e, Relative) else e.value)
        elif isinstance(e, Array):
            stack += e.items
        elif isinstance(e, Index):
            stack += (e.target, e.index)


def names_in(expr) -> Iterator[Name]:
    """Every Name inside an expression, without recursion (operator chains can be long)."""
    stack = [expr]
    while stack:
        e = stack.pop()
        if isinstance(e, Name):
            yield e
        elif isinstance(e, Binary):
            stack += (e.left, e.right)
        elif isinstance(e, Unary):
            stack.append(e.operand)
        elif isinstance(e, Ternary):
            stack += (e.cond, e.then, e.otherwise)
        elif isinstance(e, Call):
            stack += e.args
        elif isinstance(e, Relative):
            stack.append(e.expr)
        elif isinstance(e, Keyword):
            stack.append(e.value)
        elif isinstance(e, Array):
            stack += e.items
        elif isinstance(e, Index):
            stack += (e.target, e.index)
