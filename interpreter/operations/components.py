"""comp(f), offset, extrude, taper: between 2D and 3D shapes (LANGUAGE.md sections 5 and 7)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import shapely

from ..expressions import runtime_error
from ..geometry.convex import convex_faces
from ..geometry.edges import edges
from ..geometry.frames import WORLD_UP, extrusion_axes, planar_faces, reframe_flat
from ..geometry.meshes import PLANE_AXES
from ..geometry.polygons import (
    RECT,
    UNIT_SQUARE,
    inset,
    is_unit_square,
    named_footprint,
    signed_area,
)
from ..geometry.polygons import (
    normalise as normalise_polys,
)
from ..occlusion import note
from ..shapes import Flat, Prism, Solid, cross, dot, normalise
from ..terminals import UnitMesh
from .combined import combined_faces
from .extrude_faces import extrude_faces
from .selection import check_budget, select, words
from .trims import corner_planes, edge_planes

# ---- comp(f) -----------------------------------------------------------------------------------


def faces_of(app, step, shape):
    """Faces of a shape as (points in scope-local metres, outward normal in scope coordinates,
    the turns at its bottom corners); a convexified solid's cut into convex parts."""
    faces = _faces(app, step, shape)
    limit = getattr(shape.geom, "convex", 0.0)
    return convex_faces(faces, limit) if limit else faces


def _faces(app, step, shape):
    geom = shape.geom
    if isinstance(geom, Solid) and geom.name == "cube":
        geom = Prism(1, RECT)
    if isinstance(geom, Solid):
        if geom.name not in _MESH_FACES:
            raise runtime_error(
                app.module,
                step.pos,
                f"{'comp(f)' if step.name == 'comp' else step.name + '()'} of a "
                f"'{geom.name}' shape is not supported",
                "comp(f) works on extruded shapes, boxes, roofs, tapers and 2D shapes",
            )
        unit = app.engine.table.library.meshes[geom.mesh]
        metres = unit.vertices * np.asarray(shape.size, dtype=float)
        return [(rings, nrm, (0.0, 0.0)) for rings, nrm in planar_faces(metres, unit.faces)]
    size = shape.size
    k = geom.k
    p, q = PLANE_AXES[k]
    polys = [(UNIT_SQUARE, ())] if geom.polys == RECT else geom.polys

    def point(u, v, h):
        vec = [0.0, 0.0, 0.0]
        vec[p], vec[q], vec[k] = u * size[p], v * size[q], h * size[k]
        return vec

    up = [0.0, 0.0, 0.0]
    up[k] = 1.0
    if isinstance(geom, Flat):
        return [
            (
                [
                    [point(u, v, 0) for u, v in ext],
                    *[[point(u, v, 0) for u, v in h] for h in holes],
                ],
                up,
                (0.0, 0.0),
            )
            for ext, holes in polys
        ]
    faces = []
    # a prism of zero height has no side faces: they would have no area (and no frame)
    sides = polys if size[k] > 1e-12 else []
    for ext, holes in sides:
        for ring, is_hole in [(ext, False)] + [(h, True) for h in holes]:
            metric = [(u * size[p], v * size[q]) for u, v in ring]
            ccw = signed_area(metric) > 0
            # (p, q, k) is a left-handed order for k = y (x, z, y): there the sides swap
            outward_right = (ccw != is_hole) != (k == 1)
            turns = _turns(metric, outer_sign=(1 if ccw else -1) * (-1 if is_hole else 1))
            n = len(ring)
            for i, ((u0, v0), (u1, v1)) in enumerate(zip(ring, ring[1:] + ring[:1], strict=True)):
                a, b = point(u0, v0, 0), point(u1, v1, 0)
                edge = [b[i] - a[i] for i in range(3)]
                nrm = normalise(cross(edge, up) if outward_right else cross(up, edge))
                if dot(edge, edge) < 1e-18:
                    continue
                faces.append(
                    (
                        [[a, b, point(u1, v1, 1), point(u0, v0, 1)]],
                        nrm,
                        (turns[i], turns[(i + 1) % n]),
                    )
                )
    down = [-c for c in up]
    for ext, holes in polys:
        faces.append(
            (
                [
                    [point(u, v, 1) for u, v in ext],
                    *[[point(u, v, 1) for u, v in h] for h in holes],
                ],
                up,
                (0.0, 0.0),
            )
        )
    for ext, holes in polys:
        faces.append(
            (
                [
                    [point(u, v, 0) for u, v in ext],
                    *[[point(u, v, 0) for u, v in h] for h in holes],
                ],
                down,
                (0.0, 0.0),
            )
        )
    return faces


