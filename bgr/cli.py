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
                     "Write .bgr shape grammars, check and format them, derive them into meshes.",
                     epilog="Exit status: 0 success, 1 bad input, 2 bad usage. "
                     "Language reference: docs/language.md.")
    parser.add_argument("--version", action="version", version=f"bgr {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    check = commands.add_parser("check", help="parse, resolve names and report every error",
                                description="Parse each file, resolve its imports and names, and "
                                "report every error found. Exit 0 when all files are clean.")
    check.add_argument("files", nargs="+", metavar="FILE", help=".bgr files ('-' reads standard input)")
    check.add_argument("-q", "--quiet", action="store_true", help="print nothing for clean files")

    derive = commands.add_parser("derive", help="derive a grammar into a mesh or a terminal list",
                                 description="Derive FILE.bgr on a lot and write the result; the "
                                 "format follows the output's extension (.glb .gltf .obj .ply .stl .json).")
    derive.add_argument("file", metavar="FILE.bgr")
    derive.add_argument("-o", "--output", metavar="OUT", help="output file ('-' with --format json: stdout)")
    derive.add_argument("--format", choices=["glb", "gltf", "obj", "ply", "stl", "json"],
                        help="output format when the extension does not say it (json for stdout)")
    derive.add_argument("--seed", type=int, default=0, help="global random seed (default 0)")
    derive.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="override an attr; repeatable")
    derive.add_argument("--lot", metavar="W,D|LOTS.geojson",
                        help="the lot: width,depth in metres (default 20,20) or GeoJSON footprints")
    derive.add_argument("--max-depth", type=int, default=256, metavar="N", help="rule depth limit (256)")
    derive.add_argument("--max-shapes", type=int, default=10_000_000, metavar="N",
                        help="shape budget (10,000,000)")

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


def _parse_value(text: str):
    """--set values: numbers, true/false, else strings (quotes optional)."""
    if text in ("true", "false"):
        return text == "true"
    try:
        value = float(text)
    except ValueError:
        return text[1:-1] if len(text) >= 2 and text[0] == text[-1] == '"' else text
    return int(value) if value.is_integer() and "." not in text and "e" not in text.lower() else value


def cmd_derive(args) -> int:
    from .interpreter.derive import derive
    from .interpreter.writers import write, write_json

    if args.output in (None, "-") and args.format != "json":
        print("bgr derive: give an output file with -o OUT.glb (or -o - --format json for the "
              "terminal list on standard output)", file=sys.stderr)
        return EXIT_USAGE
    attrs = {}
    for item in args.set:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            print(f"bgr derive: --set {item}: write NAME=VALUE", file=sys.stderr)
            return EXIT_USAGE
        attrs[name.strip()] = _parse_value(value.strip())
    if args.max_depth < 1 or args.max_shapes < 1:
        print("bgr derive: --max-depth and --max-shapes must be positive", file=sys.stderr)
        return EXIT_USAGE
    grammar = load(Path(args.file), path=args.file)
    result = derive(grammar, seed=args.seed, attrs=attrs, lot=args.lot,
                    max_depth=args.max_depth, max_shapes=args.max_shapes)
    if args.output in (None, "-"):
        write_json(result.terminals, sys.stdout, seed=args.seed, attrs=result.attrs)
    else:
        write(result.terminals, Path(args.output), seed=args.seed, attrs=result.attrs, fmt=args.format)
        print(f"{args.output}: {len(result):,} terminals, {result.terminals.triangle_count():,} triangles",
              file=sys.stderr)
    return EXIT_OK


COMMANDS = {"check": cmd_check, "fmt": cmd_fmt, "derive": cmd_derive}


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
