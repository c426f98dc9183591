"""Wavefront .obj with its .mtl: one object per building, one group per label, shared vertices.

Layout of the file::

    # bgr seed 3
    mtllib house.mtl
    vn 0 0 1                 every distinct face normal, once for the whole file
    o lot-0                  one object per lot (its GeoJSON feature id, or lot-N)
    v 1.5 0 -2.25            the object's vertices: each distinct position once
    g Wall                   one group per terminal label
    usemtl brick             the material of the faces that follow
    f 1//1 2//1 3//1         triangles: vertex//normal, counter-clockwise seen from outside

Triangles are flat shaded: a face normal per triangle, pointing out as its winding says (mirrored
terminals are re-wound, as in the GLB).  Where faces meet at a position they share its ``v``;
positions and normals are written with six decimals (micrometres), and two positions that print
the same are one vertex.

Names are one word: anything that is not a letter, digit, ``-``, ``_`` or ``.`` becomes ``_``
(``#`` starts a comment), and a name already taken gets ``_`` appended.  Materials are named as in
the glTF (``#3b4a5a`` becomes ``c_3b4a5a``); ``Kd`` is the sRGB colour.

Numbers are formatted in bulk by :mod:`.text`, a block of lines at a time.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import BinaryIO

import numpy as np

from bgr.interpreter.terminals import TerminalTable

from .materials import Materials, materials_of
from .meshes import bake, unit_normals
from .sharing import number_rows
from .text import decimal, gather, integer, left_aligned, line_starts, quantize, render, word

LINES_PER_BLOCK = 1 << 19  # lines formatted at once: bounds the memory of a large file


def obj_name(text: str) -> str:
    """``text`` as one OBJ word."""
    return re.sub(r"[^\w.\-]", "_", text) or "_"


def unique_names(texts: list[str]) -> list[str]:
    """Each text as an OBJ word, distinct from the ones before it."""
    names: list[str] = []
    seen: set[str] = set()
    for text in texts:
        name = obj_name(text)
        while name in seen:
            name += "_"
        seen.add(name)
        names.append(name)
    return names


def obj_names(mats: Materials) -> list[str]:
    """The ``newmtl`` names of the materials."""
    return unique_names(["c_" + s[1:] if s.startswith("#") else s for s in mats.labels])


def lot_names(table: TerminalTable) -> tuple[np.ndarray, list[str]]:
    """Each terminal's object (its lot), and the objects' names.

    A table without lots (made by hand) is one object, ``lot-0``; terminals outside every lot's
    rows go to one more object after the lots.
    """
    n = len(table)
    lots = table.lots
    of_row = np.full(n, len(lots), dtype=np.int64)
    for i, lot in enumerate(lots):
        first, end = lot["rows"]
        of_row[first:end] = i
    names = [str(lot.get("name") or f"lot-{i}") for i, lot in enumerate(lots)]
    if (of_row == len(lots)).any():
        names.append(f"lot-{len(lots)}")
    return of_row, unique_names(names)


def codes(values: list[str]) -> tuple[np.ndarray, list[str]]:
    """Each value's number, in order of first use, and the distinct values."""
    first = {value: i for i, value in enumerate(dict.fromkeys(values))}
    return np.fromiter(map(first.__getitem__, values), dtype=np.int64, count=len(values)), list(
        first
    )


def _point_lines(prefix: bytes, q: np.ndarray) -> bytes:
    """``v x y z`` lines (``prefix`` ``v `` or ``vn ``) of (n, 3) quantized points."""
    numbers = [decimal(q[:, k], prefix if k == 0 else b" ") for k in range(3)]
    grid = np.empty((len(q), sum(w.shape[1] + 1 for w, _ in numbers)), dtype=np.uint64)
    at = 0
    for whole, frac in numbers:
        grid[:, at : at + whole.shape[1]] = whole
        at += whole.shape[1]
        grid[:, at] = frac
        at += 1
    grid[:, -1] |= word(b"\0" * 7 + b"\n")  # the decimals leave the last byte free
    return render(grid)


class _Blocks:
    """Lines ``0..n-1`` of one kind, formatted a block at a time and written in order."""

    def __init__(self, n: int, fmt: Callable[[int, int], bytes]) -> None:
        self.n, self.fmt = n, fmt
        self.lo = self.hi = 0
        self.text = b""
        self.starts: np.ndarray | None = None  # where each line of the block starts, once asked

    def write(self, stream: BinaryIO, lo: int, hi: int) -> None:
        while lo < hi:
            if not self.lo <= lo < self.hi:
                self.lo, self.hi = lo, min(self.n, lo + LINES_PER_BLOCK)
                self.text, self.starts = self.fmt(self.lo, self.hi), None
            end = min(hi, self.hi)
            if lo == self.lo and end == self.hi:
                stream.write(self.text)
            else:
                if self.starts is None:
                    self.starts = line_starts(self.text)
                first, last = self.starts[lo - self.lo], self.starts[end - self.lo]
                stream.write(memoryview(self.text)[first:last])
            lo = end


