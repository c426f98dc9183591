"""``bgr restyle MASS --style STYLE.bgr -o OUT``: decorate an untextured mass with a captured
style sheet (inverse/style; its arguments and its work are in that module's command.py)."""

from __future__ import annotations

from .common import ALLOW_PATH_HELP
from .options import add_memory_option, under_ceiling


def add_parser(commands) -> None:
    from ..inverse.style.command import add_restyle_parser

    add_restyle_parser(commands, ALLOW_PATH_HELP, add_memory_option)


def run(args) -> int:
    from ..inverse.style.command import run_restyle

    return under_ceiling(args, "restyle", "give a smaller mass", run_restyle)
