"""roof(kind, pitch, overhang): a roof mesh on a 2D footprint, from the geometry package."""

from __future__ import annotations

import numpy as np

from ..expressions import runtime_error
from ..geometry.meshes import PLANE_AXES, clip_below
from ..geometry.polygons import RECT, UNIT_SQUARE, metric
from ..geometry.rect_roofs import rectangle_hip
from ..geometry.skeleton import SkeletonError
from ..shapes import Flat, Solid
from ..terminals import UnitMesh


def roof(app, shape, step, args) -> bool:
    kind, pitch, overhang = args[0], args[1], args[2]
    geom = shape.geom
    if not isinstance(geom, Flat):
        raise runtime_error(
            app.module,
            step.pos,
            "roof() needs a 2D footprint",
            "use it on a lot or on the top face from comp(f)",
        )
    for what, value in (("pitch", pitch), ("overhang", overhang)):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise runtime_error(
                app.module, step.pos, f"the roof's {what} must be a number, got {value!r}"
            )
    if kind != "flat" and not 0 < pitch < 90:
        raise runtime_error(
            app.module, step.pos, f"a roof pitch must lie between 0 and 90 degrees, got {pitch:g}"
        )
    if overhang < 0:
        raise runtime_error(
            app.module, step.pos, f"a negative overhang ({overhang:g}) is not a roof"
        )
    from .components import _into_extrusion_frame

    if geom.k != 1:
        # a roof stands up from its face as an extrusion does: y along the face's normal, x kept
        # (CGA's frame), so that comp(f) of the roof finds its slopes and gable ends upright
        geom, _ = _into_extrusion_frame(app, step, shape, "face.normal", 0.0)
    k = geom.k
    p, q = PLANE_AXES[k]
    widest = max(shape.size[p], shape.size[q])
    if overhang > 10 * widest:  # past this, float error eats the roof (and no roof is built so)
        raise runtime_error(
            app.module,
            step.pos,
            f"an overhang of {overhang:g} m is more than ten times the footprint ({widest:g} m)",
            "an overhang is the eaves' reach past the walls, usually under 2 m",
        )
    polys = [(UNIT_SQUARE, ())] if geom.polys == RECT else geom.polys
    verts, faces = [], []
    base = 0
    if geom.polys == RECT and kind == "hip":  # the common case, in closed form
        v, f = rectangle_hip(shape.size[p], shape.size[q], float(pitch), float(overhang))
        verts.append(v)
        faces.append(f)
        polys = []
    for ext, holes in metric(polys, shape.size[p], shape.size[q]):
        # a flat roof leaves holes (courtyards) open; the skeleton kinds roof them over
        holes = [np.asarray(h, dtype=float) for h in holes]
        m = _mesh(
            app, step, np.asarray(ext, dtype=float), kind, float(pitch), float(overhang), holes
        )
        walls = np.array([m.planes[i].kind in ("gable", "wall") for i in m.face_plane], dtype=bool)
        m_vertices, m_faces = (
            clip_below(m.vertices, m.faces, walls)
            if walls.any()
            else (
                m.vertices,
                m.faces,
            )
        )
        verts.append(m_vertices)
        faces.append(m_faces + base)
        base += len(m_vertices)
    local = np.vstack(verts)
    tris = np.vstack(faces)
    # face-local (plane p, plane q, up) -> scope axes; an odd permutation flips the winding
    scoped = np.zeros_like(local)
    scoped[:, p], scoped[:, q], scoped[:, k] = local[:, 0], local[:, 1], local[:, 2]
    if (p, q, k) in ((0, 2, 1), (2, 1, 0), (1, 0, 2)):
        tris = tris[:, ::-1]
    if not len(scoped):
        raise runtime_error(
            app.module, step.pos, f"the {kind} roof on this footprint has no faces left"
        )
    lo, hi = scoped.min(axis=0), scoped.max(axis=0)
    extent = hi - lo
    unit = (scoped - lo) / np.where(extent > 0, extent, 1.0)
    shape.origin = shape.world(lo.tolist())
    shape.size = extent.tolist()
    shape.geom = Solid(app.engine.table.library.add(UnitMesh("roof", unit, tris)), "roof")
    return False


def _mesh(app, step, polygon: np.ndarray, kind: str, pitch: float, overhang: float, holes=()):
    """The roof mesh, or a located error for a footprint the builder cannot use (not simple,
    degenerate).  Where the kind asked for could not be built and another was (a gable whose
    ends failed), or the straight skeleton gave up on a footprint (it should not; a flat roof
    then stands in), the run goes on with a warning that names the lot and the grammar's place.
    """
    from ..geometry.roofs import roof_mesh

    try:
        mesh = roof_mesh(polygon, kind, pitch, overhang, holes)
    except ValueError as e:
        raise runtime_error(
            app.module, step.pos, f"cannot build a {kind} roof on this footprint: {e}"
        ) from None
    except SkeletonError as e:
        app.engine.warn(
            app.module, step.pos, f"cannot build a {kind} roof on this footprint ({e}); built flat"
        )
        return roof_mesh(polygon, "flat", pitch, overhang, holes)
    if mesh.fallback:
        app.engine.warn(
            app.module,
            step.pos,
            f"{mesh.fallback}: built a {mesh.kind} roof instead of a {kind} roof",
        )
    return mesh
