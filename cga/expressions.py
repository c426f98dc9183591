"""CGA expressions -> bgr expressions.

Most of CGA's expression language is bgr's with other spellings (``&&`` is ``and``, ``!`` is
``not``, ``pow(a, b)`` is ``a ** b``, ``scope.tx`` is ``scope.x``).  Two forms have no twin and
are rewritten: a conditional expression (``case c: a else: b``) becomes nested ``c ? a : b``, and
a stochastic one (``30%: a 20%: b else: c``) a chain of ``p()`` draws whose conditional
probabilities give each value CGA's chance (20 % after 30 % is ``p(0.2 / 0.7)``).  What bgr has no
counterpart for (occlusion queries, arrays, most ``geometry.*`` functions) becomes a neutral value
with a warning at its line and column, so that the grammar still derives.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from lark import Token, Tree

from ..grammar import nodes as n
from ..grammar.registry import BUILTIN_NAMES, BUILTINS, WORD_ARGUMENTS

# CGA's scope and context names with a bgr twin of another name (the rest keep theirs)
NAMES = {
    "scope.tx": "scope.x",
    "scope.ty": "scope.y",
    "scope.tz": "scope.z",
}
# the scope, split, comp and geometry names bgr has under CGA's names
SAME_NAMES = {name for name in BUILTIN_NAMES if "." in name}
# CGA functions whose result has this type when bgr has no equivalent: the neutral value stands in
_BOOLEAN = {
    "inside",
    "overlaps",
    "touches",
    "fileExists",
    "geometry.isClosedSurface",
    "geometry.isOriented",
    "geometry.isInside",
    "isNull",
}
_STRINGS = {
    "fileRandom",
    "fileSearch",
    "fileName",
    "fileDirectory",
    "fileBasename",
    "assetInfo",
    "imageInfo",
    "initialShape.name",
    "material.name",
}
OPERATORS = {"||": "or", "&&": "and"}


class Context(Protocol):
    """What an expression needs from the translator: its names and a place for warnings."""

    def warn(self, meta, message: str, hint: str | None = None) -> None: ...
    def value(self, name: str, meta) -> n.Expr | None: ...
    def function(self, name: str, args: list[n.Expr], meta) -> n.Expr | None: ...


def pos(meta) -> n.Pos:
    """A bgr position from a Lark tree's meta (or a token)."""
    if meta is None or getattr(meta, "empty", False) or not getattr(meta, "line", None):
        return n.NOWHERE
    return n.Pos(meta.line, meta.column, meta.end_line or meta.line, meta.end_column or 0)


def meta_of(x):
    return x if isinstance(x, Token) else getattr(x, "meta", None)


def dotted(t) -> str:
    """The text of a ``ref``: ``name`` or ``a.b.c``."""
    if isinstance(t, Token):
        return str(t)
    return ".".join(str(c) for c in t.children)


def unquote(tok: object) -> str:
    body = str(tok)[1:-1]
    if "\\" not in body:
        return body
    out, i = [], 0
    while i < len(body):
        c = body[i]
        if c == "\\" and i + 1 < len(body):
            nxt = body[i + 1]
            out.append({"n": "\n", "t": "\t", "r": "\r"}.get(nxt, nxt))
            i += 2
        else:
            out.append(c)
            i += 1
    return "".join(out)


def neutral(name: str) -> n.Expr:
    """What stands in for a value bgr cannot compute: false, "" or 0 by the kind of name."""
    if name == "colorRamp":  # a colour from a ramp: a mid grey stands in
        return n.String("#808080")
    if name in ("geometry.du", "geometry.dv"):  # texture-space extents, often divided by
        return n.Number(1.0)
    short = name.rsplit(".", 1)[-1]
    if name in _BOOLEAN or short.startswith("is"):
        return n.Bool(False)
    if name in _STRINGS:
        return n.String("")
    return n.Number(0.0)


