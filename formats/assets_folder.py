"""A folder of files that bgr owns (``bgr infer --kind city``'s meshes): written whole, replaced
whole, and never anything else deleted or overwritten.

Every such folder holds a manifest, :data:`MANIFEST`, naming the files bgr wrote.  A folder is
accepted as a target only when it does not exist, is empty, or holds exactly a manifest and the
files it names (regular files, no links); anything else — a folder of the user's files, ``.``,
``..``, a symlink, a regular file, the folder of the input or of the grammar — is refused with a
:class:`BgrError` *before* anything is written (:func:`check_folder`).

:func:`assets_written` stages the new files in a fresh sibling folder, moves the old folder aside,
moves the new one in and, once the caller's block (writing the grammar) has succeeded, removes
only the files the old manifest named.  When the block raises, the new folder is removed file by
file and the old one is put back, so a failed run leaves what was there before.
"""

from __future__ import annotations

import contextlib
import json
import os
import secrets
import stat
from collections.abc import Iterable, Iterator
from pathlib import Path

from bgr.grammar.errors import BgrError, Diagnostic

MANIFEST = ".bgr-assets.json"
PICK_NEW = "name a new folder with --assets DIR (bgr creates it), or an empty one"


def _refuse(folder: Path, message: str, hint: str | None = PICK_NEW) -> BgrError:
    return BgrError(Diagnostic(str(folder), 0, 0, f"refusing --assets: {message}", hint))


def _inside(path: Path, folder: Path) -> bool:
    """Whether ``path`` is ``folder`` or lies under it (both resolved)."""
    return path == folder or folder in path.parents


