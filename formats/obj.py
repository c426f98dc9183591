"""Wavefront .obj with its .mtl: one object per building, one group per label, shared vertices.

Layout of the file::

    # bgr seed 3
    mtllib house.mtl
    vn 0 0 1                 every distinct face normal, once for the whole file
    vt 0.5 1                 every distinct texture coordinate, once (textured terminals)
    o lot-0                  one object per lot (its GeoJSON feature id, or lot-N)
    v 1.5 0 -2.25            the object's vertices: each distinct position once
    g Wall                   one group per terminal label
    usemtl brick             the material of the faces that follow
    f 1//1 2//1 3//1         triangles: vertex//normal, counter-clockwise seen from outside
    f 4/1/2 5/2/2 6/3/2      a textured triangle: vertex/texture coordinate/normal

Triangles are flat shaded: a face normal per triangle, pointing out as its winding says (mirrored
terminals are re-wound, as in the GLB).  Where faces meet at a position they share its ``v``;
positions and normals are written with six decimals (micrometres), and two positions that print
the same are one vertex.

A textured terminal's faces have a ``vt`` per corner: each distinct texture coordinate is written
once, after the normals, v up the image (OBJ's way and CGA's, glTF's upside down); its material
names the images, copied beside the file (:mod:`.texture_files`), in ``map_Kd``, ``map_d`` and
``map_Bump``.

Names are one word: anything that is not a letter, digit, ``-``, ``_`` or ``.`` becomes ``_``
(``#`` starts a comment), and a name already taken gets ``_`` appended.  Materials are named as in
the glTF (``#3b4a5a`` becomes ``c_3b4a5a``); ``Kd`` is the sRGB colour.

Numbers are formatted in bulk by :mod:`.text`, a block of lines at a time.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import BinaryIO

import numpy as np

from bgr.interpreter.surfaces import DEFAULTS
from bgr.interpreter.terminals import TerminalTable

from .gltf_materials import MaterialIndex
from .materials import Materials, materials_of
from .meshes import Baked, MeshPool, bake, unit_normals
from .placement import to_site
from .sharing import number_rows
from .texcoords import baked_uvs
from .text import decimal, gather, integer, left_aligned, line_starts, quantize, render, word
from .texture_files import Copies, texture_folder

LINES_PER_BLOCK = 1 << 17  # lines formatted at once: bounds the memory of a large file


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
    """``v x y z`` lines (``prefix`` ``v ``, ``vn `` or ``vt ``) of (n, 3) or (n, 2) quantized
    points."""
    numbers = [decimal(q[:, k], prefix if k == 0 else b" ") for k in range(q.shape[1])]
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


def runs(keys: np.ndarray, fstart: np.ndarray) -> list[tuple[int, int, int, int, int]]:
    """``(object, label, material, first face, end face)`` of each run of rows with equal
    ``keys`` (3, n) whose rows have faces, from the rows' face offsets ``fstart`` (n + 1,)."""
    n = keys.shape[1]
    if n == 0:
        return []
    cuts = np.flatnonzero((keys[:, 1:] != keys[:, :-1]).any(axis=0)) + 1
    first = np.concatenate([[0], cuts]).astype(np.int64)
    end = np.concatenate([cuts, [n]]).astype(np.int64)
    out = zip(*keys[:, first].tolist(), fstart[first].tolist(), fstart[end].tolist(), strict=True)
    return [run for run in out if run[4] > run[3]]


