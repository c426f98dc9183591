"""``bgr infer --kind city``: read, cut, type, group, write (the paper's Figure 2 pipeline).

:func:`infer_city` runs the phases with a progress bar each and returns the grammar's syntax
tree, its assets (GLB bytes by file name) and, on request, statistics for every level.
"""

from __future__ import annotations

import io
import sys
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from bgr.grammar import nodes as n
from bgr.grammar.errors import BgrError
from bgr.grammar.parser import no_gc
from bgr.grammar.safe_text import comment_text
from bgr.grammar.site import crs_name
from bgr.interpreter.limits import check_memory, restart_memory

from . import emit, tree
from .batch import building_stacks, decompose_all
from .carried import Carried, carry
from .components import TOLERANCE, Component, digits_for, grid_mesh, key_grid
from .container import Mesh, pack
from .houses import roofed
from .model import CityScene
from .prisms import fit_prism
from .types import Level, Types, cluster, level_for
from .uncut import uncut_unique

MESHES = "meshes.glb"  # the one file of the assets folder: every type's mesh, a node each
READ_COST = 10  # memory per byte of a text city file (OBJ, CityJSON) read, at least (20 measured)


@dataclass
class Options:
    """Everything the command line can set (docs/inverse-city.md)."""

    up: str = "auto"
    level: int | None = None
    threshold: float | None = None
    feature_weights: dict[str, float] | None = None
    w_mu: float = 1.0  # equation 11
    w_sigma: float = 1.0
    tau: float | None = None  # neighbour distance (equation 3); default from the data
    representative: str = "mean"  # or "fewest" (triangles)
    tolerance: float = TOLERANCE  # metres: level 0's bound (components.key_grid)
    assets: str = "city.assets"  # the assets folder as the grammar names it
    compress: bool = True  # the assets GLB quantized and meshopt-compressed (container.py)
    lod: str | None = None  # CityJSON: the level of detail read (None: each object's highest)
    progress: bool = True
    seed: int = 0


@dataclass
class Placed:
    """The city at one level, before it is written: everything the grammar says."""

    level: Level
    terminals: list[emit.Terminal]
    term_mesh: list[Component]  # the representative component of each terminal
    rules: list[tree.Rule]
    city: list[tree.Placement]
    units: list[emit.Unit]
    carried: list[Carried]  # the objects that are not buildings, a mesh for each kind
    instances: list[tuple[int, np.ndarray, np.ndarray]]  # (terminal, world frame, size) each
    tau: float
    components: int  # placed: at level 0, a building whose slabs were all unique counts once


@dataclass
class CityGrammar:
    module: n.Module
    assets: dict[str, bytes]  # file name (inside the assets folder) -> GLB
    scene: CityScene
    comps: list[Component]
    placed: Placed
    types: Types
    stats: list[dict] = field(default_factory=list)


class _Bar(tqdm):
    """A phase's progress bar that also holds the phase to the memory ceiling (--max-memory,
    :func:`bgr.interpreter.limits.check_memory`): every phase of a long run updates one."""

    EVERY = 64  # updates between two looks at the process's memory (a look: ~10 us)

    def __init__(self, *args, step: str = "", **kwargs) -> None:
        self.step, self.looks = step, 0  # a disabled tqdm keeps no desc
        super().__init__(*args, **kwargs)

    def update(self, n: float | None = 1) -> bool | None:
        self.looks += 1
        if self.looks % self.EVERY == 1:
            check_memory(self.step)
        return super().update(n)


def _bar(options: Options, total: int, what: str) -> tqdm:
    return _Bar(
        step=what,
        total=total,
        desc=what,
        unit="",
        disable=not options.progress,
        file=sys.stderr,
        leave=False,
        dynamic_ncols=True,
    )


def decompose(scene: CityScene, options: Options) -> list[Component]:
    """Every building object cut into components (cut planes, slabs, boxes): all objects at
    once (:mod:`.batch`), as cutting and fitting each in turn would."""
    with _bar(options, len(scene.objects), "cutting buildings") as bar:
        return decompose_all(scene.objects, bar.update, key_grid(options.tolerance))