def read_manifest(folder: Path) -> list[str] | None:
    """The file names a bgr manifest in ``folder`` lists; None when it has none or it is not
    bgr's (unreadable, not the expected JSON, names with a path in them)."""
    path = folder / MANIFEST
    try:
        if not stat.S_ISREG(os.lstat(path).st_mode):
            return None
        doc = json.loads(path.read_bytes().decode("utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(doc, dict) or not str(doc.get("written_by", "")).startswith("bgr"):
        return None
    files = doc.get("files")
    if not isinstance(files, list) or not all(isinstance(f, str) and _plain(f) for f in files):
        return None
    return files


def _plain(name: str) -> bool:
    """A bare file name: no folder part, not ``.``/``..``, not the manifest, no NUL."""
    return (
        bool(name)
        and name not in (".", "..", MANIFEST)
        and "/" not in name
        and "\\" not in name
        and "\0" not in name
    )


def check_folder(folder: Path, keep: Iterable[Path] = ()) -> list[str]:
    """Refuse ``folder`` as an assets folder unless bgr may (re)write it; return the files its
    manifest names (to be replaced), [] for a new or empty folder.

    ``keep`` are paths the run reads or writes elsewhere (the input, the grammar): a folder that
    is or holds one of them is refused, since replacing it would take them along.
    """
    folder = Path(folder)
    if folder.name in ("", ".", ".."):
        raise _refuse(
            folder,
            f"'{folder}' names the current folder, one above it or a root; the meshes need a "
            "folder of their own, which bgr replaces whole",
        )
    if folder.is_symlink():
        raise _refuse(folder, "it is a symbolic link; bgr does not write through links")
    try:
        mode = os.lstat(folder).st_mode
    except FileNotFoundError:
        mode = None
    except OSError as e:
        raise _refuse(folder, f"cannot look at it: {e.strerror}", None) from None
    if mode is not None and not stat.S_ISDIR(mode):
        raise _refuse(folder, "it is a file, not a folder")
    whole = folder.resolve()
    for path in keep:
        if _inside(Path(path).resolve(), whole):
            raise _refuse(
                folder,
                f"it holds {path}, which this run reads or writes; bgr replaces the assets "
                "folder whole",
            )
    if mode is None:
        return []
    return _owned_files(folder)


def _owned_files(folder: Path) -> list[str]:
    """The files of bgr's manifest in ``folder``, when that is all it holds; else a refusal."""
    try:
        entries = {e.name: e for e in os.scandir(folder)}
    except OSError as e:
        raise _refuse(folder, f"cannot list it: {e.strerror}", None) from None
    if not entries:
        return []
    files = read_manifest(folder)
    if files is None:
        shown = ", ".join(sorted(entries)[:3]) + (", ..." if len(entries) > 3 else "")
        raise _refuse(
            folder,
            f"it is not empty and bgr did not write it (it has no {MANIFEST}): it holds {shown}",
        )
    foreign = sorted(
        name
        for name, entry in entries.items()
        if (name != MANIFEST and name not in files) or not entry.is_file(follow_symlinks=False)
    )
    if foreign:
        shown = ", ".join(foreign[:3]) + (", ..." if len(foreign) > 3 else "")
        raise _refuse(
            folder,
            f"it holds files bgr did not write ({shown}); bgr only replaces a folder that holds "
            f"its own assets and {MANIFEST}",
        )
    return [f for f in files if f in entries]


def _sibling(folder: Path, what: str) -> Path:
    """A fresh folder beside ``folder``, made with the umask's permissions."""
    for _ in range(100):
        path = folder.with_name(f".{folder.name}.{os.getpid()}.{secrets.token_hex(4)}.{what}")
        try:
            os.mkdir(path, 0o777)
        except FileExistsError:
            continue
        return path
    raise FileExistsError(f"no free temporary name beside {folder}")


def _make_parents(folder: Path) -> list[Path]:
    """Create the missing folders above ``folder``; return them, deepest first, for undoing."""
    missing = []
    parent = folder.parent
    while not parent.exists() and parent != parent.parent:
        missing.append(parent)
        parent = parent.parent
    for path in reversed(missing):
        os.mkdir(path)
    return missing


def _remove_named(folder: Path, names: Iterable[str]) -> None:
    """Remove the listed regular files (never a link's target) and the manifest, then the folder
    if nothing else is left in it."""
    for name in [*names, MANIFEST]:
        path = folder / name
        with contextlib.suppress(OSError):
            if stat.S_ISREG(os.lstat(path).st_mode):
                os.unlink(path)
    with contextlib.suppress(OSError):
        os.rmdir(folder)  # only an empty folder: whatever else appeared stays


def _stage(folder: Path, files: dict[str, bytes], written_by: str) -> Path:
    """The new folder's files and manifest, written in a fresh sibling of ``folder``."""
    stage = _sibling(folder, "tmp")
    try:
        for name, data in files.items():
            if not _plain(name):
                raise ValueError(f"not a plain file name: {name!r}")
            with open(stage / name, "xb") as f:
                f.write(data)
        manifest = {"written_by": written_by, "files": sorted(files)}
        with open(stage / MANIFEST, "x", encoding="utf-8") as f:
            json.dump(manifest, f, indent=1)
            f.write("\n")
    except BaseException:
        _remove_named(stage, files)
        raise
    return stage


@contextlib.contextmanager
def assets_written(
    folder: Path, files: dict[str, bytes], *, keep: Iterable[Path] = (), written_by: str = "bgr"
) -> Iterator[None]:
    """Put ``files`` (name -> bytes) in ``folder`` as its only files, for the ``with`` block to
    finish the run's other outputs; undone when the block raises (see the module docstring)."""
    from bgr.formats.atomic import cannot_write, raise_if_terminated

    folder = Path(folder)
    old_files = check_folder(folder, keep)
    created: list[Path] = []
    stage: Path | None = None
    aside: Path | None = None
    placed = False
    try:
        created = _make_parents(folder)
        stage = _stage(folder, files, written_by)
        raise_if_terminated()
        if os.path.lexists(folder):
            old_files = check_folder(folder, keep)  # again, just before it moves
            aside = _sibling(folder, "old")
            os.replace(folder, aside)  # an empty folder of ours is replaced by the rename
        os.replace(stage, folder)
        placed = True
        yield
    except BaseException as exc:
        if placed:
            _remove_named(folder, files)
        elif stage is not None:
            _remove_named(stage, files)
        if aside is not None:
            with contextlib.suppress(OSError):
                os.replace(aside, folder)
        for path in created:
            with contextlib.suppress(OSError):
                os.rmdir(path)
        if isinstance(exc, OSError):
            raise cannot_write(folder, exc) from exc
        raise
    if aside is not None:
        _remove_named(aside, old_files)


__all__ = ["MANIFEST", "assets_written", "check_folder", "read_manifest"]