def _turns(ring, outer_sign: int) -> list[float]:
    """The angle in degrees the wall turns at each corner of a ring: positive at an outer
    (convex) corner of the building, negative at an inner one, 0 where it runs straight on."""
    out = []
    n = len(ring)
    for i in range(n):
        (ax, ay), (bx, by), (cx, cy) = ring[i - 1], ring[i], ring[(i + 1) % n]
        d1, d2 = (bx - ax, by - ay), (cx - bx, cy - by)
        angle = math.degrees(
            math.atan2(d1[0] * d2[1] - d1[1] * d2[0], d1[0] * d2[0] + d1[1] * d2[1])
        )
        out.append(0.0 if abs(angle) < 1e-9 else outer_sign * angle)
    return out


def _left_right(rings, nrm, turns) -> tuple[float, float]:
    """(comp.left, comp.right) of a side face: which end of its bottom edge is on the left as
    seen from outside follows the face's x axis (section 7), not the ring's direction."""
    z = nrm
    if abs(z[1]) > 0.7071:
        return 0.0, 0.0
    y = normalise([-z[1] * z[0], 1.0 - z[1] * z[1], -z[1] * z[2]])
    x = cross(y, z)
    a, b = rings[0][0], rings[0][1]
    return turns if dot(a, x) <= dot(b, x) else (turns[1], turns[0])


# solids whose planar faces comp(f) takes apart: a roof's slopes and gable ends, a taper's caps
# and sides, an extrusion along world y (assets and the round primitives are left whole)
_MESH_FACES = ("roof", "taper", "extrusion", "envelope", "polygon", "prism")


def _face_shape(shape, rings, nrm):
    """The 2D shape of a face: x along its bottom edge, y up the face, z out (section 7)."""
    z = nrm
    if abs(z[1]) > 0.7071:  # horizontal: x follows the scope's x
        ref = [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 0.0, 1.0]
        x = normalise([ref[i] - dot(ref, z) * z[i] for i in range(3)])
        y = cross(z, x)
    else:
        ref = [0.0, 1.0, 0.0]
        y = normalise([ref[i] - dot(ref, z) * z[i] for i in range(3)])
        x = cross(y, z)
    coords = [[(dot(pt, x), dot(pt, y)) for pt in ring] for ring in rings]
    xs = [c[0] for ring in coords for c in ring]
    ys = [c[1] for ring in coords for c in ring]
    x0, y0 = min(xs), min(ys)
    w, h = max(xs) - x0, max(ys) - y0
    plane = dot(rings[0][0], z)
    origin_local = [x0 * x[i] + y0 * y[i] + plane * z[i] for i in range(3)]
    unit = [
        tuple(((cx - x0) / (w or 1.0), (cy - y0) / (h or 1.0)) for cx, cy in ring)
        for ring in coords
    ]
    polys = [(unit[0], tuple(unit[1:]))]
    face = shape.copy().cut_from(shape)
    face.origin = shape.world(origin_local)
    face.axes = (tuple(shape.direction(x)), tuple(shape.direction(y)), tuple(shape.direction(z)))
    face.size = [w, h, 0.0]
    face.geom = Flat(2, RECT if is_unit_square(polys) else polys)
    return face


_BOXES = ("cube", "extrusion", "envelope")  # solids whose walls get trim planes, as a prism's do


