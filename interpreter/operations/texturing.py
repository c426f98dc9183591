"""setupProjection, projectUV, texture, normalMap and the *UV operations (CGA's texturing).

A shape's texturing is one immutable :class:`Texturing` value, shared by copies until an
operation replaces it, so untextured derivations pay one ``None`` per shape.

Texture coordinates are affine in the world position of a point: a projection set up on a scope
is the map ``uv = L @ x + m`` from WORLD points (2 x 4 numbers, :data:`Map`), and every UV
operation (tile, scale, translate, rotate, normalize) is affine in uv, so it composes into the
map.  Because the map is in world coordinates, split pieces and faces keep it unchanged: the
geometry does not move, so tiles line up across every cut (CGA's reason for setupProjection).
An operation that moves or stretches the geometry with its scope (t, r, s, center, matrix)
composes the map with the inverse motion (:func:`follow`), so the texture sticks to the shape.
The terminal table turns the map of each terminal into one on unit scope coordinates, and the
writers compute every vertex's uv from it in bulk (terminals.TerminalTable.texturing).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from bgr.grammar.registry import UV_SETS
from bgr.grammar.textures import TextureError, load

from ..expressions import runtime_error

# u row (a, b, c, d) then v row (e, f, g, h): u = a x + b y + c z + d, v = e x + f y + g z + h
Map = tuple[float, float, float, float, float, float, float, float]
NORMAL_SET = 5  # CGA's material.normalmap layer


@dataclass(frozen=True, slots=True)
class Texturing:
    proj: tuple = (None,) * UV_SETS  # per uv-set: the projection set up (Map) or None
    uv: tuple = (None,) * UV_SETS  # per uv-set: the shape's coordinates (Map) or None
    color: int = -1  # the colour map: an index into the terminal table's images, or -1
    normal: int = -1  # the normal map, likewise


def _set(shape) -> Texturing:
    return shape.tex if shape.tex is not None else Texturing()


_UV_SET_NUMBERS = frozenset(range(UV_SETS))
_PLAIN = (float, int)  # exactly these classes: not bool


def _uv_set(app, step, value) -> int:
    if value.__class__ in _PLAIN and value in _UV_SET_NUMBERS:  # the usual case, at once
        return int(value)
    if (
        isinstance(value, bool)
        or not isinstance(value, (int, float))
        or value != int(value)
        or not 0 <= value < UV_SETS
    ):
        raise runtime_error(
            app.module,
            step.pos,
            f"'{step.name}' needs a uv-set number 0..{UV_SETS - 1}, got {value!r}",
            "uv-set 0 is the colour map's, 5 the normal map's",
        )
    return int(value)


def _number(app, step, value, what: str) -> float:
    if value.__class__ is float and value - value == 0.0:  # finite: the usual case, at once
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise runtime_error(app.module, step.pos, f"the {what} of '{step.name}' must be a number")
    return float(value)


def corners(shape) -> list[list[float]]:
    """The eight corners of the shape's scope box, in world coordinates."""
    sx, sy, sz = shape.size
    return [shape.world((x, y, z)) for x in (0.0, sx) for y in (0.0, sy) for z in (0.0, sz)]


def _apply(m: Map, p) -> tuple[float, float]:
    return (
        m[0] * p[0] + m[1] * p[1] + m[2] * p[2] + m[3],
        m[4] * p[0] + m[5] * p[1] + m[6] * p[2] + m[7],
    )


def _tile(app, step, value, extent: float, what: str) -> float:
    """A texture size in metres from a number, ("rel", f) or ("float", w); ``extent``: the
    length of the shape along that texture direction."""
    kind = None
    if isinstance(value, tuple):
        kind, value = value
    size = _number(app, step, value, what)
    if kind == "rel":
        size *= extent
    elif kind == "float" and size and extent > 1e-12:
        size = math.copysign(extent / max(1, round(extent / abs(size))), size)
    return size


# ---- setting up and baking ----------------------------------------------------------------------


_AXES: dict[str, tuple[str, int, int, int]] = {}


def _axes(text: str) -> tuple[str, int, int, int]:
    """ "scope.xy" -> ("scope", 0, 1, 2): the frame, the u and v axes and the third one."""
    frame, pair = text.split(".")
    i, j = "xyz".index(pair[0]), "xyz".index(pair[1])
    found = _AXES[text] = (frame, i, j, 3 - i - j)
    return found


