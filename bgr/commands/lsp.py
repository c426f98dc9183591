"""``bgr lsp``: the language server for editors (editor/lsp.py; docs/editors.md)."""

from __future__ import annotations

from ..grammar.errors import BgrError
from .common import EXIT_OK


def add_parser(commands) -> None:
    p = commands.add_parser(
        "lsp",
        help="run the language server (LSP over standard input and output) for editors",
        description="Run the .bgr language server: diagnostics from the checker as you type, "
        "completion, hover with the operations' docs, go to definition (across imports), "
        "document symbols and formatting, over standard input and output. An editor starts "
        "it; see docs/editors.md (VS Code, Neovim, Helix). Needs pygls: pip install 'bgr[lsp]'.",
    )
    p.set_defaults(command="lsp")


def run(args) -> int:
    try:
        from ..editor.lsp import main
    except ImportError as e:
        if "pygls" not in str(e) and "lsprotocol" not in str(e):
            raise
        raise BgrError(
            "bgr lsp needs the language-server library pygls, an optional extra: "
            "pip install 'bgr[lsp]'"
        ) from None
    main()
    return EXIT_OK
