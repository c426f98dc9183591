"""The checker's first pass: the declarations of a module and the names they define.

Rules, terminals, attrs, consts, funcs, assets, import aliases, the version, the site and the
start rule are collected into the :class:`~bgr.grammar.checker_base.Grammar`'s symbol tables;
duplicates, keywords and reserved words used as names, rule overrides of an import
(``alias.Name --> ...``) and parameter lists are checked on the way.
"""

from __future__ import annotations

from . import nodes as n
from .checker_base import CheckerBase
from .errors import suggest
from .registry import BUILTIN_NAMES, BUILTINS, KEYWORDS, OPERATIONS, PRIMITIVES
from .site import problems as site_problems

KNOWN_VERSIONS = (1,)
_RESERVED_ALIASES = {"scope", "split", "comp", "stdlib", "geometry"}


class DeclarationChecks(CheckerBase):
    """Collects the module's declarations (``collect``) before any body is checked."""

    def collect(self) -> None:
        g = self.g
        first_seen: dict[tuple[str, str], n.Pos] = {}

        def declare(space: str, name: str, pos: n.Pos, what: str) -> bool:
            if name in KEYWORDS:
                self.error(
                    pos,
                    f"'{name}' is a keyword and cannot name {_article(what)}",
                    "choose another name",
                )
                return False
            key = (space, name)
            if key in first_seen:
                self.error(
                    pos,
                    f"duplicate {what} '{name}'",
                    f"'{name}' is already defined on line {first_seen[key].line}",
                )
                return False
            first_seen[key] = pos
            return True

        versions = starts = 0
        for item in g.module.items:
            if isinstance(item, n.Version):
                versions += 1
                if versions > 1:
                    self.error(item.pos, "more than one 'version' declaration")
                elif item.number not in KNOWN_VERSIONS:
                    shown = int(item.number) if item.number.is_integer() else item.number
                    self.error(
                        item.pos,
                        f"unknown language version {shown}",
                        "this bgr reads version 1: write 'version 1' or leave the line out",
                    )
                else:
                    g.version = int(item.number)
            elif isinstance(item, n.Rule) and "." in item.name:
                if self.override(item) and declare("rule", item.name, item.pos, "rule"):
                    g.rules[item.name] = item
                self.unique_params(item, "rule")
            elif isinstance(item, n.Rule):
                if item.name in OPERATIONS:
                    self.error(
                        item.pos,
                        f"'{item.name}' is an operation and cannot name a rule",
                        "choose another name, e.g. a capitalised one",
                        len(item.name),
                    )
                elif declare("rule", item.name, item.pos, "rule"):
                    g.rules[item.name] = item
                self.unique_params(item, "rule")
            elif isinstance(item, n.TerminalDecl):
                for name in item.names:
                    if declare("rule", name, item.pos, "rule or terminal"):
                        g.terminals[name] = item.pos
            elif isinstance(item, (n.Attr, n.Const)):
                if item.name in BUILTIN_NAMES:
                    self.error(
                        item.pos, f"'{item.name}' is a built-in name and cannot be redefined"
                    )
                elif declare("value", item.name, item.pos, "attr or const"):
                    if isinstance(item, n.Attr):
                        g.attrs[item.name] = item
                    else:
                        g.consts[item.name] = item
            elif isinstance(item, n.Func):
                if item.name in BUILTINS:
                    self.error(
                        item.pos, f"'{item.name}' is a built-in function and cannot be redefined"
                    )
                elif declare("func", item.name, item.pos, "func"):
                    g.funcs[item.name] = item
                self.unique_params(item, "func")
            elif isinstance(item, n.Asset):
                if item.name in PRIMITIVES:
                    self.error(
                        item.pos, f"'{item.name}' is a built-in primitive and cannot name an asset"
                    )
                elif declare("asset", item.name, item.pos, "asset"):
                    g.assets[item.name] = item
            elif isinstance(item, n.Import):
                where = item.alias_pos if item.alias_pos.line else item.pos
                if item.alias in _RESERVED_ALIASES:
                    self.error(
                        where,
                        f"'{item.alias}' is reserved and cannot be an import alias",
                        f"write e.g. 'as {item.alias[:3]}_lib'",
                    )
                else:
                    declare("alias", item.alias, where, "import alias")
            elif isinstance(item, n.Site):
                if g.site is not None:
                    self.error(item.pos, "more than one 'site' declaration")
                else:
                    g.site = item
                for pos, message, hint in site_problems(item):
                    self.error(pos, message, hint)
            elif isinstance(item, n.Start):
                starts += 1
                if starts > 1:
                    self.error(item.pos, "more than one 'start' declaration")
                else:
                    g.start = item.name
        # the start rule is checked once every rule is known
        for item in g.module.items:
            if isinstance(item, n.Start) and item.name == g.start and item.name not in g.rules:
                hint = suggest(item.name, g.rules) or (
                    "the file has no rules" if not g.rules else None
                )
                self.error(item.pos, f"start rule '{item.name}' is not defined", hint)
                break
        if g.start is None and g.rules:  # the first rule of its own, not an override
            g.start = next((r for r in g.rules if "." not in r), None)

    def override(self, rule: n.Rule) -> bool:
        """Whether ``alias.Name --> ...`` overrides a rule or terminal of an import (as CGA's
        rule overriding): the imported module's own calls to Name run this rule instead."""
        alias, member = rule.name.split(".", 1)
        if alias in self.broken_aliases:
            return False
        target = self.g.imports.get(alias)
        if target is None:
            self.error(
                rule.pos,
                f"'{rule.name}' overrides a rule of '{alias}', which is not an import alias",
                f'import the file first: import "FILE.bgr" as {alias}',
                len(rule.name),
            )
            return False
        if "." in member or (member not in target.rules and member not in target.terminals):
            known = list(target.rules) + list(target.terminals)
            self.error(
                rule.pos,
                f"'{alias}' has no rule or terminal '{member}' to override",
                suggest(member, known) or f"its rules: {', '.join(known[:8])}",
                len(rule.name),
            )
            return False
        original = target.rules.get(member)
        want = len(original.params) if original is not None else 0
        if len(rule.params) != want:
            self.error(
                rule.pos,
                f"'{rule.name}' takes {len(rule.params)} parameter"
                f"{'' if len(rule.params) == 1 else 's'}, but the rule it overrides takes {want}",
                "an override takes the parameters of the rule it replaces",
                len(rule.name),
            )
            return False
        return True

    def unique_params(self, item: n.Rule | n.Func, what: str) -> None:
        seen = set()
        for i, p in enumerate(item.params):
            pos = item.param_pos[i] if i < len(item.param_pos) else item.pos
            if p in KEYWORDS:
                self.error(pos, f"'{p}' is a keyword and cannot name a parameter", length=len(p))
            if p in seen:
                self.error(pos, f"parameter '{p}' appears twice in this {what}", length=len(p))
            seen.add(p)
        if isinstance(item, n.Rule):
            defaulted = False
            for i, p in enumerate(item.params):
                pos = item.param_pos[i] if i < len(item.param_pos) else item.pos
                if item.default(i) is not None:
                    defaulted = True
                elif defaulted:
                    self.error(
                        pos,
                        f"parameter '{p}' has no default but follows one that has",
                        f"give it a default ('{p} = ...') or move it before the defaulted ones",
                        len(p),
                    )


def _article(what: str) -> str:
    return ("an " if what[0] in "aeiou" else "a ") + what
