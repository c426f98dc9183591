"""Derivations for ``bgr serve``, in a worker process, the latest request winning.

A grammar being edited can be slow or runaway (a recursion the budgets stop only after
millions of shapes); the server must stay responsive, so every derivation runs in one worker
process beside it.  A request made while an older one is still deriving kills the worker and
starts a fresh one (the older result would be stale the moment it came); a derivation that
takes longer than ``timeout`` seconds is killed too and reported as an error.  At most one
worker is alive at any time, whatever the number of saves.

The worker loads the grammar from its file (imports resolve as ``bgr derive``'s do), derives it
with the budgets of ``bgr derive`` (docs/limits.md) and answers with the GLB the page shows and
what picking a terminal needs: its triangles' terminal rows, labels, paths and attrs.
"""

from __future__ import annotations

import contextlib
import io
import multiprocessing
import time
from dataclasses import dataclass, field
from multiprocessing.connection import Connection
from typing import Any

import numpy as np

TIMEOUT = 60.0  # seconds a derivation may take before it is killed and reported


@dataclass(frozen=True)
class Request:
    """What to derive: the grammar's file, the seed, attr overrides and the lot (as ``bgr
    derive --lot`` takes it: "W,D" or a GeoJSON path; None: the default lot)."""

    path: str
    seed: int = 0
    attrs: dict = field(default_factory=dict)
    lot: str | None = None
    feature: int | None = None  # one footprint of a GeoJSON lot file (None: all of them)


@dataclass
class Outcome:
    """A derivation's result: the GLB and the picking data, or the error's diagnostics."""

    glb: bytes = b""
    triangles: int = 0
    terminals: list[dict] = field(default_factory=list)  # label, path per terminal row
    vertices: np.ndarray | None = None  # (V, 3) of the picking mesh
    faces: np.ndarray | None = None
    face_terminal: np.ndarray | None = None
    errors: list[dict] = field(default_factory=list)  # path, line, column, message, hint, source
    warnings: list[dict] = field(default_factory=list)
    seconds: float = 0.0


def derive(request: Request) -> Outcome:
    """Derive one request in this process (the worker's body; also used directly by tests)."""
    import bgr
    from bgr.formats.glb import write_glb
    from bgr.grammar.errors import BgrError
    from bgr.interpreter.lots import parse_lot_option

    start = time.perf_counter()
    try:
        grammar = bgr.load(request.path)
        lot = parse_lot_option(request.lot) if request.lot else None
        if lot is not None and request.feature is not None:
            if not 0 <= request.feature < len(lot):
                raise BgrError(f"the lot file has {len(lot)} footprints, not {request.feature + 1}")
            lot = [lot[request.feature]]
        result = bgr.derive(grammar, seed=request.seed, attrs=dict(request.attrs), lot=lot)
        stream = io.BytesIO()
        write_glb(result.terminals, stream, seed=result.seed, attrs=result.attrs)
        mesh = result.mesh
        table = result.terminals
        terminals = [
            {"label": str(label), "path": str(path)}
            for label, path in zip(table.label, table.path, strict=True)
        ]
        return Outcome(
            glb=stream.getvalue(),
            triangles=len(mesh.faces),
            terminals=terminals,
            vertices=np.asarray(mesh.vertices),
            faces=np.asarray(mesh.faces),
            face_terminal=np.asarray(mesh.metadata["terminal"]),
            warnings=[_diagnostic(d) for d in result.warnings],
            seconds=time.perf_counter() - start,
        )
    except BgrError as e:
        return Outcome(errors=[_diagnostic(d) for d in e.diagnostics])
    except MemoryError:
        return Outcome(errors=[{"message": "out of memory deriving the grammar"}])


def _diagnostic(d) -> dict:
    return {
        "path": d.path,
        "line": d.line,
        "column": d.column,
        "message": d.message,
        "hint": d.hint,
        "source": d.source_line,
        "length": d.length,
    }


def _serve(tasks: Connection) -> None:
    """The worker: derive each request it is sent, until its pipe closes."""
    while True:
        try:
            request = tasks.recv()
        except (EOFError, OSError):
            return
        try:
            outcome = derive(request)
        except Exception as e:  # a bug of ours: the page shows it, the worker goes on
            outcome = Outcome(errors=[{"message": f"internal error: {type(e).__name__}: {e}"}])
        tasks.send(outcome)


class Deriver:
    """One worker process at a time; :meth:`run` blocks (call it from a thread)."""

    def __init__(self, timeout: float = TIMEOUT) -> None:
        methods = multiprocessing.get_all_start_methods()
        self._context: Any = multiprocessing.get_context(
            "forkserver" if "forkserver" in methods else "spawn"
        )
        if "forkserver" in methods:  # a worker started after a kill starts with bgr loaded
            self._context.set_forkserver_preload(["bgr.editor.derivation", "bgr", "trimesh"])
        self.timeout = timeout
        self._worker = None
        self._pipe: Connection | None = None
        self._ticket = 0

    def run(self, request: Request) -> Outcome | None:
        """Derive ``request``; None when a newer request superseded it meanwhile."""
        self._ticket += 1
        ticket = self._ticket
        if self._worker is not None and self._busy:
            self.stop()  # an older derivation still running: its result would be stale
        if self._worker is None:
            self._start()
        assert self._pipe is not None
        pipe = self._pipe
        self._busy = True
        pipe.send(request)
        deadline = time.monotonic() + self.timeout
        while True:
            if ticket != self._ticket:
                return None
            try:
                ready = pipe.poll(0.05)
            except (EOFError, OSError):  # killed for a newer request
                return None
            if ready:
                try:
                    outcome = pipe.recv()
                except (EOFError, OSError):
                    return None
                self._busy = False
                return outcome
            if self._worker is not None and not self._worker.is_alive():
                self.stop()
                return Outcome(errors=[{"message": "the derivation's process died"}])
            if time.monotonic() > deadline:
                self.stop()
                return Outcome(
                    errors=[
                        {
                            "message": f"the derivation took more than {self.timeout:g} s and "
                            "was stopped",
                            "hint": "a rule that recurses without end? the budgets of docs/"
                            "limits.md stop it later than this",
                        }
                    ]
                )

    _busy = False

    def _start(self) -> None:
        mine, theirs = self._context.Pipe(duplex=True)
        worker = self._context.Process(target=_serve, args=(theirs,), daemon=True)
        worker.start()
        theirs.close()
        self._worker, self._pipe, self._busy = worker, mine, False

    def stop(self) -> None:
        """Kill the worker (if any); the next request starts a new one."""
        worker, pipe = self._worker, self._pipe
        self._worker, self._pipe, self._busy = None, None, False
        if worker is not None and worker.is_alive():
            worker.kill()
        if worker is not None:
            worker.join(5)
        if pipe is not None:
            with contextlib.suppress(OSError):
                pipe.close()
