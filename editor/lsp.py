"""``bgr lsp``: a language server for .bgr files (pygls, over standard input and output).

Every answer comes from :mod:`.analysis` (bgr's checker, registry and formatter); this module
only speaks the protocol: 0-based positions, URIs, the protocol's kinds.

* diagnostics as you type: each change of a document is checked and its errors (or warnings)
  published, at the checker's line and column, underlining what it underlines;
* completion: the file's rules, attrs, consts, funcs, assets and imports, the operations and
  functions of the language, the stdlib's modules, and after ``alias.`` the imported module's;
* hover: an operation's or function's usage and doc (docs/operations.md is made of the same),
  or what a name of the file is;
* go to definition, also of ``alias.Name`` into the imported file;
* document symbols; formatting, as ``bgr fmt``.

A document that does not check keeps answering completion, hover and definition from the last
version that did.
"""

from __future__ import annotations

import re
from pathlib import Path

from lsprotocol import types as t
from pygls.lsp.server import LanguageServer
from pygls.uris import from_fs_path, to_fs_path

from bgr import __version__

from . import analysis

_SYMBOL_KINDS = {
    "rule": t.SymbolKind.Function,
    "attr": t.SymbolKind.Variable,
    "const": t.SymbolKind.Constant,
    "func": t.SymbolKind.Method,
    "asset": t.SymbolKind.File,
    "import": t.SymbolKind.Module,
    "terminal": t.SymbolKind.Class,
}
_COMPLETION_KINDS = {
    "rule": t.CompletionItemKind.Function,
    "attr": t.CompletionItemKind.Variable,
    "const": t.CompletionItemKind.Constant,
    "func": t.CompletionItemKind.Method,
    "asset": t.CompletionItemKind.File,
    "import": t.CompletionItemKind.Module,
    "module": t.CompletionItemKind.Module,
    "terminal": t.CompletionItemKind.Class,
    "operation": t.CompletionItemKind.Keyword,
    "function": t.CompletionItemKind.Function,
}


_NAME_END = re.compile(r"[A-Za-z0-9_.]*$")  # the (dotted) name being typed, before the cursor


class BgrServer(LanguageServer):
    """The server, with the last grammar that checked of each open document."""

    def __init__(self) -> None:
        super().__init__("bgr", __version__, text_document_sync_kind=t.TextDocumentSyncKind.Full)
        self.grammars: dict[str, analysis.Grammar] = {}

    def document(self, uri: str) -> tuple[str, str]:
        """(text, path) of an open document; a document with no file path is checked as if it
        were in the current folder."""
        doc = self.workspace.get_text_document(uri)
        return doc.source, to_fs_path(uri) or str(Path.cwd() / "untitled.bgr")

    def refresh(self, uri: str) -> None:
        """Check the document and publish what the checker found."""
        text, path = self.document(uri)
        checked = analysis.check(text, path)
        if checked.grammar is not None:
            self.grammars[uri] = checked.grammar
        mine = Path(path).resolve()
        found = []
        for d in checked.diagnostics:
            ours = d.path and Path(d.path).resolve() == mine
            found.append(_diagnostic(d, ours))
        self.text_document_publish_diagnostics(
            t.PublishDiagnosticsParams(uri=uri, diagnostics=found)
        )


server = BgrServer()


@server.feature(t.TEXT_DOCUMENT_DID_OPEN)
def _opened(ls: BgrServer, params: t.DidOpenTextDocumentParams) -> None:
    ls.refresh(params.text_document.uri)


@server.feature(t.TEXT_DOCUMENT_DID_CHANGE)
def _changed(ls: BgrServer, params: t.DidChangeTextDocumentParams) -> None:
    ls.refresh(params.text_document.uri)


@server.feature(t.TEXT_DOCUMENT_DID_SAVE)
def _saved(ls: BgrServer, params: t.DidSaveTextDocumentParams) -> None:
    ls.refresh(params.text_document.uri)


@server.feature(t.TEXT_DOCUMENT_DID_CLOSE)
def _closed(ls: BgrServer, params: t.DidCloseTextDocumentParams) -> None:
    ls.grammars.pop(params.text_document.uri, None)
    ls.text_document_publish_diagnostics(
        t.PublishDiagnosticsParams(uri=params.text_document.uri, diagnostics=[])
    )


