"""Materials of an output file: one per distinct (colour, material name) pair, in first-use order.

Colours are compared as the ``#rrggbb`` the terminal list writes, so two terminals that print the
same colour share a material.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from bgr.interpreter.surfaces import DEFAULTS, name_of, set_values, values_of
from bgr.interpreter.terminals import TerminalTable

from .meshes import srgb8


@dataclass
class Materials:
    index: np.ndarray  # (N,) material of each terminal
    rgb8: np.ndarray  # (K, 3) uint8 sRGB
    names: list[str | None]  # (K,) the material() name, or None
    labels: list[str]  # (K,) a display name, unique: the material name, else the colour hex
    # (K,) each one's set(material.*) values, in surfaces.ATTRIBUTES order
    values: list[tuple[float, ...]] = field(default_factory=list)

    def surface(self, k: int) -> tuple[float, ...]:
        return self.values[k] if self.values else DEFAULTS

    def __len__(self) -> int:
        return len(self.names)

    def hex(self, k: int) -> str:
        return "#" + "".join(f"{int(c):02x}" for c in self.rgb8[k])

    def linear(self, k: int) -> list[float]:
        """The colour in linear light (glTF's baseColorFactor), from its sRGB bytes."""
        return list(_linear(self.rgb8[k].astype(np.uint8, copy=False).tobytes()))


@functools.lru_cache(maxsize=4096)
def _linear(rgb: bytes) -> tuple[float, ...]:
    """:meth:`Materials.linear` of three sRGB bytes, worked out once per colour (a textured
    style writes a material per crop, thousands in a few colours)."""
    c = np.frombuffer(rgb, dtype=np.uint8).astype(np.float64) / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return tuple(round(float(v), 6) for v in lin)


def materials_of(table: TerminalTable) -> Materials:
    table.freeze()
    rgb = srgb8(table)
    packed = (rgb[:, 0].astype(np.int64) << 16) | (rgb[:, 1].astype(np.int64) << 8) | rgb[:, 2]
    name_ids = {name: i for i, name in enumerate(dict.fromkeys(table.material))}
    if len(name_ids) <= 1:
        names_col = np.zeros(len(table), dtype=np.int64)
    else:
        names_col = np.fromiter(
            map(name_ids.__getitem__, table.material), dtype=np.int64, count=len(table)
        )
    key = (names_col << 24) | packed
    uniq, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")  # materials in order of first use
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    index = rank[inverse.reshape(-1)]
    id_names = {i: n for n, i in name_ids.items()}
    materials = [id_names[int(uniq[k] >> 24)] for k in order]  # names, or Surfaces
    names = [name_of(m) for m in materials]
    values = [values_of(m) for m in materials]
    rgb8 = rgb[first[order]] if len(order) else np.zeros((0, 3), dtype=np.uint8)

    labels: list[str] = []
    colours_per_name: dict[str | None, int] = {}
    for n in names:
        colours_per_name[n] = colours_per_name.get(n, 0) + 1
    for k, n in enumerate(names):
        hx = "#" + "".join(f"{int(c):02x}" for c in rgb8[k])
        label = hx if n is None else (n if colours_per_name[n] == 1 else f"{n} {hx}")
        if values[k] != DEFAULTS:  # the same name and colour, other values: told apart
            label += " " + surface_text(values[k])
        labels.append(label)
    return Materials(
        index=index.astype(np.int64), rgb8=rgb8, names=names, labels=labels, values=values
    )


def surface_text(values: tuple[float, ...]) -> str:
    """``opacity 0.4 metallic 0 roughness 0.8``: the values a material label adds (and the
    others where they are set)."""
    return " ".join(f"{k} {v:g}" for k, v in set_values(values).items())
