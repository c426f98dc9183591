"""``bgr fmt FILE...``: print .bgr files in the canonical layout (grammar/formatter.py),
check it (--check) or rewrite them in place (-w)."""

from __future__ import annotations

import sys
from pathlib import Path

from ..grammar.errors import BgrError
from ..grammar.formatter import format_module
from ..grammar.parser import parse
from .common import EXIT_INPUT, EXIT_OK, EXIT_USAGE, read_text, write_atomic


def add_parser(commands) -> None:
    fmt = commands.add_parser(
        "fmt",
        help="print files in the canonical layout",
        description="Format .bgr files in the canonical layout, keeping "
        "comments. Without options the result goes to standard output.",
    )
    fmt.add_argument(
        "files", nargs="+", metavar="FILE", help=".bgr files ('-' reads standard input)"
    )
    mode = fmt.add_mutually_exclusive_group()
    mode.add_argument(
        "--check", action="store_true", help="change nothing; exit 1 if a file is not formatted"
    )
    mode.add_argument("-w", "--write", action="store_true", help="rewrite the files in place")


def run(args) -> int:
    if not (args.check or args.write) and len(args.files) > 1:
        print("bgr fmt: give one file to print, or use --check or -w with several", file=sys.stderr)
        return EXIT_USAGE
    if args.write and "-" in args.files:
        print("bgr fmt: -w cannot rewrite standard input", file=sys.stderr)
        return EXIT_USAGE
    status = EXIT_OK
    for name in args.files:
        try:
            text, shown = read_text(name)
            formatted = format_module(parse(text, shown))
        except BgrError as e:
            print(e.render(), file=sys.stderr)
            status = EXIT_INPUT
            continue
        if args.check:
            if formatted != text:
                print(f"{name}: not formatted (run 'bgr fmt -w {name}')", file=sys.stderr)
                status = EXIT_INPUT
        elif args.write:
            if formatted != text:
                write_atomic(Path(name), formatted)
                print(f"{name}: formatted")
        else:
            sys.stdout.write(formatted)
    return status