def setup_projection(app, shape, step, args) -> bool:
    k = _uv_set(app, step, args[0])
    frame, i, j, w = _AXES.get(args[1]) or _axes(args[1])
    if frame == "scope":
        origin, axes = shape.origin, shape.axes
        extents = shape.size
    else:  # the world: its origin and axes; the shape's extent along each world axis
        origin, axes = (0.0, 0.0, 0.0), ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
        box = corners(shape)
        extents = [max(c[a] for c in box) - min(c[a] for c in box) for a in range(3)]
    tw = _tile(app, step, args[2], extents[i], "texture width")
    th = _tile(app, step, args[3], extents[j], "texture height")
    if tw == 0 or th == 0:
        raise runtime_error(
            app.module,
            step.pos,
            "setupProjection() needs a texture width and height other than 0",
            "sizes are metres of one texture tile; negative ones mirror it",
        )
    uo = _number(app, step, args[4], "u offset")
    vo = _number(app, step, args[5], "v offset")
    uw = _number(app, step, args[6], "uw factor")
    au = [axes[i][c] + uw * axes[w][c] for c in range(3)]
    av = axes[j]
    m: Map = (
        au[0] / tw,
        au[1] / tw,
        au[2] / tw,
        (uo - sum(au[c] * origin[c] for c in range(3))) / tw,
        av[0] / th,
        av[1] / th,
        av[2] / th,
        (vo - sum(av[c] * origin[c] for c in range(3))) / th,
    )
    tex = _set(shape)
    proj = list(tex.proj)
    proj[k] = m
    shape.tex = Texturing(tuple(proj), tex.uv, tex.color, tex.normal)  # replace() is 4x slower
    return False


def project_uv(app, shape, step, args) -> bool:
    k = _uv_set(app, step, args[0])
    tex = _set(shape)
    if tex.proj[k] is None:
        raise runtime_error(
            app.module,
            step.pos,
            f"projectUV({k}) has no projection to apply",
            f"set one up first: setupProjection({k}, scope.xy, 1, 1)",
        )
    uv = list(tex.uv)
    uv[k] = tex.proj[k]
    shape.tex = Texturing(tex.proj, tuple(uv), tex.color, tex.normal)
    return False


def delete_uv(app, shape, step, args) -> bool:
    k = _uv_set(app, step, args[0])
    if shape.tex is not None and shape.tex.uv[k] is not None:
        uv = list(shape.tex.uv)
        uv[k] = None
        shape.tex = replace(shape.tex, uv=tuple(uv))
    return False


def _image(app, step, path) -> int:
    """The terminal table's image index of a texture file, read once per derivation; -1 for
    the empty name, which removes the map (CGA: ``set(material.colormap, "")``)."""
    if not isinstance(path, str):
        raise runtime_error(app.module, step.pos, f"'{step.name}' needs a file name, got {path!r}")
    if path == "":
        return -1
    engine = app.engine
    cache = engine.__dict__.setdefault("texture_cache", {})
    key = (app.module.path, path)
    found = cache.get(key)
    if found is None:
        try:
            folders = engine.__dict__.setdefault("texture_folders", {})
            image = load(app.module.path, app.module.roots, path, app.module.folder, folders)
        except TextureError as e:
            raise runtime_error(app.module, step.pos, e.message, e.hint) from None
        found = cache[key] = engine.table.add_image(image)
    return found


def texture(app, shape, step, args) -> bool:
    tex = _set(shape)
    shape.tex = Texturing(tex.proj, tex.uv, _image(app, step, args[0]), tex.normal)
    return False


def normal_map(app, shape, step, args) -> bool:
    shape.tex = replace(_set(shape), normal=_image(app, step, args[0]))
    return False


# ---- operations on the coordinates --------------------------------------------------------------


def _baked(app, shape, step, k: int) -> Map:
    found = shape.tex.uv[k] if shape.tex is not None else None
    if found is None:
        raise runtime_error(
            app.module,
            step.pos,
            f"'{step.name}' needs the texture coordinates of uv-set {k}",
            f"give the shape coordinates first: setupProjection({k}, ...) then projectUV({k})",
        )
    return found


def _store(shape, k: int, m) -> None:
    uv = list(shape.tex.uv)
    uv[k] = tuple(float(v) for v in m)
    shape.tex = replace(shape.tex, uv=tuple(uv))


def _affine(shape, k: int, m: Map, a, b, c, d, e, f) -> None:
    """Compose uv -> (a u + b v + c, d u + e v + f) into map ``m`` of uv-set ``k``."""
    u, v = m[:4], m[4:]
    _store(
        shape,
        k,
        [a * u[t] + b * v[t] + (c if t == 3 else 0.0) for t in range(4)]
        + [d * u[t] + e * v[t] + (f if t == 3 else 0.0) for t in range(4)],
    )