def place(
    scene: CityScene, comps: list[Component], types: Types, level: Level, options: Options
) -> Placed:
    """The grammar's content at one level: terminals, building kinds, groups, the axiom.  At
    level 0 a building cut into slabs that are each of a type of their own is whole again
    (:mod:`.uncut`)."""
    if level.index == 0:
        key = key_grid(options.tolerance)
        comps, types = uncut_unique(scene.objects, comps, types, options.tolerance, key)
        comps, types = roofed(scene.objects, comps, types, options.tolerance, key)
        level = types.levels[0]
    of_comp = level.of_base[types.base_of]
    count = np.bincount(of_comp, minlength=len(level.representative))
    order = sorted(range(len(count)), key=lambda t: (-count[t], t))
    name_of = {t: f"Type{i + 1}" for i, t in enumerate(order)}
    terminals, term_mesh = [], []
    low_of, high_of = _size_ranges(comps, of_comp, len(count))
    for i, t in enumerate(order):
        rep = comps[types.base_first[level.representative[t]]]
        low, high = low_of[t], high_of[t]
        # a type whose instances are all its representative's size may be written as the
        # operations that make it; one whose instances differ is a mesh fitted to each box
        same = bool(np.all(high - low <= key_grid(options.tolerance)))
        house = rep.house if same else None
        prism = fit_prism(rep, options.tolerance) if same and house is None else None
        span = " x ".join(
            f"{a:.1f}" if abs(a - b) < 0.05 else f"{a:.1f}-{b:.1f}"
            for a, b in zip(low, high, strict=True)
        )
        terminals.append(
            emit.Terminal(
                name_of[t],
                f"type{i + 1}",
                f"{options.assets}/{MESHES}#type{i + 1}",
                _colour(rep),
                # an extrusion's numbers say its size; a mesh's comment says it
                ", ".join(
                    ([f"{count[t]} instances"] if count[t] > 1 else [])
                    + ([] if prism or house else [f"{span} m"])
                ),
                prism,
                house,
            )
        )
        term_mesh.append(rep)
    terminal_index = {t: i for i, t in enumerate(order)}
    grid = tree._grid(level.index)
    exact = level.index == 0

    # buildings: stacks of components in the frame of the lowest
    kinds, instances = building_stacks(
        comps,
        [name_of[int(t)] for t in of_comp],
        [terminal_index[int(t)] for t in of_comp],
        grid,
    )
    # building kinds, most used first
    kind_list = sorted(kinds.values(), key=lambda v: (-len(v), v[0][0]))
    rules: list[tree.Rule] = []
    leaves: dict[int, list[tree.Instance]] = {}
    units: list[emit.Unit] = []
    kind_of = np.empty(0, dtype=np.int64)
    mids = []
    kind_ids = []
    for k, found in enumerate(kind_list):
        name = f"Building{k + 1}"
        children = found[0][2] if exact else tree._average([f[2] for f in found])
        rules.append(
            tree.Rule(
                name,
                children,
                len(found),
                f"{len(found)} instances" if len(found) > 1 else "",
            )
        )
        low, high = _extent(children)
        units.append(emit.Unit(name, len(found), low, high))
        leaves[k] = [tree.Instance(name, f[1], f[3]) for f in found]
        for f in found:
            mids.append(f[3])
            kind_ids.append(k)
    kind_of = np.array(kind_ids, dtype=np.int64)
    midpoints = np.array(mids).reshape(-1, 3)
    tau = options.tau if options.tau is not None else tree.neighbour_radius(midpoints)
    graph = tree.kind_graph(kind_of, midpoints, tau, options.w_mu, options.w_sigma)
    shape = tree.communities(graph, options.seed)

    groups: list[tree.Rule] = []

    def new_rule(children: list[tree.Placement], uses: int) -> str:
        name = f"Group{len(groups) + 1}"
        groups.append(
            tree.Rule(
                name,
                children,
                uses,
                f"neighbourhood pattern {len(groups) + 1}: {uses} instances of "
                + " ".join(p.rule for p in children),
            )
        )
        low, high = _extent(children, {u.rule: u for u in units})
        units.append(emit.Unit(name, uses, low, high))
        return name

    top: list[tree.Instance] = []
    for part in shape:
        top += tree.group(part, leaves, tau, grid, new_rule)
    city = _axiom(top)

    carried = carry(scene, f"{options.assets}/{MESHES}", _colour_of)
    repeated = synthesis_units(units)
    return Placed(
        level,
        terminals,
        term_mesh,
        groups + rules,
        city,
        repeated,
        carried,
        instances,
        tau,
        len(comps),
    )