class Expressions:
    """Translates expression trees; names and calls are resolved by the context."""

    def __init__(self, ctx: Context) -> None:
        self.ctx = ctx

    def __call__(self, t) -> n.Expr:
        handler: Callable | None = (
            getattr(self, "_" + t.data, None) if isinstance(t, Tree) else None
        )
        if handler is None:
            if isinstance(t, Token) and t.type == "NAME":
                return self._value(str(t), t)
            if isinstance(t, Token) and t.type == "NUMBER":  # a probability: `30%: A`
                return n.Number(float(t), pos=pos(t))
            raise AssertionError(f"unexpected CGA expression node {t!r}")  # pragma: no cover
        out = handler(t)
        if (
            isinstance(
                out, (n.Number, n.String, n.Bool, n.Name, n.Call, n.Unary, n.Binary, n.Ternary)
            )
            and out.pos is n.NOWHERE
        ):
            out.pos = pos(t.meta)
        return out

    # ---- atoms -------------------------------------------------------------------------------
    def _number(self, t: Tree) -> n.Expr:
        return n.Number(float(str(t.children[0])))

    def _string(self, t: Tree) -> n.Expr:
        return n.String(unquote(t.children[0]))

    def _true(self, t: Tree) -> n.Expr:
        return n.Bool(True)

    def _false(self, t: Tree) -> n.Expr:
        return n.Bool(False)

    def _name(self, t: Tree) -> n.Expr:
        return self._value(dotted(t.children[0]), t.meta)

    def _dotted(self, t: Tree) -> n.Expr:
        return self._value(dotted(t), t.meta)

    def _value(self, name: str, meta) -> n.Expr:
        found = self.ctx.value(name, meta)
        if found is not None:
            return found
        if name in SAME_NAMES:
            return n.Name(name)
        if name in NAMES:
            return n.Name(NAMES[name])
        self.ctx.warn(meta, f"'{name}' has no bgr equivalent; {_show(neutral(name))} stands in")
        return neutral(name)

    def _array(self, t: Tree) -> n.Expr:
        rows = [c for c in t.children if isinstance(c, Tree) and c.data == "args"]
        if len(rows) > 1:
            self.ctx.warn(t.meta, "arrays of two dimensions are not in bgr yet; 0 stands in")
            return n.Number(0.0)
        return n.Array([self(a) for a in _args(rows[0])] if rows else [], pos=pos(t.meta))

    def _index(self, t: Tree) -> n.Expr:
        target, where = t.children[0], _args(t.children[1])
        if len(where) != 1:
            self.ctx.warn(
                t.meta, "an item of a two-dimensional array is not in bgr yet; 0 stands in"
            )
            return n.Number(0.0)
        return n.Index(self(target), self(where[0]), pos=pos(t.meta))

    def _fcall(self, t: Tree) -> n.Expr:
        name = dotted(t.children[0])
        if name in WORD_ARGUMENTS and t.children[1] is not None:
            arg = t.children[1].children[0]
            word = dotted(arg.children[0]) if isinstance(arg, Tree) and arg.data == "name" else None
            if word in WORD_ARGUMENTS[name]:  # an occlusion query's label comes after
                rest = [self.arg(a) for a in _args(t.children[1])[1:]]
                return n.Call(name, [n.Name(word), *rest])
            if name == "geometry.angle":
                self.ctx.warn(t.meta, f"geometry.angle({word or ''}) is not in bgr; 0 stands in")
                return n.Number(0.0)
            self.ctx.warn(
                t.meta,
                "geometry.area() of this selector is not in bgr yet; the "
                "whole geometry's area stands in",
            )
            return n.Call(name, [])
        if name.startswith("geometry.") and name in BUILTINS and BUILTINS[name].most == 0:
            if t.children[1] is not None:
                self.ctx.warn(
                    t.meta,
                    f"{name}() of some faces only (a face selector) is not in "
                    "bgr yet; the whole geometry's value stands in",
                )
            found = self.ctx.function(name, [], t.meta)
            return found if found is not None else n.Call(name, [])
        if name not in BUILTINS and name != "pow" and self.ctx.function(name, [], t.meta) is None:
            self.ctx.warn(
                t.meta, f"function '{name}' has no bgr equivalent; {_show(neutral(name))} stands in"
            )
            return neutral(name)
        args = [self.arg(a) for a in _args(t.children[1])]
        found = self.ctx.function(name, args, t.meta)
        if found is not None:
            return found
        if name == "pow" and len(args) == 2:
            return n.Binary("**", args[0], args[1])
        if name == "find" and len(args) == 2:  # the first occurrence
            args.append(n.Number(0.0))
        return n.Call(name, args)

    def _fcall_block(self, t: Tree) -> n.Expr:
        name = dotted(t.children[0])
        self.ctx.warn(t.meta, f"{name}(...) {{ selector: value }} is not in bgr yet; 0 stands in")
        return n.Number(0.0)

    def arg(self, t) -> n.Expr:
        """A function argument: a plain expression (``'`` and ``~`` have no meaning there)."""
        if isinstance(t, Tree) and t.data in ("rel_arg", "float_arg"):
            self.ctx.warn(t.meta, "a ' or ~ size outside an operation is dropped")
            return self(t.children[0])
        if isinstance(t, Tree) and t.data == "keyword_arg":
            self.ctx.warn(t.meta, f"named argument '{t.children[0]}' is read by position")
            return self(t.children[1])
        return self(t)

    # ---- operators -------------------------------------------------------------------------
    def _chain(self, t: Tree) -> n.Expr:
        items = t.children
        out = self(items[0])
        for k in range(1, len(items), 2):
            op = str(items[k])
            out = n.Binary(OPERATORS.get(op, op), out, self(items[k + 1]), pos=pos(t.meta))
        return out

    _or_expr = _and_expr = _cmp = _sum = _prod = _chain

    def _prefix(self, t: Tree) -> n.Expr:
        op = str(t.children[0])
        operand = self(t.children[1])
        if op == "-" and isinstance(operand, n.Number):
            return n.Unary("-", operand)
        return n.Unary("not" if op == "!" else op, operand)

    def _expr_cond(self, t: Tree) -> n.Expr:
        parts = [c for c in t.children if not (isinstance(c, Token) and c.type in ("CASE", "ELSE"))]
        conds, values = parts[0:-1:2], parts[1:-1:2]
        out = self(parts[-1])
        for cond, value in reversed(list(zip(conds, values, strict=True))):
            out = n.Ternary(self(cond), self(value), out)
        return out

    def _expr_stoch(self, t: Tree) -> n.Expr:
        parts = [c for c in t.children if not (isinstance(c, Token) and c.type in ("PCT", "ELSE"))]
        probs, values = parts[0:-1:2], parts[1:-1:2]
        return stochastic_chain(
            [self(p) for p in probs], [self(v) for v in values], self(parts[-1])
        )


