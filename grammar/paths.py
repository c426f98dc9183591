"""Which files bgr may read and write: grammar roots, regular files only, nothing in /proc.

A grammar is code that other people write, so what it names is kept within reach:

* **Roots.** Imports and assets resolve inside the *roots* of a load: the folder of the grammar
  being loaded (the current working folder for a grammar given as text without a path), the
  bundled standard library, and any folder added with ``--allow-path DIR`` or
  ``bgr.load(..., allow_paths=[DIR])``.  Paths are compared after resolving symlinks, so a link
  inside a root that points outside it is refused like the outside path itself.
* **Regular files.** Every input (grammars, imports, assets, lot, camera and model files) and
  every output must be a regular file: a FIFO would block a reader forever, and writing over a
  device or a FIFO with ``os.replace`` would swap it for a plain file.  Anything under
  ``/proc``, ``/sys`` or ``/dev`` is refused outright, as input and as output.
* **No foreign text in messages.** Only ``.bgr`` sources are ever quoted in an error; a file
  that is not a ``.bgr`` is refused before it is read as a grammar (see ``loader.read_source``).

The readers built on these checks are here too: :func:`read_input` for bytes and
:func:`read_json` for a JSON input (a lot, street, camera or terminal file), as is where the
bundled standard library lies (:func:`_stdlib_dir`, one of every load's roots).
"""

from __future__ import annotations

import os
import stat
from collections.abc import Iterable
from pathlib import Path

from .errors import BgrError, Diagnostic

# kernel and device file systems: their "files" are not data a grammar run should read or write
SPECIAL_DIRS = tuple(Path(p) for p in ("/proc", "/sys", "/dev"))

ALLOW_HINT = "widen the allowed folders with --allow-path DIR (bgr.load(..., allow_paths=[DIR]))"

STDLIB_DIR = Path(__file__).resolve().parent.parent / "stdlib"


def _stdlib_dir() -> Path:
    """The bundled stdlib: ``bgr/stdlib`` when installed, ``stdlib/`` in a source checkout."""
    try:
        import bgr.stdlib

        return Path(bgr.stdlib.__file__).resolve().parent
    except ImportError:  # pragma: no cover - only when the grammar package is used on its own
        return STDLIB_DIR


def resolved(path: str | os.PathLike) -> Path:
    """``path`` made absolute with every symlink followed (as far as it exists)."""
    return Path(os.path.realpath(os.fspath(path)))


def roots_of(
    base: str | os.PathLike, allow_paths: Iterable[str | os.PathLike] = ()
) -> tuple[Path, ...]:
    """The folders a load may read: ``base`` (the top-level grammar's folder), the stdlib and
    ``allow_paths``, resolved."""
    return tuple(dict.fromkeys(resolved(p) for p in (base, _stdlib_dir(), *allow_paths)))


def within(path: str | os.PathLike, roots: Iterable[Path]) -> bool:
    """Whether ``path``, symlinks resolved, lies inside one of ``roots``."""
    return inside(resolved(path), roots)


def inside(real: str | os.PathLike, folders: Iterable[Path]) -> bool:
    """Whether the resolved path ``real`` lies inside one of the resolved ``folders``.  On POSIX
    by their text (a style sheet's derivation checks 1,300 texture paths, and pathlib's
    ``is_relative_to`` took 20 microseconds a call); elsewhere (drive letters, case-blind
    names) by ``is_relative_to``."""
    if os.sep != "/":
        return any(Path(real).is_relative_to(folder) for folder in folders)
    text = os.fspath(real)
    for folder in folders:
        top = str(folder)
        if text == top or text.startswith(top if top.endswith("/") else top + "/"):
            return True
    return False


def _special(real: str | os.PathLike) -> bool:
    return inside(real, SPECIAL_DIRS)