def comp_faces(app, shape, step) -> bool:
    """comp(f): each face a 2D shape of its own (LANGUAGE.md section 7)."""
    faces = faces_of(app, step, shape)
    check_budget(app, step, len(faces), "faces")
    first = app.counter
    answers = [words(nrm) for _, nrm, _ in faces]
    geom = shape.geom
    walls = isinstance(geom, Prism) or (isinstance(geom, Solid) and geom.name in _BOXES)
    # with trimming on, a solid's faces get planes where they meet (a 2D shape has one face)
    shared = edges(faces) if shape.trims is not None and len(faces) > 1 else []
    for entry, selector, chosen in select(app, step, answers):
        if entry.combine and chosen:  # `=`: the faces taken, as one shape
            taken = [_face_shape(shape, faces[i][0], faces[i][1]) for i in chosen]
            piece = combined_faces(app, shape, faces, taken)
            app.engine.count_shape(app.module, entry.pos)
            app.piece(piece, entry.body, comp=(0, 1, 0.0, 0.0, selector))
            continue
        for j, i in enumerate(chosen):
            rings, nrm, turns = faces[i]
            face = _face_shape(shape, rings, nrm)
            app.engine.count_shape(app.module, entry.pos)
            corners = _left_right(rings, nrm, turns)
            # with trimming on, a face of a solid gets trim planes where it meets the others:
            # a wall's corners as comp.left/right turn, every other edge halving the angle
            # there (a new comp's replace the old)
            if face.trims is not None:
                wall = walls and abs(nrm[1]) <= 0.7071
                planes = corner_planes(face, *corners) if wall else ()
                planes += edge_planes(shape, faces, shared, i, skip_upright=walls)
                face.trims = replace(face.trims, planes=planes)
            app.piece(face, entry.body, comp=(j, len(chosen), *corners, selector))
    note(app, shape, first=first)  # a mass turning into surfaces occludes (occlusion.py)
    return True


# ---- offset ------------------------------------------------------------------------------------


# (width, height, distance) of a rectangle -> offset()'s pieces: a window's frame is the same
# rectangle inset by the same distance on every façade of a city (Helsinki: 2,070 of 3,932
# rectangles are six), and shapely's buffer is most of the operation's time
_RECT_PIECES: dict[tuple[float, float, float], dict] = {}
RECT_PIECES_MOST = 4096  # entries kept, at most: the cache is emptied when it grows past this


def _pieces(polys, su: float, sv: float, distance: float) -> dict:
    """offset()'s pieces of polygons in unit coordinates of an ``su`` x ``sv`` scope: "inside"
    and "border" -> (unit polygons, or RECT for the unit square; the box (x0, y0, w, h) in
    metres), None for an empty piece.  A pure function of its arguments."""
    inside, border = inset(polys, su, sv, distance)
    parts: dict = {}
    for name, metric_polys in (("inside", inside), ("border", border)):
        if not metric_polys:
            parts[name] = None
            continue
        unit, box = normalise_polys(metric_polys)
        parts[name] = (RECT if is_unit_square(unit) else unit, box)
    return parts


def offset(app, shape, step, args) -> bool:
    first = app.counter
    done = _offset(app, shape, step, args)
    note(app, shape, first=first)  # as comp's shape, an occluder (occlusion.py)
    return done


def _offset(app, shape, step, args) -> bool:
    if not isinstance(shape.geom, Flat):
        # a solid: each of its faces is offset in its own plane, as CGA offsets every face
        faces = faces_of(app, step, shape)
        for rings, nrm, _ in faces:
            _offset_flat(app, _face_shape(shape, rings, nrm), step, args)
        return True
    return _offset_flat(app, shape, step, args)


def _offset_flat(app, shape, step, args) -> bool:
    distance = float(args[0])
    geom = shape.geom
    p, q = PLANE_AXES[geom.k]
    su, sv = shape.size[p], shape.size[q]
    if geom.polys == RECT:
        key = (su, sv, distance)
        parts = _RECT_PIECES.get(key)
        if parts is None:
            if len(_RECT_PIECES) >= RECT_PIECES_MOST:
                _RECT_PIECES.clear()
            parts = _RECT_PIECES[key] = _pieces([(UNIT_SQUARE, ())], su, sv, distance)
    else:
        parts = _pieces(geom.polys, su, sv, distance)
    for entry in step.block.entries:
        found = parts[entry.key.name]
        if found is None:
            continue
        unit, (x0, y0, w, h) = found
        piece = shape.copy().cut_from(shape)
        move = [0.0, 0.0, 0.0]
        move[p], move[q] = x0, y0
        piece.origin = shape.world(move)
        piece.size[p], piece.size[q] = w, h
        piece.geom = Flat(geom.k, unit)
        app.engine.check_scope(app.module, step, piece)  # a negative distance grows the shape
        app.engine.count_shape(app.module, entry.pos)
        app.piece(piece, entry.body)
    return True


