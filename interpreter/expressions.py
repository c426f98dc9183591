"""Expressions compiled once into Python closures, then evaluated per shape.

``compile_expr(node, module)`` resolves every name when the grammar is prepared (the checker has
already proved they exist) and returns a function of a :class:`Context`.  Evaluating a closure
tree is several times faster than walking the syntax tree for every shape.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable
from pathlib import Path
from typing import Any

from bgr.grammar import nodes as n
from bgr.grammar.errors import BgrError, Diagnostic, source_line
from bgr.grammar.registry import BUILTIN_NAMES, OCCLUSION

from . import arrays, string_lists
from .context import Context as Context  # importable from here, as before
from .context import RuleRef as RuleRef
from .randomness import Stream, child_hash, name_hash, root_hash
from .string_lists import as_text, number_text

Value = Any
Compiled = Callable[["Context"], Value]


class BgrRuntimeError(BgrError):
    """A fault while deriving: division by zero, a negative size, a missing asset file..."""


def runtime_error(module, pos: n.Pos, message: str, hint: str | None = None) -> BgrRuntimeError:
    return BgrRuntimeError(
        Diagnostic(
            module.path,
            pos.line,
            pos.column,
            message,
            hint,
            source_line(module.module.source, pos.line),
        )
    )


def _set_or_declared(values: dict, name: str, key: tuple) -> Compiled:
    """An attr's value as the shape has it: the last set() of it on the shape's way
    (``Shape.attrs``, by (module id, name)), else its value for the lot."""

    def attr(ctx):
        shape = ctx.shape
        if shape is not None and shape.attrs:
            for k, v in shape.attrs:
                if k == key:
                    return v
        return values[name]

    return attr


def _num(module, pos, value, what="a number"):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise runtime_error(module, pos, f"expected {what}, got {_show(value)}")
    return value


def _show(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'the string "{value}"'
    if isinstance(value, tuple):
        return f"an array of {len(value)}"
    return repr(value)  # numbers, and RuleRef: "the rule 'Arched'"


_TEXT = string_lists.TEXT  # len, count, find, substring, and the string lists'


_ARITH = {
    "+": operator.add,
    "-": operator.sub,
    "*": operator.mul,
    "/": operator.truediv,
    "%": operator.mod,
    "**": operator.pow,
}
_COMPARE = {
    "==": operator.eq,
    "!=": operator.ne,
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
}


def _deg(f):
    return lambda x: f(math.radians(x))


_MATH = {
    "floor": math.floor,
    "ceil": math.ceil,
    "abs": abs,
    "sqrt": math.sqrt,
    "sin": _deg(math.sin),
    "cos": _deg(math.cos),
    "tan": _deg(math.tan),
    "round": lambda x: math.floor(x + 0.5) if x >= 0 else -math.floor(-x + 0.5),
    # CGA's other math functions: inverse trigonometry answers in degrees, as sin() takes them
    "acos": lambda x: math.degrees(math.acos(x)),
    "asin": lambda x: math.degrees(math.asin(x)),
    "atan": lambda x: math.degrees(math.atan(x)),
    "exp": math.exp,
    "ln": math.log,
    "log10": math.log10,
    "rint": lambda x: float(round(x)),  # the nearest whole number, halves to the even one
    "isinf": math.isinf,
    "isnan": math.isnan,
}


# CGA's geometry functions that measure the shape's geometry (interpreter/geometry/queries.py)
_GEOMETRY_QUERIES = frozenset(name for name in BUILTIN_NAMES if name.startswith("geometry."))


class Compiler:
    """Compiles the expressions of one checked module (a :class:`bgr.Grammar`)."""

    def __init__(self, module, values: dict[str, Value], modules: dict[int, Compiler]) -> None:
        self.module = module  # the checked Grammar
        self.values = values  # attrs and consts of this module, already evaluated
        self.modules = modules  # id(Grammar) -> Compiler, for imported names
        self.funcs: dict[str, Callable] = {}

    # ---- names -------------------------------------------------------------------------
    def name(self, e: n.Name, local: frozenset) -> Compiled:
        name = e.name
        if name in local:
            return lambda ctx: ctx.args[name]
        if name in self.values:
            values = self.values
            if name in getattr(self.module, "settable", ()):  # set() may have changed it here
                return _set_or_declared(values, name, (id(self.module), name))
            return lambda ctx: values[name]
        if name == "scope.sx":
            return lambda ctx: ctx.shape.size[0]
        if name == "scope.sy":
            return lambda ctx: ctx.shape.size[1]
        if name == "scope.sz":
            return lambda ctx: ctx.shape.size[2]
        if name in ("scope.x", "scope.y", "scope.z"):
            i = "xyz".index(name[-1])
            return lambda ctx: ctx.shape.local_origin[i]
        if name == "split.index":
            return lambda ctx: ctx.split_index
        if name == "split.total":
            return lambda ctx: ctx.split_total
        if name == "comp.index":
            return lambda ctx: ctx.comp_index
        if name == "comp.total":
            return lambda ctx: ctx.comp_total
        if name == "comp.left":
            return lambda ctx: ctx.comp_left
        if name == "comp.right":
            return lambda ctx: ctx.comp_right
        if name == "comp.sel":
            return lambda ctx: ctx.comp_sel
        if name == "depth":
            return lambda ctx: ctx.shape.depth
        if name in _GEOMETRY_QUERIES:  # geometry.area written bare, as CGA allows
            from .geometry.queries import QUERIES

            query = QUERIES[name]
            return lambda ctx: query(ctx.shape, ctx.library)
        if name == "seed":
            return lambda ctx: ctx.seed
        module, member = self.module.lookup_module(name)
        if member in module.rules or member in module.terminals:
            ref = RuleRef(module, member)
            return lambda ctx: ref
        alias, member = name.split(".", 1)
        imported = self.module.imports[alias]
        values = self.modules[id(imported)].values
        if member in getattr(imported, "settable", ()):  # set(alias.attr, v) may have changed it
            return _set_or_declared(values, member, (id(imported), member))
        return lambda ctx: values[member]

    # ---- expressions -------------------------------------------------------------------
    def expr(self, e, local: frozenset = frozenset()) -> Compiled:
        module = self.module
        if isinstance(e, (n.Number, n.String, n.Bool)):
            value = e.value
            return lambda ctx: value
        if isinstance(e, n.Name):
            return self.name(e, local)
        if isinstance(e, n.Relative):
            return self.expr(e.expr, local)
        if isinstance(e, n.Unary):
            f = self.expr(e.operand, local)
            if e.op == "not":
                return lambda ctx: not f(ctx)
            if e.op == "-":
                return lambda ctx: -_num(module, e.pos, f(ctx))
            return lambda ctx: +_num(module, e.pos, f(ctx))
        if isinstance(e, n.Ternary):
            return self.ternary(e, local)
        if isinstance(e, n.Binary):
            return self.binary(e, local)
        if isinstance(e, n.Call):
            return self.call(e, local)
        if isinstance(e, (n.Array, n.Index)):
            return self.array(e, local)
        raise TypeError(f"not an expression: {e!r}")

    def array(self, e: n.Array | n.Index, local: frozenset) -> Compiled:
        """``[a, b]`` and ``a[i]`` (arrays.py), their problems reported at their place."""
        module, pos = self.module, e.pos
        if isinstance(e, n.Array):
            parts = [self.expr(x, local) for x in e.items]

            def make(values):
                return arrays.array_of(values)
        else:
            parts = [self.expr(e.target, local), self.expr(e.index, local)]

            def make(values):
                return arrays.item(*values)

        def evaluate(ctx):
            try:
                return make([f(ctx) for f in parts])
            except arrays.ArrayError as problem:
                raise runtime_error(module, pos, str(problem)) from None

        return evaluate

    def ternary(self, e: n.Ternary, local: frozenset) -> Compiled:
        """``c1 ? a : c2 ? b : d``: the else spine is one loop, however long (grammar.limits)."""
        branches = []
        while isinstance(e, n.Ternary):
            branches.append((self.expr(e.cond, local), self.expr(e.then, local)))
            e = e.otherwise
        last = self.expr(e, local)
        if len(branches) == 1:
            (c, a) = branches[0]
            return lambda ctx: a(ctx) if c(ctx) else last(ctx)

        def pick(ctx):
            for c, a in branches:
                if c(ctx):
                    return a(ctx)
            return last(ctx)

        return pick

    def binary(self, e: n.Binary, local: frozenset) -> Compiled:
        """An operator chain: the left spine (``1 + 2 - 3 + ...``, ``a and b and c``) is one
        loop, however long, so its length costs no stack (grammar.limits)."""
        spine = []
        while isinstance(e, n.Binary):
            spine.append(e)
            e = e.left
        spine.reverse()  # innermost first: the order of evaluation
        leaf = self.expr(e, local)
        steps = [(self.combiner(node), self.expr(node.right, local)) for node in spine]
        if len(steps) == 1:
            ((combine, right),) = steps
            return lambda ctx: combine(leaf(ctx), right, ctx)

        def chain(ctx):
            value = leaf(ctx)
            for combine, right in steps:
                value = combine(value, right, ctx)
            return value

        return chain

    def combiner(self, e: n.Binary) -> Callable[[Value, Compiled, Context], Value]:
        """``combine(a, right, ctx)``: ``a op right(ctx)``; ``and``/``or`` evaluate the right
        side only when they need it."""
        module, pos = self.module, e.pos
        if e.op == "and":
            return lambda a, right, ctx: right(ctx) if a else a
        if e.op == "or":
            return lambda a, right, ctx: a if a else right(ctx)
        if e.op in _COMPARE:
            cmp = _COMPARE[e.op]

            def compare(a, right, ctx):
                b = right(ctx)
                try:
                    return cmp(a, b)
                except TypeError:
                    raise runtime_error(
                        module, pos, f"cannot compare {_show(a)} with {_show(b)}"
                    ) from None

            return compare
        fn = _ARITH[e.op]
        op = e.op

        def arith(a, right, ctx):
            b = right(ctx)
            if op == "+" and (isinstance(a, str) or isinstance(b, str)):
                # a string and a number or boolean join as text, as in CGA ("Floor" + 2)
                left, right_text = as_text(a), as_text(b)
                if left is None or right_text is None:
                    raise runtime_error(module, pos, f"cannot join {_show(a)} and {_show(b)}")
                return left + right_text
            try:
                result = fn(_num(module, pos, a), _num(module, pos, b))
            except ZeroDivisionError:
                raise runtime_error(
                    module, pos, "division by zero", "guard the divisor, e.g. x / max(n, 1)"
                ) from None
            except OverflowError:
                raise runtime_error(module, pos, "the result is too large") from None
            if isinstance(result, complex):
                raise runtime_error(module, pos, "a negative number to a fractional power")
            return result

        return arith

    def call(self, e: n.Call, local: frozenset) -> Compiled:
        module, pos, name = self.module, e.pos, e.name
        if name in ("geometry.area", "geometry.angle") and e.args:  # a bare word, not a value
            from .geometry.queries import angle, area

            word = e.args[0].name  # type: ignore[union-attr]  # the checker made sure
            query = area if name == "geometry.area" else angle
            return lambda ctx: query(ctx.shape, ctx.library, word)
        if name in OCCLUSION:  # inside(target, label): a bare word, then a value
            from .occlusion import query

            target = e.args[0].name if e.args else "all"  # type: ignore[union-attr]
            label = self.expr(e.args[1], local) if len(e.args) > 1 else None
            return lambda ctx: query(ctx, name, target, None if label is None else label(ctx))
        args = [self.expr(a, local) for a in e.args]
        if name == "rand":

            def rand(ctx):
                vals = [_num(module, pos, a(ctx)) for a in args]
                lo, hi = (0.0, 1.0) if not vals else ((0.0, vals[0]) if len(vals) == 1 else vals)
                return lo + (hi - lo) * ctx.stream.uniform()

            return rand
        if name == "randint":

            def randint(ctx):
                # the whole numbers n with a <= n <= b: bounds need not be whole (2.5 -> 3)
                a, b = (_num(module, pos, a(ctx)) for a in args)
                if not (math.isfinite(a) and math.isfinite(b)):
                    raise runtime_error(module, pos, f"randint({a!r}, {b!r}) needs finite bounds")
                lo, hi = math.ceil(a), math.floor(b)
                if hi < lo:
                    raise runtime_error(
                        module, pos, f"randint({a:g}, {b:g}): no whole number lies between them"
                    )
                return lo + min(int(ctx.stream.uniform() * (hi - lo + 1)), hi - lo)

            return randint
        if name in ("min", "max"):
            fn = min if name == "min" else max
            return lambda ctx: fn(_num(module, pos, a(ctx)) for a in args)
        if name == "listRandom":  # an item of a string list, drawn from the shape's stream
            (text,) = args

            def list_random(ctx):
                value = text(ctx)
                if not isinstance(value, str):
                    raise runtime_error(
                        module, pos, f"listRandom() needs a string, got {_show(value)}"
                    )
                found = string_lists.items(value)
                return (
                    found[min(int(ctx.stream.uniform() * len(found)), len(found) - 1)]
                    if found
                    else ""
                )

            return list_random
        if name in arrays.FUNCTIONS:  # size, index, splitString

            def array_call(ctx, fn=arrays.FUNCTIONS[name][0]):
                try:
                    return fn(*[f(ctx) for f in args])
                except arrays.ArrayError as problem:
                    raise runtime_error(module, pos, str(problem)) from None

            return array_call
        if name in _TEXT:  # CGA's string functions: len, count, find, substring, list*
            fn, kinds = _TEXT[name]

            def text_call(ctx):
                values = [f(ctx) for f in args]
                for value, kind in zip(values, kinds, strict=False):
                    if kind is str and not isinstance(value, str):
                        raise runtime_error(
                            module, pos, f"{name}() needs a string, got {_show(value)}"
                        )
                    if kind is float:
                        _num(module, pos, value)
                return fn(*values)

            return text_call
        if name == "atan2":
            y, x = args
            return lambda ctx: math.degrees(
                math.atan2(_num(module, pos, y(ctx)), _num(module, pos, x(ctx)))
            )
        if name == "p":  # CGA's p(prob): true with that probability, from the shape's stream
            (prob,) = args
            return lambda ctx: ctx.stream.uniform() < _num(module, pos, prob(ctx))
        if name == "float":
            (value,) = args

            def to_float(ctx):
                v = value(ctx)
                if isinstance(v, str):
                    found = number_text(v)
                    if found is None:  # CGA gives NaN; bgr's numbers are finite
                        raise runtime_error(module, pos, f"float() of {_show(v)}: not a number")
                    return found
                if isinstance(v, bool):
                    return 1.0 if v else 0.0
                return _num(module, pos, v)

            return to_float
        if name == "bool":
            (value,) = args

            def to_bool(ctx):
                v = value(ctx)
                if isinstance(v, str):
                    return v.strip().lower() in ("true", "1")
                if isinstance(v, bool):
                    return v
                return _num(module, pos, v) != 0

            return to_bool
        if name == "str":
            (value,) = args

            def text(ctx):
                found = as_text(value(ctx))
                if found is None:
                    raise runtime_error(module, pos, f"str() of {_show(value(ctx))}")
                return found

            return text
        if name == "clamp":
            x, lo, hi = args
            return lambda ctx: min(
                max(_num(module, pos, x(ctx)), _num(module, pos, lo(ctx))),
                _num(module, pos, hi(ctx)),
            )
        if name in _GEOMETRY_QUERIES:  # geometry.area() and the others: the shape's geometry
            from .geometry.queries import QUERIES

            query = QUERIES[name]
            return lambda ctx: query(ctx.shape, ctx.library)
        if name == "geometry.isPlanar":
            from .geometry.queries import is_planar

            tol = args[0] if args else (lambda ctx: 0.0)
            return lambda ctx: is_planar(ctx.shape, ctx.library, _num(module, pos, tol(ctx)))
        if name == "geometry.isRectangular":
            tolerance = args[0] if args else (lambda ctx: 1.0)
            return lambda ctx: is_rectangular(ctx.shape, _num(module, pos, tolerance(ctx)))
        if name in _MATH:
            fn, (a,) = _MATH[name], args

            def math_call(ctx):
                try:
                    return fn(_num(module, pos, a(ctx)))
                except (ValueError, OverflowError):
                    raise runtime_error(module, pos, f"{name}() of {a(ctx)} is undefined") from None

            return math_call
        # a func of this module or of an imported one
        target, member = module.lookup_module(name)
        compiler = self.modules[id(target)]
        return compiler.func_call(member, args, module, pos)

    def func_call(self, name: str, args: list[Compiled], caller, pos) -> Compiled:
        """A call of the func ``name``.  The checker bounds the nesting of funcs that do not call
        themselves (grammar.limits); a recursion's depth is only known while deriving, so there,
        and only there, Python's recursion limit is what stops it, with a located error."""
        func = self.module.funcs[name]
        params = func.params
        holder = self.funcs
        recursive = name in self.module.recursive_funcs

        def call(ctx):
            body = holder.get(name)
            if body is None:
                body = holder[name] = self.expr(func.body, frozenset(params))
            bound = {p: a(ctx) for p, a in zip(params, args, strict=False)}
            saved = ctx.args
            ctx.args = bound
            try:
                return body(ctx)
            except RecursionError:
                if not recursive:
                    raise
                raise runtime_error(
                    caller,
                    pos,
                    f"function '{name}' calls itself too deeply (without end?)",
                    "a func may call itself a few hundred levels deep at most",
                ) from None
            finally:
                ctx.args = saved

        return call


