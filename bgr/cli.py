"""The ``bgr`` command: a thin layer over the Python API.

Exit status (LANGUAGE.md section 12): 0 success, 1 bad input (with a message), 2 bad usage.
No input produces a Python traceback: every failure a user can cause is a BgrError, printed as
``path:line:col: error: ...``; anything else is reported as an internal error, with the
traceback only when BGR_DEBUG=1.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import traceback
from pathlib import Path

from . import __version__
from .grammar.errors import BgrError
from .grammar.formatter import format_module
from .grammar.loader import decode, load, read_source
from .grammar.parser import parse

EXIT_OK, EXIT_INPUT, EXIT_USAGE = 0, 1, 2


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # bad usage: exit 2 with a one-line reason
        self.print_usage(sys.stderr)
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="bgr", description="bgr: a building-grammar toolkit. "
                     "Write .bgr shape grammars, check them and format them.",
                     epilog="Exit status: 0 success, 1 bad input, 2 bad usage. "
                     "Language reference: docs/language.md.")
    parser.add_argument("--version", action="version", version=f"bgr {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    check = commands.add_parser("check", help="parse, resolve names and report every error",
                                description="Parse each file, resolve its imports and names, and "
                                "report every error found. Exit 0 when all files are clean.")
    check.add_argument("files", nargs="+", metavar="FILE", help=".bgr files ('-' reads standard input)")
    check.add_argument("-q", "--quiet", action="store_true", help="print nothing for clean files")

    fmt = commands.add_parser("fmt", help="print files in the canonical layout",
                              description="Format .bgr files in the canonical layout, keeping "
                              "comments. Without options the result goes to standard output.")
    fmt.add_argument("files", nargs="+", metavar="FILE", help=".bgr files ('-' reads standard input)")
    mode = fmt.add_mutually_exclusive_group()
    mode.add_argument("--check", action="store_true",
                      help="change nothing; exit 1 if a file is not formatted")
    mode.add_argument("-w", "--write", action="store_true", help="rewrite the files in place")
    return parser


def _read(name: str) -> tuple[str, str]:
    if name == "-":
        return decode(sys.stdin.buffer.read(), "<stdin>"), "<stdin>"
    return read_source(name), name


def cmd_check(args) -> int:
    status = EXIT_OK
    for name in args.files:
        try:
            if name == "-":
                text, _ = _read(name)
                load(text, path="<stdin>")
            else:
                load(Path(name), path=name)
        except BgrError as e:
            print(e.render(), file=sys.stderr)
            status = EXIT_INPUT
            continue
        if not args.quiet:
            print(f"{'<stdin>' if name == '-' else name}: ok")
    return status


def cmd_fmt(args) -> int:
    if not (args.check or args.write) and len(args.files) > 1:
        print("bgr fmt: give one file to print, or use --check or -w with several", file=sys.stderr)
        return EXIT_USAGE
    if args.write and "-" in args.files:
        print("bgr fmt: -w cannot rewrite standard input", file=sys.stderr)
        return EXIT_USAGE
    status = EXIT_OK
    for name in args.files:
        try:
            text, shown = _read(name)
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


def write_atomic(path: Path, text: str) -> None:
    """Write beside the target and rename over it, so a failure never leaves half a file."""
    folder = path.resolve().parent
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
            f.write(text)
        if path.exists():
            os.chmod(tmp, path.stat().st_mode & 0o7777)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


COMMANDS = {"check": cmd_check, "fmt": cmd_fmt}


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    try:
        return COMMANDS[args.command](args)
    except BgrError as e:
        print(e.render(), file=sys.stderr)
        return EXIT_INPUT
    except KeyboardInterrupt:
        print("bgr: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        sys.stderr.close()  # the reader went away (bgr fmt x | head): not an error of ours
        return EXIT_OK
    except Exception as e:  # a bug of ours: say so without a traceback unless asked
        if os.environ.get("BGR_DEBUG"):
            traceback.print_exc()
        print(f"bgr: internal error: {type(e).__name__}: {e} (please report it; "
              "BGR_DEBUG=1 shows the traceback)", file=sys.stderr)
        return EXIT_INPUT


if __name__ == "__main__":
    sys.exit(main())
