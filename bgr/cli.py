"""The ``bgr`` command: a thin layer over the Python API.

Each subcommand is a module of ``bgr/commands/`` (``import-cga``'s is ``cga/command.py``, beside
its translator) with ``add_parser(commands)`` and ``run(args)``; this module builds the command
line from them and dispatches.

Exit status (LANGUAGE.md section 12): 0 success, 1 bad input (with a message), 2 bad usage.
No input produces a Python traceback: every failure a user can cause is a BgrError, printed as
``path:line:col: error: ...``; anything else is reported as an internal error, with the
traceback only when BGR_DEBUG=1.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import traceback

from . import __version__
from .cga import command as import_cga
from .commands import check, derive, fmt, infer, lsp, render, restyle, retarget, serve
from .commands.common import EXIT_INPUT, EXIT_INTERRUPTED, EXIT_OK, EXIT_TERMINATED, EXIT_USAGE
from .commands.options import address_space_restored
from .formats.atomic import Terminated, on_sigterm, reset_termination
from .grammar.errors import BgrError
from .interpreter.limits import format_bytes

# the subcommands, in the order --help lists them
COMMANDS = {
    "check": check,
    "derive": derive,
    "render": render,
    "infer": infer,
    "restyle": restyle,
    "retarget": retarget,
    "fmt": fmt,
    "import-cga": import_cga,
    "lsp": lsp,
    "serve": serve,
}

# what main()'s out-of-memory message advises besides --max-memory, by command
OUT_OF_MEMORY = {
    "derive": "derive fewer or smaller shapes",
    "render": "derive fewer or smaller shapes",
    "infer": "infer from a smaller input",
    "retarget": "ask a smaller size, or give fewer boxes",
    "restyle": "give a smaller mass",
}


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # bad usage: exit 2 with a one-line reason
        self.print_usage(sys.stderr)
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="bgr",
        description="bgr: a building-grammar toolkit. "
        "Write .bgr shape grammars, check and format them, derive them into meshes.",
        epilog="Exit status: 0 success, 1 bad input, 2 bad usage, 130 interrupted, 143 terminated "
        "(SIGTERM). Imports and assets stay in the grammar's folder and the stdlib unless "
        "--allow-path widens them; inputs and outputs must be regular files. "
        "Language reference: docs/language.md; files: docs/cli.md.",
    )
    parser.add_argument("--version", action="version", version=f"bgr {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for module in COMMANDS.values():
        module.add_parser(commands)
    return parser


def _ceiling(args) -> str:
    memory = getattr(args, "memory_ceiling", None)
    return format_bytes(memory) if memory else "the machine's memory"


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    reset_termination()
    previous = _on_sigterm(on_sigterm)
    try:
        with address_space_restored():
            return COMMANDS[args.command].run(args)
    except BgrError as e:
        print(e.render(), file=sys.stderr)
        return EXIT_INPUT
    except Terminated:
        print("bgr: terminated", file=sys.stderr)
        return EXIT_TERMINATED
    except KeyboardInterrupt:
        print("bgr: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except MemoryError:
        smaller = OUT_OF_MEMORY.get(args.command, OUT_OF_MEMORY["derive"])
        print(
            f"bgr {args.command}: out of memory (the ceiling is "
            f"{_ceiling(args)}); {smaller}, or raise it with --max-memory",
            file=sys.stderr,
        )
        return EXIT_INPUT
    except BrokenPipeError:
        sys.stderr.close()  # the reader went away (bgr fmt x | head): not an error of ours
        return EXIT_OK
    except Exception as e:  # a bug of ours: say so without a traceback unless asked
        if os.environ.get("BGR_DEBUG"):
            traceback.print_exc()
        print(
            f"bgr: internal error: {type(e).__name__}: {e} (please report it; "
            "BGR_DEBUG=1 shows the traceback)",
            file=sys.stderr,
        )
        return EXIT_INPUT
    finally:
        if previous is not None:
            _on_sigterm(previous)


def _on_sigterm(handler):
    """Install ``handler`` for SIGTERM and return the previous one; None where signals cannot
    be set (not the main thread, or no SIGTERM)."""
    try:
        return signal.signal(signal.SIGTERM, handler)
    except (ValueError, AttributeError, OSError):
        return None


if __name__ == "__main__":
    sys.exit(main())
