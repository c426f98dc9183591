"""Name resolution and static checks of one parsed module, before any geometry is made.

The checker walks the tree once and collects every problem as a :class:`Diagnostic`; it does not
stop at the first.  Imports are resolved by :mod:`bgr.grammar.loader`, which hands the checker
the already-checked imported modules as :class:`Grammar` objects.
"""

from __future__ import annotations

import re
from collections.abc import Set as AbstractSet
from dataclasses import dataclass, field
from pathlib import Path

from . import nodes as n
from .annotations import annotation_errors
from .errors import Diagnostic, source_line, suggest
from .formatter import format_params
from .limits import MAX_NESTING, children, expr_depth, expressions
from .registry import (
    ATTR_NAME,
    AXES,
    AXIS,
    AXIS_NAMES,
    BUILTIN_NAMES,
    BUILTINS,
    CLEANUP_KIND,
    CLEANUP_KINDS,
    COLOR,
    COMP_INDEX_CALLS,
    COMP_KIND,
    COMP_KINDS,
    COMP_SELECTORS,
    EDGE_SELECTORS,
    EXTRUDE_KIND,
    EXTRUDE_KINDS,
    FOOTPRINT_KIND,
    FOOTPRINT_KINDS,
    GEOMETRY,
    INNER_ALIGNMENT,
    INNER_ALIGNMENTS,
    INNER_SELECTORS,
    KEYWORDS,
    MANY,
    NORMALIZE_MODE,
    NORMALIZE_MODES,
    NORMALIZE_TYPE,
    NORMALIZE_TYPES,
    NUMBER,
    NUMBER_OR_WORD,
    OCCLUSION,
    OFFSET_SELECTORS,
    OPERATIONS,
    PRIMITIVES,
    PROJECTION_AXES,
    PROJECTION_AXES_NAMES,
    ROOF_KIND,
    ROOF_KINDS,
    SETBACK_SELECTORS,
    SHAPE_ATTRIBUTES,
    SIZE,
    SPLIT_ADJUST,
    SPLIT_ADJUSTS,
    STRING,
    TEX_SIZE,
    UP_AXES,
    UP_AXIS,
    VERTEX_SELECTORS,
    WORD_ARGUMENTS,
    Op,
)
from .site import problems as site_problems
from .textures import TextureError, load

KNOWN_VERSIONS = (1,)
_COLOR_RE = re.compile(r"#[0-9a-fA-F]{6}\Z")
_SYMBOL_KINDS = {
    AXIS: AXIS_NAMES,
    COMP_KIND: COMP_KINDS,
    ROOF_KIND: ROOF_KINDS,
    FOOTPRINT_KIND: FOOTPRINT_KINDS,
    EXTRUDE_KIND: EXTRUDE_KINDS,
    PROJECTION_AXES: PROJECTION_AXES_NAMES,
    NORMALIZE_MODE: NORMALIZE_MODES,
    NORMALIZE_TYPE: NORMALIZE_TYPES,
    UP_AXIS: UP_AXES,
    CLEANUP_KIND: CLEANUP_KINDS,
    INNER_ALIGNMENT: INNER_ALIGNMENTS,
    SPLIT_ADJUST: SPLIT_ADJUSTS,
}
_TEXTURE_OPS = ("texture", "normalMap")
_RESERVED_ALIASES = {"scope", "split", "comp", "stdlib", "geometry"}


