"""t, r, s, center, matrix: changes of the scope.  Geometry is in unit scope coordinates, so it
follows the scope without being touched."""

from __future__ import annotations

import math

from ..expressions import runtime_error
from ..geometry.meshes import PLANE_AXES
from ..geometry.polygons import RECT
from ..shapes import Flat, Prism, Solid, cross, dot, normalise
from ..terminals import UnitMesh


def _amounts(app, step, shape, values) -> list[float]:
    out = []
    for i, v in enumerate(values):
        rel = isinstance(v, tuple)
        v = v[1] if rel else v
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise runtime_error(app.module, step.pos, f"'{step.name}' needs numbers, got {v!r}")
        out.append(v * shape.size[i] if rel else float(v))
    return out


def translate(app, shape, step, args) -> bool:
    d = _amounts(app, step, shape, args[:3])
    shape.origin = shape.world(d)
    return False


def scale(app, shape, step, args) -> bool:
    size = _amounts(app, step, shape, args[:3])
    if min(size) < 0:
        raise runtime_error(
            app.module,
            step.pos,
            f"negative size {min(size):g} in s()",
            "sizes are lengths; flip a shape with r() instead",
        )
    shape.size = size
    return False


def _rotate_axes(axes, axis: int, degrees: float):
    """Intrinsic rotation about the scope's own axis ``axis``."""
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    u, v = axes[i], axes[j]
    new = list(axes)
    new[i] = tuple(c * u[k] + s * v[k] for k in range(3))
    new[j] = tuple(-s * u[k] + c * v[k] for k in range(3))
    return tuple(new)


def rotate(app, shape, step, args) -> bool:
    """r(x, y, z) about the scope's origin; r(scopeCenter, x, y, z) about its centre, the
    centre staying where it is (CGA's r with a pivot word)."""
    pivot = args[0] if isinstance(args[0], str) else "scopeOrigin"
    angles = _amounts(app, step, shape, args[1:4] if isinstance(args[0], str) else args[:3])
    centre = shape.world([s / 2 for s in shape.size]) if pivot == "scopeCenter" else None
    axes = shape.axes
    for axis, deg in enumerate(angles):
        if deg:
            axes = _rotate_axes(axes, axis, deg)
    shape.axes = axes
    if centre is not None:  # the turned scope's centre back where the centre was
        moved = shape.world([s / 2 for s in shape.size])
        shape.origin = [shape.origin[k] + centre[k] - moved[k] for k in range(3)]
    return False


WORLD_AXES = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def _system(app, shape, system: str):
    """(origin, axes) of a coordinate system of rotate() and translate(): the scope's own, the
    world's (the output's axes, the site's origin), or the object's (and the pivot's, the same
    in bgr): the lot's scope as the start rule received it."""
    if system == "scope":
        return tuple(shape.origin), shape.axes
    if system == "world":
        return (0.0, 0.0, 0.0), WORLD_AXES
    return app.engine.object_frame


def translate_in(app, shape, step, args) -> bool:
    """CGA's translate(mode, coordSystem, x, y, z): ``rel`` moves the scope's origin by the
    vector, ``abs`` puts it at the point; both in the system's axes (scope: as ``t``)."""
    mode, system = args[0], args[1]
    vector = [float(v) for v in args[2:5]]
    origin, axes = _system(app, shape, system)
    offset = [sum(vector[i] * axes[i][k] for i in range(3)) for k in range(3)]
    base = shape.origin if mode == "rel" or system == "scope" else origin
    shape.origin = [base[k] + offset[k] for k in range(3)]
    return False


def rotate_in(app, shape, step, args) -> bool:
    """CGA's rotate(mode, coordSystem, x, y, z), about the scope's origin: the system's axes
    turned by the angles (x, then y, then z, each about the turned axes, as ``r``) are the
    scope's new axes in ``abs`` mode; in ``rel`` mode the motion that turns the system so is
    applied to the scope's axes (in the scope's own system both are ``r``)."""
    mode, system = args[0], args[1]
    frame = _system(app, shape, system)[1]
    turned = frame
    for axis, degrees in enumerate(args[2:5]):
        if degrees:
            turned = _rotate_axes(turned, axis, float(degrees))
    if mode == "abs":
        shape.axes = turned
        return False
    # frame[j] -> turned[j]: a vector v goes to sum_j turned[j] (frame[j] . v)
    shape.axes = tuple(
        tuple(sum(turned[j][k] * dot(frame[j], axis) for j in range(3)) for k in range(3))
        for axis in shape.axes
    )
    return False


