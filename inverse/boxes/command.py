"""``bgr retarget`` and ``bgr infer --kind boxes``: the command-line side."""

from __future__ import annotations

import math
import re
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from bgr.formats.atomic import cannot_write
from bgr.formats.atomic import write_text as write_atomic
from bgr.grammar.errors import BgrError, Diagnostic, terminal_text
from bgr.grammar.formatter import format_module
from bgr.grammar.paths import check_input, check_output, roots_of, within
from bgr.interpreter.limits import restart_memory

from .analysis import min_length
from .emit import ATTRS, write
from .model import AXES, EPS, MAX_BOXES, MAX_CHILDREN, Box, dumps, read
from .retarget import alignments, check_order, retarget

USAGE = 2
# the sizes infer checks its grammar at, as fractions of the input's (contraction and stretch)
CHECK_SCALES = (0.6, 1.5, 2.5)


def parse_size(text: str) -> tuple[float, float, float]:
    parts = [p.strip() for p in text.split(",")]
    try:
        values = [float(p) for p in parts if "_" not in p]
    except ValueError:
        values = []
    if len(values) != 3 or not all(0 < v < 1e6 for v in values):
        raise ValueError(f"--size {text}: write three lengths in metres, W,H,D (x, y up, z)")
    return values[0], values[1], values[2]


def run_retarget(args) -> int:
    try:
        size = parse_size(args.size)
        check_order(args.order)
    except (ValueError, BgrError) as e:
        print(f"bgr retarget: {terminal_text(str(getattr(e, 'message', e)))}", file=sys.stderr)
        return USAGE
    out = None if args.output in (None, "-") else Path(args.output)
    if out is not None and not (out.name.lower().endswith(".json") and not _mesh_json(out)):
        from bgr.formats import format_of

        format_of(out)  # an output bgr cannot write is refused before the work, not after it
    source = Path(args.input)
    restart_memory()  # the ceiling (--max-memory) counts from here, the modules loaded
    # refused here when too large to analyse, before any work on pairs of boxes
    root = read(source, max_boxes=args.max_boxes, max_children=MAX_CHILDREN)
    try:
        result = retarget(root, size, args.order, max_boxes=args.max_boxes)
        kept, total = alignments(root, result)
        if out is None or out.name.lower().endswith(".json") and not _mesh_json(out):
            text = dumps(result)
            if out is None:
                sys.stdout.write(text)
            else:
                write_atomic(out, text)
        else:
            save_mesh(result, roots_of(source.parent, args.allow_path), source.parent, out)
    except BgrError as e:
        raise located(e, source) from None
    boxes = sum(1 for _ in result.walk())
    print(
        f"{terminal_text(args.output or '<stdout>', keep='')}: {boxes} boxes "
        f"({sum(1 for _ in root.walk())} in the input), "
        f"{_size(result)}; {kept} of {total} alignments kept",
        file=sys.stderr,
    )
    return 0


def located(error: BgrError, source: Path) -> BgrError:
    """``error`` about the boxes file ``source`` where it names no file of its own, so that it
    prints as every bgr command's errors do: ``source: error: message``, then ``hint:``."""
    if error.path:
        return error
    return BgrError([replace(d, path=str(source)) for d in error.diagnostics])


def _mesh_json(path: Path) -> bool:
    return path.name.lower().endswith(".city.json")


def _size(box: Box) -> str:
    return " x ".join(f"{v:g}" for v in box.size) + " m"


def save_mesh(result: Box, roots: tuple[Path, ...], base: Path, out: Path) -> None:
    """Each box with a mesh gets its part fitted; each leaf without one, a cube (labelled with
    the box's source id), written by extension like bgr derive's outputs.  Colours tell the
    parts apart (:func:`colour`); a part's recessed pieces (a window's pane, a door's leaf) get
    the part's colour and the rest (its frame of wall) the wall's."""
    from bgr.formats import write as write_table
    from bgr.interpreter.geometry.meshes import primitive
    from bgr.interpreter.terminals import TerminalTable, UnitMesh

    table = TerminalTable()
    parts: dict[str, list[tuple[int, bool]]] = {}  # mesh -> (library id, infill) pieces
    cube = [(table.library.add(UnitMesh("cube", *primitive("cube"))), True)]
    for box in result.walk():
        if box.children and not box.mesh:
            continue
        if box.mesh:
            if box.mesh not in parts:
                pieces = _pieces(_load_part(roots, base, box.mesh))
                parts[box.mesh] = [(table.library.add(m), infill) for m, infill in pieces]
            meshes = parts[box.mesh]
        else:
            meshes = cube
        for mesh, infill in meshes:
            table.label.append(box.source)
            table.rule.append(box.source)
            table.path.append(box.id)
            table.origin.append(box.lo.tolist())
            table.axes.append(np.eye(3).tolist())
            table.size.append(box.size.tolist())
            table.color.append(colour(box) if infill else shade(COLOURS["wall"], box))
            table.material.append(None)
            table.mesh.append(mesh)
    table.freeze()
    write_table(table, out, seed=0, attrs={})