def scale_uv(app, shape, step, args) -> bool:
    k = _uv_set(app, step, args[0])
    m = _baked(app, shape, step, k)
    su, sv = _number(app, step, args[1], "u factor"), _number(app, step, args[2], "v factor")
    _affine(shape, k, m, su, 0.0, 0.0, 0.0, sv, 0.0)
    return False


def translate_uv(app, shape, step, args) -> bool:
    k = _uv_set(app, step, args[0])
    m = _baked(app, shape, step, k)
    tu, tv = _number(app, step, args[1], "u offset"), _number(app, step, args[2], "v offset")
    _affine(shape, k, m, 1.0, 0.0, tu, 0.0, 1.0, tv)
    return False


def rotate_uv(app, shape, step, args) -> bool:
    k = _uv_set(app, step, args[0])
    m = _baked(app, shape, step, k)
    a = math.radians(_number(app, step, args[1], "angle"))
    c, s = math.cos(a), math.sin(a)
    _affine(shape, k, m, c, -s, 0.0, s, c, 0.0)
    return False


def _ranges(shape, m: Map) -> tuple[tuple[float, float], tuple[float, float]]:
    """(min, max) of u and of v over the shape's scope box."""
    pts = [_apply(m, p) for p in corners(shape)]
    us, vs = [p[0] for p in pts], [p[1] for p in pts]
    return (min(us), max(us)), (min(vs), max(vs))


def tile_uv(app, shape, step, args) -> bool:
    k = _uv_set(app, step, args[0])
    m = _baked(app, shape, step, k)
    (u0, u1), (v0, v1) = _ranges(shape, m)
    factors = []
    for row, value, span, what in ((0, args[1], u1 - u0, "width"), (4, args[2], v1 - v0, "height")):
        gradient = math.sqrt(sum(c * c for c in m[row : row + 3]))
        if gradient < 1e-15:  # the coordinate does not change over the shape: nothing to tile
            factors.append(1.0)
            continue
        metres = span / gradient  # the shape's length along this texture direction
        size = _tile(app, step, value, metres, f"texture {what}")
        factors.append(1.0 if size == 0 else 1.0 / (size * gradient))
    _affine(shape, k, m, factors[0], 0.0, 0.0, 0.0, factors[1], 0.0)
    return False


def normalize_uv(app, shape, step, args) -> bool:
    k = _uv_set(app, step, args[0])
    m = _baked(app, shape, step, k)
    mode = args[1]
    (u0, u1), (v0, v1) = _ranges(shape, m)
    du, dv = u1 - u0, v1 - v0
    if mode == "uvUniform":
        du = dv = max(du, dv)
    su = 1.0 / du if du > 1e-12 and mode != "v" else 1.0
    sv = 1.0 / dv if dv > 1e-12 and mode != "u" else 1.0
    cu = -u0 * su if mode != "v" else 0.0
    cv = -v0 * sv if mode != "u" else 0.0
    _affine(shape, k, m, su, 0.0, cu, 0.0, sv, cv)
    return False


# ---- following the geometry ------------------------------------------------------------


def follow(shape, origin, axes, size) -> None:
    """Move the shape's maps with its geometry after an operation changed its scope from
    (origin, axes, size): each map is composed with the inverse of the motion, so every point of
    the geometry keeps its texture coordinates.  An axis of size 0 had no extent to stretch."""
    tex = shape.tex
    if origin == shape.origin and axes == shape.axes and size == shape.size:
        return
    f = [
        shape.size[a] / size[a] if abs(size[a]) > 1e-12 and abs(shape.size[a]) > 1e-12 else 1.0
        for a in range(3)
    ]
    new_o, new_axes = shape.origin, shape.axes
    # x_old = origin + A_old^T diag(1/f) A_new (x_new - new_o): B = A_old^T diag(1/f) A_new
    b = [
        [sum(axes[a][r] / f[a] * new_axes[a][c] for a in range(3)) for c in range(3)]
        for r in range(3)
    ]

    def moved(m):
        if m is None:
            return None
        out: list[float] = []
        for row in (m[:4], m[4:]):
            lin = [sum(row[r] * b[r][c] for r in range(3)) for c in range(3)]
            off = (
                row[3]
                + sum(row[r] * origin[r] for r in range(3))
                - sum(lin[c] * new_o[c] for c in range(3))
            )
            out += [*lin, off]
        return tuple(out)

    shape.tex = replace(
        tex, proj=tuple(moved(m) for m in tex.proj), uv=tuple(moved(m) for m in tex.uv)
    )
