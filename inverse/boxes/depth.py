"""How deep a box hierarchy's grammar nests, and whether bgr derive will derive it.

``bgr derive`` refuses a derivation more than ``--max-depth`` (256) rules deep.  One rule per box
nests as deep as the boxes do, so :func:`bgr.inverse.boxes.emit.write` measures the hierarchy
(:func:`nesting`), writes a chain of boxes each filling its parent as one rule when it must, and
refuses, before anything is written, a hierarchy no grammar of it could derive
(:func:`too_deep`, :func:`rule_depth`).  Everything here walks with a stack, not recursion, so a
hierarchy of any depth is measured without reaching Python's recursion limit.
"""

from __future__ import annotations

from bgr.grammar import nodes as n
from bgr.grammar.errors import Diagnostic
from bgr.interpreter.limits import DEFAULT_MAX_DEPTH

from .model import EPS, Box, shown

MAX_DEPTH = DEFAULT_MAX_DEPTH  # bgr derive's --max-depth: the grammar must derive within it


def nesting(root: Box, collapse: bool = True) -> int:
    """Levels of boxes below and with ``root``, counted without recursion; ``collapse``: a box
    whose only child fills it counts with that child (the writer makes them one rule)."""
    return _deepest(root, collapse)[1]


def _deepest(root: Box, collapse: bool = True) -> tuple[Box, int]:
    """The deepest box and its level (see :func:`nesting`), the first found of the deepest."""
    best, deepest, stack = root, 1, [(root, 1)]
    while stack:
        box, level = stack.pop()
        if level > deepest:
            best, deepest = box, level
        chained = collapse and len(box.children) == 1 and fills(box.children[0], box.lo, box.hi)
        stack += [(c, level if chained else level + 1) for c in reversed(box.children)]
    return best, deepest


def too_deep(root: Box) -> Diagnostic | None:
    """Why ``root`` cannot be a grammar that bgr derive derives (its boxes nest deeper than the
    rule depth limit once chains are collapsed), or None."""
    deepest, levels = _deepest(root)
    if levels <= MAX_DEPTH:  # Lot's successor is at depth 1, a leaf at depth ``levels``
        return None
    return Diagnostic(
        "",
        0,
        0,
        f"the boxes nest {levels} levels deep (down to box '{shown(deepest.id)}'); a grammar of "
        f"them would derive deeper than bgr derive's limit of {MAX_DEPTH} nested rules",
        f"flatten the hierarchy to at most {MAX_DEPTH} levels (a box that is its parent's "
        "only child and fills it does not count)",
    )


def deep_message(depth: int | None) -> Diagnostic:
    """The refusal of a grammar whose rules nest ``depth`` deep (None: past Python's stack)."""
    deep = "too many" if depth is None else str(depth)
    return Diagnostic(
        "",
        0,
        0,
        f"the grammar of these boxes would derive {deep} nested rules deep, over bgr derive's "
        f"limit of {MAX_DEPTH}",
        "flatten the hierarchy (fewer levels of boxes, or fewer slabs of several boxes)",
    )


def rule_depth(module: n.Module) -> int:
    """The most nested rules a derivation of ``module`` from Lot goes through (each successor
    one level, as the engine counts), computed from the rules without deriving."""
    calls: dict[str, set[str]] = {r.name: set(_successors(r.body)) for r in module.rules()}
    depth: dict[str, int] = {}
    for start in calls:  # post-order over the rule graph, without recursion
        stack = [(start, False)]
        while stack:
            name, done = stack.pop()
            if name in depth:
                continue
            targets = calls.get(name, set())
            if done:
                depth[name] = 1 + max((depth.get(t, 1) for t in targets), default=0)
            else:
                stack.append((name, True))
                stack += [(t, False) for t in targets if t not in depth and t in calls]
    return depth.get("Lot", 1) - 1


def _successors(body) -> list[str]:
    """The names of the rules a body hands shapes to, at any nesting of blocks and brackets."""
    out: list[str] = []
    if isinstance(body, n.Stochastic):
        steps = [s for c in body.choices for s in c.body.steps]
    elif isinstance(body, n.Conditional):
        steps = [s for c in body.cases for s in c.body.steps]
    else:
        steps = list(body.steps)
    while steps:
        step = steps.pop()
        if isinstance(step, n.Successor):
            out.append(step.name)
        elif isinstance(step, n.Push):
            steps += step.steps
        elif isinstance(step, n.Operation) and step.block is not None:
            entries = list(step.block.entries)
            while entries:
                entry = entries.pop()
                if isinstance(entry, n.Group):
                    entries += entry.entries
                else:
                    steps += entry.body.steps
    return out


def fills(box: Box, lo, hi) -> bool:
    return bool(((abs(box.lo - lo) <= EPS) & (abs(box.hi - hi) <= EPS)).all())