def write_obj(
    table: TerminalTable, stream: BinaryIO, mtl: BinaryIO, *, mtl_name: str, seed: int, attrs: dict
) -> None:
    """Write the terminals as OBJ to ``stream`` and their materials as MTL to ``mtl``."""
    table.freeze()
    mats = materials_of(table)
    lot_of, objects = lot_names(table)
    label_of, labels = codes(list(table.label))
    group_names = unique_names(labels)
    rows = np.lexsort((np.arange(len(table)), mats.index, label_of, lot_of))
    baked = bake(table, rows)
    nf = np.diff(baked.fstart)

    # vertices: one per distinct (object, written position) that a face uses, in file order
    used = np.zeros(len(baked.vertices), dtype=bool)
    used[baked.faces] = True
    used_at = np.flatnonzero(used)
    vq = quantize(baked.vertices[used_at])
    vlot = np.repeat(lot_of[rows], np.diff(baked.vstart))[used_at]
    ids, vfirst = number_rows([vlot, vq[:, 0], vq[:, 1], vq[:, 2]])
    vid = np.zeros(len(baked.vertices), dtype=np.int64)
    vid[used_at] = ids
    vpos = vq[vfirst]
    # normals: one per distinct written face normal, for the whole file
    nq = quantize(unit_normals(baked.vertices[baked.faces]))
    nid, nfirst = number_rows([nq[:, 0], nq[:, 1], nq[:, 2]])
    corners = vid[baked.faces]

    def v_lines(lo: int, hi: int) -> bytes:
        return _point_lines(b"v ", vpos[lo:hi])

    def vn_lines(lo: int, hi: int) -> bytes:
        return _point_lines(b"vn ", nq[nfirst[lo:hi]])

    normal_text = left_aligned(integer(np.arange(1, len(nfirst) + 1), b"//"))

    def f_lines(lo: int, hi: int) -> bytes:
        c = corners[lo:hi]
        first_v = int(c.min(initial=0))
        v_text = integer(np.arange(first_v + 1, int(c.max(initial=0)) + 2))
        vn = gather(normal_text, nid[lo:hi])
        wv, wn = v_text.shape[1], vn.shape[1]
        grid = np.empty((hi - lo, 2 + 3 * (wv + wn)), dtype=np.uint64)
        grid[:, 0] = word(b"f")
        for k in range(3):
            at = 1 + k * (wv + wn)
            grid[:, at : at + wv] = gather(v_text, c[:, k] - first_v)
            grid[:, at + wv : at + wv + wn] = vn
        grid[:, -1] = word(b"\n")
        return render(grid)

    out = stream
    out.write(f"# bgr seed {seed}\nmtllib {mtl_name}\n".encode())
    _Blocks(len(nfirst), vn_lines).write(out, 0, len(nfirst))
    v_blocks, f_blocks = _Blocks(len(vpos), v_lines), _Blocks(len(corners), f_lines)

    # runs of faces with one (object, label, material), in file order
    face_row = np.repeat(rows, nf)
    keys = np.stack([lot_of[face_row], label_of[face_row], mats.index[face_row]])
    cuts = np.flatnonzero((keys[:, 1:] != keys[:, :-1]).any(axis=0)) + 1
    starts = np.concatenate([[0], cuts]).astype(np.int64)
    ends = np.concatenate([cuts, [len(face_row)]]).astype(np.int64)
    v_end = np.searchsorted(vlot[vfirst], np.arange(len(objects)), side="right")
    names = obj_names(mats)
    current = (-1, -1)
    for lo, hi in zip(starts.tolist(), ends.tolist(), strict=True):
        if hi == lo:
            continue
        obj, label, mat = (int(k) for k in keys[:, lo])
        if obj != current[0]:
            out.write(f"o {objects[obj]}\n".encode())
            v_lo = int(v_end[obj - 1]) if obj else 0
            v_blocks.write(out, v_lo, int(v_end[obj]))
        if (obj, label) != current:
            out.write(f"g {group_names[label]}\n".encode())
        current = (obj, label)
        out.write(f"usemtl {names[mat]}\n".encode())
        f_blocks.write(out, lo, hi)

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
