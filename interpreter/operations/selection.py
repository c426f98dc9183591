"""Which components a comp block's selectors take: shared by comp(f), comp(e) and comp(v).

Each component is described by the set of selector words it answers to (``all``, its
quadrant, its slant, ``side``...); the block's entries take them left to right, and a
component taken by one entry is not offered to the next, as CGA's comp does.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

from bgr.grammar import nodes as n

from ..expressions import runtime_error

_SIN_1_DEGREE = math.sin(math.radians(1.0))
_COS_1_DEGREE = math.cos(math.radians(1.0))


def quadrant(nrm) -> str:
    """top, bottom, front, back, left or right, by a normal in the shape's scope."""
    x, y, z = nrm
    if abs(y) > 0.7071:
        return "top" if y > 0 else "bottom"
    if abs(x) >= abs(z):
        return "right" if x > 0 else "left"
    return "back" if z > 0 else "front"


def slant(nrm) -> str:
    """CGA's vertical, horizontal, aslant and nutant: the normal within 1 degree of the scope's
    horizontal plane, within 1 degree of its y axis, or between them facing up or down."""
    y = nrm[1]
    if abs(y) <= _SIN_1_DEGREE:
        return "vertical"
    if abs(y) >= _COS_1_DEGREE:
        return "horizontal"
    return "aslant" if y > 0 else "nutant"


def words(nrm, *more: str) -> frozenset[str]:
    """The selector words a component with this normal answers to, and ``more``."""
    where = quadrant(nrm)
    out = {"all", where, slant(nrm), *more}
    if where not in ("top", "bottom"):
        out.add("side")
    return frozenset(out)


def shown(value) -> str:
    return f'the string "{value}"' if isinstance(value, str) else repr(value)


def check_budget(app, step, count: int, what: str) -> None:
    """Refuse a comp whose components would overrun the shape budget, before any is made."""
    left = app.engine.max_shapes - app.engine.shapes
    if count > left:
        raise runtime_error(
            app.module,
            step.pos,
            f"this comp would make {count:,} {what}, more than {left:,} shapes (what the "
            "shape budget has left)",
            "simplify the footprint, or raise the budget with --max-shapes",
        )


def _matches(app, key, index: int, answers: frozenset[str]) -> bool:
    if isinstance(key, n.Call):  # face(i), edge(i), vertex(i)
        i = app.value(key.args[0])
        # a whole number only: face(0.5) is no face (int() would make it face 0)
        whole = isinstance(i, int) or (isinstance(i, float) and i.is_integer())
        if isinstance(i, bool) or not whole:
            raise runtime_error(
                app.module, key.pos, f"{key.name}() needs a whole number, got {shown(i)}"
            )
        return i == index
    return key.name in answers


def select(app, step, answers: list[frozenset[str]]) -> Iterator[tuple[n.Entry, str, list[int]]]:
    """(entry, its selector's name, the components it takes) for each entry of the block."""
    taken = [False] * len(answers)
    for entry in step.block.entries:
        key = entry.key  # a Name, or a Call: face(i), edge(i), vertex(i)
        chosen = [
            i for i in range(len(answers)) if not taken[i] and _matches(app, key, i, answers[i])
        ]
        for i in chosen:
            taken[i] = True
        yield entry, key.name, chosen
