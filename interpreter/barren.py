"""A fast stop for derivations that can never end: shapes handed to rules that cannot emit.

``bgr.load`` finds the rules that hand shapes only to each other in a cycle, so that no shape
they receive can ever become a terminal (:mod:`bgr.grammar.productive`; ``bgr check`` warns of
them).  Work in them is wasted: such a cycle either ends having made nothing or runs until a
limit stops it.  A binary split explosion (``A --> split(x) { ~1: A | ~1: A }``) otherwise makes
the whole shape budget, 3.5 M shapes, before it stops; counting the shapes handed to those rules
stops it after a small fraction of that, with an error that names the cycle.  Grammars that make
terminals are not affected: the count only grows in rules that can never make one.
"""

from __future__ import annotations

from .expressions import runtime_error
from .limits import DEFAULT_MAX_SHAPES

BARREN_SHAPES = 20_000
"""Shapes one derivation may hand to rules that can never end in a terminal, with the default
shape budget; a larger ``--max-shapes`` raises it in proportion.  The binary explosion reaches
it after about 40,000 shapes, where the budget took 3.5 M (30 s on a busy 2-core machine)."""


def barren_limit(max_shapes: int) -> int:
    return max(BARREN_SHAPES, BARREN_SHAPES * max_shapes // DEFAULT_MAX_SHAPES)


def handed(engine, module, step, cycle: str) -> None:
    """Count one shape handed to a rule of a cycle that cannot emit; an error past the limit."""
    engine.barren_shapes += 1
    if engine.barren_shapes > barren_limit(engine.max_shapes):
        raise runtime_error(
            module,
            step.pos,
            f"the derivation handed more than {barren_limit(engine.max_shapes):,} shapes to rules "
            f"that can never end in a terminal ({cycle})",
            "they only hand shapes to each other (bgr check warns of it): give one of them an "
            "alternative that ends in a terminal; a larger --max-shapes raises this limit too",
        )
