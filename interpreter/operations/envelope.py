"""envelope(): CGA's building envelope, the volume a zoning code allows above a lot.

The 2D shape is erected along its normal (or world y) to ``maxHeight``; each edge of its outline
is front, back, left or right by its outward normal in the scope's quadrants (as setback's, a
lot's street edge is front), and the volume is cut by a plane through that edge at the side's
base height, rising inward at the side's angle from the horizontal (90 degrees: a plain wall).
The cuts close the solid again, so it derives on like an extrusion: comp(f) takes its faces
apart and split() cuts it into slabs.

The arguments follow CGA's forms: (maxHeight, front), (.., front, back), (.., front, back,
sides) and (.., front, back, right, left), each side a base height and an angle.
"""

from __future__ import annotations

import math

import numpy as np

from ..expressions import runtime_error
from ..geometry.meshes import prism_mesh
from ..geometry.polygons import RECT, UNIT_SQUARE
from ..geometry.setbacks import edge_kinds
from ..geometry.slicing import keep_side
from ..shapes import Solid
from ..terminals import UnitMesh
from .components import _into_extrusion_frame
from .trims import DELETED


def _sides(values: list[float]) -> dict[str, tuple[float, float]]:
    """(base height, angle) of each side from CGA's argument forms."""
    pairs = [(values[i], values[i + 1]) for i in range(0, len(values), 2)]
    front = pairs[0]
    back = pairs[1] if len(pairs) > 1 else front
    right = pairs[2] if len(pairs) > 2 else back
    left = pairs[3] if len(pairs) > 3 else right
    return {"front": front, "back": back, "right": right, "left": left}


def _number(app, step, value, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise runtime_error(
            app.module, step.pos, f"envelope() needs a finite number for {what}, got {value!r}"
        )
    return float(value)


def envelope(app, shape, step, args):
    direction = args[0]
    values = [_number(app, step, v, "each height and angle") for v in args[1 : len(step.args)]]
    if len(values) % 2 == 0:
        raise runtime_error(
            app.module,
            step.pos,
            "envelope() takes a maximum height, then a base height and an angle per side",
            "envelope(world.up, 30, 10, 45) or envelope(world.up, 30, 10, 45, 6, 60)",
        )
    top, sides = values[0], _sides(values[1:])
    if top <= 0:
        return DELETED
    flat, heights = _into_extrusion_frame(app, step, shape, direction, top)
    if heights is not None:
        raise runtime_error(
            app.module,
            step.pos,
            "envelope(world.up) of a sloped face is not supported",
            "erect it along the face's normal: envelope(face.normal, ...)",
        )
    sx, sz = shape.size[0], shape.size[2]
    verts, faces = prism_mesh(flat.polys, 1)
    metres = verts * np.array([sx, top, sz])
    planes = []
    polys = [(UNIT_SQUARE, ())] if flat.polys == RECT else flat.polys
    for (a, b), kind in edge_kinds(polys, sx, sz, 0, 2):
        base, angle = sides[kind if kind in sides else "front"]
        if angle >= 90.0 - 1e-9:
            continue  # a plain wall: the prism's own
        along = np.array([b[0] - a[0], b[1] - a[1]]) / math.hypot(b[0] - a[0], b[1] - a[1])
        inward = np.array([-along[1], along[0]])  # the outline runs counter-clockwise
        slope = math.tan(math.radians(min(max(angle, 0.0), 90.0 - 1e-6)))
        normal = np.array([slope * inward[0], -1.0, slope * inward[1]])
        planes.append((normal, np.array([a[0], base, a[1]])))
    verts, faces = keep_side(metres, faces, planes)
    if len(faces) == 0:
        return DELETED
    low, high = verts.min(axis=0), verts.max(axis=0)
    size = high - low
    unit = np.divide(verts - low, size, out=np.zeros_like(verts), where=size > 1e-12)
    mesh_id = app.engine.table.library.add(UnitMesh("envelope", unit, faces))
    shape.origin = shape.world(tuple(float(v) for v in low))
    shape.size = [float(s) for s in size]
    shape.geom = Solid(mesh_id, "envelope")
    return False
