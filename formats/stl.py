"""Binary .stl: triangles only (STL has no colours or materials)."""

from __future__ import annotations

from typing import BinaryIO

from bgr.interpreter.terminals import TerminalTable

from .meshes import bake


def write_stl(table: TerminalTable, stream: BinaryIO, *, seed: int, attrs: dict) -> None:
    import trimesh  # here, not at the top: importing it costs a second of every command's start
    from trimesh.exchange.stl import export_stl

    table.freeze()
    baked = bake(table)
    mesh = trimesh.Trimesh(baked.vertices, baked.faces, process=False)
    stream.write(export_stl(mesh))
