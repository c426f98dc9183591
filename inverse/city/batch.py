"""All buildings cut and fitted at once: :func:`.cuts.slabs` and :func:`.components.fit` over
every object together, numpy array operations over all of them rather than a Python call chain
for each.

Issue 34 measured ``bgr infer`` at ~1.4 ms per object (100,000 one-triangle objects: 140 s),
nearly all of it the fixed cost of some forty small numpy calls per object.  Here the work is
grouped by object and by slab (``np.minimum.reduceat``, ``np.lexsort`` with the slab as first
key, stacked ``matmul``), and only what is per object by nature stays in a loop: a building that
may have cuts (:func:`.cuts.cut_heights`), the minimum rectangle of a footprint of more than three
corners (qhull; triangles are all done at once, :mod:`.rectangle`), the hash of each mesh.

The results are the same, bit for bit, as the per-object functions give (tests/test_linear.py
compares them): the same operations in the same order on the same numbers, with the matrix
products stacked only over slabs of equal vertex count, whose slices numpy computes as it
computes each alone.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from . import rectangle, tree
from .components import KEY_GRID, Component
from .cuts import HEIGHT_TOL, MIN_SLAB, Slab, cut_heights, slabs
from .model import CityObject


def decompose_all(
    objects: list[CityObject],
    progress: Callable[[int], object] | None = None,
    grid: float = KEY_GRID,
) -> list[Component]:
    """The components of every object to proceduralize, in the order that cutting and fitting
    one object after another gives (:func:`.pipeline.decompose`); ``progress(n)`` is told of
    objects as they are cut."""
    found: list[tuple[int, Slab]] = []
    todo = [i for i, obj in enumerate(objects) if obj.proceduralize]
    uncut = _uncut([objects[i] for i in todo])
    whole = iter(_whole([objects[i] for i, plain in zip(todo, uncut, strict=True) if plain]))
    tell = progress if progress is not None else (lambda n: None)
    tell(len(objects) - int((~uncut).sum()))  # the others are cut one by one
    for i, plain in zip(todo, uncut, strict=True):
        obj = objects[i]
        if plain:
            slab = next(whole)
            found += [(i, slab)] if slab is not None else []
        else:
            cuts = cut_heights(obj.vertices, obj.faces)
            found += [(i, s) for s in slabs(obj.vertices, obj.faces, cuts, obj.colors)]
            tell(1)
    return fit_all(found, objects, grid)


def _uncut(objects: list[CityObject]) -> np.ndarray:
    """Whether each object certainly has no cut: no vertex height that :func:`.cuts.cut_heights`
    would consider (at least MIN_SLAB above the bottom and below the top), or no triangle."""
    out = np.ones(len(objects), dtype=bool)
    sizes = np.array([len(o.vertices) for o in objects], dtype=np.int64)
    has = (sizes > 0) & np.array([len(o.faces) > 0 for o in objects], dtype=bool)
    if not has.any():
        return out
    y = np.concatenate([o.vertices[:, 1] for o, h in zip(objects, has, strict=True) if h])
    counts = sizes[has]
    starts = np.r_[0, np.cumsum(counts)[:-1]]
    bottom = np.minimum.reduceat(y, starts)
    top = np.maximum.reduceat(y, starts)
    low, high = np.repeat(bottom, counts), np.repeat(top, counts)
    z = np.round(y / HEIGHT_TOL).astype(np.int64) * HEIGHT_TOL  # as cut_heights' candidates
    inside = (z > low + HEIGHT_TOL) & (z < high - HEIGHT_TOL)
    considered = inside & ~(z < low + MIN_SLAB) & ~(z > high - MIN_SLAB)
    out[np.flatnonzero(has)] = np.add.reduceat(considered, starts) == 0
    return out


def _whole(objects: list[CityObject]) -> list[Slab | None]:
    """The one slab of each object without cuts (:func:`.cuts.slabs` with no cuts: all its
    triangles, its vertices that they use renumbered), None for an object without triangles."""
    nv = np.array([len(o.vertices) for o in objects], dtype=np.int64)
    nf = np.array([len(o.faces) for o in objects], dtype=np.int64)
    has = nf > 0
    if not has.any():
        return [None] * len(objects)
    with_faces = [o for o, h in zip(objects, has, strict=True) if h]
    v_start, f_start = np.r_[0, np.cumsum(nv[has])], np.r_[0, np.cumsum(nf[has])]
    vertices = np.concatenate([o.vertices for o in with_faces]).astype(np.float64, copy=False)
    faces = np.concatenate([o.faces for o in with_faces]).astype(np.int64, copy=False)
    used = np.zeros(len(vertices), dtype=bool)
    used[faces + np.repeat(v_start[:-1], nf[has])[:, None]] = True
    every = np.add.reduceat(~used, v_start[:-1]) == 0  # each object uses all its vertices
    bottom = np.minimum.reduceat(vertices[:, 1], v_start[:-1]).tolist()
    top = np.maximum.reduceat(vertices[:, 1], v_start[:-1]).tolist()
    source = np.arange(int(nf.max()), dtype=np.int64)
    out: list[Slab | None] = [None] * len(objects)
    for k, i in enumerate(np.flatnonzero(has).tolist()):
        v = vertices[v_start[k] : v_start[k + 1]]
        f = faces[f_start[k] : f_start[k + 1]]
        if not every[k]:
            kept, inverse = np.unique(f, return_inverse=True)
            v, f = v[kept], inverse.reshape(-1, 3).astype(np.int64)
        out[i] = Slab(bottom[k], top[k], v, f, source[: len(f)])
    return out


@dataclass
class _Stack:
    """The slabs' vertices and faces concatenated, with where each slab's begin."""

    vertices: np.ndarray  # (V, 3)
    faces: np.ndarray  # (F, 3) into vertices (offset by the slab's first vertex)
    v_start: np.ndarray  # (n + 1,)
    f_start: np.ndarray  # (n + 1,)

    @property
    def v_count(self) -> np.ndarray:
        return np.diff(self.v_start)


def fit_all(
    found: list[tuple[int, Slab]], objects: list[CityObject], grid: float = KEY_GRID
) -> list[Component]:
    """:func:`.components.fit` of every slab (with the object it came from): the minimum
    rectangle's angle, the four quarter turns' mesh keys, the frame with the least key."""
    if not found:
        return []
    stack = _stack([s for _, s in found])
    angle = _angles(stack) % 90.0
    bottom = np.minimum.reduceat(stack.vertices[:, 1], stack.v_start[:-1])
    turns = [_turns(angle + 90.0 * quarter) for quarter in range(4)]
    locals_, lows, keys = [], [], []
    for axes in turns:
        local = _times(stack, axes)
        low = np.minimum.reduceat(local, stack.v_start[:-1], axis=0)
        low[:, 1] = bottom
        local = local - np.repeat(low, stack.v_count, axis=0)
        locals_.append(local)
        lows.append(low)
        keys.append(_mesh_keys(stack, local, grid))
    best = np.array(keys).argmin(axis=0)  # the first quarter of the least key
    chosen = np.repeat(best, stack.v_count)
    vertices = locals_[0]
    for q in (1, 2, 3):
        vertices[chosen == q] = locals_[q][chosen == q]
    n = len(found)
    axes = np.stack(turns)[best, np.arange(n)]
    low = np.stack(lows)[best, np.arange(n)]
    frames = np.zeros((n, 4, 4))
    frames[:, :3, :3] = axes
    frames[:, :3, 3] = (axes @ low[:, :, None])[:, :, 0]  # each axes @ low
    frames[:, 3, 3] = 1.0
    sizes = np.maximum.reduceat(vertices, stack.v_start[:-1], axis=0)
    starts, quarter, angles = stack.v_start.tolist(), best.tolist(), angle.tolist()
    out = []
    for k, (index, slab) in enumerate(found):
        colors = objects[index].colors
        colors = None if colors is None else colors[slab.source_faces]
        local = vertices[starts[k] : starts[k + 1]]
        key = keys[quarter[k]][k]
        out.append(Component(index, frames[k], sizes[k], local, slab.faces, colors, key, angles[k]))
    return out


def _stack(found: list[Slab]) -> _Stack:
    v_count = np.array([len(s.vertices) for s in found], dtype=np.int64)
    f_count = np.array([len(s.faces) for s in found], dtype=np.int64)
    v_start, f_start = np.r_[0, np.cumsum(v_count)], np.r_[0, np.cumsum(f_count)]
    vertices = np.concatenate([s.vertices for s in found]).astype(np.float64, copy=False)
    faces = np.concatenate([s.faces for s in found]) + np.repeat(v_start[:-1], f_count)[:, None]
    return _Stack(vertices, faces.astype(np.int64, copy=False), v_start, f_start)


def _angles(stack: _Stack) -> np.ndarray:
    """The minimum rectangle's angle (degrees) of each slab seen from above, 0 where it has
    fewer than three distinct corners there (on a micrometre grid) or qhull finds no hull."""
    n = len(stack.v_start) - 1
    ground = np.round(stack.vertices[:, [0, 2]], 6)
    slab = np.repeat(np.arange(n), stack.v_count)
    order = np.lexsort((ground[:, 1], ground[:, 0], slab))
    g, s = ground[order], slab[order]
    new = np.r_[True, (s[1:] != s[:-1]) | np.any(g[1:] != g[:-1], axis=1)]
    distinct = np.bincount(s[new], minlength=n)
    angle = np.zeros(n)
    needed = np.flatnonzero(distinct >= 3)
    triangles = needed[stack.v_count[needed] == 3]
    if len(triangles):
        corners = stack.vertices[stack.v_start[triangles][:, None] + np.arange(3)][:, :, [0, 2]]
        found, clear = rectangle.triangle_angles(corners)
        angle[triangles[clear]] = found[clear]
        needed = np.setdiff1d(needed, triangles[clear])
    ground = stack.vertices[:, [0, 2]]
    for k in needed.tolist():
        angle[k] = rectangle.angle(ground[stack.v_start[k] : stack.v_start[k + 1]])
    return angle


def _turns(angle_deg: np.ndarray) -> np.ndarray:
    """:func:`.components._turn` of each angle: (n, 3, 3), the frame axes as columns."""
    a = np.radians(angle_deg)
    zero, one = np.zeros_like(a), np.ones_like(a)
    x = np.stack([np.cos(a), zero, -np.sin(a)], axis=1)
    y = np.stack([zero, one, zero], axis=1)
    z = np.stack(  # np.cross(x, y), written out as np.cross computes it
        [
            x[:, 1] * y[:, 2] - x[:, 2] * y[:, 1],
            x[:, 2] * y[:, 0] - x[:, 0] * y[:, 2],
            x[:, 0] * y[:, 1] - x[:, 1] * y[:, 0],
        ],
        axis=1,
    )
    return np.stack([x, y, z], axis=2)


def _times(stack: _Stack, axes: np.ndarray) -> np.ndarray:
    """Each slab's vertices times its axes (``vertices @ axes``): stacked over the slabs of
    one vertex count at a time, so that each product is the one a slab alone gives."""
    out = np.empty_like(stack.vertices)
    count = stack.v_count
    for size in np.unique(count).tolist():
        which = np.flatnonzero(count == size)
        rows = stack.v_start[which][:, None] + np.arange(size)
        out[rows] = stack.vertices[rows] @ axes[which]
    return out


def _mesh_keys(stack: _Stack, local: np.ndarray, key_grid: float) -> list[str]:
    """:func:`.components.mesh_key` of every slab's mesh, its vertices ``local``."""
    grid = np.rint(local / key_grid).astype(np.int64)
    n = len(stack.f_start) - 1
    f_count = np.diff(stack.f_start)
    tri_slab = np.repeat(np.arange(n), f_count)
    tri = grid[stack.faces]  # (F, 3, 3)
    corners = tri.reshape(-1, 3)
    rank = np.empty(len(corners), dtype=np.int64)
    rank[np.lexsort((corners[:, 2], corners[:, 1], corners[:, 0], np.repeat(tri_slab, 3)))] = (
        np.arange(len(corners))
    )
    order = np.argmin(rank.reshape(-1, 3), axis=1)
    turn = (np.arange(3)[None, :] + order[:, None]) % 3
    flat = np.take_along_axis(tri, turn[:, :, None], axis=1).reshape(len(tri), 9)
    flat = np.ascontiguousarray(flat[np.lexsort((*flat.T[::-1], tri_slab))])
    data = memoryview(flat).cast("B")  # each slab's rows, as flat.tobytes() gives them
    bounds = (stack.f_start * flat.itemsize * 9).tolist()
    return [hashlib.sha1(data[bounds[k] : bounds[k + 1]]).hexdigest() for k in range(n)]