def stochastic_chain(percents: list[n.Expr], values: list, otherwise):
    """``p1%: v1 p2%: v2 else: w`` as ``p(p1/100) ? v1 : (p(p2/(100-p1)) ? v2 : w)``: each value
    keeps CGA's chance, since a later draw happens only when the earlier ones failed."""
    out = otherwise
    spent: list[n.Expr] = []
    conds = []
    for pct in percents:
        if all(isinstance(s, n.Number) for s in spent) and isinstance(pct, n.Number):
            left = 100.0 - sum(s.value for s in spent if isinstance(s, n.Number))
            share: n.Expr = n.Number(min(1.0, pct.value / left) if left > 0 else 1.0)
        else:
            rest: n.Expr = n.Number(100.0)
            for s in spent:
                rest = n.Binary("-", rest, s)
            share = n.Binary("/", pct, rest)
        conds.append(n.Call("p", [share]))
        spent.append(pct)
    for cond, value in reversed(list(zip(conds, values, strict=True))):
        out = n.Ternary(cond, value, out)
    return out


def _args(t) -> list:
    return [] if t is None else list(t.children)


def _show(e: n.Expr) -> str:
    if isinstance(e, n.Bool):
        return "false"
    if isinstance(e, n.String):
        return f'"{e.value}"'
    return f"{e.value:g}" if isinstance(e, n.Number) else "0"


def bare_word(t) -> str | None:
    """The bare name an argument is (``x``, ``world.up``, ``inside``), or None."""
    if isinstance(t, Tree) and t.data == "name":
        return dotted(t.children[0])
    if isinstance(t, Tree) and t.data == "dotted":
        return dotted(t)
    if isinstance(t, Tree) and t.data in ("true", "false"):
        return t.data
    return None


def literal_string(t) -> str | None:
    """The text of an argument that is a string literal, unquoted; None for any other."""
    if isinstance(t, Tree) and t.data == "string":
        return unquote(t.children[0])
    return None
