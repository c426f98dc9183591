"""Checks of rule bodies: choices and conditions, their steps, and successor rules' arguments.

A successor names a rule or terminal of the module or of an import (``alias.Name``), or a
parameter that holds one; :func:`bind_problem` says whether its arguments bind the rule's
parameters, for the checker here and for the interpreter when a rule is handed over in a
parameter.
"""

from __future__ import annotations

from collections.abc import Set as AbstractSet

from . import nodes as n
from .check_expressions import _count
from .check_operations import OperationChecks
from .errors import suggest
from .formatter import format_params
from .registry import OPERATIONS


class RuleChecks(OperationChecks):
    """Checks each rule's body: its defaults, choices, conditions and steps."""

    def rule(self, rule: n.Rule) -> None:
        for i, _p in enumerate(rule.params):  # a default sees the parameters before it
            default = rule.default(i)
            if default is not None and not self.is_rule_ref(default):
                self.expr(default, set(rule.params[:i]), in_rule=True)
        local = set(rule.params)
        body = rule.body
        if isinstance(body, n.Sequence):
            self.sequence(body, local)
        elif isinstance(body, n.Stochastic):
            total = 0.0
            for choice in body.choices:
                if choice.prob is None:
                    self.sequence(choice.body, local)
                    continue
                self.expr(choice.prob, local, in_rule=True)
                if isinstance(choice.prob, n.Number):
                    if choice.prob.value < 0:
                        self.error(choice.prob.pos, "a probability cannot be negative")
                    total += choice.prob.value
                    if total > 100 + 1e-9:
                        self.error(
                            choice.prob.pos,
                            f"the percentages add up to {total:g}%, over 100%",
                            "the choices of one rule share 100%; 'else' takes what is left",
                        )
                self.sequence(choice.body, local)
        else:
            for case in body.cases:
                if case.cond is not None:
                    self.expr(case.cond, local, in_rule=True)
                self.sequence(case.body, local)

    def sequence(self, seq: n.Sequence, local: set[str]) -> None:
        for step in seq.steps:
            self.step(step, local)

    def step(self, step, local: set[str]) -> None:
        if isinstance(step, n.Operation):
            self.operation(step, local)
        elif isinstance(step, n.Successor):
            self.successor(step, local)
        elif isinstance(step, n.Push):
            for inner in step.steps:
                self.step(inner, local)

    def is_rule_ref(self, e, local: AbstractSet[str] = frozenset()) -> bool:
        """A bare name of a rule or terminal, handed whole to a rule parameter (``window =
        Arched``).
        """
        if not isinstance(e, n.Name) or e.name in local:
            return False
        module, member = self.g.lookup_module(e.name)
        if module is self.g and "." in e.name:
            return False
        return member in module.rules or member in module.terminals

    def successor(self, step: n.Successor, local: set[str]) -> None:
        for arg in step.args:
            value = arg.value if isinstance(arg, n.Keyword) else arg
            if not self.is_rule_ref(value, local):
                self.arg(arg, local, relative_ok=False)
        if step.name in local:  # a parameter that holds a rule: checked when it is applied
            return
        keyword = next((a for a in step.args if isinstance(a, n.Keyword)), None)
        if (
            step.name in OPERATIONS and keyword is not None
        ):  # `extrude(h = 3)`: left to us by the parser
            self.error(
                keyword.pos,
                f"operation '{step.name}' takes no keyword arguments",
                f"write the value alone, without '{keyword.name} =' (or, if '{step.name}' is a "
                "parameter holding a rule, declare it in the rule's head)",
                len(keyword.name),
            )
            return
        module, member = self.g.lookup_module(step.name)
        if module is not self.g or "." in step.name:
            alias = step.name.split(".", 1)[0]
            if alias in self.broken_aliases:
                return
            if module is self.g:  # dotted, but the alias is no import
                self.unknown_alias(alias, step.pos)
                return
        if member in module.rules:
            problem = bind_problem(module.rules[member], step.args, step.name)
            if problem is not None:
                pos, message, hint = problem
                self.error(pos or step.pos, message, hint, None if pos else len(step.name))
        elif member in module.terminals:
            if step.args:
                self.error(
                    step.pos, f"terminal '{step.name}' takes no arguments", length=len(step.name)
                )
        elif module is self.g and member in OPERATIONS:
            op = OPERATIONS[member]
            self.error(
                step.pos,
                f"operation '{member}' needs its arguments",
                f"write {op.usage()}",
                len(member),
            )
        else:
            known = list(module.rules) + list(module.terminals)
            if module is self.g:
                known += list(OPERATIONS) if member[:1].islower() else []
            hint = suggest(member, known)
            if hint is None and module is self.g:
                hint = f"define it with '{member} --> ...' or declare it with 'terminal {member}'"
            if module is not self.g:
                where = f"module '{step.name.split('.')[0]}' has no rule"
            elif member[:1].islower() and step.args:
                where = "unknown operation or rule"
            else:
                where = "unknown rule"
            self.error(step.pos, f"{where} '{member}'", hint, len(step.name))


def bind_problem(rule: n.Rule, args: list, called: str):
    """Why ``args`` cannot bind ``rule``'s parameters, as (pos or None, message, hint); or None.

    Positional arguments fill the parameters in order, keyword arguments name them, and every
    parameter left over must have a default.  The interpreter asks the same question for a rule
    handed over in a parameter, which the checker cannot see.
    """
    params = rule.params
    want = (
        f"it is declared as {rule.name}{format_params(rule)}"
        if params
        else f"'{rule.name}' takes no arguments"
    )
    positional = [a for a in args if not isinstance(a, n.Keyword)]
    plain = not rule.defaults and len(positional) == len(args)
    if len(positional) > len(params) or (plain and len(positional) != len(params)):
        return (
            None,
            (f"rule '{called}' takes {_count(len(params), 'argument')}, given {len(positional)}"),
            want,
        )
    bound = set(params[: len(positional)])
    for arg in args:
        if not isinstance(arg, n.Keyword):
            continue
        if arg.name not in params:
            hint = suggest(arg.name, params) or want
            return arg.pos, f"rule '{called}' has no parameter '{arg.name}'", hint
        if arg.name in bound:
            return arg.pos, f"parameter '{arg.name}' of rule '{called}' is given twice", want
        bound.add(arg.name)
    missing = [p for i, p in enumerate(params) if p not in bound and rule.default(i) is None]
    if missing:
        names = ", ".join(f"'{p}'" for p in missing)
        noun = "parameter" if len(missing) == 1 else "parameters"
        return None, f"rule '{called}' needs a value for {noun} {names}", want
    return None
