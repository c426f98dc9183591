"""Box hierarchies: the JSON a modeller writes, read and checked, and written back.

A box is an axis-aligned box (``lo``/``hi`` corners, y up) with a behaviour per axis — ``S``
scalable, ``R`` replicable, ``F`` fixed — an optional mesh fitted to it, and children that
tessellate it without overlap (docs/inverse-boxes.md has the format).  Retargeting makes copies
of replicable boxes: a copy keeps its ``source`` id and gets a ``replica`` number, and its own
unique ``id`` so that a retargeted hierarchy is itself valid input.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.grammar.paths import read_input
from bgr.grammar.safe_text import comment_text, unwritable

AXES = "xyz"
BEHAVIOURS = ("S", "R", "F")
EPS = 1e-6  # metres: faces closer than this coincide (the paper's epsilon-precision)
MAX_BOXES = 200_000  # a retargeting making more is refused: a size asked by mistake (~1 GB)
MAX_CHILDREN = 4_000
"""Children of one box that bgr retarget and bgr infer --kind boxes analyse at most, in the
input or among the copies an axis retargeted first has made.  The analysis compares every two
children of a box along each axis (16 bytes a pair, and in a tower a matrix product): 4,000
children cost 250 MB and 2 to 6 s an axis; 10,000 asked for 12 GB before this limit.  No
modelled building comes near it (docs/limits.md)."""
MAX_PAIRS = MAX_CHILDREN**2
"""Pairs of sibling boxes the analysis compares along one axis, over all boxes together: as many
as one box at MAX_CHILDREN.  A box retargeted first along x to 500 times its size held three
boxes of 4,000 copies and two of 2,399 (60 million pairs): the analysis along y took 7 s before
the result was refused as too large."""
MAX_PARENTS = 3_000
"""Boxes with children that the analysis of one axis goes through: each costs about a
millisecond however few its children.  A facade at 1/1000 of its size retargeted to 3 m made
12,006 of them along x (44,022 boxes), whose analysis along y took 17 s before the result was
refused as too large; the examples have 1 to 9."""
PAIRS_AT_ONCE = 1 << 20  # pairs of boxes compared in one numpy step (24 MB of float64 each)
FORMAT = '{"root": {"id": ..., "min": [x, y, z], "max": [x, y, z], "children": [...]}}'
MESH_PATH, MESH_NAME = 4096, 255  # a mesh path's characters and a name's bytes (PATH_MAX, NAME_MAX)
READS = f"a boxes file is a JSON object {FORMAT} (docs/inverse-boxes.md)"


def shown(text: str, most: int = 60) -> str:
    """An id as a message shows it: control characters escaped, at most ``most`` characters
    (an id of 100,000 characters is legal, but not worth printing)."""
    return comment_text(text, most)  # the same escaping as the grammar's comments


def _fail(
    name: str | Path,
    message: str,
    hint: str | None = None,
    line: int = 0,
    column: int = 0,
    text=None,
) -> BgrError:
    """An error in the boxes file ``name``, as every bgr command prints one (``file:line:col:
    error: message``, then ``hint:``)."""
    return BgrError(Diagnostic(str(name), line, column, message, hint, text))


@dataclass
class Box:
    id: str
    lo: np.ndarray  # (3,) float64, the min corner
    hi: np.ndarray  # (3,) float64, the max corner
    tags: tuple[str, str, str] = ("S", "S", "S")  # behaviour along x, y, z
    mesh: str | None = None
    children: list[Box] = field(default_factory=list)
    source: str = ""  # the id of the input box this one is (a copy of)
    replica: int = 0  # 0 for the box itself, k for its k-th copy

    def __post_init__(self) -> None:
        self.source = self.source or self.id

    @property
    def size(self) -> np.ndarray:
        return self.hi - self.lo

    def walk(self) -> Iterator[Box]:
        """This box and every descendant, depth first, children in order; a loop, not nested
        generators, so that a deep hierarchy costs no more per box than a flat one."""
        stack: list[Box] = [self]
        while stack:
            box = stack.pop()
            yield box
            stack.extend(reversed(box.children))

    def leaves(self) -> Iterator[Box]:
        return (b for b in self.walk() if not b.children)

    def copy(self) -> Box:
        return Box(
            self.id,
            self.lo.copy(),
            self.hi.copy(),
            self.tags,
            self.mesh,
            [c.copy() for c in self.children],
            self.source,
            self.replica,
        )

    def shift(self, axis: int, by: float) -> None:
        """Move this box and its descendants along ``axis``."""
        for b in self.walk():
            b.lo[axis] += by
            b.hi[axis] += by

    def to_json(self) -> dict:
        out: dict = {"id": self.id}
        if self.source != self.id or self.replica:
            out["source"], out["replica"] = self.source, self.replica
        out["min"] = [_num(v) for v in self.lo]
        out["max"] = [_num(v) for v in self.hi]
        out["behavior"] = dict(zip(AXES, self.tags, strict=True))
        if self.mesh is not None:
            out["mesh"] = self.mesh
        out["children"] = [c.to_json() for c in self.children]
        return out


def _num(v: float) -> float | int:
    """Coordinates as written: 12 rather than 12.000000000000002 (rounded to 1e-9 m)."""
    r = round(float(v), 9)
    return int(r) if r == int(r) and abs(r) < 2**53 else r


def dumps(root: Box) -> str:
    return json.dumps({"root": root.to_json()}, indent=1) + "\n"


# ---- reading -------------------------------------------------------------------------------


def read(path: str | Path, *, max_boxes: int | None = None, max_children: int | None = None) -> Box:
    """The hierarchy in a boxes JSON file, checked (:func:`parse`)."""
    path = Path(path)
    try:
        data = read_input(path, "boxes file")
        text = data.decode("utf-8-sig")  # a byte-order mark is fine
    except FileNotFoundError:
        raise _fail(path, "no such file", "check the path") from None
    except IsADirectoryError:
        raise _fail(path, "is a folder, not a boxes .json file", READS) from None
    except UnicodeDecodeError as e:
        from bgr.inverse.inputs import describe

        what = describe(data[:65536]) or f"not UTF-8 text (byte {e.start})"
        raise _fail(path, f"{what}, not a box hierarchy", READS) from None
    except OSError as e:
        raise _fail(path, f"cannot read the file: {e.strerror}") from None
    if path.suffix.lower() == ".bgr":
        raise _fail(
            path,
            "a grammar (.bgr), not a box hierarchy",
            f"{READS}; a grammar is resized by bgr derive --lot W,D (or --set), and bgr infer "
            "--kind schema infers from one",
        )
    return parse(text, str(path), max_boxes=max_boxes, max_children=max_children)


def parse(
    text: str,
    name: str = "<boxes>",
    *,
    max_boxes: int | None = None,
    max_children: int | None = None,
) -> Box:
    """Parse and check a boxes document; a BgrError naming the file, the line and the ids at
    fault for anything a retargeting could not use, or (the commands ask it) for more boxes
    than ``max_boxes`` or a box of more children than ``max_children``, before any work on
    pairs of boxes."""
    try:
        doc = json.loads(text, parse_constant=_no_constant)
    except json.JSONDecodeError as e:
        lines = text.splitlines()
        shown = lines[e.lineno - 1] if 0 < e.lineno <= len(lines) else None
        raise _fail(name, f"not JSON: {e.msg}", READS, e.lineno, e.colno, shown) from None
    except ValueError as e:
        raise _fail(name, str(e)) from None
    except RecursionError:
        raise _fail(name, "nested too deeply to read") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("root"), dict):
        raise _fail(name, 'a boxes file is an object with a "root" box', f"write {FORMAT}")
    extra = sorted(set(doc) - {"root"})
    if extra:
        raise _fail(
            name,
            f'unknown key(s) {", ".join(map(repr, extra))} beside "root"',
            'a boxes file holds only {"root": ...}',
        )
    ids: dict[str, str] = {}
    root = _box(doc["root"], name, "root", ids, fixed=(False, False, False))
    check_sizes(root, name, max_boxes, max_children)
    problems = check(root)
    if problems:
        more = f" (and {len(problems) - 5} more)" if len(problems) > 5 else ""
        raise _fail(name, "; ".join(problems[:5]) + more)
    return root


class _Constant:
    """NaN, Infinity or -Infinity as read: kept as a marker so that the box holding it is named."""

    def __init__(self, word: str) -> None:
        self.word = word

    def __str__(self) -> str:
        return self.word


def _no_constant(word: str) -> _Constant:
    return _Constant(word)


def _box(obj, name: str, where: str, ids: dict, fixed: tuple[bool, bool, bool]) -> Box:
    if not isinstance(obj, dict):
        raise _fail(name, f"{where} is not a box object")
    box_id = obj.get("id")
    if not isinstance(box_id, str) or not box_id.strip():
        raise _fail(name, f'{where} has no "id" (a non-empty string)')
    here = f"box '{shown(box_id)}'"
    if box_id in ids:
        raise _fail(name, f"two boxes have the id '{shown(box_id)}' ({ids[box_id]} and {where})")
    ids[box_id] = where
    unknown = set(obj) - {"id", "min", "max", "behavior", "mesh", "children", "source", "replica"}
    if unknown:
        raise _fail(
            name,
            f"{here} has unknown key(s) {', '.join(sorted(unknown))}",
            "a box has id, min, max, behavior, mesh and children",
        )
    corners = []
    for key in ("min", "max"):
        v = obj.get(key)
        constant = (
            next((c for c in v if isinstance(c, _Constant)), None) if isinstance(v, list) else None
        )
        if constant is not None:
            raise _fail(
                name, f'{here}: "{key}" holds {constant}, which is not a number a box may have'
            )
        if (
            not isinstance(v, list)
            or len(v) != 3
            or not all(isinstance(c, int | float) and not isinstance(c, bool) for c in v)
        ):
            raise _fail(name, f'{here}: "{key}" must be three numbers [x, y, z]')
        # an int of 400 digits is no float: compare it as it is (math.isfinite would overflow)
        if not all((not isinstance(c, float) or math.isfinite(c)) and abs(c) < 1e9 for c in v):
            raise _fail(
                name, f'{here}: "{key}" holds a number that is not finite or is beyond 1e9 m'
            )
        corners.append(np.array(v, dtype=np.float64))
    lo, hi = corners
    if np.any(hi - lo <= EPS):
        axis = AXES[int(np.argmax(hi - lo <= EPS))]
        raise _fail(
            name,
            f"{here}: max must exceed min on every axis (along {axis}: "
            f"{lo[AXES.index(axis)]:g} to {hi[AXES.index(axis)]:g})",
        )
    behavior = obj.get("behavior", {})
    if not isinstance(behavior, dict):
        raise _fail(name, f'{here}: "behavior" must be an object such as {{"x": "R"}}')
    tags = []
    for i, axis in enumerate(AXES):
        tag = behavior.get(axis, "F" if fixed[i] else "S")
        if tag not in BEHAVIOURS:
            raise _fail(
                name,
                f"{here}: behavior {axis} is {json.dumps(tag, default=str)}",
                "write S (scale), R (replicate) or F (fixed)",
            )
        # an F box's descendants keep their size along that axis whatever they say
        tags.append("F" if fixed[i] else tag)
    extra = set(behavior) - set(AXES)
    if extra:
        raise _fail(name, f"{here}: behavior has axis {sorted(extra)[0]!r}", "use x, y, z")
    mesh = obj.get("mesh")
    if mesh is not None and (not isinstance(mesh, str) or not mesh.strip()):
        raise _fail(name, f'{here}: "mesh" must be a file path')
    if mesh is not None and _path_problem(mesh):
        raise _fail(
            name,
            f'{here}: "mesh" holds {_path_problem(mesh)}, which no file path has',
            f"name the part's file relatively to the boxes file, at most {MESH_PATH:,} "
            f"characters and {MESH_NAME} bytes a name",
        )
    children = obj.get("children", [])
    if not isinstance(children, list):
        raise _fail(name, f'{here}: "children" must be a list of boxes')
    source = obj.get("source", box_id)
    replica = obj.get("replica", 0)
    if not isinstance(source, str) or not source.strip():
        raise _fail(name, f'{here}: "source" must be the id of the box it is a copy of')
    if not isinstance(replica, int) or isinstance(replica, bool) or replica < 0:
        raise _fail(name, f'{here}: "replica" must be a whole number, 0 or more')
    now = (tags[0] == "F", tags[1] == "F", tags[2] == "F")
    parent = shown(box_id)
    kids = [_box(c, name, f"child {k} of '{parent}'", ids, now) for k, c in enumerate(children)]
    return Box(box_id, lo, hi, (tags[0], tags[1], tags[2]), mesh, kids, source, replica)


def _path_problem(mesh: str) -> str | None:
    """What makes ``mesh`` no file path the system takes (a NUL, too long), or None."""
    if "\0" in mesh:
        return "a NUL character"
    if unwritable(mesh):  # a lone surrogate ("\ud800" in the JSON): no file name, no grammar text
        return unwritable(mesh)
    if len(mesh) > MESH_PATH:
        return f"{len(mesh):,} characters"
    longest = max(
        len(p.encode("utf-8", "surrogatepass")) for p in mesh.replace("\\", "/").split("/")
    )
    return f"a name of {longest:,} bytes" if longest > MESH_NAME else None


def check_sizes(
    root: Box, name: str | Path, max_boxes: int | None, max_children: int | None
) -> None:
    """A BgrError for a hierarchy too large to work on: more than ``max_boxes`` boxes (the
    most a retargeting may make: the input is part of it), or a box of more than
    ``max_children`` children (the analysis compares every two of them).  None: no limit."""
    count = 0
    for box in root.walk():
        count += 1
        if max_children is not None and len(box.children) > max_children:
            raise _fail(
                name,
                f"box '{shown(box.id)}' has {len(box.children):,} children, more than the "
                f"{max_children:,} bgr analyses in one box",
                "group them into boxes of their own (a row, a floor, a bay): the analysis "
                "compares every two children of a box",
            )
    if max_boxes is not None and count > max_boxes:
        raise _fail(
            name,
            f"{count:,} boxes, more than the {max_boxes:,} a retargeting may make",
            "bgr retarget --max-boxes N raises the limit",
        )


def check(root: Box, eps: float = EPS) -> list[str]:
    """What makes a hierarchy invalid: children outside their parent, overlapping siblings,
    negative sizes.  Retargeting results are checked with this too."""
    problems = []
    for box in root.walk():
        if np.any(box.hi - box.lo < -eps):
            problems.append(f"box '{shown(box.id)}' has a negative size")
        for child in box.children:
            if np.any(child.lo < box.lo - eps) or np.any(child.hi > box.hi + eps):
                inside = f"is not inside its parent '{shown(box.id)}'"
                problems.append(f"box '{shown(child.id)}' {inside}")
        if len(box.children) > 1:
            lo = np.array([c.lo for c in box.children])
            hi = np.array([c.hi for c in box.children])
            for i, j in overlapping(lo, hi, eps):
                a, b = box.children[i], box.children[j]
                problems.append(f"boxes '{shown(a.id)}' and '{shown(b.id)}' overlap")
    return problems


def overlapping(lo: np.ndarray, hi: np.ndarray, eps: float = EPS) -> Iterator[tuple[int, int]]:
    """Pairs i < j of boxes overlapping by more than ``eps`` on every axis, in order of i then
    j; compared a block of rows at a time, so memory stays PAIRS_AT_ONCE, not n x n."""
    n = len(lo)
    rows = max(1, PAIRS_AT_ONCE // max(n, 1))
    for start in range(0, n, rows):
        stop = min(start + rows, n)
        top = np.minimum(hi[start:stop, None], hi[None])
        over = top - np.maximum(lo[start:stop, None], lo[None])
        i, j = np.nonzero(np.all(over > eps, axis=2))
        i += start
        keep = i < j
        yield from zip(i[keep].tolist(), j[keep].tolist(), strict=True)


def uncovered(box: Box, eps: float = EPS) -> float:
    """The volume of ``box`` its children leave empty (0 for a leaf: its part fills it), exact:
    the box is cut into cells at every child's faces and the cells no child holds are summed."""
    kids = [c for c in box.children if np.all(c.size > eps)]
    if not box.children:
        return 0.0
    cuts = [
        np.unique(
            np.round(
                np.r_[box.lo[a], box.hi[a], [c.lo[a] for c in kids], [c.hi[a] for c in kids]], 9
            )
        )
        for a in range(3)
    ]
    held = np.zeros([len(c) - 1 for c in cuts], dtype=bool)
    for c in kids:
        held[
            tuple(
                slice(*np.searchsorted(cuts[a], np.round([c.lo[a], c.hi[a]], 9))) for a in range(3)
            )
        ] = True
    cells = np.einsum("i,j,k->ijk", *(np.diff(c) for c in cuts))
    return float(cells[~held].sum())


def holes(source: Box, result: Box, eps: float = EPS) -> list[str]:
    """The boxes of ``result`` whose children leave empty space (more than ``eps`` of their
    volume) though their source's children filled it: a wall the input closed, left open."""
    volume = {b.id: float(np.prod(b.size)) for b in source.walk()}
    closed = {b.id for b in source.walk() if b.children and uncovered(b) <= eps * volume[b.id]}
    return [
        b.id
        for b in result.walk()
        if b.source in closed and uncovered(b) > eps * max(float(np.prod(b.size)), eps)
    ]
