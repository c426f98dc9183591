"""A small process pool for ``--workers N`` that dies with its parent and never hangs.

``concurrent.futures.ProcessPoolExecutor`` runs a manager thread and queue feeder threads
beside the caller.  Under ``bgr derive --workers N`` that cost three things: a
worker killed by the kernel surfaced as an internal ``BrokenProcessPool``; a parent killed with
SIGKILL left its workers blocked forever on a queue they themselves held open (and with them
the forkserver and the resource tracker, which live while any worker does); and a SIGTERM
raised in the main thread while the manager thread was joining could deadlock ``shutdown`` or
print "cannot join current thread".

This pool has no threads in the parent.  Each worker is a process with a pipe; the parent
sends a worker one task at a time, only when the worker is idle (so neither side can block
the other on a full pipe), waits on the pipes *and* the processes' sentinels together, and so
learns of a dead worker the moment it dies.  Each worker also holds the read end of a second
pipe whose write end only the parent has: when the parent dies, by any signal, the read ends
see end-of-file and a watcher thread in each worker ends it at once, even mid-task.  On any
exit from :meth:`Pool.ordered` other than success the workers are killed, not asked.
"""

from __future__ import annotations

import atexit
import contextlib
import os
import signal
import threading
import time
import traceback
from collections.abc import Callable, Iterator
from multiprocessing.connection import Connection, wait
from typing import Any

from bgr.grammar.errors import BgrError, Diagnostic


class WorkerDied(BgrError):
    """A worker process ended while it had work (killed by the kernel for memory, by a user)."""


def _die_with_parent(alive: Connection) -> None:
    """Block until the parent is gone (its end of ``alive`` closes), then end this process."""
    with contextlib.suppress(EOFError, OSError):
        alive.recv()
    os._exit(1)


def _serve(tasks: Connection, alive: Connection, initializer: Callable, initargs: tuple) -> None:
    """A worker's life: run each ``(function, argument)`` the parent sends and send back
    ``(True, result)`` or ``(False, description)``, until told to stop (None) or orphaned."""
    # Ctrl-C reaches the whole process group; the parent decides what the workers do about it
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_die_with_parent, args=(alive,), daemon=True).start()
    initializer(*initargs)
    while True:
        try:
            task = tasks.recv()
        except (EOFError, OSError):
            return
        if task is None:
            return
        function, argument = task
        try:
            reply: tuple[bool, Any] = (True, function(argument))
        except Exception:  # an internal error: the parent reports it with the worker's trace
            reply = (False, traceback.format_exc())
        tasks.send(reply)


class _Worker:
    def __init__(self, context, initializer: Callable, initargs: tuple, number: int) -> None:
        self.tasks, theirs = context.Pipe(duplex=True)
        # the worker watches the reader; only the parent holds the writer, and never writes
        watched, self.alive = context.Pipe(duplex=False)
        self.process = context.Process(
            target=_serve,
            args=(theirs, watched, initializer, initargs),
            name=f"bgr-worker-{number}",
            daemon=True,
        )
        self.process.start()
        theirs.close()
        watched.close()
        self.task: tuple[int, Any] | None = None  # (sequence number, argument) while busy


