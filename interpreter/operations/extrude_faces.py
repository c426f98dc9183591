"""extrude() of a solid: each of its faces extruded along its own normal, as CGA extrudes every
face of the geometry.  The prisms make one mesh; the scope keeps its axes and becomes their
bounding box (a solid named "extrusion": comp(f) takes its planar faces apart)."""

from __future__ import annotations

import numpy as np

from ..geometry.meshes import prism_mesh
from ..geometry.polygons import normalise as normalise_polys
from ..shapes import Solid, cross
from ..terminals import UnitMesh


def extrude_faces(app, shape, faces: list, height: float) -> None:
    """``faces``: (rings in scope metres, outward normal in the scope) of the shape's faces."""
    verts_all, tris_all, base = [], [], 0
    for rings, normal in faces:
        nrm = np.asarray(normal, dtype=np.float64)
        first = np.asarray(rings[0], dtype=np.float64)
        e1 = first[1] - first[0]
        e1 -= nrm * float(e1 @ nrm)
        if float(np.linalg.norm(e1)) < 1e-12:
            continue
        e1 /= np.linalg.norm(e1)
        e2 = np.asarray(cross(e1, nrm))  # (e1, normal, e2) right-handed, as a prism's (x, y, z)
        origin = first[0]
        flat = [
            [((np.asarray(p) - origin) @ e1, (np.asarray(p) - origin) @ e2) for p in ring]
            for ring in rings
        ]
        unit, (u0, v0, w, d) = normalise_polys([(tuple(flat[0]), tuple(map(tuple, flat[1:])))])
        if w <= 0 or d <= 0:
            continue
        verts, tris = prism_mesh(unit, 1)
        metres = (
            origin
            + np.outer(u0 + verts[:, 0] * w, e1)
            + np.outer(verts[:, 1] * height, nrm)
            + np.outer(v0 + verts[:, 2] * d, e2)
        )
        if height < 0:  # extruded against the normal: the prism is mirrored, so turn it round
            tris = tris[:, ::-1]
        verts_all.append(metres)
        tris_all.append(tris + base)
        base += len(metres)
    if not verts_all:
        return
    metres = np.vstack(verts_all)
    low, high = metres.min(axis=0), metres.max(axis=0)
    size = high - low
    unit = np.divide(metres - low, size, out=np.zeros_like(metres), where=size > 1e-12)
    mesh_id = app.engine.table.library.add(UnitMesh("extrusion", unit, np.vstack(tris_all)))
    shape.origin = shape.world(tuple(float(v) for v in low))
    shape.size = [float(s) for s in size]
    shape.geom = Solid(mesh_id, "extrusion")