# ---- extrude and taper -------------------------------------------------------------------------


def _flat(app, step, shape) -> Flat:
    if not isinstance(shape.geom, Flat):
        raise runtime_error(
            app.module,
            step.pos,
            f"{step.name}() needs a 2D shape, and this one is already 3D",
            "extrude a lot or a face (from comp(f)), not a mass",
        )
    return shape.geom


def _height(app, step, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise runtime_error(app.module, step.pos, f"{step.name}() needs a number, got {value!r}")
    if value < 0:
        raise runtime_error(
            app.module,
            step.pos,
            f"negative height {value:g} in {step.name}()",
            "heights are lengths; use r() to turn a shape over",
        )
    return float(value)


def footprint(app, shape, step, args) -> bool:
    """Swap a 2D shape's outline for a named footprint (L, U, T, cross, circle) in its scope."""
    geom = _flat(app, step, shape)
    kind, a, b = args[0], args[1], args[2]
    for name, value in (("a", a), ("b", b)):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise runtime_error(
                app.module, step.pos, f"footprint() needs a number for {name}, got {value!r}"
            )
    if kind == "circle":
        sides = 24 if len(step.args) < 2 else a
        if sides != int(sides) or not 3 <= sides <= 1024:
            raise runtime_error(
                app.module, step.pos, f"a circle footprint needs 3 to 1024 sides, got {sides:g}"
            )
        a = sides
    else:
        b = a if len(step.args) < 3 else b
        for name, value in (("a", a), ("b", b)):
            most = 0.5 if kind == "U" and name == "a" else 1.0  # U's two wings must not meet
            if kind != "rect" and not 0 < value < most:
                raise runtime_error(
                    app.module,
                    step.pos,
                    f"footprint({kind}) needs 0 < {name} < {most:g} (a fraction of the scope), "
                    f"got {value:g}",
                )
    polys = named_footprint(kind, a, b)
    shape.geom = Flat(geom.k, RECT if kind == "rect" else polys)
    return False


def polygon(app, shape, step, args) -> bool:
    """Swap a horizontal 2D shape for the polygon through the given corners (x, z pairs in
    metres, in the scope's frame): how an inferred city writes a footprint it extrudes, and a
    way to hand-write one.  The scope keeps its axes and shrinks to the polygon's bounding box."""
    geom = _flat(app, step, shape)
    if geom.k != 1:
        raise runtime_error(
            app.module,
            step.pos,
            "polygon() needs a horizontal 2D shape, and this face is upright",
            "give the corners on a lot (or a piece of one), then extrude",
        )
    values = args[:-1]
    for i, value in enumerate(values):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise runtime_error(
                app.module,
                step.pos,
                f"polygon() needs numbers, got {value!r:.40} (argument {i + 1})",
            )
    if len(values) % 2:
        raise runtime_error(
            app.module,
            step.pos,
            f"polygon() takes x, z pairs, and {len(values)} numbers leave one over",
            "write the corners as polygon(x1, z1, x2, z2, x3, z3, ...)",
        )
    ring = [(float(x), float(z)) for x, z in zip(values[0::2], values[1::2], strict=True)]
    if len(ring) > 3 and ring[0] == ring[-1]:
        ring.pop()  # a closed ring, as GeoJSON writes one
    area = signed_area(ring) if len(ring) >= 3 else 0.0
    if abs(area) < 1e-9:
        raise runtime_error(
            app.module,
            step.pos,
            "polygon() needs three corners or more around a non-zero area",
            "corners that all lie on one line make no footprint",
        )
    if not shapely.Polygon(ring).is_valid:
        raise runtime_error(
            app.module,
            step.pos,
            "polygon()'s edges cross each other or touch",
            "list the corners in order round the outline, each once",
        )
    if area < 0:  # clockwise: walk it the other way, so the caps of an extrusion face outward
        ring.reverse()
    unit, (u0, w0, width, depth) = normalise_polys([(tuple(ring), ())])
    x, z = shape.axes[0], shape.axes[2]
    shape.origin = tuple(shape.origin[i] + u0 * x[i] + w0 * z[i] for i in range(3))
    shape.size = [width, 0.0, depth]
    shape.geom = Flat(1, RECT if is_unit_square(unit) else unit)
    return False


def _signed_height(app, step, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        shown = "an array" if isinstance(value, tuple) else repr(value)
        raise runtime_error(
            app.module, step.pos, f"{step.name}() needs a finite number, got {shown}"
        )
    return float(value)


def _into_extrusion_frame(app, step, shape, direction: str, height: float):
    """Give ``shape`` the scope CGA gives an extruded shape; its 2D outline in that scope.

    y points along the extrusion (the face's normal, or world y for ``world.up``), x keeps its
    old direction as far as it can, z completes a right-handed frame (``geometry.frames``).  A
    negative height extrudes against the normal: the scope's y still follows the normal (CGA
    reports a negative scope.sy there; bgr keeps sizes positive and moves the origin down y).
    Returns (outline flat along y, heights of its points above the scope's origin along y:
    all 0 unless a tilted face is extruded along world y).
    """
    geom = _flat(app, step, shape)
    axes = shape.axes
    normal = axes[geom.k]
    along = WORLD_UP if direction == "world.up" else normal
    if geom.k == 1 and along == normal:  # a lot or a piece of one: the frame stays as it is
        flat, heights = geom, None
    elif geom.k == 2 and along == normal and geom.polys == RECT:  # a face: x, z, -y
        w, h = shape.size[0], shape.size[1]
        shape.origin = [shape.origin[i] + h * axes[1][i] for i in range(3)]
        shape.axes = (axes[0], axes[2], tuple(-c for c in axes[1]))
        shape.size = [w, 0.0, h]
        flat, heights = Flat(1, RECT), None
    else:
        if abs(dot(along, normal)) < 1e-9:
            raise runtime_error(
                app.module,
                step.pos,
                f"{step.name}(world.up) of a vertical face has no volume",
                "extrude a wall along its normal: extrude(d)",
            )
        frame = extrusion_axes(axes, along)
        origin, size, polys, heights = reframe_flat(
            shape.origin, axes, shape.size, geom.k, geom.polys, frame
        )
        shape.origin, shape.axes, shape.size = origin, frame, size
        flat = Flat(1, polys)
        if max(heights) <= 1e-9 * max(1.0, *size):
            heights = None
    if height < 0:
        shape.origin = [shape.origin[i] + height * shape.axes[1][i] for i in range(3)]
    return flat, heights


def extrude(app, shape, step, args) -> bool:
    given = len(step.args)  # extrude(height) or extrude(direction, height)
    direction = args[0] if given == 2 else "face.normal"
    height = _signed_height(app, step, args[given - 1])
    geom = shape.geom
    if isinstance(geom, Solid) and geom.name == "edge" and direction == "face.normal":
        # an edge from comp(e): a wall along it, up its y (the mean normal of its faces)
        if height < 0:
            shape.origin = [shape.origin[i] + height * shape.axes[1][i] for i in range(3)]
        shape.size = [shape.size[0], abs(height), 0.0]
        shape.geom = Flat(2, RECT)
        return False
    if not isinstance(geom, Flat) and direction == "face.normal":
        # a solid: each face along its own normal, as CGA extrudes every face
        faces = [(rings, nrm) for rings, nrm, _ in faces_of(app, step, shape)]
        extrude_faces(app, shape, faces, height)
        return False
    flat, heights = _into_extrusion_frame(app, step, shape, direction, height)
    if heights is None:
        shape.size[1] = abs(height)
        shape.geom = Prism(1, flat.polys)
    else:
        _sheared_prism(app, shape, flat, heights, height)
    return False


def _sheared_prism(app, shape, flat: Flat, heights: list[float], height: float) -> None:
    """A tilted face extruded along world y: a prism whose caps keep the face's slope."""
    from ..geometry.meshes import prism_mesh

    verts, faces = prism_mesh(flat.polys, 1)
    w, d = shape.size[0], shape.size[2]
    # the face is planar: its height above the origin is affine in (x, z); fit it from the
    # points of the outline (least squares over all of them, exact for a plane)
    pts = [
        (u * w, v * d)
        for ext, holes in ([(UNIT_SQUARE, ())] if flat.polys == RECT else flat.polys)
        for ring in [ext, *holes]
        for u, v in ring
    ]
    design = np.column_stack([np.ones(len(pts)), np.array(pts)])
    coef, *_ = np.linalg.lstsq(design, np.array(heights), rcond=None)
    base = coef[0] + coef[1] * verts[:, 0] * w + coef[2] * verts[:, 2] * d
    y = base + verts[:, 1] * height
    lo, hi = float(y.min()), float(y.max())
    verts = verts.copy()
    verts[:, 1] = (y - lo) / ((hi - lo) or 1.0)
    if height < 0:  # the caps swapped sides: turn the triangles over
        faces = faces[:, ::-1]
    # the origin already sits at the lowest outline point (moved down by a negative height)
    shift = lo - (min(0.0, height))
    shape.origin = [shape.origin[i] + shift * shape.axes[1][i] for i in range(3)]
    shape.size = [w, hi - lo, d]
    mesh = UnitMesh("extrusion", verts, np.ascontiguousarray(faces))
    shape.geom = Solid(app.engine.table.library.add(mesh), "extrusion")


def taper(app, shape, step, args) -> bool:
    height, ratio = _height(app, step, args[0]), args[1]
    geom, _ = _into_extrusion_frame(app, step, shape, "face.normal", height)
    if isinstance(ratio, bool) or not isinstance(ratio, (int, float)) or not 0 <= ratio <= 1000:
        raise runtime_error(
            app.module, step.pos, f"taper() needs a ratio from 0 to 1000, got {ratio!r}"
        )
    from ..geometry.meshes import _lift, _orient
    from ..geometry.polygons import triangulate

    polys = [(UNIT_SQUARE, ())] if geom.polys == RECT else geom.polys
    pts2, tris = triangulate(polys)
    centre = pts2.mean(axis=0)
    top2 = centre + (pts2 - centre) * ratio
    k = geom.k
    bottom, top = _lift(pts2, k, 0.0), _lift(top2, k, 1.0)
    up = np.eye(3)[k]
    verts = [bottom, top]
    faces = [_orient(bottom, tris, lambda c: np.broadcast_to(-up, c.shape))]
    if ratio > 0:
        faces.append(_orient(top, tris, lambda c: np.broadcast_to(up, c.shape)) + len(bottom))
    base, middle = len(bottom) + len(top), np.array([*centre, 0.5])
    mid3 = _lift(middle[None, :2], k, 0.5)[0]

    def outward(c: np.ndarray) -> np.ndarray:
        """A side quad's normal points away from the taper's middle."""
        return c - mid3

    for ext, holes in polys:
        for ring in [ext, *holes]:
            for a, b in zip(ring, ring[1:] + ring[:1], strict=True):
                quad2 = np.array([a, b, b, a], dtype=float)
                lifted = np.vstack(
                    [_lift(quad2[:2], k, 0.0), _lift(centre + (quad2[2:] - centre) * ratio, k, 1.0)]
                )
                quad_faces = _orient(lifted, np.array([[0, 1, 2], [0, 2, 3]]), outward)
                verts.append(lifted)
                faces.append(quad_faces + base)
                base += 4
    mesh = UnitMesh("taper", np.vstack(verts), np.vstack(faces))
    shape.size[k] = height
    shape.geom = Solid(app.engine.table.library.add(mesh), "taper")
    return False