def evaluate_values(
    grammar,
    overrides: dict[str, Value],
    modules: dict[int, Compiler],
    seed: int = 0,
    lot_index: int = 0,
) -> dict[str, Value]:
    """Evaluate a module's attrs and consts in dependency order (attrs may be overridden).

    rand() in an attr draws from a stream of the seed, the lot and the attr's own name: each lot
    of a GeoJSON gets its own draw, and the draw does not depend on how a path was spelt.
    """
    values: dict[str, Value] = {}
    compiler = Compiler(grammar, values, modules)
    modules[id(grammar)] = compiler
    pending = {**grammar.attrs, **grammar.consts}
    ctx = Context(None, {}, None, seed)

    def compute(name):
        if name in grammar.attrs and name in overrides:
            values[name] = overrides[name]
        else:
            item = pending[name]
            ctx.stream = Stream(
                child_hash(
                    root_hash(seed), name_hash(Path(grammar.path).stem + "." + name), lot_index
                )
            )
            try:
                values[name] = compiler.expr(item.value)(ctx)
            except AttributeError:  # a func that reads the shape, called where there is none
                raise runtime_error(
                    grammar,
                    item.pos,
                    f"'{name}' reads the shape (scope.*, depth) through a "
                    "function, but attrs and consts are evaluated before any shape exists",
                    "compute it in a rule instead",
                ) from None

    for root in pending:  # dependencies first, with a stack: a long chain of attrs is no recursion
        stack = [(root, False)]
        while stack:
            name, ready = stack.pop()
            if name in values:
                continue
            if ready:
                compute(name)
                continue
            stack.append((name, True))
            if not (name in grammar.attrs and name in overrides):
                deps = n.names_in(pending[name].value)
                stack += ((d.name, False) for d in deps if d.name in pending)
    return values


def is_rectangular(shape, tolerance: float) -> bool:
    """geometry.isRectangular of a shape: its 2D outline, or an extruded prism's base."""
    from .geometry.meshes import PLANE_AXES
    from .geometry.polygons import is_rectangle
    from .shapes import Flat, Prism, Solid

    geom = shape.geom
    if isinstance(geom, Solid):
        return geom.name == "cube"
    if isinstance(geom, (Flat, Prism)):
        p, q = PLANE_AXES[geom.k]
        return is_rectangle(geom.polys, shape.size[p], shape.size[q], tolerance)
    return False
