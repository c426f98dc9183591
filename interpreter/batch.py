"""Deriving many lots: one after another in this process, on a local process pool
(``--workers N``), or on a Dask cluster (``--dask ADDRESS``) — with the same bytes out.

Every lot is derived on its own, by a fresh :class:`Engine` into its own small terminal table,
from the global seed and the lot's index in the run (LANGUAGE.md section 9: a shape's random
stream depends only on the seed and its derivation path, and a lot's path starts with its
index).  Nothing a lot makes depends on which process derived it or on the lots derived before
it, so the results can be computed anywhere and put back in lot order.

Lots are sent out in batches and a bounded number of batches is in flight at once; results are
yielded in lot order as soon as they are ready, so a caller that writes each lot and drops it
(the streaming writers of :mod:`bgr.formats.sinks`) holds a few batches, not the city.

The budgets (``max_shapes``, ``max_triangles``) hold for the whole run, or for each lot on its
own with ``Job.per_lot`` (``bgr derive`` writing a streamed format: memory then holds one lot
at a time, and a city of 100,000 lots must not be stopped by a budget meant for one run).  For
the whole run, lots derived in this process start from the counts of the lots before them, so
a runaway stops mid-lot; lots derived elsewhere get the whole budget each, and this process
adds the counts up as the results come in.  A run that succeeds writes the same files either
way.
"""

from __future__ import annotations

import gc
import itertools
import math
import multiprocessing
import os
import uuid
from collections import deque
from collections.abc import Callable, Generator, Iterable, Iterator
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from bgr.grammar.checker import Grammar
from bgr.grammar.errors import BgrError, Diagnostic, Warnings
from bgr.grammar.parser import no_gc

from .engine import Engine
from .limits import default_max_memory, memory_in_use
from .lots import Lot, attr_overrides
from .occlusion import (
    Occluder,
    Occluders,
    first_pass,
    lot_bounds,
    neighbourhoods,
    uses_occlusion,
)
from .shared import forget, share
from .terminals import TerminalTable
from .workers import Pool

# the split cache (pure: sizes -> placed pieces) is kept across the lots one process derives,
# and emptied when it holds more entries than this, so that a long run does not grow with it;
# it also keeps reuse.py's analysis of the grammar (Reuse.share) and the compiled expressions
# and plans (shared.py)
CACHE_ENTRIES = 50_000

# job token -> this process's resident memory when it began deriving that run's lots: the
# memory ceiling budgets what a run allocates from there (every lot this process derives of
# the run together), not what the process held before it
_MEMORY_BASES: dict[str, int] = {}


def memory_base(job: Job) -> int:
    """Resident memory of this process when it derived its first lot of ``job``."""
    base = _MEMORY_BASES.get(job.token)
    if base is None:
        if len(_MEMORY_BASES) >= 64:  # a worker that outlives many runs forgets old ones
            _MEMORY_BASES.clear()
        base = _MEMORY_BASES[job.token] = memory_in_use()
    return base


@dataclass
class Job:
    """What deriving any lot of a run needs besides the lot: sent once to every worker."""

    grammar: Grammar
    seed: int
    attrs: dict  # the caller's attr overrides (--set), checked
    values: dict  # the run's attr values (grammar defaults with attrs), which properties override
    start: str | None = None
    strict: bool = False
    several: bool = True  # lots are named "lot 3" and paths "Lot.3" when the run has several
    max_depth: int = 256
    max_shapes: int = 3_500_000
    max_triangles: int = 20_000_000
    max_memory: int | None = None  # None: 80 % of the memory available to the process deriving
    # (the ceiling is on what the run allocates in that process, from its first lot: memory_base)
    # the shape and triangle budgets hold for each lot on its own (a run whose lots are written
    # as they come and dropped), not for all lots together (a run that keeps them all)
    per_lot: bool = False
    # names the run in a worker that outlives it (a Dask worker): its split cache is the run's
    token: str = field(default_factory=lambda: uuid.uuid4().hex)


