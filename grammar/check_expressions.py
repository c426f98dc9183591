"""Checks of expressions: every name and call resolved, argument counts, nesting depth.

A name is a parameter, an attr or const of the module or of an import (``alias.name``), or a
built-in; a call is a built-in or a func.  Definition cycles among attrs and consts and
expressions nested too deeply through the funcs they call (:mod:`bgr.grammar.limits`) are
reported here too.
"""

from __future__ import annotations

from . import nodes as n
from .checker_base import CheckerBase
from .errors import suggest
from .limits import MAX_NESTING, children, expr_depth, expressions
from .registry import (
    AXIS_NAMES,
    BUILTIN_NAMES,
    BUILTINS,
    OCCLUSION,
    OPERATIONS,
    PRIMITIVES,
    ROOF_KINDS,
    WORD_ARGUMENTS,
)


class ExpressionChecks(CheckerBase):
    """Resolves the names and calls of expressions and bounds their nesting."""

    def arg(self, arg, local: set[str], relative_ok: bool) -> None:
        if isinstance(arg, n.Keyword):
            self.expr(arg.value, local, in_rule=True)
        elif isinstance(arg, n.Relative):
            if not relative_ok:
                self.error(
                    arg.pos,
                    "a relative size ('f) is not allowed here",
                    "relative sizes go in s(), t() and split sizes",
                )
            self.expr(arg.expr, local, in_rule=True)
        else:
            self.expr(arg, local, in_rule=True)

    def expr(self, e, local: set[str], in_rule: bool) -> None:
        """Resolve every name and call in an expression (iteratively: chains can be long)."""
        stack = [e]
        while stack:
            e = stack.pop()
            if isinstance(e, n.Name):
                self.name(e, local, in_rule)
            elif isinstance(e, n.Binary):
                stack += (e.right, e.left)
            elif isinstance(e, n.Unary):
                stack.append(e.operand)
            elif isinstance(e, n.Ternary):
                stack += (e.otherwise, e.then, e.cond)
            elif isinstance(e, n.Array):
                stack += reversed(e.items)
            elif isinstance(e, n.Index):
                stack += (e.index, e.target)
            elif isinstance(e, n.Call):
                self.call(e)
                if e.name in OCCLUSION:
                    self.g.occlusion = True
                if e.name in WORD_ARGUMENTS and e.args:  # a bare word, not a value
                    self.word_argument(e.name, e.args[0])
                    stack += reversed(e.args[1:])  # an occlusion query's label: a value
                    continue
                stack += reversed(e.args)
            elif isinstance(e, n.Relative):
                self.error(e.pos, "a relative size ('f) is not allowed here")

    def word_argument(self, name: str, arg) -> None:
        """geometry.area(top), geometry.angle(maxSlope): a word from a fixed set, written bare."""
        words = WORD_ARGUMENTS[name]
        if not (isinstance(arg, n.Name) and arg.name in words):
            what = "a face selector" if name == "geometry.area" else "one of its words"
            self.error(
                arg.pos,
                f"{name}() takes {what}",
                f"one of {', '.join(words)}, e.g. {name}({words[0]})",
            )

    def name(self, e: n.Name, local: set[str], in_rule: bool) -> None:
        name = e.name
        if name in local or name in self.g.attrs or name in self.g.consts:
            return
        if name in BUILTIN_NAMES:
            if not in_rule and name != "seed":
                self.error(
                    e.pos,
                    f"'{name}' is only known while deriving a shape",
                    "use it in a rule or a func, not in an attr or const",
                )
            return
        if "." in name:
            alias, member = name.split(".", 1)
            if alias in self.broken_aliases:
                return
            if alias in self.g.imports:
                module = self.g.imports[alias]
                if member in module.attrs or member in module.consts:
                    return
                if member in module.rules or member in module.terminals:
                    self.error(
                        e.pos,
                        f"'{name}' is a rule, not a value",
                        "a rule can only be handed whole to a rule parameter: R(part = Name)",
                    )
                    return
                if member[:1].isupper():  # most likely a rule handed to a parameter
                    hint = suggest(member, list(module.rules) + list(module.terminals))
                    self.error(e.pos, f"module '{alias}' has no rule '{member}'", hint)
                    return
                hint = suggest(member, list(module.attrs) + list(module.consts))
                self.error(e.pos, f"module '{alias}' has no attr or const '{member}'", hint)
                return
            if alias in ("scope", "split", "comp"):
                known = [k for k in BUILTIN_NAMES if k.startswith(alias + ".")]
                self.error(
                    e.pos,
                    f"unknown name '{name}'",
                    suggest(name, known) or f"known: {', '.join(known)}",
                )
                return
            self.unknown_alias(alias, e.pos)
            return
        if name in self.g.rules or name in self.g.terminals:
            self.error(
                e.pos,
                f"'{name}' is a rule, not a value",
                "a rule can only be handed whole to a rule parameter: R(part = Name)",
            )
            return
        known = list(local) + list(self.g.attrs) + list(self.g.consts) + list(BUILTIN_NAMES)
        hint = suggest(name, known)
        if hint is None and (name in AXIS_NAMES or name in ROOF_KINDS or name in PRIMITIVES):
            hint = (
                "bare words like this are only arguments of split, roof, i and similar operations"
            )
        self.error(e.pos, f"unknown name '{name}'", hint, len(name))

    def call(self, e: n.Call) -> None:
        name, count = e.name, len(e.args)
        if name in BUILTINS:
            b = BUILTINS[name]
            if count < b.least or (b.most is not None and count > b.most):
                want = (
                    str(b.least)
                    if b.least == b.most
                    else (f"{b.least} or more" if b.most is None else f"{b.least} to {b.most}")
                )
                noun = "argument" if want == "1" else "arguments"
                self.error(
                    e.pos,
                    f"'{name}' takes {want} {noun}, given {count}",
                    f"{b.usage}: {b.doc}",
                    len(name),
                )
            return
        module, member = self.g.lookup_module(name)
        if "." in name and name.split(".", 1)[0] in self.broken_aliases:
            return
        if "." in name and module is self.g:
            self.unknown_alias(name.split(".", 1)[0], e.pos)
            return
        if member in module.funcs:
            params = module.funcs[member].params
            if count != len(params):
                self.error(
                    e.pos,
                    f"function '{name}' takes {_count(len(params), 'argument')}, given {count}",
                    f"it is declared as {member}({', '.join(params)})",
                    len(name),
                )
            return
        if module is self.g and name in OPERATIONS:
            self.error(
                e.pos,
                f"'{name}' is an operation, not a function; it cannot be used in an expression",
                length=len(name),
            )
            return
        if module is self.g and (name in self.g.rules or name in self.g.terminals):
            self.error(e.pos, f"'{name}' is a rule, not a function", length=len(name))
            return
        known = list(module.funcs) + (list(BUILTINS) if module is self.g else [])
        self.error(e.pos, f"unknown function '{name}'", suggest(member, known), len(name))

    def unknown_alias(self, alias: str, pos: n.Pos) -> None:
        hint = (
            suggest(alias, self.g.imports) or f"import it first: import stdlib.{alias} as {alias}"
        )
        self.error(pos, f"unknown module '{alias}'", hint, len(alias))

    def value_cycles(self) -> None:
        """attr a = b + 1; attr b = a: report a definition cycle among attrs and consts."""
        values: dict[str, n.Attr | n.Const] = {**self.g.attrs, **self.g.consts}
        deps = {
            name: {x.name for x in n.names_in(item.value) if x.name in values}
            for name, item in values.items()
        }
        state: dict[str, int] = {}
        for root in deps:
            if state.get(root):
                continue
            stack = [(root, iter(sorted(deps[root])))]
            path = [root]
            state[root] = 1
            while stack:
                node, children = stack[-1]
                child = next(children, None)
                if child is None:
                    state[node] = 2
                    stack.pop()
                    path.pop()
                elif state.get(child) == 1:
                    cycle = path[path.index(child) :] + [child]
                    self.error(
                        values[child].pos,
                        "attrs and consts define each other in a cycle: " + " -> ".join(cycle),
                    )
                    state[child] = 2
                elif not state.get(child):
                    state[child] = 1
                    stack.append((child, iter(sorted(deps[child]))))
                    path.append(child)

    def call_depth(self, name: str) -> int:
        """The levels a call of ``name`` adds: its func's body; 0 for a built-in, or a func whose
        depth is not known yet (it calls itself: that is bounded while deriving)."""
        module, member = self.g.lookup_module(name)
        return max(module.func_depths.get(member, 0), 0)

    def reported(self, e) -> bool:
        """Does ``e`` call a func whose nesting was already reported as too deep (depth -1)?"""
        for name in _calls_in(e):
            module, member = self.g.lookup_module(name)
            if module.func_depths.get(member) == -1:
                return True
        return False

    def call_nesting(self) -> None:
        """Nesting through func calls (grammar.limits): each func's body with the bodies of the
        funcs it calls, then every expression that calls a func.  Funcs are worked out callees
        first, with a stack; a func that calls itself, directly or not, is marked recursive."""
        g = self.g
        calls = {name: _calls_in(f.body) for name, f in g.funcs.items()}
        state: dict[str, int] = {}
        for root in g.funcs:
            if root in state:
                continue
            state[root] = 1
            path, pending = [root], [iter(calls[root])]
            while pending:
                callee = next(pending[-1], None)
                if callee is None:
                    name = path.pop()
                    pending.pop()
                    state[name] = 2
                    self.func_nesting(name)
                elif callee not in g.funcs:
                    continue
                elif state.get(callee) == 1:
                    g.recursive_funcs.update(path[path.index(callee) :])
                elif callee not in state:
                    state[callee] = 1
                    path.append(callee)
                    pending.append(iter(calls[callee]))
        if not any(m.func_depths for m in [g, *g.imports.values()]):
            return
        for item in g.module.items:
            if isinstance(item, n.Func):
                continue
            for e in expressions(item):
                if _calls_in(e) and not self.reported(e):
                    self.too_deep(e, expr_depth(e, self.call_depth))

    def func_nesting(self, name: str) -> None:
        """A func too deep is reported once: its callers are marked (-1) without a message."""
        body = self.g.funcs[name].body
        if self.reported(body):
            self.g.func_depths[name] = -1
            return
        depth = expr_depth(body, self.call_depth)
        self.g.func_depths[name] = -1 if self.too_deep(body, depth) else depth

    def too_deep(self, e, depth: int) -> bool:
        if depth <= MAX_NESTING:
            return False
        self.error(
            e.pos,
            f"expression nested too deeply ({depth} levels with the funcs it calls; "
            f"at most {MAX_NESTING})",
            "every level of a called func's body counts: compute parts in attrs or consts, "
            "or hand them to a rule as parameters",
        )
        return True


def _calls_in(e) -> list[str]:
    """The names called in an expression (built-ins included), without recursion."""
    out, stack = [], [e]
    while stack:
        node = stack.pop()
        if isinstance(node, n.Call):
            out.append(node.name)
        stack += children(node)
    return out


def _count(k: int, word: str) -> str:
    return f"{k} {word}" if k == 1 else f"{k} {word}s"
