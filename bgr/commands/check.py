"""``bgr check FILE...``: parse each file, resolve its imports and names, report every error.
It reads only the grammar front end (no numpy), so it starts quickly."""

from __future__ import annotations

import sys
from pathlib import Path

from ..grammar.errors import BgrError
from ..grammar.loader import load
from .common import EXIT_INPUT, EXIT_OK, add_allow_path, read_text


def add_parser(commands) -> None:
    check = commands.add_parser(
        "check",
        help="parse, resolve names and report every error",
        description="Parse each file, resolve its imports and names, and "
        "report every error found. Exit 0 when all files are clean.",
    )
    check.add_argument(
        "files", nargs="+", metavar="FILE", help=".bgr files ('-' reads standard input)"
    )
    check.add_argument("-q", "--quiet", action="store_true", help="print nothing for clean files")
    add_allow_path(check)


def run(args) -> int:
    status = EXIT_OK
    for name in args.files:
        shown = "<stdin>" if name == "-" else name
        try:
            source = read_text(name)[0] if name == "-" else Path(name)
            grammar = load(source, path=shown, allow_paths=args.allow_path)
        except BgrError as e:
            print(e.render(), file=sys.stderr)
            status = EXIT_INPUT
            continue
        print(*(w.render() + "\n" for w in grammar.warnings), sep="", end="", file=sys.stderr)
        count = len(grammar.warnings)  # the file checks: warnings leave the status at 0
        if not args.quiet:
            print(f"{shown}: ok" + (f" ({count} warning{'s' * (count > 1)})" if count else ""))
    return status