@dataclass
class LotResult:
    """One lot derived: its terminals (a frozen table with the lot as ``lots[0]``, rows from 0),
    the warnings it raised, the shapes and triangles it made; or the error that stopped it."""

    index: int
    table: TerminalTable | None
    warnings: list[Diagnostic] = field(default_factory=list)
    shapes: int = 0
    triangles: int = 0
    error: BgrError | None = None


def lot_name(lot: Lot, index: int, several: bool) -> str:
    """How messages name a lot: its feature ("feature 12 (id 4253124)"), else "lot N"."""
    return lot.name or (f"lot {index}" if several else "")


@no_gc()  # the engine pauses it while deriving; freezing the table makes as many objects
def derive_lot(
    job: Job,
    index: int,
    lot: Lot,
    *,
    shapes: int = 0,
    triangles: int = 0,
    cache: dict | None = None,
    occluders: Occluders | None = None,
) -> LotResult:
    """Derive one lot; ``shapes`` and ``triangles`` are the run's counts so far (the budgets
    are the run's); ``occluders``: the lot's own and its neighbours' occluders when the run
    found them beforehand (:func:`lot_occluders`), else a grammar that asks an occlusion
    query derives the lot twice here.  A BgrError is returned in the result, naming the lot,
    not raised."""
    name = lot_name(lot, index, job.several)
    warnings = Warnings(job.strict)
    try:
        make_engine = _engine_maker(job, index, lot, warnings, shapes, triangles)
        engine = make_engine(warnings)
        if occluders is not None:
            engine.occlusion = occluders
        elif uses_occlusion(job.grammar):  # derived once with every query false (occlusion.py)
            engine.occlusion = first_pass(
                lambda: make_engine(Warnings()), lot.shape.copy(), job.start, index, job.several
            )
        table = engine.table
        if cache is not None:
            engine.split_cache = cache
            engine.reuse.share(cache)
            share(engine, cache)
        try:
            engine.derive(lot.shape.copy(), job.start, index=index, several=job.several)
        finally:
            engine.release()
    except BgrError as e:
        return LotResult(index, None, list(warnings.items), error=naming(e, name))
    rule = job.start or job.grammar.start
    frame = lot.shape  # the lot's frame: the inverse modules read a face's side in it
    table.grammar = str(job.grammar.path or "")
    table.site = lot.site
    table.lots.append(
        {
            "path": f"{rule}.{index}" if job.several else rule,
            "origin": list(frame.origin),
            "axes": [list(a) for a in frame.axes],
            "size": list(frame.size),
            # what the output files say of the building: its terminals (rows), its name, its
            # attrs after the feature's overrides and the feature's own properties
            "rows": [0, len(table)],
            "id": lot.feature_id,
            "name": lot.feature_id if lot.feature_id is not None else f"lot-{index}",
            "attrs": dict(engine.attrs),
            "properties": dict(lot.properties),
        }
    )
    if engine.reports:  # report() calls, in order (interpreter/reports.py sums them up)
        table.lots[-1]["reports"] = list(engine.reports)
    if engine.prints:  # print() texts, in order: bgr derive writes them
        table.lots[-1]["prints"] = list(engine.prints)
    return LotResult(
        index,
        table.freeze(),
        list(warnings.items),
        engine.shapes - shapes,
        engine.triangles - triangles,
    )


