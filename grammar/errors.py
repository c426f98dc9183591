"""Errors a user can act on: ``path:line:col: error: message``, the source line, a caret, a hint.

Every failure that reaches a user is a :class:`BgrError`.  One error may carry several
:class:`Diagnostic` entries (the checker reports every problem it finds, not only the first);
the error's own ``path``, ``line`` and ``column`` are those of the first diagnostic.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from dataclasses import dataclass, replace


@dataclass
class Diagnostic:
    path: str
    line: int
    column: int
    message: str
    hint: str | None = None
    source_line: str | None = None
    length: int = 1  # how many characters the caret underlines
    severity: str = "error"  # or "warning": the run goes on (bgr derive prints it, Result keeps it)

    def render(self) -> str:
        """The message as a terminal shows it: every character of the input it quotes (a file
        name, a box id, a source line) that would move the cursor, colour the terminal or
        turn the text (ESC, CR, NUL, bidi controls) written as its escape (``\\x1b``)."""
        path = terminal_text(self.path, keep="")
        where = f"{path}:{self.line}:{self.column}" if self.line else path
        head = f"{self.severity}: {terminal_text(self.message)}"
        out = [f"{where}: {head}" if where else head]
        if self.source_line is not None and self.line:
            text, column = _excerpt(self.source_line.rstrip("\r\n"), self.column)
            if not text.replace("\t", " ").isprintable():  # the caret stays under its character
                cut = max(column - 1, 0)
                before = terminal_text(text[:cut], keep="\t")
                text, column = before + terminal_text(text[cut:], keep="\t"), len(before) + 1
            gutter = f"{self.line:>5} | "
            out.append(gutter + text)
            # keep tabs so that the caret lines up under tab-indented code
            lead = "".join(c if c == "\t" else " " for c in text[: max(column - 1, 0)])
            width = max(1, min(self.length, max(len(text) - column + 1, 1)))
            out.append(" " * (len(gutter) - 2) + "| " + lead + "^" + "~" * (width - 1))
        if self.hint:
            out.append(f"hint: {terminal_text(self.hint)}")
        return "\n".join(out)


def terminal_text(text: str, keep: str = "\n\t") -> str:
    """``text`` with each character that is not printable, but those in ``keep``, written as
    its Python escape: what an error quotes from a hostile file cannot drive the terminal."""
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() or c in keep else repr(c)[1:-1] for c in text)


_SHOWN = 160  # characters of a source line a message shows: a 10 MB line is cut around the caret


def _excerpt(text: str, column: int) -> tuple[str, int]:
    """A long line cut to about _SHOWN characters around ``column`` (marked with "..."), and the
    column in the cut text."""
    if len(text) <= _SHOWN:
        return text, column
    start = max(0, column - 1 - _SHOWN // 2)
    end = start + _SHOWN
    head = "..." if start else ""
    return head + text[start:end] + ("..." if end < len(text) else ""), column - start + len(head)


class BgrError(Exception):
    """The one exception type users of bgr see: bad input, with where and why."""

    def __init__(self, diagnostics: Diagnostic | Iterable[Diagnostic] | str, path: str = ""):
        if isinstance(diagnostics, str):
            diagnostics = [Diagnostic(path, 0, 0, diagnostics)]
        elif isinstance(diagnostics, Diagnostic):
            diagnostics = [diagnostics]
        self.diagnostics: list[Diagnostic] = list(diagnostics)
        first = self.diagnostics[0]
        self.path: str = first.path
        self.line: int = first.line
        self.column: int = first.column
        self.message: str = first.message
        self.hint: str | None = first.hint
        super().__init__(self.render())

    def __reduce__(self):
        # rebuilt from its diagnostics, not its text, when a worker process sends it back
        return (type(self), (self.diagnostics,))

    def render(self) -> str:
        text = "\n".join(d.render() for d in self.diagnostics)
        if len(self.diagnostics) > 1:
            text += f"\n{len(self.diagnostics)} errors"
        return text


class Warnings:
    """Where the warnings of a run go: problems it works around (a footprint skipped, a property
    ignored, a roof built as another kind) without stopping.

    Each is kept once, as a one-line :class:`Diagnostic` of severity ``warning`` (its source line
    and hint left out: a run over thousands of footprints may warn about hundreds); ``strict``
    makes the first one an error instead, shown in full (``--strict``).
    """

    def __init__(self, strict: bool = False) -> None:
        self.strict = strict
        self.items: list[Diagnostic] = []
        self.features: list[int | None] = []  # per item: the lot file's feature it is about
        self._seen: set[tuple] = set()

    def warn(
        self,
        diagnostic: Diagnostic,
        error: type[BgrError] | None = None,
        feature: int | None = None,
    ) -> None:
        """Keep ``diagnostic`` as a warning, or raise it (as ``error``, default BgrError) when
        strict."""
        if self.strict:
            raise (error or BgrError)(replace(diagnostic, severity="error"))
        self.add(diagnostic, feature)

    def add(self, diagnostic: Diagnostic, feature: int | None = None) -> None:
        """Keep a warning (once), whatever ``strict`` says."""
        key = (diagnostic.path, diagnostic.line, diagnostic.column, diagnostic.message)
        if key not in self._seen:
            self._seen.add(key)
            self.items.append(replace(diagnostic, severity="warning", hint=None, source_line=None))
            self.features.append(feature)

    def __len__(self) -> int:
        return len(self.items)


class HeldWarnings:
    """Warnings held back while a file is read in several passes (a GeoJSON file's features are
    parsed, then projected and cleaned together), then passed on sorted by the feature they are
    about, so that they come in the file's order whatever the pass that found them."""

    def __init__(self, target: Warnings, feature: int = -1, pending: list | None = None) -> None:
        self.target, self.feature = target, feature
        self.pending: list = pending if pending is not None else []

    def at(self, feature: int) -> HeldWarnings:
        """The same store, for warnings about one feature."""
        return HeldWarnings(self.target, feature, self.pending)

    def warn(self, diagnostic: Diagnostic, error: type[BgrError] | None = None) -> None:
        self.pending.append((self.feature, len(self.pending), diagnostic, error))

    def flush(self) -> None:
        """Pass the warnings on in feature order (the first raised, when strict)."""
        pending = sorted(self.pending, key=lambda p: p[:2])
        self.pending.clear()
        for feature, _, diagnostic, error in pending:
            self.target.warn(diagnostic, error, None if feature < 0 else feature)


