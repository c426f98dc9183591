"""The texture images of a file that refers to them by name (OBJ's .mtl, CityJSON's
``appearance``): each image a textured terminal uses is COPIED, byte for byte, into a folder
named after the output (``house.obj`` -> ``house_textures/``), and the file names it there by
a relative path, so the output folder can be moved or zipped as a whole.

Copies rather than links: a link to the grammar's folder breaks when the output moves, and a
GLB already holds its images.  Each distinct image (one resolved source path) is copied once;
its name is the source file's name made safe (letters, digits, ``-``, ``_`` and ``.``) with the
extension its type calls for, and ``_2``, ``_3``... before the extension when two images would
share one.  The copies are written atomically with the file that names them (:mod:`.atomic`):
a failed run leaves none of them, and removes the folder when it made it and it stays empty.
"""

from __future__ import annotations

import contextlib
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import BinaryIO

import numpy as np

from bgr.interpreter.terminals import TerminalTable

from .atomic import atomic_files

SUFFIX = {"image/png": (".png",), "image/jpeg": (".jpg", ".jpeg")}
# the longest format extensions first, as formats.format_of matches them
OUTPUT_SUFFIXES = (".city.jsonl", ".city.json", ".gltf", ".json", ".glb", ".obj", ".ply", ".stl")


def texture_folder(output: str | Path) -> str:
    """The name of the folder an output's images go to: its name without the format's
    extension, then ``_textures`` (``house.obj`` and ``house.city.json``: ``house_textures``)."""
    name = Path(str(output)).name
    for suffix in OUTPUT_SUFFIXES:
        if name.lower().endswith(suffix) and len(name) > len(suffix):
            name = name[: -len(suffix)]
            break
    return safe_name(name) + "_textures"


def safe_name(text: str) -> str:
    """``text`` as a file name any system and any reader of an OBJ line takes."""
    name = re.sub(r"[^\w.\-]", "_", text, flags=re.ASCII).strip(".")
    return name or "texture"


def used_images(table: TerminalTable, maps: tuple[int, ...] = (0, 1)) -> list[int]:
    """The indices of the images some textured terminal uses, in order: as colour map (0 in
    ``maps``) or normal map (1)."""
    used = np.asarray(table.tex_maps).reshape(-1, 2)[:, list(maps)].reshape(-1)
    return [int(k) for k in np.unique(used[used >= 0])]


@dataclass
class Copies:
    """The images of a table and where they go: ``names`` maps an image's source path to its
    relative path from the output's folder (``house_textures/brick.png``)."""

    folder: str
    names: dict[str, str]
    data: dict[str, bytes]  # relative path -> the image's bytes

    @classmethod
    def of(cls, table: TerminalTable, folder: str, maps: tuple[int, ...] = (0, 1)) -> Copies:
        """The copies of the images ``table`` uses as the ``maps`` (0: colour, 1: normal)."""
        names: dict[str, str] = {}
        data: dict[str, bytes] = {}
        taken: set[str] = set()
        for k in used_images(table, maps):
            image = table.images[k]
            if image.path in names:
                continue
            source = PurePosixPath(image.path.replace("\\", "/")).name
            kinds = SUFFIX.get(image.mime, (".png",))
            given = next((x for x in kinds if source.lower().endswith(x)), None)
            stem_text = source[: -len(given)] if given else source
            suffix = given or kinds[0]
            base = safe_name(stem_text)
            name, n = base + suffix, 1
            while name.lower() in taken:  # case-insensitive file systems too
                n += 1
                name = f"{base}_{n}{suffix}"
            taken.add(name.lower())
            names[image.path] = f"{folder}/{name}"
            data[names[image.path]] = image.data
        return cls(folder, names, data)


@contextlib.contextmanager
def atomic_with_images(targets: list[Path], copies: Copies | None) -> Iterator[list[BinaryIO]]:
    """:func:`atomic_files` of ``targets`` and the image ``copies`` beside the first target:
    yields the targets' streams (the images are written here); all or nothing."""
    if copies is None or not copies.data:
        with atomic_files(targets) as streams:
            yield streams
        return
    base = Path(targets[0]).parent
    folder = base / copies.folder
    made = False
    if base.is_dir() and not folder.is_dir():
        try:
            folder.mkdir()
            made = True
        except OSError:  # a file of that name, say: atomic_files says why it cannot write
            pass
    try:
        images = [base / relative for relative in copies.data]
        with atomic_files([*targets, *images]) as streams:
            for stream, data in zip(streams[len(targets) :], copies.data.values(), strict=True):
                stream.write(data)
            yield streams[: len(targets)]
    except BaseException:
        if made:
            with contextlib.suppress(OSError):
                folder.rmdir()  # only when empty: nothing of anyone else's is removed
        raise
