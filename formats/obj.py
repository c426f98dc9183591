"""Wavefront .obj with its .mtl: vertices of every terminal, faces grouped by material.

Material names are the glTF ones with anything that is not a letter, digit, ``-``, ``_`` or ``.``
replaced by ``_`` (an OBJ name is one word, and ``#`` starts a comment): ``#3b4a5a`` becomes
``c_3b4a5a``.  ``Kd`` is the sRGB colour.
"""

from __future__ import annotations

import re
from typing import BinaryIO

import numpy as np

from bgr.interpreter.terminals import TerminalTable

from .materials import Materials, materials_of
from .meshes import bake

_CHUNK = 100_000  # rows formatted per string operation


def obj_names(mats: Materials) -> list[str]:
    names, seen = [], set()
    for label in mats.labels:
        name = "c_" + label[1:] if label.startswith("#") else re.sub(r"[^\w.\-]", "_", label)
        while name in seen:
            name += "_"
        seen.add(name)
        names.append(name)
    return names


def _rows(stream: BinaryIO, fmt: str, values: np.ndarray) -> None:
    for lo in range(0, len(values), _CHUNK):
        part = values[lo : lo + _CHUNK]
        stream.write(((fmt * len(part)) % tuple(part.ravel().tolist())).encode("ascii"))


def write_obj(
    table: TerminalTable, stream: BinaryIO, mtl: BinaryIO, *, mtl_name: str, seed: int, attrs: dict
) -> None:
    table.freeze()
    mats = materials_of(table)
    names = obj_names(mats)
    rows = np.argsort(mats.index, kind="stable")
    baked = bake(table, rows)
    stream.write(f"# bgr seed {seed}\nmtllib {mtl_name}\n".encode())
    _rows(stream, "v %.9g %.9g %.9g\n", baked.vertices)
    mat_of_face = np.repeat(mats.index[rows], np.diff(baked.fstart))
    cuts = np.flatnonzero(np.diff(mat_of_face)) + 1
    for lo, hi in zip(
        np.concatenate([[0], cuts]), np.concatenate([cuts, [len(mat_of_face)]]), strict=True
    ):
        if hi > lo:
            stream.write(f"usemtl {names[mat_of_face[lo]]}\n".encode())
            _rows(stream, "f %d %d %d\n", baked.faces[lo:hi] + 1)
    lines = ["# bgr materials"]
    for k, name in enumerate(names):
        r, g, b = (c / 255.0 for c in mats.rgb8[k])
        lines += [
            f"newmtl {name}",
            f"Kd {r:.6g} {g:.6g} {b:.6g}",
            "Ka 0 0 0",
            "Ks 0 0 0",
            "d 1",
            "illum 1",
            "",
        ]
    mtl.write("\n".join(lines).encode("utf-8"))