def building_stacks(
    comps: list[Component], rule_of: list[str], terminal_of: list[int], grid: tuple[float, float]
) -> tuple[dict, list]:
    """The buildings as stacks of components, all at once: ``kinds`` (a signature -> the
    buildings that have it, each (object, frame, placements sorted by key, centre)) and
    ``instances`` ((terminal, frame, size) of each component), as :func:`.pipeline.place`
    made them one building at a time.  ``rule_of`` and ``terminal_of`` name each component's
    type."""
    kinds: dict[bytes, list] = {}
    instances: list = []
    if not comps:
        return kinds, instances
    count = len(comps)
    building = np.array([c.building for c in comps])
    frames = np.stack([c.frame for c in comps])
    sizes = np.stack([c.size for c in comps])
    _, first, inverse = np.unique(building, return_index=True, return_inverse=True)
    appearance = np.argsort(np.argsort(first, kind="stable"), kind="stable")[inverse.reshape(-1)]
    # buildings in order of their first component, each one's components from the lowest
    order = np.lexsort((np.arange(count), frames[:, 1, 3], appearance))
    starts = np.flatnonzero(np.r_[True, np.diff(appearance[order]) != 0])
    ends = np.r_[starts[1:], count]
    which = np.repeat(np.arange(len(starts)), ends - starts)
    angles, offsets = tree.relative_all(frames[order[starts]][which], frames[order])
    rank = np.unique(rule_of, return_inverse=True)[1].reshape(-1)[order]
    keys = tree.keys_all(rank, angles, offsets, sizes[order], grid)
    by_key = np.lexsort((*keys.T[::-1], which))  # within each building, by key (stably)
    centres = (frames[:, :3, :3] @ (sizes / 2)[:, :, None])[:, :, 0] + frames[:, :3, 3]
    for s, e in zip(starts.tolist(), ends.tolist(), strict=True):
        members = order[s:e].tolist()
        placed = [
            tree.Placement(rule_of[i], float(angles[j]), offsets[j], comps[i].size)
            for j, i in enumerate(members, start=s)
        ]
        instances += [(terminal_of[i], comps[i].frame, comps[i].size) for i in members]
        ordering = (by_key[s:e] - s).tolist()
        centre = centres[members[0]] if e - s == 1 else np.mean(centres[members], axis=0)
        lowest = comps[members[0]]
        kinds.setdefault(keys[by_key[s:e]].tobytes(), []).append(
            (lowest.building, lowest.frame, [placed[j] for j in ordering], centre)
        )
    return kinds, instances
