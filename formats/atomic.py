"""All-or-nothing output files: write beside the target, then rename over it.

``with atomic_files([a, b]) as (fa, fb): ...`` yields binary files open on temporary names in the
targets' folders.  When the block ends normally the temporaries are renamed over the targets; when
it raises, every temporary is removed, so a failed write leaves neither a partial file nor litter.
``bgr`` turns SIGTERM into the same exception path as Ctrl-C (``bgr.cli.main``), so a terminated
run cleans up too; :func:`write_text` is the one-file text form (``bgr fmt -w``, ``bgr infer -o``).

Only a run killed outright (SIGKILL, a power cut) can leave a temporary behind.  Temporaries are
named ``.{target}.{pid}.{random}.tmp``, and each write first removes the stale temporaries of
its own targets (:func:`remove_stale`).  A target must be, or become, a regular file: a FIFO, a
device or anything under /proc is refused before a temporary is made (``paths.check_output``).
"""

from __future__ import annotations

import contextlib
import os
import secrets
import signal
import time
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.grammar.paths import check_output

# a temporary whose name carries no writer PID (an earlier bgr's, or another tool's) is stale
# only once it is this old: no write of ours takes that long between open and rename
UNOWNED_STALE_AFTER = 3600.0


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the program is, so that it unwinds as for Ctrl-C: the atomic
    writers remove their temporaries (a ``kill`` leaves no ``.tmp`` beside the output)."""


# set by bgr's SIGTERM handler: a termination that some code swallowed (an exception raised in a
# __del__, a weakref callback or a generator's close is only printed) is raised again before an
# output is finished or put in place, rather than lost while the file is completed
_terminating = False


def on_sigterm(signum, frame) -> None:
    """bgr's SIGTERM handler (installed by ``bgr.cli.main``)."""
    global _terminating
    _terminating = True
    raise Terminated


def reset_termination() -> None:
    global _terminating
    _terminating = False


def raise_if_terminated() -> None:
    """Raise :class:`Terminated` if a SIGTERM came, even one whose first raise was lost."""
    if _terminating:
        raise Terminated


def _open_temp(target: Path) -> tuple[Path, BinaryIO]:
    folder = target.parent
    for _ in range(100):
        tmp = folder / f".{target.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp"
        try:
            # mode 0o666 lets the umask decide the permissions, as for any new file
            fd = os.open(
                tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666
            )
        except FileExistsError:
            continue
        return tmp, os.fdopen(fd, "wb")
    raise FileExistsError(f"no free temporary name in {folder}")


@contextlib.contextmanager
def _signals_held() -> Iterator[None]:
    """Hold SIGTERM and SIGINT while a temporary is created and recorded: a signal that landed
    between ``os.open`` and the record would unwind past a file nobody knows to remove.  The
    held signal is delivered when the block ends, with the temporary on the list."""
    mask = getattr(signal, "pthread_sigmask", None)
    if mask is None:  # Windows: no signal masks
        yield
        return
    previous = mask(signal.SIG_BLOCK, {signal.SIGTERM, signal.SIGINT})
    try:
        yield
    finally:
        mask(signal.SIG_SETMASK, previous)


def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists (as far as this process can tell)."""
    if pid == os.getpid():
        return True
    if os.name == "nt":  # os.kill would terminate it there: assume alive, let age decide
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # PermissionError: it exists, under another user
        return True
    return True


def is_stale(tmp: Path, target_name: str, now: float | None = None) -> bool:
    """Whether ``tmp`` is a temporary of ``target_name`` left by a writer that is gone.

    The rule: ``.{target}.{pid}.{hex}.tmp`` is stale when no process ``pid`` exists, since the
    writer holds it only while it runs (a recycled PID merely keeps it until a later write).  A
    name without a PID (an older bgr's ``.{target}.{hex}.tmp``) is stale once its last change is
    over :data:`UNOWNED_STALE_AFTER` seconds old, so a concurrent writer of another kind is
    never robbed of its file.  Anything else is not a temporary of ours.
    """
    prefix, suffix = f".{target_name}.", ".tmp"
    name = tmp.name
    if not (name.startswith(prefix) and name.endswith(suffix)):
        return False
    middle = name[len(prefix) : -len(suffix)].split(".")
    if len(middle) == 2 and middle[0].isdigit() and middle[1]:
        return not _alive(int(middle[0]))
    if len(middle) == 1 and middle[0]:
        try:
            age = (time.time() if now is None else now) - tmp.lstat().st_mtime
        except OSError:
            return False
        return age > UNOWNED_STALE_AFTER
    return False


def remove_stale(target: Path) -> None:
    """Remove the stale temporaries of ``target`` in its folder (see :func:`is_stale`)."""
    prefix = f".{target.name}."
    try:
        names = os.listdir(target.parent)
    except OSError:
        return
    for name in names:
        if name.startswith(prefix) and name.endswith(".tmp"):
            tmp = target.parent / name
            if is_stale(tmp, target.name) and not tmp.is_symlink() and tmp.is_file():
                _remove(tmp)


def _remove(path: Path) -> None:
    with contextlib.suppress(OSError):
        os.unlink(path)


def cannot_write(target: Path, exc: OSError) -> BgrError:
    if isinstance(exc, FileNotFoundError) and not target.parent.is_dir():
        reason, hint = (
            f"the folder {target.parent} does not exist",
            "create it first, or check the path",
        )
    else:
        reason, hint = exc.strerror or str(exc), None
    return BgrError(Diagnostic(str(target), 0, 0, f"cannot write the output file: {reason}", hint))


@contextlib.contextmanager
def atomic_files(targets: list[Path]) -> Iterator[list[BinaryIO]]:
    temps: list[tuple[Path, BinaryIO]] = []
    placed: list[Path] = []
    current = targets[0]
    try:
        for target in targets:
            current = target
            if target.is_dir():
                raise IsADirectoryError(21, "it is a folder", str(target))
            check_output(target)
            remove_stale(target)
            with _signals_held():
                temps.append(_open_temp(target))
        current = targets[0]
        yield [f for _, f in temps]
        raise_if_terminated()
        for (tmp, f), target in zip(temps, targets, strict=True):
            current = target
            f.close()
            if target.exists():  # keep the permissions of the file being replaced
                with contextlib.suppress(OSError):
                    os.chmod(tmp, target.stat().st_mode & 0o7777)
            os.replace(tmp, target)
            placed.append(target)
    except BaseException as exc:
        for tmp, f in temps:
            f.close()
            _remove(tmp)
        for target in placed:  # half of a file pair (.obj without its .mtl) is no output either
            _remove(target)
        if isinstance(exc, OSError):
            raise cannot_write(current, exc) from exc
        raise


def write_text(path: Path, text: str) -> None:
    """Write ``text`` as UTF-8 (newlines as given) to ``path``, atomically."""
    with atomic_files([Path(path)]) as (f,):
        f.write(text.encode("utf-8"))