@server.feature(t.TEXT_DOCUMENT_COMPLETION, t.CompletionOptions(trigger_characters=["."]))
def _complete(ls: BgrServer, params: t.CompletionParams) -> t.CompletionList:
    text, _ = ls.document(params.text_document.uri)
    lines = text.splitlines()
    line = lines[params.position.line] if params.position.line < len(lines) else ""
    name = _NAME_END.search(line[: params.position.character])
    prefix = name.group() if name else ""
    # a dotted name replaces all of what was typed (editors stop a word at the dot)
    typed = t.Range(
        t.Position(params.position.line, params.position.character - len(prefix)), params.position
    )
    items = [
        t.CompletionItem(
            label=c.label,
            kind=_COMPLETION_KINDS.get(c.kind),
            detail=c.detail or None,
            documentation=t.MarkupContent(t.MarkupKind.Markdown, c.doc) if c.doc else None,
            text_edit=t.TextEdit(typed, c.label) if "." in prefix else None,
        )
        for c in analysis.completions(ls.grammars.get(params.text_document.uri), prefix)
    ]
    return t.CompletionList(is_incomplete=False, items=items)


@server.feature(t.TEXT_DOCUMENT_HOVER)
def _hover(ls: BgrServer, params: t.HoverParams) -> t.Hover | None:
    text, _ = ls.document(params.text_document.uri)
    word = analysis.word_at(text, params.position.line + 1, params.position.character + 1)
    if word is None:
        return None
    found = analysis.hover(ls.grammars.get(params.text_document.uri), word)
    if found is None:
        return None
    return t.Hover(contents=t.MarkupContent(kind=t.MarkupKind.Markdown, value=found))


@server.feature(t.TEXT_DOCUMENT_DEFINITION)
def _definition(ls: BgrServer, params: t.DefinitionParams) -> t.Location | None:
    text, _ = ls.document(params.text_document.uri)
    grammar = ls.grammars.get(params.text_document.uri)
    word = analysis.word_at(text, params.position.line + 1, params.position.character + 1)
    if grammar is None or word is None:
        return None
    found = analysis.definition(grammar, word)
    if found is None:
        return None
    return t.Location(uri=_uri(found.path), range=_range(found.pos, len(found.name)))


@server.feature(t.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
def _symbols(ls: BgrServer, params: t.DocumentSymbolParams) -> list[t.DocumentSymbol]:
    grammar = ls.grammars.get(params.text_document.uri)
    if grammar is None:
        return []
    return [
        t.DocumentSymbol(
            name=s.name,
            kind=_SYMBOL_KINDS[s.kind],
            range=_range(s.pos, len(s.name)),
            selection_range=_range(s.pos, len(s.name)),
            detail=s.detail or None,
        )
        for s in analysis.symbols(grammar)
    ]


@server.feature(t.TEXT_DOCUMENT_FORMATTING)
def _format(ls: BgrServer, params: t.DocumentFormattingParams) -> list[t.TextEdit] | None:
    text, path = ls.document(params.text_document.uri)
    new = analysis.formatted(text, path)
    if new is None or new == text:
        return []  # nothing to change, or text that does not parse: its diagnostics say why
    lines = text.split("\n")
    whole = t.Range(t.Position(0, 0), t.Position(len(lines), 0))
    return [t.TextEdit(range=whole, new_text=new)]


def _range(pos, length: int = 1) -> t.Range:
    """The protocol's 0-based range of a checker position (1-based), ``length`` characters
    long where the position has no end."""
    line, column = max(pos.line - 1, 0), max(pos.column - 1, 0)
    if getattr(pos, "end_line", 0) and pos.end_line == pos.line and pos.end_column >= pos.column:
        length = pos.end_column - pos.column + 1
    return t.Range(t.Position(line, column), t.Position(line, column + max(length, 1)))


def _diagnostic(d, ours: bool) -> t.Diagnostic:
    """A checker diagnostic for the protocol; one in another file (an import) is shown on the
    document's first line, naming that file."""
    message = d.message + (f" ({d.hint})" if d.hint else "")
    warning = d.severity == "warning"
    severity = t.DiagnosticSeverity.Warning if warning else t.DiagnosticSeverity.Error
    if ours:
        start = t.Position(max(d.line - 1, 0), max(d.column - 1, 0))
        end = t.Position(start.line, start.character + max(d.length, 1))
        return t.Diagnostic(t.Range(start, end), message, severity=severity, source="bgr")
    where = f"{d.path}:{d.line}:{d.column}: " if d.path else ""
    first = t.Range(t.Position(0, 0), t.Position(0, 1))
    return t.Diagnostic(first, where + message, severity=severity, source="bgr")


def _uri(path: str) -> str:
    return from_fs_path(str(Path(path).resolve())) or path


def main() -> None:
    """Serve over standard input and output until the client says exit."""
    server.start_io()