def write_obj(
    table: TerminalTable,
    stream: BinaryIO,
    mtl: BinaryIO,
    *,
    mtl_name: str,
    seed: int,
    attrs: dict,
    textures: Copies | None = None,
) -> None:
    """Write the terminals as OBJ to ``stream`` and their materials as MTL to ``mtl``.

    A textured table's MTL names its images as ``textures`` says (where :func:`bgr.formats.write`
    copies them; by default ``{stem}_textures/{image}``, which the caller must then write)."""
    table.freeze()
    maps: list[tuple[str | None, str | None]] = []
    if table.textured():  # a material per (colour, name, images), as the GLB has
        index = MaterialIndex()
        local = index.of(table)
        mats, maps = index.all(), index.textures
        mats.index = local.index
        if textures is None:
            textures = Copies.of(table, texture_folder(Path(mtl_name).stem + ".obj"))
    else:
        mats = materials_of(table)
    lot_of, objects = lot_names(table)
    label_of, labels = codes(list(table.label))
    rows = np.lexsort((np.arange(len(table)), mats.index, label_of, lot_of))  # the file's order
    pool = MeshPool.of(table)
    baked = bake(table, rows, pool)
    baked.vertices = to_site(baked.vertices, table.site)  # the input's frame, if any

    # vertices: one per distinct (object, written position) that a face uses, in file order
    used = np.zeros(len(baked.vertices), dtype=bool)
    used[baked.faces] = True
    used_at = np.flatnonzero(used)
    vq = quantize(np.take(baked.vertices, used_at, axis=0))
    vlot = np.repeat(lot_of[rows], np.diff(baked.vstart))[used_at]
    ids, vfirst = number_rows([vlot, vq[:, 0], vq[:, 1], vq[:, 2]])
    vid = np.zeros(len(baked.vertices), dtype=np.int64)
    vid[used_at] = ids
    vpos = vq[vfirst]
    v_end = np.searchsorted(vlot[vfirst], np.arange(len(objects)), side="right")
    corners = vid[baked.faces]
    # normals: one per distinct written face normal, for the whole file
    nq = quantize(unit_normals(np.take(baked.vertices, baked.faces, axis=0)))
    nid, nfirst = number_rows([nq[:, 0], nq[:, 1], nq[:, 2]])
    # texture coordinates: one vt per distinct written uv, for the whole file; -1: none
    vt, tq = texture_corners(table, rows, pool, baked)
    slashes = b"/" if len(tq) else b"//"
    normal_text = left_aligned(integer(np.arange(1, len(nfirst) + 1), slashes))
    vt_text = np.zeros((0, 1), dtype=np.uint64)
    if len(tq):  # "/k", and "/" first for a corner without one (its face reads v//vn)
        vt_text = left_aligned(integer(np.arange(0, len(tq) + 1), b"/"))
        vt_text[0] = 0
        vt_text[0, 0] = word(b"/")

    def f_lines(lo: int, hi: int) -> bytes:
        c = corners[lo:hi]
        first = int(c.min(initial=0))  # the vertex numbers of a block, formatted once each
        v_text = integer(np.arange(first + 1, int(c.max(initial=0)) + 2))
        vn = gather(normal_text, nid[lo:hi])
        wv, wt, wn = v_text.shape[1], vt_text.shape[1] if len(tq) else 0, vn.shape[1]
        width = wv + wt + wn
        grid = np.empty((hi - lo, 2 + 3 * width), dtype=np.uint64)
        grid[:, 0] = word(b"f")
        for k in range(3):
            at = 1 + k * width
            grid[:, at : at + wv] = gather(v_text, c[:, k] - first)
            if wt:
                grid[:, at + wv : at + wv + wt] = gather(vt_text, vt[lo:hi, k] + 1)
            grid[:, at + wv + wt : at + width] = vn
        grid[:, -1] = word(b"\n")
        return render(grid)

    stream.write(f"# bgr seed {seed}\nmtllib {mtl_name}\n".encode())
    _Blocks(len(nfirst), lambda lo, hi: _point_lines(b"vn ", nq[nfirst[lo:hi]])).write(
        stream, 0, len(nfirst)
    )
    _Blocks(len(tq), lambda lo, hi: _point_lines(b"vt ", tq[lo:hi])).write(stream, 0, len(tq))
    v_lines = _Blocks(len(vpos), lambda lo, hi: _point_lines(b"v ", vpos[lo:hi]))
    f_blocks = _Blocks(len(corners), f_lines)
    groups, materials = unique_names(labels), obj_names(mats)
    keys = np.stack([lot_of[rows], label_of[rows], mats.index[rows]])
    current = (-1, -1)
    for obj, label, mat, lo, hi in runs(keys, baked.fstart):
        if obj != current[0]:
            stream.write(f"o {objects[obj]}\n".encode())
            v_lines.write(stream, int(v_end[obj - 1]) if obj else 0, int(v_end[obj]))
        if (obj, label) != current:
            stream.write(f"g {groups[label]}\n".encode())
        current = (obj, label)
        stream.write(f"usemtl {materials[mat]}\n".encode())
        f_blocks.write(stream, lo, hi)
    alpha = {image.path: image.alpha for image in table.images}
    mtl.write(mtl_text(mats, materials, maps, textures.names if textures else {}, alpha))


