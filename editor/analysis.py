"""What an editor asks of a .bgr file, answered from bgr's own checker and registry.

The language server (:mod:`bgr.editor.lsp`) is a thin layer over these functions: each takes
the text of a document (and its path, which imports resolve from) and returns plain data, so
they are tested without a client and nothing here parses .bgr a second way: the diagnostics are
:func:`bgr.load`'s, the symbols and definitions come from the checked :class:`Grammar`, the
operation and function docs from the registry the reference is generated from
(docs/operations.md), and formatting is ``bgr fmt``'s formatter.

Positions are the checker's: 1-based lines and columns (the protocol's 0-based ones are the
server's business).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from bgr.grammar import nodes as n
from bgr.grammar.checker import Grammar
from bgr.grammar.errors import BgrError, Diagnostic
from bgr.grammar.formatter import format_source
from bgr.grammar.loader import load
from bgr.grammar.registry import BUILTINS, OPERATIONS

# a name as the language writes one, dotted for an imported module's (``win.Frame``) or a
# shape attribute (``scope.sx``)
_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*")


@dataclass(frozen=True)
class Checked:
    """A document checked: its grammar when it checks, and every problem found."""

    grammar: Grammar | None
    diagnostics: list[Diagnostic]


@dataclass(frozen=True)
class Symbol:
    """A name a file declares: what it is (rule, attr, const, func, asset, import, terminal),
    where, and a line of detail (a rule's parameters, an attr's value)."""

    name: str
    kind: str
    path: str
    pos: n.Pos
    detail: str = ""


@dataclass(frozen=True)
class Completion:
    label: str
    kind: str  # rule | attr | const | func | asset | module | terminal | operation | function
    detail: str = ""
    doc: str = ""


def check(text: str, path: str) -> Checked:
    """The grammar of ``text`` (a document at ``path``) and its diagnostics: the checker's errors
    when it does not check, its warnings when it does."""
    try:
        grammar = load(text, path=path)
    except BgrError as e:
        return Checked(None, list(e.diagnostics))
    return Checked(grammar, list(grammar.warnings))


def formatted(text: str, path: str) -> str | None:
    """``bgr fmt``'s layout of the text, or None when it does not parse."""
    try:
        return format_source(text, path)
    except BgrError:
        return None


def word_at(text: str, line: int, column: int) -> str | None:
    """The (dotted) name under a 1-based position, or None."""
    lines = text.splitlines()
    if not 1 <= line <= len(lines):
        return None
    for found in _WORD.finditer(lines[line - 1]):
        # on the name, or just after it (where a cursor that typed it stops)
        if found.start() + 1 <= column <= found.end() + 1:
            return found.group()
    return None


def real_path(grammar: Grammar) -> str:
    """The file a checked module came from (a stdlib module's ``path`` is what messages show,
    ``stdlib/NAME.bgr``; its ``folder`` is where it really is)."""
    if grammar.folder is not None:
        return str(Path(grammar.folder) / Path(grammar.path).name)
    return grammar.path


def symbols(grammar: Grammar) -> list[Symbol]:
    """The names the grammar's own file declares, in file order."""
    out = []
    path = real_path(grammar)
    for item in grammar.module.items:
        pos = getattr(item, "pos", None)
        if isinstance(item, n.Rule):
            params = f"({', '.join(item.params)})" if item.params else ""
            out.append(Symbol(item.name, "rule", path, item.pos, f"{item.name}{params}"))
        elif isinstance(item, n.Attr):
            out.append(Symbol(item.name, "attr", path, item.pos, _value(item.value)))
        elif isinstance(item, n.Const):
            out.append(Symbol(item.name, "const", path, item.pos, _value(item.value)))
        elif isinstance(item, n.Func):
            out.append(Symbol(item.name, "func", path, item.pos, f"({', '.join(item.params)})"))
        elif isinstance(item, n.Asset):
            out.append(Symbol(item.name, "asset", path, item.pos, item.path))
        elif isinstance(item, n.Import):
            what = item.path if item.path is not None else f"stdlib.{item.module}"
            out.append(Symbol(item.alias, "import", path, item.pos, what))
        elif isinstance(item, n.TerminalDecl) and pos is not None:
            out += [Symbol(name, "terminal", path, pos) for name in item.names]
    return out


def definition(grammar: Grammar, word: str) -> Symbol | None:
    """Where ``word`` is declared: in this file, or (``alias.Name``) in the module it imports."""
    module, member = grammar, word
    if "." in word:
        alias, rest = word.split(".", 1)
        if alias not in grammar.imports:
            return None
        module, member = grammar.imports[alias], rest
    for symbol in symbols(module):
        if symbol.name == member and symbol.kind != "import":
            return symbol
    if "." not in word:
        for symbol in symbols(grammar):
            if symbol.kind == "import" and symbol.name == word:
                return symbol
    return None


def hover(grammar: Grammar | None, word: str) -> str | None:
    """Markdown for the name: an operation's or function's usage and doc from the registry,
    or what a name of the file (or of a module it imports) is."""
    if word in OPERATIONS:
        op = OPERATIONS[word]
        return f"```bgr\n{op.usage()}\n```\n\n{op.doc}\n\nExample: `{op.example}`"
    if word in BUILTINS:
        fn = BUILTINS[word]
        return f"```bgr\n{fn.usage}\n```\n\n{fn.doc}"
    if grammar is None:
        return None
    found = definition(grammar, word)
    if found is None:
        return None
    where = "" if found.path == real_path(grammar) else f" (in {Path(found.path).name})"
    detail = f": `{found.detail}`" if found.detail else ""
    return f"{found.kind} **{found.name}**{detail}{where}, line {found.pos.line}"


def completions(grammar: Grammar | None, prefix: str = "") -> list[Completion]:
    """What may be written where the cursor is: after ``alias.``, the names of that module;
    else this file's names, its imports, the operations and functions of the language and the
    stdlib's modules (as ``stdlib.NAME``)."""
    if "." in prefix and grammar is not None:
        alias = prefix.split(".", 1)[0]
        module = grammar.imports.get(alias)
        if module is not None:
            return [
                Completion(f"{alias}.{s.name}", s.kind, s.detail)
                for s in symbols(module)
                if s.kind != "import"
            ]
    out: list[Completion] = []
    if grammar is not None:
        out += [Completion(s.name, s.kind, s.detail) for s in symbols(grammar)]
    out += [Completion(name, "operation", op.usage(), op.doc) for name, op in OPERATIONS.items()]
    out += [Completion(name, "function", fn.usage, fn.doc) for name, fn in BUILTINS.items()]
    out += [
        Completion(f"stdlib.{p.stem}", "module", f"import stdlib.{p.stem} as {p.stem}")
        for p in sorted(_stdlib().glob("*.bgr"))
    ]
    return out


def _stdlib() -> Path:
    """The bundled stdlib's folder."""
    import bgr.stdlib

    return Path(bgr.stdlib.__file__).resolve().parent


def _value(expr) -> str:
    """A short text of an attr's or const's value."""
    from bgr.grammar.formatter import format_expr

    try:
        text = format_expr(expr)
    except Exception:  # a node the formatter does not print alone: say nothing
        return ""
    return text if len(text) <= 60 else text[:57] + "..."
