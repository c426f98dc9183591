"""comp(f) { side = A }: CGA's ``=`` operator, all the faces a selector takes as one shape.

The faces are kept where they are, as one mesh (named ``polygon``, so a comp(f) of it gives
them back one by one, in the order they were taken); the shape's scope keeps the solid's axes
and becomes the box of those faces along them.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..geometry.meshes import flat_mesh
from ..shapes import Solid
from ..terminals import UnitMesh


def combined_faces(app, shape, faces: list, face_shapes: list):
    """One shape holding ``face_shapes`` (the 2D shapes of the faces taken), in the axes of
    ``shape``, the solid they were taken from."""
    points, triangles, count = [], [], 0
    axes = np.asarray(shape.axes, dtype=float)  # rows: the scope's axes in the world
    origin = np.asarray(shape.origin, dtype=float)
    for face in face_shapes:
        unit, tris = flat_mesh(face.geom.polys, 2)
        local = unit * np.asarray(face.size, dtype=float)
        world = np.asarray(face.origin) + local @ np.asarray(face.axes, dtype=float)
        points.append((world - origin) @ axes.T)  # in the solid's scope, in metres
        triangles.append(tris + count)
        count += len(unit)
    metres = np.vstack(points)
    low, high = metres.min(axis=0), metres.max(axis=0)
    size = high - low
    unit = (metres - low) / np.where(size > 1e-12, size, 1.0)
    mesh = UnitMesh("polygon", unit, np.vstack(triangles).astype(np.int32))
    piece = shape.copy().cut_from(shape)
    piece.origin = shape.world(low.tolist())
    piece.size = [float(s) for s in size]
    piece.geom = Solid(app.engine.table.library.add(mesh), "polygon")
    if piece.trims is not None:  # the faces' own planes are not carried over
        piece.trims = replace(piece.trims, planes=())
    return piece
