"""The glTF file's materials and textures: which material each terminal gets, the ``materials``,
``textures``, ``images`` and ``samplers`` members, and the texture coordinates of textured
primitives.  Kept apart from :mod:`.glb` (the scene, its nodes and buffer) because this is the
one part of the file that depends on colours and images rather than geometry.

* one material per distinct (colour, material name) pair, and per textured pair one per distinct
  (colour map, normal map), in first-use order over the whole file (:class:`MaterialIndex`);
* a material with a colour map has ``baseColorTexture`` (and ``alphaMode`` BLEND when the image
  has alpha); one with a normal map ``normalTexture`` on TEXCOORD_1;
* a texture per image, all with one sampler that repeats (CGA's tiles run past 0..1).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from bgr.interpreter.surfaces import ATTRIBUTES, DEFAULTS
from bgr.interpreter.terminals import TerminalTable

from .materials import Materials, materials_of, surface_text
from .meshes import MeshPool, face_offsets
from .texcoords import corner_tangents, corner_uvs

SPECULAR = "KHR_materials_specular"  # a material with set(material.specular.*)
LINEAR, REPEAT = 9729, 10497


class MaterialIndex:
    """The file's materials, in first-use order over every part added: each part's
    :class:`Materials` gets the file's material numbers as its ``index``."""

    def __init__(self) -> None:
        self.numbers: dict[tuple, int] = {}
        self.names: list[str | None] = []
        self.rgb8: list[np.ndarray] = []
        self.values: list[tuple[float, ...]] = []  # set(material.*): surfaces.ATTRIBUTES
        # per material: (colour map, normal map) image paths, None for none (texcoords.py)
        self.textures: list[tuple[str | None, str | None]] = []

    def __len__(self) -> int:
        return len(self.names)

    def of(self, table: TerminalTable) -> Materials:
        local = materials_of(table)
        number = np.empty(len(local), dtype=np.int64)
        for k, name in enumerate(local.names):
            key = (name, *(int(c) for c in local.rgb8[k]), local.surface(k))
            if key not in self.numbers:
                self.numbers[key] = len(self.names)
                self.names.append(name)
                self.rgb8.append(local.rgb8[k])
                self.values.append(local.surface(k))
                self.textures.append((None, None))
            number[k] = self.numbers[key]
        local.index = number[local.index] if len(local.index) else local.index
        if len(table.tex_rows):  # a textured terminal's material also names its images
            self._textured(table, local)
        return local

    def _textured(self, table: TerminalTable, local: Materials) -> None:
        """Give the textured rows the materials of their (colour, name, colour map, normal
        map), numbered in first-use order: a Python step per distinct combination, not per
        row."""
        rows = np.asarray(table.tex_rows, dtype=np.int64)
        maps = np.asarray(table.tex_maps, dtype=np.int64).reshape(-1, 2) + 1  # 0: none
        n_images = len(table.images) + 1
        code = (local.index[rows] * n_images + maps[:, 0]) * n_images + maps[:, 1]
        combos, first, inverse = np.unique(code, return_index=True, return_inverse=True)
        number = np.empty(len(combos), dtype=np.int64)
        paths = [None, *(image.path for image in table.images)]
        for j in np.argsort(first, kind="stable").tolist():  # in order of first use
            row = int(first[j])
            k = int(local.index[rows[row]])
            images = (paths[int(maps[row, 0])], paths[int(maps[row, 1])])
            key = (self.names[k], *(int(c) for c in self.rgb8[k]), self.values[k], *images)
            if key not in self.numbers:
                self.numbers[key] = len(self.names)
                self.names.append(self.names[k])
                self.rgb8.append(self.rgb8[k])
                self.values.append(self.values[k])
                self.textures.append(images)
            number[j] = self.numbers[key]
        local.index[rows] = number[inverse.reshape(-1)]

    def all(self) -> Materials:
        """Every material so far, with its display label (which needs all of them)."""
        rgb8 = np.array(self.rgb8, dtype=np.uint8).reshape(-1, 3)
        per_name: dict[str | None, int] = {}
        for n in self.names:
            per_name[n] = per_name.get(n, 0) + 1
        labels = []
        for k, n in enumerate(self.names):
            hx = "#" + "".join(f"{int(c):02x}" for c in rgb8[k])
            label = hx if n is None else (n if per_name[n] == 1 else f"{n} {hx}")
            if self.textures[k] != (None, None):  # the image's file name tells them apart
                label += " " + " ".join(p.rsplit("/", 1)[-1] for p in self.textures[k] if p)
            if self.values[k] != DEFAULTS:
                label += " " + surface_text(self.values[k])
            labels.append(label)
        return Materials(np.zeros(0, np.int64), rgb8, list(self.names), labels, list(self.values))

    def extensions(self) -> list[str]:
        """The glTF extensions the materials use (for ``extensionsUsed``)."""
        return [SPECULAR] if any(v[3:6] != DEFAULTS[3:6] for v in self.values) else []

    def members(self, images: dict[str, int], alpha: dict[str, bool]) -> list[dict]:
        """The ``materials`` member: PBR, the colour in linear light, its maps as textures
        (``images``: an image path's texture number; ``alpha``: whether it has alpha)."""
        mats = self.all()
        materials: list[dict] = [
            {
                "name": mats.labels[k],
                "pbrMetallicRoughness": {
                    "baseColorFactor": mats.linear(k) + [mats.surface(k)[0]],
                    "metallicFactor": mats.surface(k)[1],
                    "roughnessFactor": mats.surface(k)[2],
                },
                "doubleSided": True,
                "extras": {"color": mats.hex(k), "material": mats.names[k]},
            }
            for k in range(len(mats))
        ]
        for k, material in enumerate(materials):
            values = mats.surface(k)
            if values[0] < 1.0:  # set(material.opacity, ...): seen through
                material["alphaMode"] = "BLEND"
            if values[3:6] != DEFAULTS[3:6]:  # set(material.specular.*)
                material["extensions"] = {SPECULAR: {"specularColorFactor": list(values[3:6])}}
            for i in (6, 7):  # shininess, reflectivity: glTF has no word for them
                if values[i] != DEFAULTS[i]:
                    material["extras"][ATTRIBUTES[i]] = values[i]
        for k, (color, normal) in enumerate(self.textures):
            if color is not None:
                pbr: dict = materials[k]["pbrMetallicRoughness"]
                pbr["baseColorTexture"] = {"index": images[color]}
                if alpha.get(color):
                    materials[k]["alphaMode"] = "BLEND"
            if normal is not None:
                materials[k]["normalTexture"] = {"index": images[normal], "texCoord": 1}
        return materials


