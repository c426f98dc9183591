"""CityJSON 2.0's ``appearance``: the colours of bgr's terminals as ``materials`` and their
colour maps as ``textures``, on every triangle surface that has one (:mod:`.cityjson` writes
the geometry; this module adds what it looks like).

- **One theme, ``bgr``**, the default for both (``default-theme-material`` and
  ``default-theme-texture``): a reader that picks the default theme sees bgr's look.
- **materials**: one per distinct (colour, material name), as the OBJ and GLB writers make
  them, named like them, ``diffuseColor`` the sRGB colour in 0..1 (as OBJ's ``Kd``; CityGML's
  X3DMaterial takes the colour as given).  A geometry whose surfaces share one material says
  ``"value"``, else ``"values"`` per surface.
- **textures**: one per distinct colour-map image, ``type`` PNG or JPG, ``image`` the relative
  path of its copy beside the file (:mod:`.texture_files`), ``wrapMode`` "wrap" (CGA's tiles run
  past 0..1); ``vertices-texture`` every distinct (u, v) once, six decimals, v up the image (v 0
  at its bottom, as CityGML and CGA have it).  A textured triangle's ``texture`` value is
  ``[[texture, a, b, c]]`` (its one ring: the texture, then a texture vertex per corner in the
  order of its boundary); an untextured one's ``[[null]]``.  A geometry without any textured
  triangle has no ``texture`` member.  Normal maps have no place in CityJSON: they are left out.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from bgr.interpreter.terminals import TerminalTable

from .materials import materials_of
from .meshes import MeshPool, face_offsets
from .sharing import number_rows
from .texcoords import baked_uvs
from .text import decimal, quantize, render, word
from .texture_files import Copies

THEME = "bgr"
TYPES = {"image/png": "PNG", "image/jpeg": "JPG"}


def _dumps(value) -> str:
    return json.dumps(value, ensure_ascii=False, allow_nan=False, separators=(",", ":"))


@dataclass
class Appearance:
    """The document's appearance, and per triangle (of :class:`.cityjson.Triangles`) its
    material and its texture (-1: none) with its corners' texture vertices."""

    member: dict  # the ``appearance`` member, without vertices-texture (written as text)
    uv: np.ndarray  # (U, 2) int64: the distinct texture vertices, quantized (text.quantize)
    material: np.ndarray  # (T,) material of each triangle
    texture: np.ndarray  # (T,) texture of each triangle, -1 for none
    corners: np.ndarray  # (T, 3) texture vertex of each corner (-1 where untextured)

    @classmethod
    def of(
        cls, table: TerminalTable, row: np.ndarray, face: np.ndarray, copies: Copies | None
    ) -> Appearance:
        """``row`` and ``face``: each written triangle's terminal and its index among the
        table's baked triangles (:func:`.meshes.bake` of every row, in order)."""
        mats = materials_of(table)
        member: dict = {
            "materials": [
                {"name": mats.labels[k], "diffuseColor": [round(c / 255, 6) for c in rgb.tolist()]}
                for k, rgb in enumerate(mats.rgb8)
            ]
        }
        T = len(row)
        texture = np.full(T, -1, dtype=np.int64)
        corners = np.full((T, 3), -1, dtype=np.int64)
        uv = np.zeros((0, 2), dtype=np.int64)
        maps = np.asarray(table.tex_maps).reshape(-1, 2)
        coloured = maps[:, 0] >= 0
        if copies is not None and coloured.any():
            images = np.unique(maps[coloured, 0]).tolist()
            number = np.full(len(table.images), -1, dtype=np.int64)
            number[images] = np.arange(len(images))
            member["textures"] = [
                {
                    "type": TYPES.get(table.images[k].mime, "PNG"),
                    "image": copies.names[table.images[k].path],
                    "wrapMode": "wrap",
                }
                for k in images
            ]
            tex_of_row = np.full(len(table), -1, dtype=np.int64)
            rows = np.asarray(table.tex_rows)[coloured]
            tex_of_row[rows] = number[maps[coloured, 0]]
            texture = tex_of_row[row]
            # every baked triangle of the coloured rows: its uvs, then those of the written ones
            pool = MeshPool.of(table)
            fstart = face_offsets(table, np.arange(len(table)), pool)
            order = np.argsort(rows, kind="stable")
            rows = rows[order]
            nf = np.diff(fstart)[rows]
            faces = np.repeat(fstart[rows] - (np.cumsum(nf) - nf), nf) + np.arange(int(nf.sum()))
            slot = np.full(int(fstart[-1]), -1, dtype=np.int64)
            slot[faces] = np.arange(len(faces))
            uvq = quantize(baked_uvs(table, rows, pool))  # (F, 3, 2)
            mine = texture >= 0
            written = uvq[slot[face[mine]]].reshape(-1, 2)
            ids, first = number_rows([written[:, 0], written[:, 1]])
            corners[mine] = ids.reshape(-1, 3)
            uv = written[first]
            member["default-theme-texture"] = THEME
        member["default-theme-material"] = THEME
        return cls(member, uv, mats.index[row], texture, corners)

    def geometry_text(self, triangles: np.ndarray) -> str:
        """The ``material`` and ``texture`` members (text, starting with a comma) of a
        MultiSurface whose surfaces are the given triangles."""
        mat = self.material[triangles]
        if len(mat) and (mat == mat[0]).all():
            text = f',"material":{{"{THEME}":{{"value":{int(mat[0])}}}}}'
        else:
            text = f',"material":{{"{THEME}":{{"values":{_ints(mat[:, None], "%d")}}}}}'
        tex = self.texture[triangles]
        if not (tex >= 0).any():
            return text
        # printf in C for every surface, then an untextured one's -1s become [[null]]
        rows = np.column_stack([tex, self.corners[triangles]])
        values = _ints(rows, "[[%d,%d,%d,%d]]").replace("[[-1,-1,-1,-1]]", "[[null]]")
        return text + f',"texture":{{"{THEME}":{{"values":{values}}}}}'

    def text(self) -> str:
        """The ``appearance`` member's text (starting with a comma); its vertices-texture
        written in bulk from the quantized integers, six decimals (:mod:`.text`)."""
        body = _dumps(self.member)
        if "textures" not in self.member:
            return f',"appearance":{body}'
        return f',"appearance":{body[:-1]},"vertices-texture":{_pairs(self.uv)}}}'


def _ints(rows: np.ndarray, pattern: str) -> str:
    """A JSON array of integer rows, each written by ``pattern``: printf formatting in C."""
    if not len(rows):
        return "[]"
    return "[" + ((pattern + ",") * len(rows) % tuple(rows.ravel().tolist()))[:-1] + "]"


def _pairs(q: np.ndarray) -> str:
    """``[[u,v],...]`` of (n, 2) quantized numbers (:func:`.text.quantize`), as the OBJ writer
    formats its ``vt``: a grid of words, no Python call per number."""
    if not len(q):
        return "[]"
    (wu, fu), (wv, fv) = decimal(q[:, 0], b"["), decimal(q[:, 1], b",")
    grid = np.empty((len(q), wu.shape[1] + wv.shape[1] + 3), dtype=np.uint64)
    a, b = wu.shape[1], wu.shape[1] + 1 + wv.shape[1]
    grid[:, :a], grid[:, a], grid[:, a + 1 : b], grid[:, b] = wu, fu, wv, fv
    grid[:, -1] = word(b"],")
    return "[" + render(grid)[:-1].decode("ascii") + "]"