def _load_part(roots: tuple[Path, ...], base: Path, mesh: str):
    """A box's part, read only from under ``roots`` (as a grammar's assets are)."""
    import trimesh

    from bgr.interpreter.terminals import UnitMesh

    path = base / mesh
    if not within(path, roots):
        raise BgrError(
            Diagnostic(
                "",
                0,
                0,
                f"mesh '{mesh}' is outside the boxes file's folder ({base})",
                "let bgr read it with --allow-path DIR",
            )
        )
    check_input(path, "mesh")
    if not path.is_file():
        raise BgrError(f"mesh '{mesh}' not found (looked for {path})")
    try:
        loaded: Any = trimesh.load(path, force="mesh")
        verts = np.asarray(loaded.vertices, dtype=np.float64)
        faces = np.asarray(loaded.faces)
    except Exception as e:  # any reader failure is the file's fault
        raise BgrError(f"cannot read mesh '{mesh}': {e}") from None
    if len(verts) == 0:
        raise BgrError(f"mesh '{mesh}' has no geometry")
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    unit = (verts - lo) / np.where(hi - lo > 0, hi - lo, 1.0)
    return UnitMesh(Path(mesh).stem, unit, faces)


def _pieces(part) -> list[tuple[Any, bool]]:
    """A part as (mesh, infill) pieces: its connected pieces that touch neither the front nor
    the back of its box (z 0 and 1: a pane, a door leaf, a shop window) are its infill, the
    rest its frame.  A part with no such piece, or all of them, is one infill piece."""
    import trimesh
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from bgr.interpreter.terminals import UnitMesh

    faces, verts = part.faces, part.vertices
    if len(faces) == 0:
        return [(part, True)]
    # pieces are faces joined by edges (pieces may share a corner vertex)
    pairs = trimesh.Trimesh(verts, faces, process=False).face_adjacency
    graph = coo_matrix(
        (np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(faces), len(faces))
    )
    _, piece = connected_components(graph, directed=False)
    z = verts[faces][:, :, 2]
    inner = [
        k for k in np.unique(piece) if z[piece == k].min() > 1e-6 and z[piece == k].max() < 1 - 1e-6
    ]
    infill = np.isin(piece, inner)
    if infill.all() or not infill.any():
        return [(part, True)]
    return [
        (UnitMesh(f"{part.name}-{what}", verts, faces[keep]), keep is infill)
        for what, keep in (("frame", ~infill), ("infill", infill))
    ]


# What a box is, by the words of its source id or its mesh's name (the first that matches), and
# the colour each kind gets: glass, wood and stone apart from the wall at a glance.
KINDS = (
    ("door", ("door", "entrance", "entry", "lobby", "gate")),
    ("shop", ("shop", "store", "vitrine")),
    ("window", ("window", "wide", "narrow", "glass", "pane", "glazing")),
    ("trim", ("sill", "lintel", "cornice", "ledge", "trim", "frame", "band", "parapet")),
    ("porch", ("porch", "canopy", "balcony", "stair")),
    ("roof", ("roof",)),
)
COLOURS = {
    "wall": (0.80, 0.68, 0.55),  # warm render
    "trim": (0.94, 0.92, 0.86),  # pale stone
    "window": (0.27, 0.40, 0.54),  # blue glass
    "shop": (0.44, 0.62, 0.68),  # shop glass, lighter and greener
    "door": (0.40, 0.24, 0.14),  # wood
    "porch": (0.58, 0.58, 0.56),  # concrete
    "roof": (0.45, 0.30, 0.26),  # tiles
}


def kind(box: Box) -> str:
    """The kind of part a box is (a key of COLOURS) by the last word of its mesh's name, else
    of its source id, that names one; wall when none does."""
    for text in (Path(box.mesh).stem if box.mesh else "", box.source):
        # the last word that names a kind: ids go from the whole to the part (door-bay-cornice)
        for word in reversed(re.sub(r"[-_~.\d]+", " ", text).lower().split()):
            for name, keys in KINDS:
                if any(k in word for k in keys):
                    return name
    return "wall"


def colour(box: Box) -> tuple[float, float, float]:
    """A box's colour: its kind's (:data:`COLOURS`), a shade lighter or darker by its place."""
    return shade(COLOURS[kind(box)], box)


def shade(rgb: tuple[float, float, float], box: Box) -> tuple[float, float, float]:
    """``rgb`` a little lighter or darker in a checkerboard of the box's own size (its place
    along each axis counted in its lengths), so that neighbours of a kind, a window and its
    copy, a bay and the next, stay apart where they share a face."""
    steps = sum(
        math.floor(float(box.lo[a] / box.size[a]) + 1e-6) for a in range(3) if box.size[a] > EPS
    )
    k = 0.93 if steps % 2 else 1.0
    return (rgb[0] * k, rgb[1] * k, rgb[2] * k)