def _engine_maker(
    job: Job, index: int, lot: Lot, warnings: Warnings, shapes: int = 0, triangles: int = 0
) -> Callable[[Warnings], Engine]:
    """A function making the lot's engines (each with its own warnings): the run's attrs and
    the lot's overrides of them (read now, their warnings into ``warnings``), the budgets
    counted from ``shapes`` and ``triangles``."""
    max_memory = job.max_memory if job.max_memory is not None else default_max_memory()
    overrides = dict(job.attrs)
    overrides.update(attr_overrides(lot, job.values, warnings))
    name = lot_name(lot, index, job.several)

    def make_engine(warnings: Warnings) -> Engine:
        made = Engine(
            job.grammar,
            job.seed,
            overrides,
            job.max_depth,
            job.max_shapes,
            lot_index=index,
            warnings=warnings,
            lot_name=name,
            max_triangles=job.max_triangles,
            max_memory=max_memory,
            memory_base=memory_base(job),
        )
        made.shapes, made.triangles = shapes, triangles
        return made

    return make_engine


def lot_occluders(job: Job, index: int, lot: Lot) -> list[Occluder]:
    """The occluders of the lot's first pass (every query false; occlusion.py), for the
    lots around it; none when that pass fails (the lot's own derivation reports why)."""
    try:
        make_engine = _engine_maker(job, index, lot, Warnings())
        found = first_pass(
            lambda: make_engine(Warnings()), lot.shape.copy(), job.start, index, job.several
        )
    except BgrError:
        return []
    return found.items


def naming(error: BgrError, name: str) -> BgrError:
    """The error with the lot it happened on named at the start of each message (the location
    stays the grammar's ``file:line:col``); unchanged when the run has one unnamed lot."""
    if not name:
        return error
    named = [
        d if d.message.startswith(f"{name}: ") else replace(d, message=f"{name}: {d.message}")
        for d in error.diagnostics
    ]
    return type(error)(named)


def derive_lots(
    job: Job,
    lots: Iterable[Lot],
    *,
    workers: int = 1,
    dask: str | None = None,
    batch_size: int | None = None,
    count: int | None = None,
    first_passes: Callable[[int], None] | None = None,
) -> Iterator[LotResult]:
    """Every lot's :class:`LotResult`, in lot order; the first lot that fails raises its
    BgrError (after the results before it), as a serial run would.

    ``workers`` > 1 derives on a local process pool; ``dask`` (a scheduler address, or
    ``"local"`` for a LocalCluster of ``workers`` processes) on a Dask cluster.  ``count`` (the
    number of lots, when known) sizes the batches.
    """
    if workers < 1:
        raise BgrError(f"--workers must be at least 1, got {workers}")
    if count is None and hasattr(lots, "__len__"):
        count = len(lots)  # type: ignore[arg-type]
    occluders: Iterator[Occluders | None] = itertools.repeat(None)
    if uses_occlusion(job.grammar) and job.several:
        # inter occlusion: every lot's first pass before any lot's second (occlusion.py)
        lots = list(lots)
        count = len(lots)
        occluders = _around(job, lots, workers, dask, batch_size, first_passes)
    numbered = zip(itertools.count(), lots, occluders)
    if dask is None and workers == 1:
        yield from _serial(job, numbered)
        return
    size = batch_size or _batch_size(count, workers)
    batches = iter(lambda: list(itertools.islice(numbered, size)), [])
    window = 4 * workers
    if dask is not None:
        results = _on_dask(job, batches, dask, workers, window, derive_batch)
    else:
        results = _on_pool(job, batches, workers, window, _pool_batch)
    shapes = triangles = 0
    try:
        for result in results:
            shapes += result.shapes
            triangles += result.triangles
            yield _checked(job, result, shapes, triangles)
    finally:
        results.close()  # a failed lot stops the workers now, not when the generator is collected


