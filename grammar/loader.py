"""Reading files and resolving imports: the public ``load`` behind :func:`bgr.load`.

A file is parsed, its imports are loaded (relative paths from the importing file's folder,
``stdlib.NAME`` from the bundled standard library), then it is checked.  Every error of every
file involved is collected and raised together as one :class:`BgrError`.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

from . import nodes as n
from .annotations import annotation_warnings
from .checker import Checker, Grammar
from .errors import BgrCheckError, BgrError, BgrSyntaxError, Diagnostic, source_line, suggest
from .parser import parse
from .paths import ALLOW_HINT, _stdlib_dir, check_input, read_input, roots_of, within
from .paths import STDLIB_DIR as STDLIB_DIR
from .productive import unproductive_cycles


def stdlib_modules() -> list[str]:
    return sorted(p.stem for p in _stdlib_dir().glob("*.bgr"))


def read_source(path: str | os.PathLike) -> str:
    """Read a .bgr file as UTF-8, with errors a user can act on.

    Only ``.bgr`` files are read: error messages quote the source, so reading any other file as
    a grammar could print its lines (a password file, a process environment).  Special files
    (FIFOs, devices, /proc) are refused before they are opened (:mod:`.paths`).
    """
    shown = str(path)
    if Path(path).suffix.lower() != ".bgr":
        raise BgrError(
            Diagnostic(
                shown,
                0,
                0,
                "not a .bgr file: grammars are read from .bgr files only",
                "rename it to end in .bgr (its text is not shown here)",
            )
        )
    try:
        data = read_input(path, "grammar")
    except FileNotFoundError:
        raise BgrError(Diagnostic(shown, 0, 0, "no such file", "check the path")) from None
    except IsADirectoryError:
        raise BgrError(Diagnostic(shown, 0, 0, "is a folder, not a .bgr file")) from None
    except OSError as e:
        raise BgrError(
            Diagnostic(shown, 0, 0, f"cannot read the file: {e.strerror or e}")
        ) from None
    return decode(data, shown)


def decode(data: bytes, path: str) -> str:
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        line = data.count(b"\n", 0, e.start) + 1
        column = e.start - (data.rfind(b"\n", 0, e.start) + 1) + 1
        raise BgrSyntaxError(
            Diagnostic(
                path,
                line,
                column,
                f"the file is not UTF-8 text (byte 0x{data[e.start]:02x})",
                "save it as UTF-8",
            )
        ) from None
    return text[1:] if text.startswith("\ufeff") else text


class Loader:
    """Loads a root file and everything it imports, each file once."""

    def __init__(self, roots: tuple[Path, ...] = ()) -> None:
        self.roots = roots  # the folders imports may resolve in (paths.roots_of)
        self.done: dict[str, Grammar] = {}
        self.failed: set[str] = set()
        self.diagnostics: list[Diagnostic] = []

    def load_text(
        self, text: str, path: str, key: str | None, stack: tuple[str, ...]
    ) -> Grammar | None:
        try:
            module = parse(text, path)
        except BgrError as e:
            self.diagnostics += e.diagnostics
            return None
        folder = Path(key).parent if key else Path.cwd()
        grammar = Grammar(path, module, roots=self.roots, folder=folder)
        # ``alias.Name --> ...``: rules this module overrides in the module imported as alias
        overriding: dict[str, list[str]] = {}
        for item in module.items:
            if isinstance(item, n.Rule) and "." in item.name:
                alias, member = item.name.split(".", 1)
                overriding.setdefault(alias, []).append(member)
        broken: dict[str, bool] = {}
        for item in module.items:
            if isinstance(item, n.Import):
                own = item.alias in overriding  # a copy of its own, which the overrides change
                imported = self.load_import(item, folder, module, stack, fresh=own)
                if imported is not None:
                    grammar.imports[item.alias] = imported
                    for member in overriding.get(item.alias, []):
                        imported.overrides[member] = (grammar, f"{item.alias}.{member}")
                broken[item.alias] = imported is None
        self.diagnostics += Checker(grammar, broken).check()
        return grammar

    def load_import(
        self,
        item: n.Import,
        folder: Path,
        module: n.Module,
        stack: tuple[str, ...],
        fresh: bool = False,
    ) -> Grammar | None:
        def fail(message: str, hint: str | None = None) -> None:
            self.diagnostics.append(
                Diagnostic(
                    module.path,
                    item.pos.line,
                    item.pos.column,
                    message,
                    hint,
                    source_line(module.source, item.pos.line),
                )
            )

        if item.module is not None:
            parts = item.module.split(".")
            if parts[0] != "stdlib" or len(parts) != 2:
                fail(
                    f"cannot import '{item.module}' by name: only stdlib.NAME modules are",
                    f'import other files by path: import "{"/".join(parts)}.bgr" as {item.alias}',
                )
                return None
            target = _stdlib_dir() / f"{parts[1]}.bgr"
            if not target.is_file():
                hint = suggest(parts[1], stdlib_modules())
                fail(
                    f"there is no stdlib module '{parts[1]}'",
                    hint or "known: " + ", ".join(stdlib_modules()),
                )
                return None
            shown = f"stdlib/{parts[1]}.bgr"
        else:
            target = folder / (item.path or "")  # the parser sets path when module is None
            shown = _display(target)
            if not within(target, self.roots):
                fail(
                    f"cannot import '{item.path}': it is outside the folders this grammar may "
                    "read (" + ", ".join(_display(r) for r in self.roots) + ")",
                    ALLOW_HINT,
                )
                return None
            if target.suffix.lower() != ".bgr":
                fail(
                    f"cannot import '{item.path}': only .bgr files can be imported",
                    "its text is not read; import a .bgr grammar",
                )
                return None
            try:
                check_input(target, "imported file")
            except BgrError as e:  # a FIFO, a device: say so at the import line
                fail(f"cannot import '{item.path}': {e.message}", e.hint)
                return None
            if not target.is_file():
                fail(f"cannot find the imported file '{item.path}'", f"looked for {target}")
                return None
        key = str(target.resolve())
        if key in stack:
            chain = (
                " -> ".join(Path(k).name for k in stack[stack.index(key) :])
                + f" -> {Path(key).name}"
            )
            fail(
                f"import cycle: {chain}",
                "a module cannot import itself, directly or through others",
            )
            return None
        if key in self.done and not fresh:
            return self.done[key]
        if key in self.failed:
            return None
        try:
            text = read_source(target)
        except BgrError as e:
            self.diagnostics += e.diagnostics
            self.failed.add(key)
            return None
        grammar = self.load_text(text, shown, key, stack + (key,))
        if grammar is None:
            self.failed.add(key)
        elif not fresh:
            self.done[key] = grammar
        return grammar


def load(
    source: str | bytes | os.PathLike,
    path: str | None = None,
    *,
    allow_paths: Iterable[str | os.PathLike] = (),
) -> Grammar:
    """Parse, resolve and check a grammar; return it, or raise :class:`BgrError` with every problem.

    ``source`` is a path (a :class:`os.PathLike`, or a one-line string naming an existing file or
    ending in ``.bgr``), or the text of a grammar (a string with a newline or ``-->`` in it, or
    bytes).  ``path`` names text in messages and is the base for its relative imports.

    Imports and assets must resolve (symlinks followed) inside the grammar's folder, the bundled
    stdlib, or a folder of ``allow_paths``; the grammar's folder is that of the file, or of
    ``path`` when it ends in ``.bgr``, else the current working folder (text given as such).
    """
    key = None
    if isinstance(source, bytes):
        text = decode(source, path or "<text>")
    elif isinstance(source, os.PathLike) or _looks_like_path(source):
        key = str(Path(source).resolve())
        path = path or str(source)
        text = read_source(source)
    elif isinstance(source, str):
        text = source
    else:
        raise TypeError(
            f"bgr.load takes a path or the text of a grammar, not {type(source).__name__}"
        )
    if path is not None and key is None and Path(path).suffix == ".bgr":
        key = str(Path(path).resolve())
    loader = Loader(roots_of(Path(key).parent if key else Path.cwd(), allow_paths))
    try:
        grammar = loader.load_text(text, path or "<text>", key, (key,) if key else ())
    except RecursionError:
        raise BgrSyntaxError(
            Diagnostic(
                path or "<text>",
                0,
                0,
                "the grammar nests expressions or blocks too deeply to process",
                "split deep nesting into separate rules",
            )
        ) from None
    if loader.diagnostics:
        unique = {(d.path, d.line, d.column, d.message): d for d in loader.diagnostics}
        ordered = sorted(
            unique.values(), key=lambda d: (d.path != (path or "<text>"), d.path, d.line, d.column)
        )
        raise (BgrSyntaxError if grammar is None else BgrCheckError)(ordered)
    assert grammar is not None
    # warnings: each file's own (an import's once, in the order the files were loaded)
    modules = {id(m): m for m in [*loader.done.values(), grammar]}  # the file itself once
    for module in modules.values():
        grammar.warnings += unproductive_cycles(module)
        grammar.warnings += annotation_warnings(module.path, module.module)
    return grammar


def _display(path: Path) -> str:
    """A path as messages show it: relative to the working folder when inside it."""
    try:
        rel = os.path.relpath(path)
    except ValueError:  # another drive on Windows
        return str(path)
    return str(path) if rel.startswith("..") else rel


def _looks_like_path(source: object) -> bool:
    if not isinstance(source, str) or "\n" in source or "-->" in source:
        return False
    return source.endswith(".bgr") or os.path.isfile(source)
