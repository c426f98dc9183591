"""``bgr lsp`` driven as an editor drives it: pytest-lsp starts ``python -m bgr lsp`` and talks
LSP to it over standard input and output (issue 32: diagnostics on a broken file at the
checker's positions, completion inside a rule body, hover on an operation, definition across
an import, formatting)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

pytest.importorskip("pygls")
pytest_lsp = pytest.importorskip("pytest_lsp")

from lsprotocol import types as t  # noqa: E402
from pytest_lsp import ClientServerConfig, LanguageClient, client_capabilities  # noqa: E402

import bgr  # noqa: E402

pytestmark = [pytest.mark.asyncio, pytest.mark.xdist_group("lsp")]

WINDOW = """terminal Glass
attr frame = 0.1
Window --> s('1, '1, frame) Glass
"""

HOUSE = """import "window.bgr" as win
terminal Wall
attr floors = 3

Lot --> extrude(floors * 3) comp(f) { side: Facade | top: Wall }
Facade --> split(y) { ~3: Floor }*
Floor --> split(x) { ~2: Wall | 1.5: win.Window | ~2: Wall }*
"""


@pytest_lsp.fixture(
    config=ClientServerConfig(server_command=[sys.executable, "-m", "bgr", "lsp"]),
)
async def client(lsp_client: LanguageClient, tmp_path_factory):
    folder = tmp_path_factory.mktemp("lsp")
    (folder / "window.bgr").write_text(WINDOW)
    (folder / "house.bgr").write_text(HOUSE)
    await lsp_client.initialize_session(
        t.InitializeParams(
            capabilities=client_capabilities("visual-studio-code"),
            root_uri=folder.as_uri(),
        )
    )
    lsp_client.folder = folder  # type: ignore[attr-defined]
    yield
    await lsp_client.shutdown_session()


def open_document(client: LanguageClient, path: Path, text: str, version: int = 1) -> str:
    uri = path.as_uri()
    client.text_document_did_open(
        t.DidOpenTextDocumentParams(
            text_document=t.TextDocumentItem(uri=uri, language_id="bgr", version=version, text=text)
        )
    )
    return uri


def change(client: LanguageClient, uri: str, text: str, version: int) -> None:
    client.text_document_did_change(
        t.DidChangeTextDocumentParams(
            text_document=t.VersionedTextDocumentIdentifier(uri=uri, version=version),
            content_changes=[t.TextDocumentContentChangeWholeDocument(text=text)],
        )
    )


async def diagnostics_of(client: LanguageClient, uri: str) -> list[t.Diagnostic]:
    await client.wait_for_notification(t.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    return client.diagnostics.get(uri, [])


async def test_a_broken_file_gets_the_checkers_diagnostics(client: LanguageClient):
    path = client.folder / "broken.bgr"  # type: ignore[attr-defined]
    text = "terminal A\nLot --> extrude(3) Nowhere\n"
    uri = open_document(client, path, text)
    found = await diagnostics_of(client, uri)
    with pytest.raises(bgr.BgrError) as checker:
        bgr.load(text, path=str(path))
    want = checker.value.diagnostics[0]
    assert len(found) == len(checker.value.diagnostics)
    assert found[0].severity == t.DiagnosticSeverity.Error
    assert "Nowhere" in found[0].message
    assert (found[0].range.start.line, found[0].range.start.character) == (
        want.line - 1,
        want.column - 1,
    )
    # fixed as the user types: the diagnostics go
    change(client, uri, "terminal A\nLot --> extrude(3) A\n", 2)
    assert not await diagnostics_of(client, uri)


async def test_completion_inside_a_rule_body(client: LanguageClient):
    path = client.folder / "house.bgr"  # type: ignore[attr-defined]
    uri = open_document(client, path, HOUSE)
    await diagnostics_of(client, uri)
    # at the end of "Floor --> split(x) { ~2: Wall | 1.5: win.Window | ~2: Wall }*", line 7
    result = await client.text_document_completion_async(
        t.CompletionParams(
            text_document=t.TextDocumentIdentifier(uri=uri), position=t.Position(6, 10)
        )
    )
    labels = {item.label for item in result.items}
    assert {"Facade", "Floor", "floors", "extrude", "split", "rand", "stdlib.palette"} <= labels
    # after "win." the imported module's names
    change(client, uri, HOUSE + "Other --> win.\n", 2)
    await diagnostics_of(client, uri)
    result = await client.text_document_completion_async(
        t.CompletionParams(
            text_document=t.TextDocumentIdentifier(uri=uri), position=t.Position(7, 14)
        )
    )
    assert {"win.Window", "win.frame", "win.Glass"} <= {item.label for item in result.items}
    # each replaces all of "win." (an editor's word stops at the dot)
    window = next(item for item in result.items if item.label == "win.Window")
    assert window.text_edit.new_text == "win.Window"
    assert (window.text_edit.range.start.character, window.text_edit.range.end.character) == (
        10,
        14,
    )


async def test_hover_on_an_operation_shows_its_doc(client: LanguageClient):
    path = client.folder / "house.bgr"  # type: ignore[attr-defined]
    uri = open_document(client, path, HOUSE)
    await diagnostics_of(client, uri)
    hover = await client.text_document_hover_async(
        t.HoverParams(text_document=t.TextDocumentIdentifier(uri=uri), position=t.Position(4, 10))
    )
    assert hover is not None
    assert "extrude" in hover.contents.value
    assert bgr.grammar.registry.OPERATIONS["extrude"].doc in hover.contents.value


async def test_definition_across_an_import(client: LanguageClient):
    path = client.folder / "house.bgr"  # type: ignore[attr-defined]
    uri = open_document(client, path, HOUSE)
    await diagnostics_of(client, uri)
    column = HOUSE.splitlines()[6].index("win.Window") + 5
    found = await client.text_document_definition_async(
        t.DefinitionParams(
            text_document=t.TextDocumentIdentifier(uri=uri), position=t.Position(6, column)
        )
    )
    assert found is not None
    assert found.uri == (client.folder / "window.bgr").resolve().as_uri()  # type: ignore[attr-defined]
    assert found.range.start.line == 2  # "Window --> ..." is line 3 of window.bgr


async def test_document_symbols_and_formatting(client: LanguageClient):
    path = client.folder / "house.bgr"  # type: ignore[attr-defined]
    messy = HOUSE.replace("Lot --> extrude(floors * 3)", "Lot-->extrude( floors*3 )")
    uri = open_document(client, path, messy)
    await diagnostics_of(client, uri)
    symbols = await client.text_document_document_symbol_async(
        t.DocumentSymbolParams(text_document=t.TextDocumentIdentifier(uri=uri))
    )
    names = {(s.name, s.kind) for s in symbols}
    assert ("Lot", t.SymbolKind.Function) in names and ("floors", t.SymbolKind.Variable) in names
    edits = await client.text_document_formatting_async(
        t.DocumentFormattingParams(
            text_document=t.TextDocumentIdentifier(uri=uri),
            options=t.FormattingOptions(tab_size=4, insert_spaces=True),
        )
    )
    assert len(edits) == 1
    assert edits[0].new_text == bgr.format_source(messy)
