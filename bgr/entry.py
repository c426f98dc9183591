"""The ``bgr`` command's entry point: ``bgr --version`` answers before the command line's
modules (the parser, the interpreter, numpy) are imported; everything else is bgr.cli."""

from __future__ import annotations

import sys


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if args == ["--version"]:
        from . import version

        print(f"bgr {version()}")
        return 0
    from .cli import main as cli_main

    return cli_main(argv)
