"""``bgr import-cga FILE.cga -o FILE.bgr``: the command, kept beside the translator it runs."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..formats.atomic import write_text
from ..grammar.errors import BgrError, Diagnostic
from .files import translate_file


def add_parser(commands) -> None:
    command = commands.add_parser(
        "import-cga",
        help="translate a CityEngine CGA rule file into a .bgr grammar",
        description="Translate a CityEngine CGA rule file (2014.0 onwards) and the CGA files it "
        "imports into .bgr grammars, comments kept. Every construct bgr has no counterpart for "
        "is reported with its file:line:col and left out, so the grammar still derives; "
        "assets and textures are looked up beside the file (a rule package's assets/ folder "
        "beside its rules/), a missing asset becomes a box of its scope. docs/cga.md lists "
        "what translates.",
    )
    command.add_argument("file", metavar="FILE.cga")
    command.add_argument(
        "-o",
        "--output",
        metavar="FILE.bgr",
        help="the grammar to write (default: FILE.bgr in the current folder); imported CGA "
        "files are written beside it",
    )
    command.add_argument(
        "--strict",
        action="store_true",
        help="treat every construct that could not be translated as an error: report them "
        "all, write nothing and exit 1",
    )
    command.add_argument(
        "-q", "--quiet", action="store_true", help="do not print the warnings, only their count"
    )


def run(args: argparse.Namespace) -> int:
    source = Path(args.file)
    output = Path(args.output) if args.output else Path(source.stem + ".bgr")
    if output.suffix.lower() != ".bgr":
        raise BgrError(
            Diagnostic(
                str(output),
                0,
                0,
                "the output must be a .bgr file",
                f"-o {output.with_suffix('.bgr')}",
            )
        )
    result = translate_file(source, output)
    result.warnings.sort(key=lambda d: (d.path != str(source), d.path, d.line, d.column))
    if args.strict and result.warnings:
        raise BgrError([_as_error(w) for w in result.warnings])
    for path, text in result.outputs.items():
        write_text(path, text)
    if not args.quiet:
        for w in result.warnings:
            print(w.render(), file=sys.stderr)
    written = ", ".join(str(p) for p in result.outputs)
    count = len(result.warnings)
    print(
        f"{written}: written; {count} construct{'s' if count != 1 else ''} not translated"
        + (" (see above)" if count and not args.quiet else ""),
        file=sys.stderr,
    )
    return 0


def _as_error(d: Diagnostic) -> Diagnostic:
    return Diagnostic(d.path, d.line, d.column, d.message, d.hint, d.source_line, d.length)
