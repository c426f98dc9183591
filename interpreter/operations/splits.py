"""split(axis) { ... }: cut the scope into pieces (LANGUAGE.md section 6).

The sizes are evaluated per shape; the placement comes from :mod:`bgr.interpreter.split_solver`,
memoised on (block, sizes, length) because a façade's floors and tiles repeat the same lengths
thousands of times.  Each piece's geometry is the part of the shape's geometry inside it.
"""

from __future__ import annotations

import math

import numpy as np

from bgr.grammar import nodes as n

from ..expressions import runtime_error
from ..geometry.meshes import PLANE_AXES
from ..geometry.polygons import RECT, clip, is_unit_square, metric, renormalise
from ..geometry.polygons import normalise as normalise_polys
from ..geometry.slicing import slab
from ..limits import format_bytes
from ..shapes import Flat, Prism, Solid
from ..split_solver import Piece, Repeat, SplitError, solve
from ..terminals import UnitMesh


def _constant(entries) -> tuple | None:
    """The sizes when every one is a number written in the grammar (most façade splits), so
    they need no evaluating per shape; None when one is an expression."""
    out = []
    for entry in entries:
        if isinstance(entry, n.Group):
            inner = _constant(entry.entries)
            if inner is None:
                return None
            out.append(inner)
        elif isinstance(entry.key, n.Number) and math.isfinite(entry.key.value):
            out.append(float(entry.key.value))
        else:
            return None
    return tuple(out)


def _sizes(app, entries) -> tuple:
    """The evaluated sizes of a block's entries (a nested tuple for repeat groups): with the
    block and the length, all the placement depends on, so it keys the solver's memo."""
    known = app.engine.constant_sizes  # id(entries) -> sizes; the grammar outlives the engine
    key = id(entries)
    if key not in known:
        known[key] = _constant(entries)
    found = known[key]
    if found is not None:
        return found
    out = []
    for entry in entries:
        if isinstance(entry, n.Group):
            out.append(_sizes(app, entry.entries))
            continue
        size = app.value(entry.key)
        if isinstance(size, bool) or not isinstance(size, (int, float)) or not math.isfinite(size):
            raise runtime_error(
                app.module, entry.pos, f"a split size must be a finite number, got {size!r}"
            )
        out.append(float(size))
    return tuple(out)


def _items(entries, sizes: tuple) -> tuple:
    """The solver's items for those sizes (built only when the memo misses)."""
    return tuple(
        Repeat(_items(entry.entries, size))
        if isinstance(entry, n.Group)
        else Piece(entry.kind, size, entry)
        for entry, size in zip(entries, sizes, strict=True)
    )


def _clip(app, step, geom, axis: int, lo: float, hi: float):
    """The piece of a geometry between unit coordinates lo and hi along ``axis``; None if empty."""
    if isinstance(geom, Solid):
        return geom if geom.name == "cube" else _clip_solid(app, geom, axis, lo, hi)
    if axis == geom.k:
        return geom if isinstance(geom, Prism) else None
    if geom.polys == RECT:
        return geom
    which = PLANE_AXES[geom.k].index(axis)
    polys = renormalise(clip(geom.polys, which, lo, hi), which, lo, hi)
    if not polys:
        return None
    return type(geom)(geom.k, polys, geom.name)


def _clip_solid(app, geom: Solid, axis: int, lo: float, hi: float):
    """A mesh solid's slab between unit coordinates lo and hi, closed where it was closed
    (geometry.slicing); an edge's or a vertex's bare geometry stays as it is.  The slabs of a
    mesh are made once per derivation (a roof split into the same tiles on every house)."""
    engine = app.engine
    key = (geom.mesh, axis, lo, hi)
    found = engine.solid_slabs.get(key, _MISSING)
    if found is _MISSING:
        unit = engine.table.library.meshes[geom.mesh]
        if len(unit.faces) == 0:
            found = geom
        else:
            verts, faces = slab(unit.vertices, unit.faces, axis, lo, hi)
            # an asset's texture coordinates do not survive the cut: the slab is bare
            piece = UnitMesh(unit.name, verts, faces)
            found = Solid(engine.table.library.add(piece), geom.name) if len(faces) else None
        engine.solid_slabs[key] = found
    return found


_MISSING = object()