# ---- infer -------------------------------------------------------------------------------


def run_infer(args) -> int:
    source = Path(args.input)
    restart_memory()  # the ceiling (--max-memory) counts from here, the modules loaded
    out = None if args.output in (None, "-") else Path(args.output)
    if out is not None:
        check_grammar_output(out)
    root = read(source, max_boxes=MAX_BOXES, max_children=MAX_CHILDREN)
    try:
        written = write(root, str(args.input), source.parent, (out or Path("x")).parent)
        text = format_module(written.module)
        # everything is checked before the grammar is written: a failure writes nothing
        report = compare(root, out or Path.cwd() / "stdout.bgr", source.parent)
    except BgrError as e:
        raise located(e, source) from None
    if out is None:
        sys.stdout.write(text)
    else:
        write_atomic(out, text)
    how = "exact" if written.exact else "approximate"
    print(
        f"{terminal_text(args.output or '<stdout>', keep='')}: {len(written.module.rules())} "
        f"rules, {how}; {terminal_text(report)}",
        file=sys.stderr,
    )
    return 0


def check_grammar_output(out: Path) -> None:
    """Refuse, before any work, a grammar output that cannot be written (a folder, a device)."""
    if out.is_dir():
        raise BgrError(
            Diagnostic(
                str(out),
                0,
                0,
                "cannot write the grammar: it is a folder",
                "name a file for -o, such as boxes.bgr",
            )
        )
    check_output(out)
    if not out.parent.is_dir():
        raise cannot_write(out, FileNotFoundError(2, "no such folder"))


def compare(root: Box, where: Path, base: Path) -> str:
    """How the grammar does against bgr retarget at CHECK_SCALES of the input's size (raised
    to what the fixed boxes need): the sizes where it gives the same boxes, and the alignments
    each keeps."""
    least = [min_length(root, a) for a in range(3)]
    sizes = [
        tuple(
            v if t == "F" else max(v * scale, need)
            for v, t, need in zip(root.size, root.tags, least, strict=True)
        )
        for scale in CHECK_SCALES
    ]
    named = write(root, "", base, where.parent, labels=True)
    grammar = _loaded(format_module(named.module), where, base)
    same = mine = theirs = total = 0
    for size in sizes:
        try:
            target = retarget(root, size)
            derived = derive_boxes(grammar, named.runs, size, root, named.ids)
        except BgrError as e:
            return f"not checked against bgr retarget ({e.message})"
        a, t = alignments(root, target)
        b, _ = alignments(root, derived)
        theirs, mine, total = theirs + a, mine + b, total + t
        same += _same_leaves(target, derived)
    shown = ", ".join("x".join(f"{v:g}" for v in s) for s in sizes)
    where_same = "at all" if same == len(sizes) else f"at {same} of"
    return (
        f"checked at {shown} m: bgr retarget's boxes {where_same} {len(sizes)} sizes; "
        f"{mine} of {total} alignments kept (bgr retarget: {theirs})"
    )


def derive_boxes(
    grammar, runs: set[str], size, root: Box, ids: dict[str, str] | None = None
) -> Box:
    """The boxes a grammar written with ``labels=True`` derives at ``size``, as a flat
    hierarchy under ``root``'s id: each named by the input box it is (``ids``: the grammar's
    labels -> box ids), copies (a repeat index above 0 under a run rule) as copies."""
    import bgr

    result = bgr.derive(grammar, attrs=dict(zip(ATTRS, (float(v) for v in size), strict=True)))
    t = result.terminals.freeze()
    out = Box(root.id, root.lo.copy(), root.lo + np.asarray(size, dtype=float), root.tags)
    for k, (short, path) in enumerate(zip(t.label, t.path, strict=True)):
        label = (ids or {}).get(short, short)
        steps = path.split("/")
        copy = any(
            prev.rsplit(".", 1)[0] in runs and not step.endswith(".0")
            for prev, step in zip(steps, steps[1:], strict=False)
        )
        lo, hi = t.origin[k].copy(), t.origin[k] + t.size[k]
        out.children.append(
            Box(f"{label}~{k}" if copy else label, lo, hi, source=label, replica=int(copy))
        )
    return out


def _loaded(text: str, where: Path, base: Path):
    """The grammar ``text`` loaded as if it were the file ``where`` (its assets resolve), with
    no file written: the output's folder may not exist yet, and nothing is left there."""
    import bgr

    return bgr.load(
        text.encode("utf-8"), path=str(where.with_name("inferred.bgr")), allow_paths=[str(base)]
    )


def _same_leaves(a: Box, b: Box) -> bool:
    def leaves(box):
        rows = [(*x.lo, *x.hi) for x in box.walk() if not x.children or x.mesh]
        return np.array(sorted(np.round(rows, 6).tolist()))

    la, lb = leaves(a), leaves(b)
    return la.shape == lb.shape and bool(np.allclose(la, lb, atol=1e-6))


__all__ = ["run_retarget", "run_infer", "parse_size", "AXES"]