def image_members(image_views: list[tuple[int, str]]) -> list[tuple[str, list[dict]]]:
    """The ``textures``, ``images`` and ``samplers`` members, in that order: a texture per
    image (``image_views``: its bufferView and mimeType), all with one repeating sampler."""
    return [
        ("textures", [{"sampler": 0, "source": k} for k in range(len(image_views))]),
        ("images", [{"bufferView": v, "mimeType": m} for v, m in image_views]),
        (
            "samplers",
            [{"magFilter": LINEAR, "minFilter": LINEAR, "wrapS": REPEAT, "wrapT": REPEAT}],
        ),
    ]


@dataclass
class UvSets:
    """The texture coordinates of one part's textured primitives: per set (0: the colour map's,
    TEXCOORD_0; 1: the normal map's, TEXCOORD_1) the rows that need it in file order, where
    each row's first corner sits in the set's block, and the block once filled."""

    rows: list[list[int]]
    at: list[dict[int, int]]
    corners: list[int]
    blocks: list[tuple[int, np.ndarray]] = field(default_factory=list)

    @classmethod
    def of(
        cls,
        table: TerminalTable,
        baked: np.ndarray,
        mats: Materials,
        textures: list[tuple[str | None, str | None]],
        pool: MeshPool,
    ) -> UvSets:
        index = np.asarray(mats.index, dtype=np.int64)
        baked = np.asarray(baked, dtype=np.int64)
        textured = np.array([t != (None, None) for t in textures] + [False], dtype=bool)
        has_normal = np.array([t[1] is not None for t in textures] + [False], dtype=bool)
        uv_rows = baked[textured[index[baked]]] if len(table.tex_rows) else baked[:0]
        normal_rows = uv_rows[has_normal[index[uv_rows]]]
        rows, at, corners = [], [], []
        for chosen in (uv_rows, normal_rows):
            starts = 3 * face_offsets(table, chosen, pool)
            rows.append(chosen.tolist())
            at.append(dict(zip(rows[-1], starts[:-1].tolist(), strict=True)))
            corners.append(int(starts[-1]))
        return cls(rows, at, corners)

    @property
    def nbytes(self) -> int:
        # and a TANGENT per normal-mapped corner
        return 8 * sum(self.corners) + 16 * self.corners[1]

    def fill(self, block, table: TerminalTable, pool: MeshPool) -> None:
        """Reserve each used set's block (``block(count, 2)`` of the file's builder) and write
        its coordinates."""
        for which, chosen in enumerate(self.rows):
            if chosen:
                start, data = block(self.corners[which], 2)
                data[:] = corner_uvs(table, np.asarray(chosen), pool, which)
                self.blocks.append((start, data))
            else:
                self.blocks.append((0, np.zeros((0, 2), np.float32)))
        if self.rows[1]:  # filled by tangents() once the corners are placed
            self.blocks.append(block(self.corners[1], 4))

    def tangents(self, table, baked, fstart, positions, normals, pool: MeshPool) -> None:
        """The TANGENT of every normal-mapped corner, from its placed triangle (``positions``
        and ``normals``: the part's baked corners, whose rows ``baked`` start at ``fstart``)."""
        if not self.rows[1]:
            return
        at_row = np.empty(len(table), dtype=np.int64)
        at_row[baked] = np.arange(len(baked))
        nr = np.asarray(self.rows[1], dtype=np.int64)
        count = 3 * pool.fcount[table.mesh[nr]]
        corner = np.repeat(3 * fstart[at_row[nr]] - np.cumsum(count) + count, count)
        corner += np.arange(int(count.sum()))
        uv1 = self.blocks[1][1]
        self.blocks[2][1][:] = corner_tangents(positions[corner], normals[corner], uv1)

    def attributes(self, row: int, count: int, accessor) -> dict[str, int]:
        """TEXCOORD_0 / TEXCOORD_1 of a primitive whose rows start at ``row`` and that has
        ``count`` corners (a textured material's rows are consecutive), as ``accessor(start,
        data)`` of the file's builder makes them."""
        out: dict[str, int] = {}
        for which in (0, 1):
            first = self.at[which].get(row)
            if first is not None:
                start, data = self.blocks[which]
                out[f"TEXCOORD_{which}"] = accessor(start + first * 8, data[first : first + count])
                if which == 1:
                    start, data = self.blocks[2]
                    out["TANGENT"] = accessor(start + first * 16, data[first : first + count])
        return out
