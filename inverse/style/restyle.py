"""Style retargeting onto a given mass (section 5): ``bgr restyle MASS --style STYLE.bgr``.

The mass's structure is found as the source's was (section 4.2: floors, cuts at local maxima of
the floor-area ratio, blocks).  Each of its blocks takes one of the style sheet's source blocks
by the transformation cost of equations 6 and 7 (greedy, bottom to top; the bottom block takes
the source's bottom and the top block its top, the paper's forced matches), and becomes a lot:
the outline of its first floor, at its base height, extruded to its height by the sheet's
``Lot`` rule with ``block`` naming the source block, so that the block's walls are split by that
block's rules (equations 8 and 9) in the grammar itself.

Deviation: a mass of **one** block from a source of several takes them all, stacked (the
sheet's ``Stack``: bottom and top blocks at their own heights, those between stretched).  The
paper's forced matches give the single block both the source's bottom and its top block; taking
the bottom one alone, as the greedy order would, put a 7 m ground floor's rows eight times up a
60 m slab and dropped every upper storey of the look.
"""

from __future__ import annotations

import os
from collections.abc import Iterable

import numpy as np

from bgr.grammar import nodes as n
from bgr.grammar.checker import Grammar
from bgr.grammar.errors import BgrError, Diagnostic
from bgr.grammar.parser import no_gc

STACK = -2
"""The sheet's ``block`` value for all source blocks stacked on one target block."""


def shape_cost(source: tuple[float, float, float], target: tuple[float, float, float]) -> float:
    """Equation 7: each block's (width, height, depth) normalised to sum 1, and the product
    over the three dimensions of the larger-over-smaller ratio."""
    s = np.asarray(source, float) / float(np.sum(source))
    t = np.asarray(target, float) / float(np.sum(target))
    return float(np.prod(np.maximum(s / t, t / s)))


def relative_volumes(blocks: list[tuple[float, float, float]]) -> np.ndarray:
    """vol-bar of section 5.1.1: each block's volume over its building's total."""
    v = np.array([w * h * d for w, h, d in blocks], float)
    return v / v.sum()


def match_blocks(
    source: list[tuple[float, float, float]], target: list[tuple[float, float, float]]
) -> list[int]:
    """For each target block (bottom to top), the source block of least Psi = Psi_shape x
    Psi_volume (equation 6).  The bottom target block takes the source's bottom block and the
    top target block its top one; a block between them chooses among the source's middle
    blocks (the paper: its bottom and top have shapes and textures found nowhere else), or
    among all of them when the source has none."""
    if not source or not target:
        return []
    vs, vt = relative_volumes(source), relative_volumes(target)
    middle = list(range(1, len(source) - 1)) or list(range(len(source)))
    out = []
    for j, t in enumerate(target):
        if j == 0:
            out.append(0)
        elif j == len(target) - 1:
            out.append(len(source) - 1)
        else:
            costs = [
                shape_cost(source[i], t) * max(vs[i], vt[j]) / min(vs[i], vt[j]) for i in middle
            ]
            out.append(middle[int(np.argmin(costs))])
    return out


def source_blocks(grammar, prefix: str = "") -> list[tuple[float, float, float]]:
    """The source blocks' sizes a style sheet records (``const block0_width`` ...)."""
    out = []
    k = 0
    while f"{prefix}block{k}_width" in grammar.consts:
        size = []
        for what in ("width", "height", "depth"):
            value = grammar.consts.get(f"{prefix}block{k}_{what}")
            if value is None or not isinstance(value.value, n.Number):
                break
            size.append(float(value.value.value))
        if len(size) != 3 or min(size) <= 0:
            break
        out.append((size[0], size[1], size[2]))
        k += 1
    if not out:
        raise BgrError(
            Diagnostic(
                grammar.path,
                0,
                0,
                "not a style sheet: it records no source blocks (const block0_width, ...)",
                "give a grammar written by bgr infer --kind style",
            )
        )
    return out


def _front_first(ring: np.ndarray) -> np.ndarray:
    """The ring turned to start at its front edge: the longest of the edges facing -z."""
    ring = np.asarray(ring, float)
    if len(ring) > 1 and np.allclose(ring[0], ring[-1]):
        ring = ring[:-1]
    edges = np.roll(ring, -1, axis=0) - ring
    length = np.hypot(edges[:, 0], edges[:, 1])
    centre = ring.mean(axis=0)
    mid = ring + edges / 2
    # an edge faces -z when its midpoint lies on the -z side of the centre and it runs along x
    facing = (mid[:, 1] < centre[1]) & (np.abs(edges[:, 0]) >= np.abs(edges[:, 1]))
    score = np.where(facing, length, -1.0)
    k = int(np.argmax(score)) if facing.any() else int(np.argmin(mid[:, 1]))
    return np.roll(ring, -k, axis=0)


