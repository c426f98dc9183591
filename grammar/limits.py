"""How deeply a grammar may nest, measured without recursion (docs/language.md, "Limits").

The checker, the formatter, the expression compiler and the derivation walk nested expressions
and blocks with Python calls, one or a few per level, so the nesting a file may have is bounded
here, once, where the parser and the checker can report it with a place; every later stage can
then trust it and never meets Python's recursion limit (1,000 frames by default).

Flat chains are not nesting: every stage handles the left spine of an operator chain
(``1 + 1 + ... + 1``, ``a and b and c``) and the else spine of a ternary chain
(``c1 ? a : c2 ? b : d``) in a loop, so they count as one level however long they are.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

from . import nodes as n

MAX_NESTING = 100
"""Levels of expression nesting (parentheses, prefix operators, ``**``, calls, ternary
branches), the bodies of the funcs an expression calls included."""

MAX_BLOCK_NESTING = 50
"""Levels of ``{ }`` blocks, ``{ }*`` repeat groups and ``[ ]`` brackets inside one rule."""


_LEAVES = (n.Number, n.String, n.Bool, n.Name)


def children(e) -> list:
    """The sub-expressions one level below ``e``: a whole left spine of binary operators, or a
    whole else spine of ternaries, is one level."""
    if isinstance(e, n.Binary):
        out = []
        while isinstance(e, n.Binary):
            out.append(e.right)
            e = e.left
        out.append(e)
        return out
    if isinstance(e, n.Ternary):
        out = []
        while isinstance(e, n.Ternary):
            out += (e.cond, e.then)
            e = e.otherwise
        out.append(e)
        return out
    if isinstance(e, n.Unary):
        return [e.operand]
    if isinstance(e, n.Call):
        return list(e.args)
    if isinstance(e, n.Relative):
        return [e.expr]
    if isinstance(e, n.Keyword):
        return [e.value]
    if isinstance(e, n.Array):
        return list(e.items)
    if isinstance(e, n.Index):
        return [e.target, e.index]
    return []


def expr_depth(e, call_depth: Callable[[str], int] | None = None) -> int:
    """Levels of nesting of an expression, counted iteratively.

    ``call_depth(name)`` gives the levels a call of the func ``name`` adds below the call (its
    body's depth); without it, a call counts only its arguments.
    """
    depth: dict[int, int] = {}
    stack: list[tuple[object, bool]] = [(e, False)]
    while stack:
        node, done = stack.pop()
        if not done:
            stack.append((node, True))
            stack += ((k, False) for k in children(node))
            continue
        d = max((depth[id(k)] for k in children(node)), default=0)
        if call_depth is not None and isinstance(node, n.Call):
            d = max(d, call_depth(node.name))
        depth[id(node)] = d + 1
    return depth[id(e)]


def expressions(item) -> Iterator:
    """Every top-level expression of a declaration or rule (attr values, func bodies, defaults,
    percentages, conditions, arguments, split sizes and selectors), without recursion."""
    if isinstance(item, (n.Attr, n.Const)):
        yield item.value
        return
    if isinstance(item, n.Func):
        yield item.body
        return
    if not isinstance(item, n.Rule):
        return
    yield from (d for d in item.defaults if d is not None)
    for node, _level in steps_in(item):
        if isinstance(node, (n.Choice, n.Case)):
            test = node.prob if isinstance(node, n.Choice) else node.cond
            if test is not None:
                yield test
        elif isinstance(node, (n.Operation, n.Successor)):
            yield from node.args
        elif isinstance(node, n.Entry):
            yield node.key


def steps_in(rule: n.Rule) -> Iterator[tuple[object, int]]:
    """Every branch, step, block entry and group of a rule, with its bracket level: the number of
    ``{ }``, ``{ }*`` and ``[ ]`` around it (a block's entries are one level in)."""
    body = rule.body
    branches = (
        body.choices
        if isinstance(body, n.Stochastic)
        else (body.cases if isinstance(body, n.Conditional) else [])
    )
    stack: list[tuple[object, int]] = [(b, 0) for b in reversed(branches)]
    if isinstance(body, n.Sequence):
        stack += ((s, 0) for s in reversed(body.steps))
    while stack:
        node, level = stack.pop()
        yield node, level
        if isinstance(node, (n.Choice, n.Case)):
            stack += ((s, level) for s in reversed(node.body.steps))
        elif isinstance(node, n.Push):
            stack += ((s, level + 1) for s in reversed(node.steps))
        elif isinstance(node, n.Operation) and node.block is not None:
            stack += ((e, level + 1) for e in reversed(node.block.entries))
        elif isinstance(node, n.Group):
            stack += ((e, level + 1) for e in reversed(node.entries))
        elif isinstance(node, n.Entry):
            stack += ((s, level) for s in reversed(node.body.steps))


def nesting_problem(item) -> tuple[n.Pos, str, str] | None:
    """(place, message, hint) when a declaration or rule nests deeper than the limits allow."""
    if isinstance(item, n.Rule):
        deepest, first = 0, None
        for node, level in steps_in(item):
            if level > deepest:
                deepest = level
            if level > MAX_BLOCK_NESTING and first is None:
                first = node.pos  # type: ignore[attr-defined]
        if first is not None:
            return (
                first,
                f"blocks nested too deeply ({deepest} levels; at most {MAX_BLOCK_NESTING})",
                "move the inner blocks into a rule of their own",
            )
    for e in expressions(item):
        if isinstance(e, _LEAVES):  # most arguments: no walk needed
            continue
        depth = expr_depth(e)
        if depth > MAX_NESTING:
            return (
                e.pos,
                f"expression nested too deeply ({depth} levels; at most {MAX_NESTING})",
                "compute parts of it in attrs or consts, or hand them to a rule as parameters",
            )
    return None