def _around(
    job: Job,
    lots: list[Lot],
    workers: int,
    dask: str | None,
    batch_size: int | None,
    progress: Callable[[int], None] | None,
) -> Iterator[Occluders]:
    """Each lot's occluders for its second pass: its own first pass's and those of the lots
    within NEIGHBOURHOOD of it (``inter``), the first passes derived like the lots themselves
    (here, on the pool or on Dask); ``progress(n)`` is told of each lot's first pass."""
    numbered: Iterator[tuple[int, Lot, Occluders | None]]
    numbered = zip(itertools.count(), lots, itertools.repeat(None))
    if dask is None and workers == 1:
        found = []
        for index, lot, _ in numbered:
            found.append(lot_occluders(job, index, lot))
            if progress is not None:
                progress(1)
    else:
        size = batch_size or _batch_size(len(lots), workers)
        batches = iter(lambda: list(itertools.islice(numbered, size)), [])
        if dask is not None:
            parts = _on_dask(job, batches, dask, workers, 4 * workers, occluders_batch)
        else:
            parts = _on_pool(job, batches, workers, 4 * workers, _pool_occluders)
        found = []
        for part in parts:
            found.append(part)
            if progress is not None:
                progress(1)
    near = neighbourhoods(np.array([lot_bounds(lot.shape) for lot in lots]))
    for index, own in enumerate(found):
        yield Occluders(own, [item for other in near[index] for item in found[other]])


COLLECT_EVERY = 256  # lots between two collections in a serial run (see _serial)


def _serial(job: Job, numbered: Iterator[tuple[int, Lot, Occluders | None]]) -> Iterator[LotResult]:
    """The lots derived one after another in this process, the cyclic collector paused from
    the first to the last (between two lots too, while the caller writes one: the lots make
    no cycles, tests/test_engine_release.py, and each time the collector was switched back on
    it rescanned what the lot left alive, ~0.5 s of Helsinki's 12); every COLLECT_EVERY lots it
    runs once, so a grammar that made cycles after all could not grow without bound."""
    cache: dict = {}
    shapes = triangles = 0
    enabled = gc.isenabled()
    gc.disable()
    try:
        for index, lot, occluders in numbered:
            if index % COLLECT_EVERY == COLLECT_EVERY - 1:
                gc.collect()
            if len(cache) > CACHE_ENTRIES:
                forget(cache)
                cache.clear()
            result = derive_lot(
                job,
                index,
                lot,
                shapes=shapes,
                triangles=triangles,
                cache=cache,
                occluders=occluders,
            )
            if result.error is not None:
                raise result.error
            if not job.per_lot:
                shapes += result.shapes
                triangles += result.triangles
            yield result
    finally:
        forget(cache)  # the compiled expressions' reference cycles, not left to the collector
        if enabled:
            gc.enable()


def _checked(job: Job, result: LotResult, shapes: int, triangles: int) -> LotResult:
    """A result from a worker, raised if it failed or if the run's budgets are now passed."""
    if result.error is not None:
        raise result.error
    if job.per_lot:
        return result
    for made, limit, what, option in (
        (shapes, job.max_shapes, "shapes", "--max-shapes"),
        (triangles, job.max_triangles, "triangles of terminals", "--max-triangles"),
    ):
        if made > limit:
            raise BgrError(
                Diagnostic(
                    str(job.grammar.path or ""),
                    0,
                    0,
                    f"the derivation made more than {limit:,} {what} (all lots together, "
                    f"after lot {result.index})",
                    f"derive fewer lots at once, or raise the budget with {option} N",
                )
            )
    return result


def _batch_size(count: int | None, workers: int) -> int:
    """Lots per batch: small enough that every worker gets several batches (the last one to
    finish does not idle the others long), large enough to amortise sending them."""
    if count is None:
        return 16
    return max(1, min(32, math.ceil(count / (8 * workers))))


# --------------------------------------------------------------------------------------------
# a local process pool

_JOB: Job | None = None  # the job of this worker process (set by _start_worker)
_CACHE: dict = {}  # the split cache of the run named by _CACHE_OF
_CACHE_OF = ""


def _start_worker(job: Job) -> None:
    global _JOB
    _JOB = job


# a batch: (index, lot, the lot's occluders or None) for each of its lots
Batch = list[tuple[int, Lot, "Occluders | None"]]


def _pool_batch(batch: Batch) -> list[LotResult]:
    assert _JOB is not None, "the pool's initializer did not run"
    return derive_batch(_JOB, batch)