@dataclass
class Grammar:
    """A checked module: its tree, its symbol tables, its imported modules and its warnings.

    Names are resolved per module: a rule of an imported module refers to that module's own
    rules, attrs and functions; the importer reaches them as ``alias.Name``."""

    path: str
    module: n.Module
    rules: dict[str, n.Rule] = field(default_factory=dict)
    terminals: dict[str, n.Pos] = field(default_factory=dict)
    attrs: dict[str, n.Attr] = field(default_factory=dict)
    consts: dict[str, n.Const] = field(default_factory=dict)
    funcs: dict[str, n.Func] = field(default_factory=dict)
    assets: dict[str, n.Asset] = field(default_factory=dict)
    imports: dict[str, Grammar] = field(default_factory=dict)
    start: str | None = None
    version: int = 1
    site: n.Site | None = None  # where its metres are on Earth (grammar/site.py)
    # the folders its imports and assets may resolve in (grammar/paths.py), set by bgr.load;
    # empty (a Grammar made by hand) leaves its assets unchecked
    roots: tuple[Path, ...] = ()
    # the real folder of its file, where its relative texture and asset paths start (``path`` is
    # what messages show: stdlib/NAME.bgr for a stdlib module); None: the folder of ``path``
    folder: Path | None = None
    # levels of each func's body, the bodies of the funcs it calls included (grammar.limits)
    func_depths: dict[str, int] = field(default_factory=dict)
    recursive_funcs: set[str] = field(default_factory=set)  # funcs that call themselves
    warnings: list[Diagnostic] = field(default_factory=list)  # bgr.load: its own and its imports'
    barren: dict[str, str] = field(default_factory=dict)  # rule -> its cycle (.productive)
    settable: set[str] = field(default_factory=set)  # attrs a set() of its rules changes
    occlusion: bool = False  # whether it asks inside(), overlaps() or touches() (occlusion.py)
    # rules of this module that its importer overrides (``alias.Name --> ...`` there): member ->
    # (the importer, the override's name in it); a module imported with overrides is a copy of
    # its own (Loader), so other importers of the file keep its rules
    overrides: dict[str, tuple[Grammar, str]] = field(default_factory=dict)

    def lookup_module(self, dotted: str) -> tuple[Grammar, str]:
        """Split ``alias.Name`` into (module, member); a plain name is this module's own."""
        if "." in dotted:
            alias, member = dotted.split(".", 1)
            if alias in self.imports:
                target = self.imports[alias]
                return target.overrides.get(member) or (target, member)
        if self.overrides and dotted in self.overrides:
            return self.overrides[dotted]
        return self, dotted