def _axiom(top: list[tree.Instance]) -> list[tree.Placement]:
    """What the axiom places: the instances that reached the top, by rule and position (to the
    millimetre), each turned by its frame's angle; the angles and positions of all at once."""
    if not top:
        return []
    frames = np.stack([inst.frame for inst in top])
    where = np.round(frames[:, :3, 3], 3).tolist()
    angles = np.degrees(np.arctan2(-frames[:, 2, 0], frames[:, 0, 0])).tolist()  # turn_of
    order = sorted(range(len(top)), key=lambda k: (top[k].rule, *where[k]))
    return [tree.Placement(top[k].rule, angles[k], top[k].frame[:3, 3]) for k in order]


def _size_ranges(
    comps: list[Component], of_comp: np.ndarray, types: int
) -> tuple[np.ndarray, np.ndarray]:
    """The least and greatest size (per axis) of each type's components: one grouping of all
    components, not a pass over them for each type."""
    low, high = np.zeros((types, 3)), np.zeros((types, 3))
    if not comps:
        return low, high
    sizes = np.stack([c.size for c in comps])
    order = np.argsort(of_comp, kind="stable")
    present, starts = np.unique(of_comp[order], return_index=True)
    low[present] = np.minimum.reduceat(sizes[order], starts, axis=0)
    high[present] = np.maximum.reduceat(sizes[order], starts, axis=0)
    return low, high


def synthesis_units(units: list[emit.Unit], most: int = 12) -> list[emit.Unit]:
    """What synthesis puts on new lots: the buildings and groups the city repeats (or all of them
    when it repeats none), without the flat ones (under 2 m: roads, terrain, water read as
    objects) and the ones over twice the median width (a plot that size swallows a lot), the
    ``most`` most used."""
    standing = [u for u in units if u.high[1] - u.low[1] >= 2.0] or units
    widths = np.array([u.high[0] - u.low[0] for u in standing])
    typical = [u for u, w in zip(standing, widths, strict=True) if w <= 2 * np.median(widths)]
    chosen = [u for u in typical if u.uses > 1] or typical
    return sorted(chosen, key=lambda u: -u.uses)[:most]


