"""The third check of a captured-model JSON, its meaning: the scene graph, footprints and floors.

:class:`_Reader` holds the diagnostics of this stage and the labels met so far (with whether
each is fixed).  It checks that block ids are unique, parents known and acyclic, attachments name
real faces, a prism's footprint is a simple polygon and the floors sum to the block's height; and
it composes each block's frame down the scene graph.  The faces themselves are built and checked
by :mod:`.captured_faces`.
"""

from __future__ import annotations

import math

from bgr.grammar.errors import BgrError, Diagnostic, suggest

from .captured_checks import _diag, _num
from .captured_geometry import _face_names, _Frame, _names_hint
from .captured_schema import TOL
from .model import default_fixed

# ---- stage 3: meaning ---------------------------------------------------------------------------


class _Reader:
    def __init__(self, data: dict, path: str, fixed: dict[str, bool] | None) -> None:
        from bgr.grammar.registry import KEYWORDS

        self.data, self.path = data, path
        self.keywords = set(KEYWORDS)
        self.diags: list[Diagnostic] = []
        declared = {k: v["fixed"] for k, v in data.get("labels", {}).items()}
        self.fixed = {**declared, **(fixed or {})}
        self.used: list[str] = []

    def fail(self, where: str, message: str, hint: str | None = None) -> None:
        self.diags.append(_diag(self.path, where, message, hint))

    def raise_if_failed(self) -> None:
        if self.diags:
            raise BgrError(self.diags)

    def is_fixed(self, label: str) -> bool:
        return self.fixed.get(label, default_fixed(label))

    def use_label(self, label: str, where: str) -> None:
        if label in self.keywords:
            self.fail(
                where,
                f"{label!r} is a keyword of the bgr language, so it cannot name a terminal",
                f"rename it, e.g. {label}_",
            )
        elif label not in self.used:
            self.used.append(label)

    # ---- the scene graph --------------------------------------------------------------------
    def check_blocks(self) -> dict[str, int]:
        blocks = self.data["blocks"]
        ids: dict[str, int] = {}
        for i, b in enumerate(blocks):
            if b["id"] in ids:
                self.fail(
                    f"blocks[{i}].id",
                    f"{b['id']!r} is also the id of blocks[{ids[b['id']]}]",
                    "block ids are unique",
                )
            else:
                ids[b["id"]] = i
        for i, b in enumerate(blocks):
            where = f"blocks[{i}]"
            if "sides" in b and b["shape"] != "cylinder":
                self.fail(
                    f"{where}.sides", f"only a cylinder has sides, and this block is a {b['shape']}"
                )
            if "footprint" in b and b["shape"] != "prism":
                self.fail(
                    f"{where}.footprint",
                    f"only a prism has a footprint, and this block is a {b['shape']}",
                )
            parent = b.get("parent")
            if parent is not None and parent not in ids:
                self.fail(
                    f"{where}.parent",
                    f"no block has the id {parent!r}",
                    suggest(parent, ids) or "parent is the id of another block, or null",
                )
            if b["shape"] == "prism" and "footprint" in b:
                self.check_footprint(b, where)
        # cycles: follow each chain of parents
        reported: set[int] = set()
        for i in range(len(blocks)):
            chain, j = [], i
            while j is not None and j not in chain:
                chain.append(j)
                parent = blocks[j].get("parent")
                j = ids.get(parent) if parent is not None else None
            if j is not None and j == i and i not in reported:
                cycle = chain[chain.index(j) :]
                reported.update(cycle)
                names = " -> ".join(repr(blocks[k]["id"]) for k in cycle + [j])
                self.fail(
                    f"blocks[{i}].parent",
                    f"the parents form a cycle: {names}",
                    "the scene graph is a tree: one block at its root has parent null",
                )
        for i, b in enumerate(blocks):
            for k, att in enumerate(b.get("attach", [])):
                where = f"blocks[{i}].attach[{k}]"
                if att["face"] not in _face_names(b):
                    self.fail(
                        f"{where}.face",
                        f"{att['face']!r} is not a face of this {b['shape']}",
                        suggest(att["face"], _face_names(b)) or _names_hint(b),
                    )
                target = ids.get(att["to"])
                if target is None:
                    self.fail(
                        f"{where}.to",
                        f"no block has the id {att['to']!r}",
                        suggest(att["to"], ids) or "to is the id of another block",
                    )
                elif target == i:
                    self.fail(f"{where}.to", "a block cannot be attached to itself")
                elif att["to_face"] not in _face_names(blocks[target]):
                    other = blocks[target]
                    self.fail(
                        f"{where}.to_face",
                        f"{att['to_face']!r} is not a face of block {att['to']!r} (a "
                        f"{other['shape']})",
                        suggest(att["to_face"], _face_names(other)) or _names_hint(other),
                    )
        return ids

    def check_footprint(self, b: dict, where: str) -> None:
        w, _, d = b["size"]
        pts = b["footprint"]
        ok = True
        for k, (x, z) in enumerate(pts):
            if not (-TOL <= x <= w + TOL and -TOL <= z <= d + TOL):
                self.fail(
                    f"{where}.footprint[{k}]",
                    f"[{_num(x)}, {_num(z)}] lies outside the block's "
                    f"plan [0, {_num(w)}] x [0, {_num(d)}]",
                    "size is [width, height, depth]: the "
                    "footprint lies within x in [0, width], z in [0, depth]",
                )
                ok = False
        n = len(pts)
        for k in range(n):
            p, q = pts[k], pts[(k + 1) % n]
            if math.hypot(q[0] - p[0], q[1] - p[1]) <= TOL:
                hint = (
                    "do not close the ring: the last point is joined to the first"
                    if k == n - 1
                    else "each edge of the footprint is a face: it needs a length"
                )
                self.fail(f"{where}.footprint[{(k + 1) % n}]", "repeats the point before it", hint)
                ok = False
        if ok:
            from shapely.geometry import Polygon
            from shapely.validation import explain_validity

            poly = Polygon([(x, z) for x, z in pts])
            if not poly.is_valid or poly.area <= TOL:
                reason = explain_validity(poly) if not poly.is_valid else "it has no area"
                self.fail(
                    f"{where}.footprint",
                    f"not a simple polygon: {reason}",
                    "the points go once round the plan, edges not crossing",
                )

    def frames(self, ids: dict[str, int]) -> list[_Frame]:
        """Each block's frame in world coordinates: its transform composed with its parents'."""
        blocks = self.data["blocks"]
        done: dict[int, _Frame] = {}
        for i in range(len(blocks)):
            chain, j = [], i
            while j not in done:  # up to a root or a block already placed (no cycles by now)
                chain.append(j)
                parent = blocks[j].get("parent")
                if parent is None:
                    break
                j = ids[parent]
            for k in reversed(chain):
                t = blocks[k].get("transform", {})
                local = _Frame(
                    math.radians(t.get("rotate", 0.0)),
                    [float(v) for v in t.get("translate", (0.0, 0.0, 0.0))],
                )
                parent = blocks[k].get("parent")
                done[k] = local.then(done[ids[parent]]) if parent is not None else local
        return [done[i] for i in range(len(blocks))]

    # ---- floors and subfaces ----------------------------------------------------------------
    def floors(self, b: dict, where: str) -> list[tuple[str | None, float]]:
        height = float(b["size"][1])
        floors = b.get("floors") or [{"height": height}]
        total = math.fsum(f["height"] for f in floors)
        if not abs(total - height) <= TOL:
            self.fail(
                f"{where}.floors",
                f"the floor heights sum to {_num(total)} m but the block is "
                f"{_num(height)} m tall (size[1])",
                f"difference {_num(height - total)} m",
            )
        return [(f.get("name"), float(f["height"])) for f in floors]