class Checker:
    """Checks one module.  ``check()`` returns the diagnostics; the Grammar is filled in."""

    def __init__(self, grammar: Grammar, import_errors: dict[str, bool] | None = None) -> None:
        self.g = grammar
        self.source = grammar.module.source
        self.diagnostics: list[Diagnostic] = []
        # aliases whose import failed: names under them are not reported a second time
        self.broken_aliases = set(k for k, bad in (import_errors or {}).items() if bad)
        self.comp_kind = "f"  # the kind of the comp whose block is being checked

    # ---- reporting ------------------------------------------------------------------------
    def error(
        self, pos: n.Pos, message: str, hint: str | None = None, length: int | None = None
    ) -> None:
        if length is None:
            length = pos.end_column - pos.column if pos.end_line == pos.line else 1
        self.diagnostics.append(
            Diagnostic(
                self.g.path,
                pos.line,
                pos.column,
                message,
                hint,
                source_line(self.source, pos.line),
                max(length, 1),
            )
        )

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

    # ---- declarations ---------------------------------------------------------------------
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

    # ---- rules ----------------------------------------------------------------------------
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

    def unknown_alias(self, alias: str, pos: n.Pos) -> None:
        hint = (
            suggest(alias, self.g.imports) or f"import it first: import stdlib.{alias} as {alias}"
        )
        self.error(pos, f"unknown module '{alias}'", hint, len(alias))

    # ---- operations -----------------------------------------------------------------------
    def operation(self, step: n.Operation, local: set[str]) -> None:
        op = OPERATIONS[step.name]
        signature = self.pick_signature(op, step)
        if signature is not None:
            for i, arg in enumerate(step.args):
                param = op.param(signature, i)
                self.op_arg(arg, param.kind, param.name, op, local)
        else:
            # no signature fits (reported): check the expressions, but not a bare word that one
            # of the operation's signatures takes (extrude(world.up, 1, 2) is one mistake)
            words = {
                word
                for sig in op.signatures
                for p in sig
                if p.kind in _SYMBOL_KINDS
                for word in _SYMBOL_KINDS[p.kind]
            }
            for arg in step.args:
                if not (isinstance(arg, n.Name) and arg.name in words):
                    self.arg(arg, local, relative_ok=True)
        if op.block is None:
            if step.block is not None:  # the grammar lets any call carry a block
                self.error(step.block.pos, f"'{op.name}' takes no {{ }} block")
            return
        if step.block is None:
            self.error(
                step.pos,
                f"'{op.name}' needs a {{ ... }} block",
                f"for example: {op.example}",
                len(op.name),
            )
            return
        if step.block.repeat and op.block != "split":
            end = step.block.pos
            star = n.Pos(end.end_line, end.end_column - 1, end.end_line, end.end_column)
            self.error(
                star,
                f"only split blocks repeat; '{op.name}' {{ ... }} cannot take a '*'",
                "remove the '*'",
            )
        outer = self.comp_kind
        if op.block == "comp":
            kind = step.args[0] if step.args else None
            self.comp_kind = kind.name if isinstance(kind, n.Name) else "f"
        self.block_entries(step.block.entries, op, local, in_group=False)
        self.comp_kind = outer

    def pick_signature(self, op: Op, step: n.Operation):
        count = len(step.args)
        for sig, (least, most) in zip(op.signatures, op.arities(), strict=True):
            if least <= count <= most:
                return sig
        counts = " or ".join(
            str(a) if a == b else f"{a} or more" if b == MANY else f"{a} to {b}"
            for a, b in op.arities()
        )
        noun = "argument" if counts == "1" else "arguments"
        self.error(
            step.pos,
            f"'{op.name}' takes {counts} {noun}, given {count}",
            f"write {op.usage()}",
            len(op.name),
        )
        return None

    def set_target(self, arg, op: Op) -> None:
        """set()'s first argument: a bare word naming an attr of this file."""
        if not isinstance(arg, n.Name):
            self.error(arg.pos, "set() changes an attr: name it bare", f"for example: {op.example}")
        elif arg.name in SHAPE_ATTRIBUTES:
            return
        elif "." in arg.name and arg.name.split(".", 1)[0] in self.g.imports:
            module, member = self.g.lookup_module(arg.name)
            if member in module.attrs:
                module.settable.add(member)  # its rules read the value set() gave
            else:
                self.error(
                    arg.pos,
                    f"unknown attr '{arg.name}'",
                    suggest(member, list(module.attrs)) or "set() changes attrs of that file",
                )
        elif "." in arg.name and arg.name.split(".", 1)[0] in self.broken_aliases:
            return
        elif arg.name in self.g.consts:
            self.error(arg.pos, f"'{arg.name}' is a const: set() changes attrs only")
        elif arg.name in self.g.attrs:
            self.g.settable.add(arg.name)
        else:
            hint = "set() changes this file's attrs (declare it: attr NAME = value) or an import's"
            self.error(
                arg.pos,
                f"unknown attr '{arg.name}'",
                suggest(arg.name, list(self.g.attrs)) or hint,
            )

    def op_arg(self, arg, kind: str, pname: str, op: Op, local: set[str]) -> None:
        if kind in NUMBER_OR_WORD:
            if isinstance(arg, n.Name) and arg.name in NUMBER_OR_WORD[kind]:
                return
            kind = NUMBER
        if kind == ATTR_NAME:
            self.set_target(arg, op)
            return
        if kind in _SYMBOL_KINDS or kind in (AXES, GEOMETRY):
            if not isinstance(arg, n.Name):
                allowed = self.allowed_symbols(kind)
                self.error(
                    arg.pos,
                    f"the {pname} of '{op.name}' is a bare word, one of {allowed}",
                    f"for example: {op.example}",
                )
                return
            word = arg.name
            if kind in _SYMBOL_KINDS:
                if word not in _SYMBOL_KINDS[kind]:
                    self.error(
                        arg.pos,
                        f"unknown {kind} '{word}'",
                        suggest(word, _SYMBOL_KINDS[kind])
                        or f"use one of {self.allowed_symbols(kind)}",
                    )
            elif kind == AXES:
                if not word or set(word) - set("xyz") or len(set(word)) != len(word):
                    self.error(
                        arg.pos,
                        f"'{word}' is not a set of axes",
                        "write the axes as one word of x, y and z, e.g. center(xz)",
                    )
            else:  # GEOMETRY
                module, member = self.g.lookup_module(word)
                if member in PRIMITIVES and module is self.g:
                    return
                if "." in word and word.split(".", 1)[0] in self.broken_aliases:
                    return
                if member not in module.assets:
                    known = list(PRIMITIVES) + list(self.g.assets)
                    self.error(
                        arg.pos,
                        f"unknown primitive or asset '{word}'",
                        suggest(word, known) or 'declare it: asset NAME = "path/to/mesh.glb"',
                    )
            return
        if isinstance(arg, n.Relative) and arg.floating and kind != TEX_SIZE:
            self.error(
                arg.pos,
                f"a floating size (~w) is not allowed as the {pname} of '{op.name}'",
                "floating sizes go in split sizes, setupProjection() and tileUV()",
            )
            return
        if isinstance(arg, n.Relative) and kind not in (SIZE, TEX_SIZE):
            self.error(
                arg.pos,
                f"a relative size ('f) is not allowed as the {pname} of '{op.name}'",
                "relative sizes go in s(), t(), split sizes, setupProjection() and tileUV()",
            )
            return
        self.arg(arg, local, relative_ok=True)
        expr = arg.expr if isinstance(arg, n.Relative) else arg
        if op.name in _TEXTURE_OPS and isinstance(expr, n.String):
            self.texture_file(expr)
        if kind in (NUMBER, SIZE, TEX_SIZE) and isinstance(expr, (n.String, n.Bool)):
            self.error(expr.pos, f"the {pname} of '{op.name}' must be a number")
        elif kind == STRING and isinstance(expr, (n.Number, n.Bool)):
            self.error(
                expr.pos,
                f"the {pname} of '{op.name}' must be a string",
                f"for example: {op.example}",
            )
        elif kind == COLOR:
            if isinstance(expr, n.String) and not _COLOR_RE.match(expr.value):
                self.error(
                    expr.pos,
                    f"'{expr.value}' is not a colour",
                    'write "#rrggbb" with six hexadecimal digits, or three numbers in 0..1',
                )
            elif isinstance(expr, (n.Number, n.Bool)):
                self.error(
                    expr.pos,
                    'a single colour argument is a "#rrggbb" string',
                    "or give three numbers: color(r, g, b)",
                )

    def texture_file(self, expr: n.String) -> None:
        """A literal texture path must name a readable PNG or JPEG within the grammar's roots
        (a computed one is checked when the derivation first uses it)."""
        if not self.g.roots or expr.value == "":  # by hand: not checked; "": no map
            return
        try:
            load(self.g.path, self.g.roots, expr.value, self.g.folder)
        except TextureError as e:
            self.error(expr.pos, e.message, e.hint)

    def allowed_symbols(self, kind: str) -> str:
        if kind == AXES:
            return "x, y, z, xy, xz, yz, xyz"
        if kind == GEOMETRY:
            return ", ".join(list(PRIMITIVES) + list(self.g.assets))
        return ", ".join(_SYMBOL_KINDS[kind])

    def block_entries(self, entries, op: Op, local: set[str], in_group: bool) -> None:
        for entry in entries:
            if isinstance(entry, n.Group):
                if op.block != "split":
                    self.error(
                        entry.pos,
                        f"repeat groups {{ ... }}* belong in split blocks, not in '{op.name}'",
                    )
                else:
                    self.block_entries(entry.entries, op, local, in_group=True)
                continue
            if op.block == "split":
                self.expr(entry.key, local, in_rule=True)
                if isinstance(entry.key, (n.String, n.Bool)):
                    self.error(entry.key.pos, "a split size must be a number")
            else:
                self.selector(entry, op, local)
            self.sequence(entry.body, local)

    def selector(self, entry: n.Entry, op: Op, local: set[str]) -> None:
        comp_selectors = {"e": EDGE_SELECTORS, "v": VERTEX_SELECTORS}
        allowed = {
            "comp": comp_selectors.get(self.comp_kind, COMP_SELECTORS),
            "setback": SETBACK_SELECTORS,
            "innerRectangle": INNER_SELECTORS,
        }.get(op.block or "", OFFSET_SELECTORS)
        key = entry.key
        if entry.kind != "abs":
            self.error(
                entry.pos,
                f"'{op.name}' selectors have no size prefix",
                f"write e.g. '{allowed[0]}: A'",
            )
            return
        if isinstance(key, n.Name) and key.name in allowed:
            return
        index_call = COMP_INDEX_CALLS.get(self.comp_kind, "face")
        if op.block == "comp" and isinstance(key, n.Call) and key.name == index_call:
            if len(key.args) != 1:
                self.error(key.pos, f"{index_call}() takes one argument, the {index_call} index")
            else:
                self.expr(key.args[0], local, in_rule=True)
            return
        word = key.name if isinstance(key, (n.Name, n.Call)) else None
        extra = f", {index_call}(i)" if op.block == "comp" else ""
        hint = suggest(word, allowed) if word else None
        self.error(
            key.pos,
            f"unknown {op.name} selector" + (f" '{word}'" if word else ""),
            hint or f"use one of {', '.join(allowed)}{extra}",
        )

    # ---- expressions ----------------------------------------------------------------------
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


def _article(what: str) -> str:
    return ("an " if what[0] in "aeiou" else "a ") + what


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


def _count(k: int, word: str) -> str:
    return f"{k} {word}" if k == 1 else f"{k} {word}s"
