"""What every subcommand shares: exit statuses, argument types, reading a grammar's text and
writing a file atomically."""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from ..grammar.errors import BgrError, Diagnostic
from ..grammar.loader import decode, read_source

EXIT_OK, EXIT_INPUT, EXIT_USAGE = 0, 1, 2
EXIT_INTERRUPTED, EXIT_TERMINATED = 130, 143  # 128 + SIGINT, 128 + SIGTERM, as shells report

ALLOW_PATH_HELP = (
    "also let imports and assets read files under DIR (repeatable); by default they must stay "
    "in the grammar's own folder or the stdlib"
)


def add_allow_path(command: argparse.ArgumentParser, help: str = ALLOW_PATH_HELP) -> None:
    """--allow-path DIR: the folders beyond the grammar's own that files may be read from."""
    command.add_argument("--allow-path", action="append", default=[], metavar="DIR", help=help)


def read_text(name: str) -> tuple[str, str]:
    """A grammar's text and the name to show for it; ``-`` is standard input."""
    if name == "-":
        return decode(sys.stdin.buffer.read(), "<stdin>"), "<stdin>"
    return read_source(name), name


def write_atomic(path: Path, text: str) -> None:
    """Write beside the target and rename over it, so a failure never leaves half a file."""
    from ..formats.atomic import write_text

    write_text(path, text)


def parse_value(text: str, item: str = ""):
    """--set values: numbers, true/false, else strings (quotes optional).

    A number is written as in the .bgr language (ASCII digits, optional sign, fraction and
    exponent; interpreter/values.py): "1_000" and "١٠" stay strings, though Python's float()
    reads both.  A number must be finite and in range, and "nan" or "inf" is refused rather
    than passed on as a string that fails later, far from the option."""
    from ..interpreter.values import NUMBER_SYNTAX, is_number, number_of, number_problem

    if text in ("true", "false"):
        return text == "true"
    value = number_of(text)
    if value is None and (NUMBER_SYNTAX.fullmatch(text) or _SPECIAL.fullmatch(text)):
        value = float(text)  # 1e400, inf, nan: refused below
    if value is None:
        return text[1:-1] if len(text) >= 2 and text[0] == text[-1] == '"' else text
    problem = number_problem(value) if is_number(value) else None
    if problem:
        raise BgrError(
            Diagnostic(
                "",
                0,
                0,
                f"--set {item or text}: {text[:40]} is {problem}",
                "write a number such as 12.5, or a string in quotes: --set 'NAME=\"text\"'",
            )
        )
    return int(value) if isinstance(value, int) else value


# what float() reads as infinite or not a number
_SPECIAL = re.compile(r"[+-]?(inf|infinity|nan)", re.IGNORECASE)


def set_values(items: list[str]) -> dict | str:
    """The attrs of the --set NAME=VALUE options, or what is wrong with one of them."""
    attrs = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            return f"--set {item}: write NAME=VALUE"
        attrs[name.strip()] = parse_value(value.strip(), item)
    return attrs


def whole(text: str) -> int:
    """An argparse type: a whole number in ASCII digits (int() also takes "1_000" and "١٠")."""
    if not re.fullmatch(r"\s*[+-]?[0-9]{1,30}\s*", text):
        raise argparse.ArgumentTypeError(f"{text[:40]!r} is not a whole number")
    return int(text)


def count(text: str) -> int:
    """An argparse type: a whole number of at least 0 (a count of workers)."""
    value = whole(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"{text[:40]!r} is not 0 or more")
    return value