class Pool:
    """``workers`` processes started from ``context`` (a multiprocessing context), each having
    run ``initializer(*initargs)`` once."""

    def __init__(
        self,
        workers: int,
        context,
        initializer: Callable,
        initargs: tuple,
        doing: str = "deriving",
        memory_hint: str = "run with fewer --workers or a lower --max-memory",
    ) -> None:
        self._workers: list[_Worker] = []
        self._doing = doing  # what errors say a worker was doing: "deriving lot 3"
        self._memory_hint = memory_hint
        # a run interrupted outside ordered() (Ctrl-C while the caller writes a lot) leaves the
        # generator suspended until the interpreter tears it down, after multiprocessing has
        # closed the processes' sentinels; end the workers before that, while join still works
        atexit.register(self.kill)
        try:
            for number in range(workers):
                self._workers.append(_Worker(context, initializer, initargs, number + 1))
        except BaseException:
            self.kill()
            raise

    def ordered(
        self,
        function: Callable[[Any], Any],
        arguments: Iterator[Any],
        window: int,
        describe: Callable[[Any], str] = lambda argument: "a task",
    ) -> Iterator[Any]:
        """``function(argument)`` for every argument, yielded in the arguments' order, with at
        most ``window`` tasks sent or finished and not yet yielded.  A dead worker raises
        :class:`WorkerDied` naming ``describe(its argument)``.  The pool is closed when this
        ends: politely when every result was yielded, by SIGKILL otherwise."""
        done: dict[int, Any] = {}
        sent = yielded = 0
        exhausted = False
        finished = False
        try:
            while True:
                for worker in self._workers:
                    if exhausted or worker.task is not None or sent - yielded >= window:
                        continue
                    argument = next(arguments, _END)
                    if argument is _END:
                        exhausted = True
                        continue
                    worker.task = (sent, argument)
                    self._send(worker, (function, argument), describe)
                    sent += 1
                if yielded in done:
                    result = done.pop(yielded)
                    yielded += 1
                    yield result
                    continue
                if exhausted and yielded == sent:
                    finished = True
                    return
                self._collect(done, describe)
        finally:
            if finished:
                self.close()
            else:
                self.kill()

    def _send(self, worker: _Worker, task: tuple, describe: Callable[[Any], str]) -> None:
        try:
            worker.tasks.send(task)
        except OSError:  # the worker died while idle: its pipe is closed
            worker.process.join(1)
            raise self._died(worker, describe) from None

    def _collect(self, done: dict[int, Any], describe: Callable[[Any], str]) -> None:
        """Wait until a busy worker replies or dies; file its result under its number."""
        busy = [w for w in self._workers if w.task is not None]
        ready = set(wait([w.tasks for w in busy] + [w.process.sentinel for w in busy]))
        for worker in busy:
            assert worker.task is not None
            if worker.tasks in ready:  # a reply is read even if the process died after it
                try:
                    ok, value = worker.tasks.recv()
                except (EOFError, OSError):
                    worker.process.join(1)
                    raise self._died(worker, describe) from None
                if not ok:
                    raise BgrError(
                        f"internal error in a worker process while {self._doing} "
                        f"{describe(worker.task[1])}:\n{value}"
                    )
                done[worker.task[0]] = value
                worker.task = None
            elif worker.process.sentinel in ready:
                raise self._died(worker, describe)

    def _died(self, worker: _Worker, describe: Callable[[Any], str]) -> WorkerDied:
        code = worker.process.exitcode
        if code is not None and code < 0:
            try:
                how = f"killed by signal {-code} ({signal.Signals(-code).name})"
            except ValueError:
                how = f"killed by signal {-code}"
        else:
            how = f"ended with status {code}"
        doing = describe(worker.task[1]) if worker.task is not None else "nothing"
        return WorkerDied(
            Diagnostic(
                "",
                0,
                0,
                f"worker process {worker.process.name} {how} while {self._doing} {doing}",
                "a worker killed by signal 9 was most likely stopped by the system for want of "
                f"memory: {self._memory_hint}",
            )
        )

    def close(self) -> None:
        """Ask idle workers to stop, wait briefly, then kill any that has not."""
        for worker in self._workers:
            with contextlib.suppress(OSError):
                worker.tasks.send(None)
        deadline = time.monotonic() + 2.0
        try:
            for worker in self._workers:
                worker.process.join(max(0.0, deadline - time.monotonic()))
        finally:
            self.kill()

    def kill(self) -> None:
        """End every worker now (SIGKILL) and release the pipes.  Safe to call twice."""
        atexit.unregister(self.kill)
        for worker in self._workers:
            if worker.process.exitcode is None:
                worker.process.kill()
        for worker in self._workers:
            worker.process.join(5.0)  # SIGKILL cannot be caught: bounded only for safety
            for end in (worker.tasks, worker.alive):
                with contextlib.suppress(OSError):  # closed already at interpreter exit
                    end.close()
        self._workers = []


_END = object()
