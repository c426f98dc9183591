"""The options of the commands that derive or read data: GeoJSON lots (--map, --front), the
derivation's budgets (--max-depth, --max-shapes, --max-triangles) and the memory ceiling
(--max-memory), which is enforced here by capping the process's address space."""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from collections.abc import Callable
from typing import Any

from ..grammar.errors import BgrError
from ..interpreter.limits import (
    DEFAULT_MAX_DEPTH,
    DEFAULT_MAX_SHAPES,
    DEFAULT_MAX_TRIANGLES,
    default_max_memory,
    memory_ceiling,
    parse_memory,
)
from .common import EXIT_USAGE, whole


def add_lot_options(command: argparse.ArgumentParser) -> None:
    """--map and --front: how the footprints of a GeoJSON --lot become lots (docs/cli.md, Lots)."""
    command.add_argument(
        "--map",
        action="append",
        default=[],
        type=_argument("parse_map"),
        metavar="NAME=PROPERTY[:TYPE]",
        help="set attr NAME from each footprint's PROPERTY (it may hold colons), coerced to "
        "TYPE int (rounded, halves away from zero), float, str or bool; repeatable, e.g. "
        "--map floors=building:levels:int",
    )
    command.add_argument(
        "--front",
        type=_argument("parse_front"),
        metavar="first|longest|street:LINES.geojson",
        help="each footprint's front edge (the scope's x): its first edge (default), its longest, "
        "or the one nearest to a line of a GeoJSON street file in the lots' CRS",
    )


def _argument(parser: str):
    """An argparse type from a parser of interpreter/lots.py (imported when used: numpy and
    shapely are slow to load for bgr check) that raises BgrError: a bad value is a usage error."""

    def convert(text: str):
        from ..interpreter import lots

        try:
            return getattr(lots, parser)(text)
        except BgrError as e:
            raise argparse.ArgumentTypeError(e.message) from None

    return convert


def lot_options(args):
    """The LotOptions of --front and --map, None without them, or what is wrong with them."""
    from ..interpreter.lots import LotOptions

    if not args.map and args.front is None:
        return None
    lot = args.lot or ""
    if not lot or ("," in lot and not lot.lower().endswith((".json", ".geojson"))):
        return "--front and --map apply to a GeoJSON lot file: give --lot LOTS.geojson"
    front, streets = args.front or ("first", None)
    return LotOptions(front=front, streets=streets, mapping=tuple(args.map))


def add_budget_options(command: argparse.ArgumentParser) -> None:
    """The limits a derivation runs under (interpreter/limits.py, docs/limits.md)."""
    command.add_argument(
        "--max-depth",
        type=whole,
        default=DEFAULT_MAX_DEPTH,
        metavar="N",
        help=f"rule depth limit (default {DEFAULT_MAX_DEPTH})",
    )
    command.add_argument(
        "--max-shapes",
        type=whole,
        default=DEFAULT_MAX_SHAPES,
        metavar="N",
        help=f"shape budget of the run, or of each lot when derive streams its output "
        f"(.glb .city.jsonl .json) (default {DEFAULT_MAX_SHAPES:,})",
    )
    command.add_argument(
        "--max-triangles",
        type=whole,
        default=DEFAULT_MAX_TRIANGLES,
        metavar="N",
        help=f"triangle budget of the terminals, of the run or of each lot as --max-shapes "
        f"(default {DEFAULT_MAX_TRIANGLES:,})",
    )
    add_memory_option(command)


def add_memory_option(command: argparse.ArgumentParser) -> None:
    """--max-memory: derive and render, and the commands that read data (infer, retarget)."""
    command.add_argument(
        "--max-memory",
        metavar="SIZE",
        help="memory ceiling on what the run allocates, e.g. 4G or 512M (default: 80%% of the "
        "memory available at start)",
    )


def memory_limit(args) -> int | None | str:
    """The --max-memory ceiling in bytes (None: unknown, none enforced), or what is wrong with
    it.  The process's address space is capped a little above it (:func:`cap_address_space`)."""
    if args.max_memory is None:
        memory = default_max_memory()
    else:
        memory = parse_memory(args.max_memory)
        if memory is None:
            return f"--max-memory {args.max_memory}: write a size such as 4G, 512M or 1.5GB"
    args.memory_ceiling = memory  # for main()'s out-of-memory message
    if memory is not None:
        cap_address_space(memory)
    return memory


def budgets(args) -> dict | str:
    """The derive() keywords of the budget options, or what is wrong with them.

    The memory ceiling is enforced twice: the engine measures the process as it derives (a
    located error), and the process's address space is capped a little above the ceiling, so
    an allocation that would pass it in one go (a writer's arrays) fails as MemoryError, which
    main() reports in one line instead of the system killing the process.
    """
    if args.max_depth < 1 or args.max_shapes < 1 or args.max_triangles < 1:
        return "--max-depth, --max-shapes and --max-triangles must be positive"
    memory = memory_limit(args)
    if isinstance(memory, str):
        return memory
    return {
        "max_depth": args.max_depth,
        "max_shapes": args.max_shapes,
        "max_triangles": args.max_triangles,
        "max_memory": memory,
    }


def cap_address_space(ceiling: int) -> None:
    """Lower RLIMIT_AS to what the process has mapped now, plus the ceiling and 1 GB of slack
    for the mappings that are reserved but never touched (thread stacks, malloc arenas)."""
    try:
        import resource

        with open("/proc/self/statm", "rb") as f:
            mapped = int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (ImportError, OSError, ValueError, IndexError):
        return  # not Linux: the engine's own measurement is the only ceiling
    wanted = mapped + ceiling + 2**30
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    if soft == resource.RLIM_INFINITY or wanted < soft:
        limit = wanted if hard == resource.RLIM_INFINITY else min(wanted, hard)
        with contextlib.suppress(ValueError, OSError, OverflowError):
            resource.setrlimit(resource.RLIMIT_AS, (limit, hard))


@contextlib.contextmanager
def address_space_restored():
    """Put back the address-space limit cap_address_space() lowered: main() may be called in a
    process that goes on (a test, a server), whose later work must not inherit the ceiling."""
    try:
        import resource

        before = resource.getrlimit(resource.RLIMIT_AS)
    except ImportError:
        yield
        return
    try:
        yield
    finally:
        with contextlib.suppress(ValueError, OSError):
            resource.setrlimit(resource.RLIMIT_AS, before)


def under_ceiling(args, command: str, advice: str, run: Callable[[Any], int]) -> int:
    """``run(args)`` under the run's memory ceiling (--max-memory; the inverse modules check
    it at their expensive steps, ``advice`` is what the message suggests)."""
    memory = memory_limit(args)
    if isinstance(memory, str):
        print(f"bgr {command}: {memory}", file=sys.stderr)
        return EXIT_USAGE
    with memory_ceiling(memory, args.input, advice):
        return run(args)