def _fit(app, piece) -> None:
    """split(axis, adjust): the piece's scope fitted to the geometry it holds, as CGA's default
    split does (a row of a triangle as wide as the triangle is there)."""
    geom = piece.geom
    if isinstance(geom, (Flat, Prism)):
        if geom.polys == RECT:
            return
        p, q = PLANE_AXES[geom.k]
        unit, (x0, y0, w, h) = normalise_polys(metric(geom.polys, piece.size[p], piece.size[q]))
        if w <= 0 or h <= 0:
            return
        move = [0.0, 0.0, 0.0]
        move[p], move[q] = x0, y0
        piece.origin = piece.world(move)
        piece.size[p], piece.size[q] = w, h
        piece.geom = type(geom)(geom.k, RECT if is_unit_square(unit) else unit, geom.name)
        return
    library = app.engine.table.library
    mesh = library.meshes[geom.mesh]
    if not len(mesh.faces):
        return
    used = mesh.vertices[np.unique(mesh.faces)]
    low, high = used.min(axis=0), used.max(axis=0)
    if np.allclose(low, 0.0, atol=1e-9) and np.allclose(high, 1.0, atol=1e-9):
        return
    span = np.where(high - low > 1e-12, high - low, 1.0)
    verts = (mesh.vertices - low) / span
    fitted = UnitMesh(mesh.name, verts, mesh.faces, mesh.uv, mesh.image)
    piece.origin = piece.world(tuple(float(low[i] * piece.size[i]) for i in range(3)))
    piece.size = [float(piece.size[i] * (high[i] - low[i])) for i in range(3)]
    piece.geom = Solid(library.add(fitted), geom.name)


def split(app, shape, step, args) -> bool:
    axis = "xyz".index(args[0])
    adjust = len(step.args) > 1 and args[1] == "adjust"
    length = shape.size[axis]
    entries = step.block.entries
    sizes = app.engine.constant_sizes.get(id(entries))  # most splits: numbers in the grammar
    if sizes is None:
        sizes = _sizes(app, entries)
    key = (id(step.block), sizes, length)
    cache = app.engine.split_cache
    placed = cache.get(key)
    if placed is None:
        items = _items(step.block.entries, sizes)
        if step.block.repeat:
            items = (Repeat(items),)
        engine = app.engine
        by_budget = engine.max_shapes - engine.shapes
        room = engine.memory_full_at - engine.shapes  # inf without a ceiling
        by_memory = max(int(room), 0) if room < by_budget else by_budget
        try:
            placed = solve(items, length, limit=min(by_budget, by_memory))
        except SplitError as e:
            if e.count is not None and by_memory < by_budget:
                raise runtime_error(
                    app.module,
                    step.pos,
                    f"this split would make {e.count:,} pieces, more than the memory ceiling "
                    f"({format_bytes(engine.max_memory or 0)}) leaves room for",
                    "make the pieces larger, or raise the ceiling with --max-memory SIZE",
                ) from None
            raise runtime_error(
                app.module,
                step.pos,
                str(e),
                "make the pieces larger, or raise the budget with --max-shapes",
            ) from None
        if len(cache) > 100_000:
            cache.clear()
        cache[key] = placed
    pieces = []
    engine = app.engine
    whole = shape.geom
    # the pieces share the whole's geometry when cutting leaves it as it is (see _clip)
    uncut = (
        (isinstance(whole, Solid) and whole.name == "cube")
        or (isinstance(whole, Prism) and (axis == whole.k or whole.polys == RECT))
        or (isinstance(whole, Flat) and axis != whole.k and whole.polys == RECT)
    )
    frame = (tuple(shape.origin), shape.axes)
    (ox, oy, oz), (dx, dy, dz) = shape.origin, shape.axes[axis]
    for p in placed:
        if uncut:
            geom = whole
        else:
            lo, hi = (p.offset / length, (p.offset + p.size) / length) if length > 0 else (0, 0)
            geom = _clip(app, step, whole, axis, lo, hi)
            if geom is None:
                continue
        engine.count_shape(app.module, p.payload.pos)  # as it is made: memory is watched
        piece = shape.copy()
        piece.frame = frame
        at = p.offset
        piece.origin = [ox + at * dx, oy + at * dy, oz + at * dz]
        piece.size[axis] = p.size
        piece.geom = geom
        if adjust and not uncut:
            _fit(app, piece)
        pieces.append((piece, p.payload))
    total = len(pieces)
    for index, (piece, entry) in enumerate(pieces):
        app.piece(piece, entry.body, split=(index, total))
    return True