def _extent(
    children: list[tree.Placement], units: dict | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The corners of the boxes a rule places, in the rule's own frame."""
    points = []
    for p in children:
        a = np.radians(p.angle)
        rot = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
        if p.size is not None:
            low, high = np.zeros(3), p.size
        elif units and p.rule in units:
            low, high = units[p.rule].low, units[p.rule].high
        else:
            low = high = np.zeros(3)
        corners = np.array(
            [
                [x, y, z]
                for x in (low[0], high[0])
                for y in (low[1], high[1])
                for z in (low[2], high[2])
            ]
        )
        points.append(corners @ rot.T + p.offset)
    allp = np.concatenate(points) if points else np.zeros((1, 3))
    return allp.min(axis=0), allp.max(axis=0)


def _count(number: int, noun: str) -> str:
    return f"{number} {noun}{'s' if number != 1 else ''}"


def _colour(comp: Component) -> str | None:
    return _colour_of(comp.colors)


def _colour_of(colors: np.ndarray | None) -> str | None:
    """The most common face colour, as ``#rrggbb``; None without colours."""
    if colors is None or len(colors) == 0:
        return None
    values, counts = np.unique(np.asarray(colors)[:, :3], axis=0, return_counts=True)
    r, g, b = values[int(np.argmax(counts))]
    return f"#{int(r):02x}{int(g):02x}{int(b):02x}"


def _reading_cost(path: str | Path) -> int:
    """The memory reading a city file takes, at least: READ_COST times its size (0 when it
    cannot be seen: the reader says why)."""
    try:
        size = Path(path).stat().st_size
    except (OSError, ValueError):
        return 0
    text = str(path).lower().endswith((".obj", ".json", ".jsonl"))
    return size * (READ_COST if text else 1)


@no_gc()
def infer_city(
    path: str | Path, options: Options | None = None, *, stats: bool = False
) -> CityGrammar:
    """The grammar of a city model (see the module docstring and docs/inverse-city.md)."""
    options = options or Options()
    from .read import read_city

    restart_memory()  # the ceiling (--max-memory) counts from here, the modules loaded
    check_memory("reading the city", _reading_cost(path))
    scene = read_city(path, up=options.up, lod=options.lod)
    check_memory("reading the city")
    comps = decompose(scene, options)
    if not comps and not scene.objects:
        raise BgrError(f"{path}: no buildings to proceduralize")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # k-means' empty clusters are dropped by cluster()
        bar = _bar(options, len({c.key for c in comps}), "typing components")
        with bar:
            types = cluster(
                comps,
                progress=bar,
                feature_weights=options.feature_weights,
                representative=options.representative,
                seed=options.seed,
            )
    level = level_for(types, level=options.level, threshold=options.threshold)
    placed = place(scene, comps, types, level, options)
    check_memory("placing components")
    return build(scene, comps, types, placed, options)


def build(
    scene: CityScene, comps: list[Component], types: Types, placed: Placed, options: Options
) -> CityGrammar:
    named = []
    digits = digits_for(options.tolerance)
    if placed.level.index > 0:  # a lossy level: lengths no finer than it moves things
        digits = min(digits, tree.level_digits(placed.level.index))
    with _bar(options, len(placed.terminals) + len(placed.carried), "writing meshes") as bar:
        for t, rep in zip(placed.terminals, placed.term_mesh, strict=True):
            if not t.operations:  # a footprint extruded (and roofed) is written as operations
                named.append(Mesh(t.asset, *grid_mesh(rep.vertices, rep.faces, digits)))
            bar.update()
        for kind in placed.carried:
            named.append(kind.mesh(digits, options.compress))
            bar.update()
    packed = pack(
        named,
        "bgr infer --kind city",
        compress=options.compress,
        step=10.0**-digits,  # the grammar's grid: a mesh on it is stored exactly
        coarsest=options.tolerance / 4,  # a mesh too large for 16 bits of that keeps floats
    )
    assets = {MESHES: packed} if named else {}
    header = _header(scene, comps, types, placed)
    module = emit.module(
        header,
        placed.terminals,
        placed.rules,
        placed.city,
        placed.units,
        [(c.terminal, c.placement) for c in placed.carried],
        site_of(scene),
        exact=placed.level.index == 0,
        digits=digits,
    )
    return CityGrammar(module, assets, scene, comps, placed, types)


def _header(scene: CityScene, comps: list[Component], types: Types, placed: Placed) -> list[str]:
    extruded = sum(t.prism is not None for t in placed.terminals)
    roofed_types = sum(t.house is not None for t in placed.terminals)
    lines = [
        f"# Inferred by bgr infer --kind city from {comment_text(Path(scene.source).name)}: "
        f"{len(scene.objects)} objects,",
        f"# {placed.components} components in {len(placed.terminals)} types (level "
        f"{placed.level.index} of {len(types.levels) - 1}), {len(placed.rules)} non-terminal "
        "rules;",
        f"# {extruded} of the types are footprints extruded (polygon, extrude), "
        + (
            f"{roofed_types} house{'s' if roofed_types > 1 else ''} (polygon, extrude, roof), "
            if roofed_types
            else ""
        )
        + "the others meshes;",
        "# a mesh type's comment gives its size (width x height x depth), and any type's its "
        "instances where several.",
    ]
    if site_of(scene) is not None:
        lines.append(
            "# The site line puts bgr derive's output back at the input's coordinates (bgr's own "
            "are y up, local)."
        )
    elif scene.crs:  # a CRS pyproj does not know: said, not declared
        lines.append(f"# The input names its CRS as {comment_text(scene.crs)}.")
    return lines


def site_of(scene: CityScene) -> n.Site | None:
    """The grammar's ``site`` declaration (grammar/site.py): the input's CRS (as EPSG:NNNN where
    pyproj can name it so), its up axis and the exact offset its coordinates were re-centred
    by; None for an input in plain local metres with y up, bgr's own frame (a z-up input near
    the origin still needs ``up z`` to come back in its own axes)."""
    crs = crs_name(scene.crs) if scene.crs else None
    if crs is None and not np.any(scene.offset) and scene.up == "y":
        return None
    x, y, z = (float(v) for v in scene.offset)
    return n.Site(crs, (x, y, z), scene.up)


@no_gc()
def to_text(grammar: CityGrammar) -> str:
    from bgr.grammar.formatter import format_module

    buffer = io.StringIO()
    buffer.write(format_module(grammar.module))
    return buffer.getvalue()


def write(
    grammar: CityGrammar,
    text: str,
    output: Path | None,
    assets_dir: Path,
    keep: tuple[Path, ...] = (),
) -> None:
    """Write the assets folder and the grammar (``output``; None: standard output), all or
    nothing.

    The assets go in a fresh folder beside their place, swapped in whole with a manifest of
    the files bgr wrote (formats/assets_folder.py): a folder bgr did not write is refused, never
    replaced, and a failure (the grammar's write included) puts the old folder back.  ``keep``:
    paths the folder must not hold (the input).
    """
    from bgr.formats.assets_folder import assets_written
    from bgr.formats.atomic import write_text

    keep = (*keep, *(() if output is None else (Path(output),)))
    with assets_written(
        Path(assets_dir), grammar.assets, keep=keep, written_by="bgr infer --kind city"
    ):
        if output is None:
            sys.stdout.write(text)
        else:
            write_text(Path(output), text)


def rebuilt(placed: Placed) -> tuple[np.ndarray, np.ndarray]:
    """The triangles the grammar of ``placed`` derives on the default lot (each component type's
    mesh fitted to each instance's box, and the carried objects), computed directly."""
    verts, faces, count = [], [], 0
    for terminal, frame, size in placed.instances:
        rep = placed.term_mesh[terminal]
        scale = np.divide(size, rep.size, out=np.ones(3), where=rep.size > 1e-12)
        world = (rep.vertices * scale) @ frame[:3, :3].T + frame[:3, 3]
        verts.append(world)
        faces.append(rep.faces + count)
        count += len(world)
    for kind in placed.carried:
        verts.append(kind.vertices + kind.placement.offset)
        faces.append(kind.faces + count)
        count += len(verts[-1])
    if not verts:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    return np.concatenate(verts), np.concatenate(faces)


def level_stats(source: str | Path, grammar: CityGrammar, options: Options) -> list[dict]:
    """For every level: the counts of the paper's Table 1, sizes, and the geometric error of
    the derived city against the input (symmetric Hausdorff and Chamfer distances)."""
    from .distance import surface_distances

    scene, types = grammar.scene, grammar.types
    comps = grammar.comps
    parts = list(scene.objects)
    in_v = np.concatenate([o.vertices for o in parts]) if parts else np.zeros((0, 3))
    offsets = np.cumsum([0] + [len(o.vertices) for o in parts])
    in_f = (
        np.concatenate([o.faces + offsets[i] for i, o in enumerate(parts)])
        if parts
        else np.zeros((0, 3), dtype=np.int64)
    )
    rows = []
    for level in types.levels:
        placed = place(scene, comps, types, level, options)
        built = build(scene, comps, types, placed, options)
        text = to_text(built)
        out_v, out_f = rebuilt(placed)
        d = surface_distances(in_v, in_f, out_v, out_f)
        rows.append(
            {
                "level": level.index,
                "components": placed.components,
                "terminals": len(placed.terminals) + len(placed.carried),
                "nonterminals": len(placed.rules) + 3,  # and Lot, City, Synthesis
                "rules": len(placed.rules) + 4 + len(placed.terminals) + len(placed.carried),
                "input_triangles": int(len(in_f)),
                "output_triangles": int(sum(len(m.faces) for m in placed.term_mesh))
                + int(sum(len(kind.faces) for kind in placed.carried)),
                "input_bytes": Path(source).stat().st_size,
                "output_bytes": len(text.encode()) + sum(len(b) for b in built.assets.values()),
                "hausdorff": d.hausdorff,
                "chamfer": d.chamfer,
            }
        )
    return rows