class BgrSyntaxError(BgrError):
    """The text is not a .bgr file: a token out of place, an unknown character, a bad literal."""


class BgrCheckError(BgrError):
    """The file parses but does not check: unknown names, wrong argument counts, duplicates."""


def suggest(name: str, known: Iterable[str]) -> str | None:
    """The closest known name to a misspelt one, as a hint, or None when nothing is close."""
    known = sorted(set(known))
    for candidate in known:  # a difference of case only is the most likely slip
        if candidate.lower() == name.lower() and candidate != name:
            return f"did you mean '{candidate}'?"
    close = difflib.get_close_matches(name, known, n=1, cutoff=0.6)
    return f"did you mean '{close[0]}'?" if close else None


def normalise_newlines(source: str) -> str:
    """CRLF and a lone CR (old Mac files) made LF, as the parser reads text: so that every
    reader of a file (check, derive, fmt, messages) agrees where its lines end."""
    return source.replace("\r\n", "\n").replace("\r", "\n") if "\r" in source else source


def source_lines(source: str) -> list[str]:
    """Lines as the lexer counts them: "\n", "\r\n" and "\r" end a line (str.splitlines also
    breaks at "\f", "\u2028" ... which would put messages and comments on the wrong line)."""
    return normalise_newlines(source).split("\n")


def source_line(source: str, line: int) -> str | None:
    lines = source_lines(source)
    return lines[line - 1] if 0 < line <= len(lines) else None