def _pool_occluders(batch: Batch) -> list[list[Occluder]]:
    assert _JOB is not None, "the pool's initializer did not run"
    return occluders_batch(_JOB, batch)


def occluders_batch(job: Job, batch: Batch) -> list[list[Occluder]]:
    """The first-pass occluders of each lot of a batch, in a worker (:func:`lot_occluders`)."""
    return [lot_occluders(job, index, lot) for index, lot, _ in batch]


def derive_batch(job: Job, batch: Batch) -> list[LotResult]:
    """Derive a batch of lots in a worker; a failed lot ends the batch (the lots after it
    would not be written)."""
    global _CACHE_OF
    if job.token != _CACHE_OF:  # a cache's keys are ids of one grammar's nodes
        forget(_CACHE)
        _CACHE.clear()
        _CACHE_OF = job.token
    out = []
    for index, lot, occluders in batch:
        if len(_CACHE) > CACHE_ENTRIES:
            forget(_CACHE)
            _CACHE.clear()
        result = derive_lot(job, index, lot, cache=_CACHE, occluders=occluders)
        out.append(result)
        if result.error is not None:
            break
    return out


def _context():
    """forkserver where the platform has it: workers start from a clean process (forking one
    whose threads hold locks — a progress bar's — can hang); spawn elsewhere."""
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")


def _on_pool(
    job: Job, batches: Iterator[Batch], workers: int, window: int, function: Callable
) -> Generator:
    """``function(batch)`` (a module-level function of one batch) of every batch, on a local
    pool whose workers hold the job; the items of each batch's result, in order."""
    pool = Pool(workers, _context(), _start_worker, (job,))
    for results in pool.ordered(function, batches, window, describe=_lots_of):
        yield from results


def _lots_of(batch: Batch) -> str:
    """How a dead worker's message names the lots it was deriving."""
    first, last = batch[0][0], batch[-1][0]
    name = lot_name(batch[0][1], first, True)
    return name if first == last else f"lots {first}-{last} (from {name})"


def _in_order(submit: Callable[[Batch], Any], batches: Iterator[Batch], window: int) -> Iterator:
    """Submit batches, at most ``window`` in flight, and yield their results in order."""
    pending: deque = deque()
    for batch in batches:
        pending.append(submit(batch))
        while len(pending) >= window:
            yield from pending.popleft().result()
    while pending:
        yield from pending.popleft().result()


# --------------------------------------------------------------------------------------------
# a Dask cluster


def _on_dask(
    job: Job, batches: Iterator[Batch], address: str, workers: int, window: int, function: Callable
) -> Generator:
    """``function(job, batch)`` of every batch on a Dask cluster; the items of each batch's
    result, in order."""
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise BgrError(
            "--dask needs Dask's distributed scheduler, an optional extra: pip install 'bgr[dask]'"
        ) from None
    cluster = None
    try:
        if address == "local":
            cluster = LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                silence_logs=40,  # logging.ERROR: the cluster's chatter is not the user's
            )
            client = Client(cluster)
        else:
            client = Client(address, timeout="15s")
    except (OSError, TimeoutError, ValueError) as e:
        if cluster is not None:
            cluster.close()
        raise BgrError(
            Diagnostic(
                "",
                0,
                0,
                f"--dask {address}: cannot reach a Dask scheduler there ({str(e)[:120]})",
                "start one with 'dask scheduler' and workers with 'dask worker ADDRESS', or "
                "give --dask local for a cluster on this machine",
            )
        ) from None
    window = max(window, 4 * len(client.scheduler_info().get("workers", {})) or window)
    try:
        shared = client.scatter(job, broadcast=True)
        yield from _in_order(
            lambda batch: client.submit(function, shared, batch, pure=False), batches, window
        )
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def default_workers() -> int:
    """The cores this process may use (``--workers 0`` asks for them)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - macOS, Windows
        return os.cpu_count() or 1
