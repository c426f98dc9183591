"""Name resolution and static checks of one parsed module, before any geometry is made.

The checker walks the tree once and collects every problem as a :class:`Diagnostic`; it does not
stop at the first.  Imports are resolved by :mod:`bgr.grammar.loader`, which hands the checker
the already-checked imported modules as :class:`Grammar` objects.
"""

from __future__ import annotations

from . import nodes as n
from .annotations import annotation_errors
from .check_declarations import KNOWN_VERSIONS as KNOWN_VERSIONS
from .check_declarations import DeclarationChecks
from .check_rules import RuleChecks
from .check_rules import bind_problem as bind_problem
from .checker_base import Grammar as Grammar
from .errors import Diagnostic


class Checker(DeclarationChecks, RuleChecks):
    """Checks one module.  ``check()`` returns the diagnostics; the Grammar is filled in.

    Its parts are mixins by concern: declarations (:mod:`.check_declarations`), rule bodies
    (:mod:`.check_rules`), operations (:mod:`.check_operations`) and expressions
    (:mod:`.check_expressions`), on the shared state of :mod:`.checker_base`."""

    # ---- entry point ----------------------------------------------------------------------
    def check(self) -> list[Diagnostic]:
        self.collect()
        for item in self.g.module.items:
            if isinstance(item, (n.Attr, n.Const)):
                self.expr(item.value, set(), in_rule=False)
            elif isinstance(item, n.Func):
                self.expr(item.body, set(item.params), in_rule=True)
            elif isinstance(item, n.Rule):
                self.rule(item)
        self.value_cycles()
        self.call_nesting()
        self.diagnostics += annotation_errors(self.g.path, self.g.module)
        return self.diagnostics