def center(app, shape, step, args) -> bool:
    which, received = args[0], args[-1]
    # the centre of the received scope, in this scope's frame
    target = received.world([received.size[i] / 2 for i in range(3)])
    mine = shape.world([shape.size[i] / 2 for i in range(3)])
    delta = [target[i] - mine[i] for i in range(3)]
    move = [0.0, 0.0, 0.0]
    for axis in which:
        k = "xyz".index(axis)
        move[k] = dot(delta, shape.axes[k])
    shape.origin = shape.world(move)
    return False


def matrix(app, shape, step, args) -> bool:
    """A 3x4 affine map in the scope's frame.  Its linear part is split into an orthonormal frame
    and scale factors (Gram-Schmidt); a shear, which a scope cannot hold, is dropped."""
    m = _amounts(app, step, shape, [v for v in args[:-1]])
    cols = [[m[r * 4 + c] for r in range(3)] for c in range(3)]
    offset = [m[3], m[7], m[11]]
    lengths = [dot(col, col) ** 0.5 for col in cols]
    if min(lengths) < 1e-12:
        raise runtime_error(app.module, step.pos, "matrix() flattens the scope (a zero column)")
    x = normalise(cols[0])
    y = normalise([cols[1][k] - dot(cols[1], x) * x[k] for k in range(3)])
    z = cross(x, y)
    if dot(z, cols[2]) < 0:
        raise runtime_error(
            app.module, step.pos, "matrix() mirrors the scope; scopes stay right-handed"
        )
    new_origin = shape.world(offset)
    shape.axes = tuple(tuple(shape.direction(v)) for v in (x, y, z))
    shape.origin = new_origin
    shape.size = [shape.size[i] * lengths[i] for i in range(3)]
    return False


def reverse_normals(app, shape, step, args) -> bool:
    """Turn a 2D shape over: half a turn about an axis in its plane, the outline kept in place.

    Faces are one-sided in the files people open (glTF materials are not double-sided), so a
    face seen from behind disappears: a window reveal made from the faces of the recess prism
    looks into the wall until it is turned over.  A face (flat along z) turns about its y, so
    its x and z reverse; a lot (flat along y) about its z.
    """
    geom = shape.geom
    if not isinstance(geom, Flat):  # a solid: every triangle turned over, as CGA does
        library = app.engine.table.library
        mesh = library.meshes[app.engine.mesh_id(geom)]
        turned = UnitMesh(mesh.name, mesh.vertices, mesh.faces[:, ::-1], mesh.uv, mesh.image)
        if mesh.uv is not None:
            turned.uv = mesh.uv[:, ::-1]
        name = "extrusion" if isinstance(geom, Prism) else geom.name
        shape.geom = Solid(library.add(turned), name)
        return False
    k = geom.k
    about = 2 if k == 1 else 1
    flipped = [a for a in range(3) if a != about]  # the normal and one axis in the plane
    move = [shape.size[a] if a in flipped else 0.0 for a in range(3)]
    shape.origin = shape.world(tuple(move))
    shape.axes = tuple(
        tuple(-c for c in axis) if a in flipped else axis for a, axis in enumerate(shape.axes)
    )
    if geom.polys != RECT:
        # the in-plane axis that reversed: mirror the outline along it so it stays in place
        which = PLANE_AXES[k].index(next(a for a in flipped if a != k))
        polys = [
            (_mirror(ext, which), tuple(_mirror(h, which) for h in holes))
            for ext, holes in geom.polys
        ]
        shape.geom = Flat(k, polys, geom.name)
    return False


def _mirror(ring, which: int) -> tuple:
    """A unit ring mirrored along coordinate ``which``, its order reversed to keep its turn."""
    if which == 0:
        return tuple((1.0 - u, v) for u, v in reversed(ring))
    return tuple((u, 1.0 - v) for u, v in reversed(ring))
