"""CGA attrs and consts whose value reads the shape, translated.

CGA evaluates an attr's default on the initial shape (``attr h = geometry.area / 10``); bgr's
attrs and consts are values of the grammar, not of a shape.  Such an attr gets a plain default
and is ``set()`` to its expression when the start rule begins, after what it reads (through
functions too): the same values on every lot, as CityEngine computes them.
"""

from __future__ import annotations

from ..grammar import nodes as n
from ..grammar.registry import OPERATIONS

SHAPE_NAMES = ("scope.", "split.", "comp.", "geometry.", "initialShape.")


class At:
    """A place (line, column) for a warning about a node the translator built."""

    def __init__(self, p: n.Pos) -> None:
        self.line, self.column = p.line, p.column


def shape_attrs(tr, items: list, attrs: list[n.Attr], consts: list[n.Const]) -> list:
    """Attrs and consts whose value reads the shape: a plain default, then ``set()`` when the
    start rule begins, in an order where each comes after what it reads."""
    funcs = {f.name: f.body for f in items if isinstance(f, n.Func)}
    values = {a.name: a.value for a in attrs} | {c.name: c.value for c in consts}
    memo: dict[str, bool] = {}

    def reads_shape(e, seen=frozenset()) -> bool:
        for x in _walk(e):
            if isinstance(x, n.Name) and x.name.startswith(SHAPE_NAMES):
                return True
            if isinstance(x, n.Call) and x.name.startswith("geometry."):
                return True
            ref = x.name if isinstance(x, (n.Name, n.Call)) else None
            if ref is None or ref in seen:
                continue
            if ref not in memo and (ref in values or ref in funcs):
                target = values.get(ref, funcs.get(ref))
                memo[ref] = reads_shape(target, seen | {ref})
            if memo.get(ref):
                return True
        return False

    moving = [d for d in attrs + consts if reads_shape(d.value)]
    if not moving:
        return items
    sets = []
    for d in _ordered(moving, funcs):
        sets.append(n.Operation("set", [n.Name(d.name), d.value]))
        tr.warn(
            At(d.pos),
            f"'{d.name}' reads the shape: bgr computes it when the start "
            "rule begins (set()), so --set does not override it",
        )
    out = []
    for item in items:
        if any(item is d for d in moving):
            item = n.Attr(
                item.name,
                _placeholder(item.value),
                pos=item.pos,
                annotations=getattr(item, "annotations", None)
                or ([] if isinstance(item, n.Attr) else [n.Annotation("Hidden")]),
            )
        out.append(item)
    return prepend_to_start(tr, out, sets)


def prepend_to_start(tr, items: list, steps: list) -> list:
    rules = [r for r in items if isinstance(r, n.Rule)]
    if not rules:
        return items
    start = next((r for r in rules if r.name == tr.start), rules[0])
    if isinstance(start.body, n.Sequence):
        start.body.steps[:0] = steps
        return items
    inner = n.Rule(tr.fresh(start.name + "Main", OPERATIONS), [], start.body, pos=start.pos)
    start.body = n.Sequence(steps + [n.Successor(inner.name)])
    at = items.index(start)
    return items[: at + 1] + [inner] + items[at + 1 :]


_walk = n.walk  # every node of an expression


def _placeholder(e: n.Expr) -> n.Expr:
    """A literal of the type ``e`` seems to have: its first literal leaf's, else 0."""
    for x in _walk(e):
        if isinstance(x, n.Ternary):
            continue
        if isinstance(x, n.String):
            return n.String("")
        if isinstance(x, n.Bool):
            return n.Bool(False)
        if isinstance(x, (n.Number, n.Binary, n.Unary)):
            return n.Number(0.0)
    return n.Number(0.0)


def _ordered(decls: list, funcs: dict) -> list:
    """Declarations in file order, each moved after those it reads (through functions too)."""
    names = {d.name for d in decls}
    done: list = []
    placed: set[str] = set()

    def reads(e, seen: set) -> set[str]:
        out = set()
        for x in _walk(e):
            if isinstance(x, n.Name) and x.name in names:
                out.add(x.name)
            elif isinstance(x, n.Call) and x.name in funcs and x.name not in seen:
                seen.add(x.name)
                out |= reads(funcs[x.name], seen)
        return out

    def place(d, stack=()):
        if d.name in placed or d.name in stack:
            return
        for name in sorted(reads(d.value, set())):
            place(next(o for o in decls if o.name == name), (*stack, d.name))
        placed.add(d.name)
        done.append(d)

    for d in decls:
        place(d)
    return done
