"""A streamed output written by a second process while this one derives the lots.

``bgr derive`` on many lots in one process spends a tenth of its time adding each lot to the
file (Helsinki: 1.1 of 10.6 s, the GLB's corners, normals and JSON).  On a machine with a second
core that work can run beside the derivation: :func:`background` starts a writer process before
the grammar is loaded (its imports overlap the load), and its :meth:`Writer.open_sink` is
:func:`.sinks.open_sink` with the file written over there.  The lots' frozen tables go through a
pipe, one at a time (a slow disk holds the derivation back instead of queueing lots in memory);
the file is the same bytes, and as atomic: the writer puts it in place only when this process
says the run is complete, and removes its temporary on any error, interrupt or termination, its
own or this process's.  An error over there (a full disk) comes back here as the same exception.

Only streamed outputs (:data:`.sinks.STREAMED` to a file) are written in the background; the
gathered ones need every lot at the end anyway.  ``--workers N`` and ``--dask`` derive in other
processes already and write here.  ``BGR_BACKGROUND=0`` in the environment writes here too (to
time the derivation in one process, as ``bench/helsinki.py --one-process`` does).
"""

from __future__ import annotations

import contextlib
import os
import signal
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from bgr.grammar.errors import BgrError
from bgr.interpreter.terminals import TerminalTable

from .atomic import on_sigterm, remove_stale
from .sinks import Sink, open_sink, streams

ABORT = "abort"  # this process failed or was interrupted: the writer removes its temporary
STOP_WAIT = 10.0  # seconds a writer is given to clean up and exit before it is terminated


class _Abort(Exception):
    """Raised in the writer to unwind its atomic file when this process gives up."""


def worth_it(path: str, fmt: str | None, group_by: str, workers: int) -> bool:
    """Whether a run that derives in this process should write ``path`` in a background one:
    a streamed file (not standard output) and a second core to run it on."""
    if workers != 1 or str(path) == "-" or not streams(path, fmt, group_by):
        return False
    if os.environ.get("BGR_BACKGROUND", "1") == "0":  # one process, to measure it alone
        return False
    from bgr.interpreter.batch import default_workers

    return default_workers() > 1


class Writer:
    """The writer process, started and waiting for :meth:`open_sink`."""

    def __init__(self) -> None:
        from bgr.interpreter.batch import _context

        self.conn, theirs = _context().Pipe()
        self.process = _context().Process(target=_serve, args=(theirs,), daemon=True)
        self.process.start()
        theirs.close()
        self.path: Path | None = None
        self.done = False  # the writer has exited on its own: the file is complete, or it failed
        self.complete = False

    @contextlib.contextmanager
    def open_sink(self, path: str | Path, **options: Any) -> Iterator[Sink]:
        """:func:`.sinks.open_sink`'s sink, written by the writer process: complete and in place
        when the block ends without an error, nothing written otherwise."""
        self.path = Path(str(path))
        self._send(("open", str(path), options))
        self._reply()  # a refused path is reported now, as it would be here
        sink = _Forward(self)
        yield sink
        self._send(None)
        self._reply()
        self.done = self.complete = True

    def close(self) -> None:
        """Stop the writer: after a complete file it has exited; otherwise it is told to
        remove its temporary, and terminated if it does not exit in time."""
        if not self.done:
            with contextlib.suppress(OSError, ValueError):
                self.conn.send(ABORT)
        self.process.join(STOP_WAIT)
        if self.process.is_alive():
            self.process.terminate()  # its SIGTERM handler removes the temporary too
            self.process.join(STOP_WAIT)
        self.conn.close()
        if self.path is not None and not self.complete:  # a writer killed outright (SIGKILL)
            remove_stale(self.path)  # leaves its temporary: its process is gone, so it is stale

    def _send(self, item) -> None:
        try:
            self.conn.send(item)
        except (BrokenPipeError, ConnectionResetError, EOFError):
            self._reply()  # the writer stopped: its error, if it sent one, says why
            raise BgrError("the output's writer process stopped unexpectedly") from None

    def _reply(self) -> None:
        """Wait for the writer's answer; raise its error."""
        try:
            kind, value = self.conn.recv()
        except (EOFError, ConnectionResetError, OSError):
            raise BgrError("the output's writer process stopped unexpectedly") from None
        if kind == "error":
            self.done = True  # it has cleaned up and exited
            raise value

    def check(self) -> None:
        """Raise the writer's error now, if it has sent one (no waiting)."""
        if self.conn.poll():
            self._reply()


class _Forward(Sink):
    """This process's side: counts and checks each table as any sink does, then sends it."""

    def __init__(self, writer: Writer) -> None:
        super().__init__()
        self.writer = writer

    def take(self, table: TerminalTable) -> None:
        self.writer.check()
        self.writer._send(table.freeze())


@contextlib.contextmanager
def background(enabled: bool) -> Iterator[Writer | None]:
    """A started :class:`Writer`, stopped when the block ends; None when not ``enabled`` or
    when no process can be started (the caller then writes in its own)."""
    if not enabled:
        yield None
        return
    try:
        writer = Writer()
    except (OSError, RuntimeError, ValueError):  # no process to be had (a limit, a sandbox):
        yield None  # the file is written here, as it always could be
        return
    try:
        yield writer
    finally:
        writer.close()


def _serve(conn) -> None:
    """The writer process: open the sink it is given, add the tables that come, finish it when
    told the run is complete; any error is sent back and the temporary removed."""
    signal.signal(signal.SIGTERM, on_sigterm)  # a kill unwinds the atomic file, as in bgr
    try:
        message = conn.recv()
    except (EOFError, KeyboardInterrupt):
        return
    if not isinstance(message, tuple) or message[0] != "open":
        return
    _, path, options = message
    try:
        with open_sink(path, **options) as sink:
            conn.send(("opened", None))
            while (item := conn.recv()) is not None:
                if isinstance(item, str):  # ABORT
                    raise _Abort
                sink.take(item)
        conn.send(("done", None))
    except (_Abort, EOFError):  # this process gave up or went away: nothing is written
        return
    except BaseException as exc:  # noqa: BLE001 - every failure goes back to the deriver
        _send_error(conn, exc)


def _send_error(conn, exc: BaseException) -> None:
    try:
        conn.send(("error", exc))
    except Exception:  # noqa: BLE001 - an exception that does not pickle: its text
        with contextlib.suppress(OSError):
            conn.send(("error", BgrError(f"writing the output: {type(exc).__name__}: {exc}")))
