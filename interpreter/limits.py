"""The limits a derivation runs under, and how memory is measured against its ceiling.

Grammars and footprints come from other people: a rule that doubles itself, a repeat of
millimetre tiles over a kilometre, a scale by 1e308.  Each limit here stops one kind of runaway
with a located error *before* the work is done, so that a run on a shared machine ends within
seconds instead of exhausting it.  The defaults are chosen on the project's 2-core CI machine
(docs/limits.md has the measurements): the largest shipped benchmark, ``grid_city`` n = 40
(2.9 M shapes, 989,000 terminals, 4.0 M triangles), runs under all of them.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import sys
from collections.abc import Iterator

from bgr.grammar.errors import BgrError, Diagnostic

DEFAULT_MAX_DEPTH = 256
"""Rule applications nested in one another (a rule calling itself without end)."""

DEFAULT_MAX_SHAPES = 3_500_000
"""Shapes made in one run: every split piece, face, inset and successor.  grid_city n = 40
makes 2.9 M.  A split explosion among rules that can never reach a terminal stops long before
it (interpreter/barren.py); one that makes terminals runs up to it in about 25 s."""

DEFAULT_MAX_TRIANGLES = 20_000_000
"""Triangles of the terminals emitted (5x grid_city n = 40); a GLB of this many is ~200 MB."""

MAX_COORDINATE = 1e9
"""Largest scope size or coordinate, in metres, any shape may have.  Projected city
coordinates reach 1e7 (a UTM northing); past 1e9 float32 files lose the metre and products
of sizes overflow, so a larger value is a grammar's mistake, reported where it happens."""

MAX_INPUT_COORDINATE = 1e8
"""Largest |coordinate|, in metres, of a model read as data (the cities of ``bgr infer``): the
bound of a lot's footprint (interpreter/values.py).  A projected CRS reaches 2e7 m; a vertex at
1e308 is an exporter's mistake, and it would hang GEOS and crash scipy's k-means further on."""

BYTES_PER_SHAPE = 1000
"""What one shape costs while deriving, roughly (its piece, its Shape, its terminal row):
1.1 KB measured on a repeat of 1 M terminals.  A split whose pieces would not fit in the memory
left under the ceiling is refused before it is laid out."""

MEMORY_CHECK_EVERY = 8192
"""Shapes between two looks at the process's memory (a look costs a few microseconds)."""


def memory_in_use() -> int:
    """Resident memory of this process in bytes (its peak where the current value is unknown)."""
    try:
        with open("/proc/self/statm", "rb") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError, AttributeError):
        pass
    try:
        import resource
    except ImportError:  # Windows: no measurement, so no ceiling is enforced
        return 0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak if sys.platform == "darwin" else peak * 1024


def peak_memory() -> int:
    """The most resident memory this process has held, in bytes (0 when unknown)."""
    try:
        import resource
    except ImportError:
        return 0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak if sys.platform == "darwin" else peak * 1024


def available_memory() -> int | None:
    """Memory the machine can give a new process now, in bytes (None when unknown)."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def address_space_left() -> int | None:
    """How much more address space this process may map under its RLIMIT_AS (None: no limit)."""
    try:
        import resource

        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft == resource.RLIM_INFINITY:
            return None
        with open("/proc/self/statm", "rb") as f:
            mapped = int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (ImportError, OSError, ValueError, IndexError):
        return None
    return max(soft - mapped, 0)


def default_max_memory() -> int | None:
    """The memory ceiling when none is given: 80 % of what the machine has available now (or
    of the address space the process may still map, when a limit such as ``ulimit -v`` is
    lower), so a runaway stops with a located error before the system swaps or kills."""
    room = [v for v in (available_memory(), address_space_left()) if v]
    return int(min(room) * 0.8) if room else None


_SIZE = re.compile(r"(\d+(?:\.\d+)?)\s*([kmgt]?)i?b?", re.IGNORECASE)
_UNITS = {"": 1, "k": 2**10, "m": 2**20, "g": 2**30, "t": 2**40}


def parse_memory(text: str) -> int | None:
    """``--max-memory`` values: ``4G``, ``512M``, ``1.5GiB``, ``2000000000`` (bytes); None when
    it is not such a size (the caller reports it)."""
    match = _SIZE.fullmatch(text.strip())
    if not match:
        return None
    value = float(match.group(1)) * _UNITS[match.group(2).lower()]
    return int(value) if math.isfinite(value) and value >= 1 else None


def format_bytes(count: float) -> str:
    """1.5 GB, 640 MB: how a limit is shown in a message."""
    for unit, size in (("TB", 2**40), ("GB", 2**30), ("MB", 2**20), ("KB", 2**10)):
        if count >= size:
            return f"{count / size:.3g} {unit}"
    return f"{int(count)} bytes"


class MemoryCeiling:
    """The memory ceiling of a command that does not derive (``bgr infer``, ``bgr retarget``),
    measured as the engine measures a derivation: the process's resident memory less what it
    held when the work began, so what a notebook or a test session held before does not
    count.  Checked at each step of the work, and before an array whose size is known up front
    is allocated (``more``), so a large input stops with a located error instead of swapping."""

    def __init__(self, limit: int, path: str = "", hint: str = "") -> None:
        self.limit, self.path, self.hint = limit, path, hint
        self.restart()

    def restart(self) -> None:
        """Count from now."""
        self.base, self.peak = memory_in_use(), peak_memory()

    def used(self) -> int:
        """What the run has grown by: now, or at its peak since the start where the process's
        peak has risen since (a step's arrays freed before the next look still count)."""
        return max(memory_in_use() - self.base, peak_memory() - max(self.peak, self.base))

    def check(self, step: str, more: int = 0) -> None:
        """A BgrError naming ``step`` when the run has grown past the ceiling, or would with
        ``more`` bytes."""
        used = self.used()
        if used + max(more, 0) > self.limit:
            needs = f"{step} needs more than {format_bytes(self.limit)} of memory"
            if more > 0:
                needs += f" ({format_bytes(more)} more, {format_bytes(max(used, 0))} in use)"
            raise BgrError(
                Diagnostic(
                    self.path,
                    0,
                    0,
                    needs,
                    (self.hint + ", or raise" if self.hint else "Raise")
                    + " the ceiling with --max-memory SIZE",
                )
            )


# the ceiling in force (process-wide, as the address-space cap is: the threads a step starts
# see it too)
_CEILING: list[MemoryCeiling | None] = [None]


@contextlib.contextmanager
def memory_ceiling(limit: int | None, path: str = "", hint: str = "") -> Iterator[None]:
    """Within the block, :func:`check_memory` holds the work to ``limit`` bytes from now (None:
    no ceiling).  The inverse modules call check_memory at their expensive steps; the command
    line opens the block with --max-memory, library callers may too."""
    before = _CEILING[0]
    _CEILING[0] = None if limit is None else MemoryCeiling(limit, path, hint)
    try:
        yield
    finally:
        _CEILING[0] = before


def restart_memory() -> None:
    """Count the ceiling in force from now: a command calls it once its modules are loaded, so
    that importing numpy, scipy and trimesh (about 100 MB) is not taken for its work."""
    ceiling = _CEILING[0]
    if ceiling is not None:
        ceiling.restart()


def check_memory(step: str, more: int = 0) -> None:
    """The active ceiling's :meth:`MemoryCeiling.check`; nothing outside a memory_ceiling()."""
    ceiling = _CEILING[0]
    if ceiling is not None:
        ceiling.check(step, more)