def check_input(path: str | os.PathLike, what: str = "file", real: bool = False) -> None:
    """Refuse ``path`` as an input unless it is a regular file outside /proc, /sys and /dev.

    A path that does not exist, or is a folder, is let through: the reader's own message for
    those ("no such file", "is a folder") says more.  ``os.stat`` looks without opening, so a
    FIFO never blocks here.  ``real``: the caller resolved ``path`` already (realpath costs a
    system call per component, and a style sheet's derivation reads 1,300 files).
    """
    shown = str(path)
    if _special(path if real else resolved(path)):
        raise BgrError(
            Diagnostic(
                shown,
                0,
                0,
                f"refusing to read the {what}: it is in /proc, /sys or /dev",
                "bgr reads regular files only",
            )
        )
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return
    if not stat.S_ISREG(mode) and not stat.S_ISDIR(mode):
        raise BgrError(
            Diagnostic(
                shown,
                0,
                0,
                f"refusing to read the {what}: it is a {_kind(mode)}, not a regular file",
                "bgr reads regular files only",
            )
        )


def read_input(path: str | os.PathLike, what: str = "file", real: bool = False) -> bytes:
    """The bytes of a regular input file; :func:`check_input` first, then a non-blocking open
    checked again with ``fstat`` (the path may change between the two).  OSErrors such as
    FileNotFoundError reach the caller, whose message names the file's role.  ``real``: see
    :func:`check_input`."""
    check_input(path, what, real)
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    with os.fdopen(fd, "rb") as f:
        mode = os.fstat(fd).st_mode
        if stat.S_ISDIR(mode):
            raise IsADirectoryError(21, "Is a directory", str(path))
        if not stat.S_ISREG(mode):
            raise BgrError(
                Diagnostic(
                    str(path),
                    0,
                    0,
                    f"refusing to read the {what}: it is a {_kind(mode)}, not a regular file",
                    "bgr reads regular files only",
                )
            )
        return f.read()


def check_output(path: str | os.PathLike) -> None:
    """Refuse ``path`` as an output unless it is, or will become, a regular file.

    An existing target (or what a symlink target points to) must be a regular file: renaming a
    new file over a FIFO or a device would replace it.  Nothing under /proc, /sys or /dev is
    written, whether it exists or not.
    """
    shown = str(path)
    if _special(resolved(path)):
        raise BgrError(
            Diagnostic(
                shown,
                0,
                0,
                "refusing to write the output: it is in /proc, /sys or /dev",
                "write to a regular file",
            )
        )
    try:
        mode = os.stat(path).st_mode  # follows a symlink to what it names
    except OSError:
        return  # a new file, or a dangling link: the rename makes a regular file
    if not stat.S_ISREG(mode) and not stat.S_ISDIR(mode):
        raise BgrError(
            Diagnostic(
                shown,
                0,
                0,
                f"refusing to write the output: it is a {_kind(mode)}, not a regular file",
                "write to a regular file",
            )
        )


def _kind(mode: int) -> str:
    for test, name in (
        (stat.S_ISFIFO, "FIFO (named pipe)"),
        (stat.S_ISCHR, "character device"),
        (stat.S_ISBLK, "block device"),
        (stat.S_ISSOCK, "socket"),
        (stat.S_ISDIR, "folder"),
    ):
        if test(mode):
            return name
    return "special file"


def read_json(path, what: str, hint: str | None = None):
    """The parsed JSON of a file, or a BgrError that says which file and what is wrong with it
    (``what`` names the file's role: "lot file", "camera file"...)."""
    import json

    shown = str(path)
    try:
        return json.loads(read_input(path, what).decode("utf-8"))
    except FileNotFoundError:
        raise BgrError(Diagnostic(shown, 0, 0, f"no such {what}", hint)) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise BgrError(Diagnostic(shown, 0, 0, f"cannot read the {what}: {exc}")) from None
    except json.JSONDecodeError as exc:
        raise BgrError(
            Diagnostic(shown, exc.lineno, exc.colno, f"not valid JSON: {exc.msg}")
        ) from None
    except ValueError as exc:  # an integer of more digits than Python converts (4,300)
        raise BgrError(Diagnostic(shown, 0, 0, f"not usable JSON: {exc}")) from None
    except RecursionError:
        raise BgrError(
            Diagnostic(shown, 0, 0, "not usable JSON: it nests arrays or objects too deeply")
        ) from None