def texture_corners(
    table: TerminalTable, rows: np.ndarray, pool: MeshPool, baked: Baked
) -> tuple[np.ndarray, np.ndarray]:
    """(each face corner's vt number, -1 for none; the distinct uvs quantized, in the order
    the file lists them) of the faces of ``rows`` as baked.  v runs up the image (OBJ's way,
    and CGA's)."""
    corners = np.full((len(baked.faces), 3), -1, dtype=np.int64)
    if not table.textured():
        return corners, np.zeros((0, 2), dtype=np.int64)
    textured = np.zeros(len(table), dtype=bool)
    textured[table.tex_rows] = True
    mine = textured[rows]
    uq = quantize(baked_uvs(table, rows[mine], pool).reshape(-1, 2))
    tid, tfirst = number_rows([uq[:, 0], uq[:, 1]])
    corners[np.repeat(mine, np.diff(baked.fstart))] = tid.reshape(-1, 3)
    return corners, uq[tfirst]


def mtl_text(
    mats: Materials,
    names: list[str],
    maps: list[tuple[str | None, str | None]] | None = None,
    files: dict[str, str] | None = None,
    alpha: dict[str, bool] | None = None,
) -> bytes:
    """The .mtl: each material's sRGB colour as ``Kd``, no ambient light, no specular light
    unless the grammar set it (``Ks``, ``Ns`` and ``illum 2``: set(material.specular.*,
    shininess)); a
    textured material (``maps``: its colour and normal map paths) names its images by their
    copies' paths (``files``): ``map_Kd`` the colour map, ``map_d`` it again when it has alpha
    (its opacity), ``map_Bump`` and ``bump`` the normal map."""
    lines = ["# bgr materials"]
    for k, name in enumerate(names):
        r, g, b = (c / 255.0 for c in mats.rgb8[k])
        values = mats.surface(k)
        opacity, metallic, roughness = values[:3]
        sr, sg, sb = values[3:6]
        specular = values[3:7] != DEFAULTS[3:7]  # set(material.specular.*, shininess)
        lines += [
            f"newmtl {name}",
            f"Kd {r:.6g} {g:.6g} {b:.6g}",
            "Ka 0 0 0",
            f"Ks {sr:.6g} {sg:.6g} {sb:.6g}",
            f"d {opacity:.6g}",
            "illum 2" if specular else "illum 1",  # 2: with the specular highlight
        ]
        if specular:
            lines.append(f"Ns {values[6]:.6g}")
        if values != DEFAULTS:  # set(material.*): the PBR extension's
            lines += [f"Pm {metallic:.6g}", f"Pr {roughness:.6g}"]
        color, normal = maps[k] if maps else (None, None)
        if color is not None and files:
            lines.append(f"map_Kd {files[color]}")
            if alpha and alpha.get(color):
                lines.append(f"map_d {files[color]}")
        if normal is not None and files:
            lines += [f"map_Bump {files[normal]}", f"bump {files[normal]}"]
        lines.append("")
    return "\n".join(lines).encode("utf-8")
