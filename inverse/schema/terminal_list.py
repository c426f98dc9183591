"""A terminal list (``bgr derive -o x.json``) read and checked, and the rule tree of its paths.

:func:`read_terminals` turns each entry into a :class:`_Terminal` (its label, path and frame,
with the plane it lies in), checking every field and naming the element at fault;
:func:`_tree` rebuilds the rule tree from the derivation paths as :class:`_Node` objects.  These
are the pieces the rest of the terminal-list reader (:mod:`.terminal_planes`,
:mod:`.terminal_cells`, :mod:`.terminals`) works on.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.grammar.safe_text import unwritable
from bgr.interpreter.limits import MAX_INPUT_COORDINATE

TOL = 1e-6  # metres: coordinates that agree this closely are the same
_HEX = re.compile(r"#[0-9a-fA-F]{6}")


@dataclass
class _Terminal:
    """One terminal of the list, with the plane it lies in read from its own frame.

    ``k`` is the scope axis the terminal is flat along (its size there is 0), so its plane is
    spanned by the other two axes in index order: a face from comp(f) is flat along z (plane x,
    y), a piece of a lot along y (plane x, z).  Nothing assumes which axis is up.  A solid (no
    size 0) has ``k`` 2 for when it stands alone, but beside flat terminals it joins the face
    one of its axes is normal to (:func:`_same_plane`).  ``k`` is None when two or three sizes
    are 0 (a line or a point, which has no area to subdivide).
    """

    index: int
    label: str
    path: str
    origin: tuple[float, float, float]
    axes: tuple[tuple[float, float, float], ...]
    size: tuple[float, float, float]
    color: str | None = None
    k: int | None = field(init=False, default=2)
    flat: bool = field(init=False, default=False)

    def __post_init__(self) -> None:
        zeros = [i for i in range(3) if self.size[i] < TOL]
        self.flat = len(zeros) == 1
        self.k = zeros[0] if self.flat else (2 if not zeros else None)

    @property
    def normal(self) -> tuple[float, float, float]:
        return self.axes[self.k]

    @property
    def plane(self) -> tuple[int, int]:
        """The indices of the two scope axes the terminal's plane is spanned by, in order."""
        return _PLANES[self.k]


_PLANES = {0: (1, 2), 1: (0, 2), 2: (0, 1)}


@dataclass
class _Node:
    path: str
    items: list = field(default_factory=list)  # child _Node or _Terminal, in derivation order
    terminals: list = field(default_factory=list)  # every terminal below, in order
    gathered: bool = False  # a face gathered from a rule's children, not a rule of its own

    @property
    def name(self) -> str:
        last = self.path.rsplit("/", 1)[-1]
        return last.rsplit(".", 1)[0]


def _error(path: str, message: str, hint: str | None = None) -> BgrError:
    return BgrError(Diagnostic(path, 0, 0, message, hint))


def _vector(value, n: int, where: str, path: str) -> tuple:
    """``n`` numbers, each finite and within MAX_INPUT_COORDINATE (a terminal at 1e308 is no
    place: it made a lot of 1e308 that the check of the inferred grammar blamed on bgr)."""
    if (
        not isinstance(value, list)
        or len(value) != n
        or not all(
            isinstance(v, (int, float))
            and not isinstance(v, bool)
            and abs(v) <= MAX_INPUT_COORDINATE  # NaN compares false
            for v in value
        )
    ):
        raise _error(
            path,
            f"{where} must be a list of {n} finite numbers within ±{MAX_INPUT_COORDINATE:.0e} m, "
            f"got {json.dumps(value)[:60]}".replace("e+0", "e"),
        )
    return tuple(float(v) for v in value)


def read_terminals(data: dict, path: str = "<terminals>") -> list[_Terminal]:
    """The terminals of a parsed terminal-list JSON, checked: each error names the element."""
    if not isinstance(data, dict) or not isinstance(data.get("terminals"), list):
        raise _error(
            path,
            "not a bgr terminal list: expected an object with a 'terminals' list",
            "write one with: bgr derive FILE.bgr -o terminals.json",
        )
    out = []
    for i, t in enumerate(data["terminals"]):
        where = f"terminals[{i}]"
        if not isinstance(t, dict):
            raise _error(path, f"{where} is not an object")
        for key in ("label", "path"):
            if not isinstance(t.get(key), str) or not t.get(key):
                raise _error(path, f"{where}.{key} must be a non-empty string")
            if unwritable(t[key]):  # the inferred grammar writes it as a label string
                raise _error(path, f"{where}.{key} holds {unwritable(t[key])}, which no label has")
        origin = _vector(t.get("origin"), 3, f"{where}.origin", path)
        axes_raw = t.get("axes")
        if not isinstance(axes_raw, list) or len(axes_raw) != 3:
            raise _error(path, f"{where}.axes must be three 3-vectors")
        axes = tuple(_vector(a, 3, f"{where}.axes[{j}]", path) for j, a in enumerate(axes_raw))
        size = _vector(t.get("size"), 3, f"{where}.size", path)
        if min(size) < 0:
            raise _error(path, f"{where}.size has a negative entry")
        color = t.get("color")
        color = color if isinstance(color, str) and _HEX.fullmatch(color) else None
        out.append(_Terminal(i, t["label"], t["path"], origin, axes, size, color))
    return out


def _tree(terminals: list[_Terminal]) -> _Node:
    """The rule tree of the paths; children in derivation (first appearance) order."""
    nodes: dict[str, _Node] = {}
    root = _Node("")

    def node(path: str) -> _Node:
        found = nodes.get(path)
        if found is None:
            found = nodes[path] = _Node(path)
            parent = node(path.rsplit("/", 1)[0]) if "/" in path else root
            parent.items.append(found)
        return found

    for t in terminals:
        node(t.path).items.append(t)

    def fill(n: _Node) -> None:
        for item in n.items:
            if isinstance(item, _Node):
                fill(item)
                n.terminals += item.terminals
            else:
                n.terminals.append(item)

    fill(root)
    return root


def _dot(a, b) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