def thinnest(ring: np.ndarray, samples: int = 5) -> tuple[float, float]:
    """(r_x, r_z): the footprint's thinnest extent behind its walls facing x (and z) over its
    bounding box's extent along x (z); 1 for a rectangle.  Each edge is sampled at ``samples``
    points; from each the polygon is crossed inward along the edge's normal, and the length of
    the crossing that starts there is its extent behind the wall.  The sheet's recesses are
    scaled by them (emit.py), so that none reaches through an arm of an L."""
    import shapely

    ring = np.asarray(ring, float)
    if len(ring) > 1 and np.allclose(ring[0], ring[-1]):
        ring = ring[:-1]
    poly = shapely.Polygon(ring)
    xmin, zmin, xmax, zmax = poly.bounds
    extent = np.array([xmax - xmin, zmax - zmin])
    if len(ring) < 3 or min(extent) <= 0:
        return 1.0, 1.0
    edges = np.roll(ring, -1, axis=0) - ring
    axis = (np.abs(edges[:, 1]) > np.abs(edges[:, 0])).astype(int)  # 0: across x, 1: across z
    axis = 1 - axis  # an edge along x faces z: its extent behind is along z
    t = (np.arange(samples) + 0.5) / samples
    starts = (ring[:, None, :] + t[None, :, None] * edges[:, None, :]).reshape(-1, 2)
    normal = np.zeros((len(ring), 2))
    normal[np.arange(len(ring)), axis] = 1.0
    normal = np.repeat(normal, samples, axis=0)
    reach = 2.0 * float(max(extent))
    tol = 1e-6 * reach
    forward = shapely.contains_xy(poly, *(starts + 10 * tol * normal).T)
    normal[~forward] *= -1.0  # inward
    rays = shapely.linestrings(np.stack([starts + tol * normal, starts + reach * normal], axis=1))
    parts, index = shapely.get_parts(shapely.intersection(rays, poly), return_index=True)
    first = shapely.distance(parts, shapely.points(starts[index] + tol * normal[index])) < 2 * tol
    length = np.full(len(starts), np.inf)
    np.minimum.at(length, index[first], shapely.length(parts[first]) + tol)
    across = np.repeat(axis, samples)
    out = []
    for a in (0, 1):
        mine = length[(across == a) & np.isfinite(length)]
        out.append(float(np.clip(mine.min() / extent[a], 0.0, 1.0)) if mine.size else 1.0)
    return out[0], out[1]


@no_gc()  # numpy work and a derivation, no cycles: a full collection took 0.25 s of a restyle
def restyle(
    mass: str,
    style: str | Grammar,
    seed: int = 0,
    section: int = 0,
    allow_paths: Iterable[str | os.PathLike] = (),
):
    """The styled mass (a bgr.interpreter.derive.Result) and a one-line report.  ``style`` is
    the sheet's path (then only its section ``section`` is loaded and checked, where the sheet
    is laid out as bgr infer writes it: sections.py) or the sheet already loaded (a sheet of
    many buildings takes seconds to load: put each of its sections on many masses with one
    load)."""
    from bgr.interpreter.derive import derive
    from bgr.interpreter.lots import footprint

    from .capture import read_model
    from .remesh import capture_geometry
    from .sections import load_section

    if isinstance(style, Grammar):
        grammar, alone = style, False
    else:  # the section alone when the sheet is laid out as emit writes it (sections.py)
        grammar, alone = load_section(style, section, allow_paths)
    several = alone or "S0block0_width" in grammar.consts
    if (
        section
        and not several
        or section < 0
        or several
        and f"S{section}block0_width" not in grammar.consts
    ):
        raise BgrError(
            Diagnostic(
                grammar.path,
                0,
                0,
                f"--section {section}: the style sheet holds no captured building of that number",
                "count its sections from 0 (its attr style)",
            )
        )
    prefix = f"S{section}" if several else ""
    sources = source_blocks(grammar, prefix)
    mesh = read_model(mass)
    capture, frame = capture_geometry(mesh, None)
    scale = capture.scale
    targets = [tuple(v * scale for v in b.size) for b in capture.blocks]
    matched = match_blocks(sources, targets)  # type: ignore[arg-type]
    if len(targets) == 1 and len(sources) > 1:
        matched = [STACK]  # both forced matches at once: every source block, stacked
    lots = []
    for j, block in enumerate(capture.blocks):
        ring = _front_first(capture.contours[block.levels[0]])
        points = np.column_stack([ring[:, 0], np.full(len(ring), block.bottom), ring[:, 1]])
        world = frame.unapply(points)
        base = float(world[:, 1].mean())
        rx, rz = thinnest(ring)
        lots.append(
            footprint(
                [(float(x), float(z)) for x, _, z in world],
                {
                    **({"style": section} if several else {}),
                    "block": matched[j],
                    "block_base": base,
                    "block_height": (block.top - block.bottom) * scale,
                    "recess_x": rx,
                    "recess_z": rz,
                },
                name=f"block {j}",
            )
        )
    result = derive(grammar, seed=seed, lot=lots)
    pairs = ", ".join(f"{j}<-{'all' if i == STACK else i}" for j, i in enumerate(matched))
    return result, f"{len(lots)} blocks styled by source blocks ({pairs})"
