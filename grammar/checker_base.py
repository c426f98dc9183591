"""What every part of the checker shares: the :class:`Grammar` it fills in, and its base class.

A :class:`Grammar` is one checked module with its symbol tables.  :class:`CheckerBase` holds the
state of one check (the module, the diagnostics found so far, the broken import aliases) and
reports a problem; the checks themselves are mixins on it (``check_*.py``), put together as
:class:`bgr.grammar.checker.Checker`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from . import nodes as n
from .errors import Diagnostic, source_line


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


class CheckerBase:
    """The state of one module's check and the one way to report a problem in it."""

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
