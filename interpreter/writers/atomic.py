"""All-or-nothing output files: write beside the target, then rename over it.

``with atomic_files([a, b]) as (fa, fb): ...`` yields binary files open on temporary names in the
targets' folders.  When the block ends normally the temporaries are renamed over the targets; when
it raises, every temporary is removed, so a failed write leaves neither a partial file nor litter.
"""

from __future__ import annotations

import contextlib
import os
import secrets
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

from ...grammar.errors import BgrError, Diagnostic


def _open_temp(target: Path) -> tuple[Path, BinaryIO]:
    folder = target.parent
    for _ in range(100):
        tmp = folder / f".{target.name}.{secrets.token_hex(4)}.tmp"
        try:
            # mode 0o666 lets the umask decide the permissions, as for any new file
            fd = os.open(
                tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666
            )
        except FileExistsError:
            continue
        return tmp, os.fdopen(fd, "wb")
    raise FileExistsError(f"no free temporary name in {folder}")


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
            temps.append(_open_temp(target))
        current = targets[0]
        yield [f for _, f in temps]
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
