"""Binary little-endian .ply: every terminal's vertices with its sRGB colour, and the triangles."""

from __future__ import annotations

from typing import Any, BinaryIO

import numpy as np
import trimesh
from trimesh.exchange.ply import export_ply

from bgr.interpreter.terminals import TerminalTable

from .meshes import bake, srgb8


def write_ply(table: TerminalTable, stream: BinaryIO, *, seed: int, attrs: dict) -> None:
    table.freeze()
    baked = bake(table)
    rgba = np.full((len(baked.vertices), 4), 255, dtype=np.uint8)
    rgba[:, :3] = np.repeat(srgb8(table), np.diff(baked.vstart), axis=0)
    # trimesh cannot export 0 coloured vertices
    colours: dict[str, Any] = {"vertex_colors": rgba} if len(rgba) else {}
    mesh = trimesh.Trimesh(baked.vertices, baked.faces, process=False, **colours)
    stream.write(export_ply(mesh, encoding="binary", vertex_normal=False, include_attributes=False))
