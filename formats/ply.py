"""Binary little-endian .ply: shared vertices with a normal and a colour each, and the triangles.

Each vertex carries ``x y z`` (double: geographic lots sit far from the origin), ``nx ny nz``
(float, the unit face normal, pointing out as the winding says) and ``red green blue`` (uchar,
the terminal's sRGB colour).  Faces are flat shaded and coloured per terminal, so a vertex is
shared by the triangles that meet at one position with one normal and one colour: the triangles
of one planar face, and of neighbouring terminals in one plane and one colour.  Positions and
normals count as equal when they round to the same micrometre (and millionth), as in the OBJ.
"""

from __future__ import annotations

from typing import BinaryIO

import numpy as np

from bgr.interpreter.terminals import TerminalTable

from .materials import materials_of
from .meshes import bake, srgb8, unit_normals
from .placement import to_site
from .sharing import number_rows
from .text import quantize

VERTEX = np.dtype(
    [
        ("x", "<f8"),
        ("y", "<f8"),
        ("z", "<f8"),
        ("nx", "<f4"),
        ("ny", "<f4"),
        ("nz", "<f4"),
        ("red", "u1"),
        ("green", "u1"),
        ("blue", "u1"),
    ]
)
FACE = np.dtype([("count", "u1"), ("vertex_indices", "<i4", (3,))])
_TYPES = {"<f8": "double", "<f4": "float", "|u1": "uchar"}


def header(vertices: int, faces: int, seed: int) -> bytes:
    lines = ["ply", "format binary_little_endian 1.0", f"comment bgr seed {seed}"]
    lines.append(f"element vertex {vertices}")
    lines += [f"property {_TYPES[VERTEX[name].str]} {name}" for name in VERTEX.fields or ()]
    lines += [f"element face {faces}", "property list uchar int vertex_indices", "end_header"]
    return ("\n".join(lines) + "\n").encode("ascii")


def write_ply(table: TerminalTable, stream: BinaryIO, *, seed: int, attrs: dict) -> None:
    """Write the terminals as one binary PLY mesh to ``stream``."""
    table.freeze()
    baked = bake(table)
    baked.vertices = to_site(baked.vertices, table.site)  # the input's frame, if any
    nf = np.diff(baked.fstart)
    normals = unit_normals(np.take(baked.vertices, baked.faces, axis=0))
    nq = quantize(normals)
    normal_id, _ = number_rows([nq[:, 0], nq[:, 1], nq[:, 2]])
    colour_id = np.repeat(materials_of(table).index, nf)
    vq = quantize(baked.vertices)
    position_id, _ = number_rows([vq[:, 0], vq[:, 1], vq[:, 2]])

    # a vertex per distinct (position, normal, colour) among the triangles' corners
    corner_face = np.repeat(np.arange(len(baked.faces)), 3)
    corner_id, first = number_rows(
        [position_id[baked.faces.reshape(-1)], normal_id[corner_face], colour_id[corner_face]]
    )
    face_of_first = corner_face[first]
    out = np.empty(len(first), dtype=VERTEX)
    at = np.take(baked.vertices, baked.faces.reshape(-1)[first], axis=0)
    out["x"], out["y"], out["z"] = at[:, 0], at[:, 1], at[:, 2]
    n = np.take(normals, face_of_first, axis=0).astype(np.float32) + np.float32(0.0)  # no -0.0
    out["nx"], out["ny"], out["nz"] = n[:, 0], n[:, 1], n[:, 2]
    rgb = np.take(srgb8(table), np.repeat(np.arange(len(table)), nf)[face_of_first], axis=0)
    out["red"], out["green"], out["blue"] = rgb[:, 0], rgb[:, 1], rgb[:, 2]
    faces = np.empty(len(baked.faces), dtype=FACE)
    faces["count"] = 3
    faces["vertex_indices"] = corner_id.reshape(-1, 3)

    stream.write(header(len(out), len(faces), seed))
    stream.write(out.view(np.uint8).data)  # the records' bytes, not a copy
    stream.write(faces.view(np.uint8).data)
