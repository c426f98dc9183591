"""A box hierarchy written as a .bgr grammar (``bgr infer --kind boxes``).

Every box is a rule; its children become nested splits (a guillotine cut of the box: along the
axis with the most clean cuts, slabs of several boxes becoming rules of their own).  Sizes follow
the behaviours: fixed boxes absolute, scalable ones floating, and replicable ones a *run*,
``BayRun(n) --> split(x) { scope.sx / n: Bay }*``, whose count ``n`` comes from the retargeting's
cascade written out in the rule's parameter defaults::

    func grow(used, share, size) = ...   # the length the cascade has used after one more R box
    Facade(d = scope.sx - 18, u1 = grow(0, d * 3 / 12, 3), ...) --> split(x) {
        ~1.5: Pier | 3 + u1: BayRun(1 + round(u1 / 3)) | ... }

so that the grammar derived at another size replicates what ``bgr retarget`` replicates (taller
R boxes first, ``floor(share / length)`` copies, the rest to the S boxes in proportion, the R
boxes scaled when there is no S box).  What nested splits cannot say — a non-guillotine layout
(boxes placed as fractions of their parent), slabs mixing behaviours, alignments between
subtrees — is approximated; :func:`write` says whether the grammar is exact.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from bgr.grammar import nodes as n
from bgr.grammar.errors import BgrError
from bgr.grammar.safe_text import RESERVED, identifier, unwritable

from .analysis import min_length
from .depth import MAX_DEPTH, deep_message, nesting, rule_depth, too_deep
from .depth import fills as _fills
from .depth import shown as _shown
from .model import AXES, EPS, Box

ATTRS = ("width", "height", "length")  # x, y, z ('depth' is the derivation depth in .bgr)
_RESERVED = set(RESERVED) | {"Lot"}
_NUDGE = 0.000000001


@dataclass
class Slab:
    lo: float
    hi: float
    boxes: list[Box]


@dataclass
class Written:
    module: n.Module
    exact: bool  # False when some part is approximated
    notes: list[str] = field(default_factory=list)  # what is approximated, for the header
    runs: set[str] = field(default_factory=set)  # the rules that repeat a box
    ids: dict[str, str] = field(default_factory=dict)  # label -> box id (labels=True)


def write(
    root: Box,
    source: str = "",
    base: Path | None = None,
    out_dir: Path | None = None,
    labels: bool = False,
) -> Written:
    """The grammar of ``root``; mesh paths (relative to ``base``, the boxes file's folder) are
    written relative to ``out_dir``, where the grammar goes.  ``labels``: a rule per box (no
    sharing) labelling its terminals with a short name per box (``Written.ids`` maps each to the
    box's id, whatever it holds) — the same derivation, with names, which is how ``infer`` tells
    which derived box is which input box.  A grammar that bgr derive's rule depth limit would
    stop has its chains of boxes collapsed, or is refused with a :class:`BgrError` (:mod:`.depth`).
    """
    args = (root, source, base or Path("."), out_dir or Path("."), labels)
    problem = too_deep(root)
    if problem:
        raise BgrError(problem)
    written = None
    try:
        if nesting(root, collapse=False) <= MAX_DEPTH:  # one rule per box, the usual grammar
            written = _Writer(*args).module()
        if written is None or rule_depth(written.module) > MAX_DEPTH:
            # each chain of boxes filling their parent as one rule, so that it derives
            written = _Writer(*args, flatten=True).module()
    except RecursionError:  # slabs within slabs nesting past Python's stack
        raise BgrError(deep_message(None)) from None
    depth = rule_depth(written.module)
    if depth > MAX_DEPTH:
        raise BgrError(deep_message(depth))
    return written


_NAME_LENGTH = 64  # a rule or asset name from a box id or mesh keeps this many characters


def _num(x: float) -> n.Number:
    r = round(float(x), 9)
    return n.Number(r if abs(r - x) < 1e-9 else float(x))


def _bin(op: str, a, b) -> n.Binary:
    return n.Binary(op, a, b)


def _name(s: str) -> n.Name:
    return n.Name(s)


class _Writer:
    def __init__(
        self,
        root: Box,
        source: str,
        base: Path,
        out_dir: Path,
        labels: bool,
        flatten: bool = False,
    ) -> None:
        self.root = root
        self.labels = labels
        self.flatten = flatten  # a box whose only child fills it: one rule with the child
        self.ids: dict[str, str] = {}  # label -> box id (labels=True)
        self.source = source
        self.base = base
        self.out_dir = out_dir
        self.taken: set[str] = set(_RESERVED) | set(ATTRS)
        self.rules: list[n.Rule] = []
        self.by_key: dict[tuple, str] = {}
        self.terminals: list[str] = []
        self.assets: dict[str, n.Asset] = {}
        self.runs: dict[tuple[str, int], str] = {}
        self.uses_grow = False
        self.notes: list[str] = []
        self.keys = self._keys(root)
        self.collapsed = False  # some chain was written as one rule (flatten)

    # ---- names ---------------------------------------------------------------------------
    def fresh(self, base: str) -> str:
        words = [w for w in re.split(r"[^A-Za-z0-9]+", base) if w and not w.isdigit()]
        words = [w.rstrip("0123456789") or w for w in words]
        camel = "".join(w[0].upper() + w[1:] for w in words)
        out = identifier(camel, "Part", prefix="B", most=_NAME_LENGTH, taken=self.taken)
        self.taken.add(out)
        return out

    def asset(self, mesh: str) -> str:
        if mesh not in self.assets:
            if unwritable(mesh):  # checked before the path is: the system cannot take it either
                raise BgrError(
                    f"mesh '{_shown(mesh)}' holds {unwritable(mesh)}, which a grammar "
                    "(UTF-8 text) cannot hold: rename the file"
                )
            try:
                full = (self.base / mesh).resolve()
            except OSError as e:  # a name longer than the system takes
                raise BgrError(f"mesh '{_shown(mesh)}' is not a path: {e.strerror}") from None
            path = Path(os.path.relpath(full, self.out_dir.resolve()))

            stem = Path(mesh).stem.lower()
            name = identifier(stem, "part", prefix="m_", sep="_", taken=self.taken)
            self.taken.add(name)
            self.assets[mesh] = n.Asset(name, path.as_posix())
        return self.assets[mesh].name

    def label(self, box: Box) -> n.Operation:
        """``label("b12")``: a short name for the box, whatever its id holds (NUL, 100,000
        characters); :attr:`ids` maps it back."""
        name = f"b{len(self.ids)}"
        self.ids[name] = box.id
        return n.Operation("label", [n.String(name)])

    # ---- boxes ---------------------------------------------------------------------------
    def _keys(self, root: Box) -> dict[int, tuple]:
        """Every box's key (what makes two boxes the same rule), children first, without
        recursion: a child's key is held as a number, so keys stay flat however deep."""
        keys: dict[int, tuple] = {}
        number: dict[tuple, int] = {}
        stack: list[tuple[Box, bool]] = [(root, False)]
        while stack:
            box, ready = stack.pop()
            if not ready:
                stack.append((box, True))
                stack += [(c, False) for c in box.children]
                continue
            key = (
                box.id if self.labels else "",
                box.tags,
                box.mesh,
                tuple(round(v, 6) for v in box.size),
                tuple(
                    (tuple(round(v, 6) for v in c.lo - box.lo), number[keys[id(c)]])
                    for c in box.children
                ),
            )
            keys[id(box)] = key
            number.setdefault(key, len(number))
        return keys

    def key(self, box: Box) -> tuple:
        return self.keys[id(box)]

    def box_rule(self, box: Box) -> str:
        key = self.key(box)
        if key in self.by_key:
            return self.by_key[key]
        name = self.by_key[key] = self.fresh(Path(box.mesh).stem if box.mesh else box.id)
        steps: list[n.Step] = []
        while self.flatten and len(box.children) == 1 and _fills(box.children[0], box.lo, box.hi):
            if box.mesh:  # the chain's meshes, each on the same scope
                named = [self.label(box)] if self.labels else []
                steps.append(n.Push([*named, n.Operation("i", [_name(self.asset(box.mesh))])]))
            box = box.children[0]
            self.collapsed = True
        named = [self.label(box)] if self.labels and (box.mesh or not box.children) else []
        if box.mesh:
            insert = [*named, n.Operation("i", [_name(self.asset(box.mesh))])]
            steps += [n.Push(insert)] if box.children else insert
        elif not box.children:
            steps += named
        if box.children:
            params, defaults, body = self.region(box.children, box.lo, box.hi, name, box.tags)
            steps += body
            self.rules.append(n.Rule(name, params, n.Sequence(steps), defaults=defaults))
        elif steps:
            self.rules.append(n.Rule(name, [], n.Sequence(steps)))
        else:
            self.terminals.append(name)
        return name

    # ---- a region's boxes as a split -----------------------------------------------------
    def region(self, boxes: list[Box], lo, hi, owner: str, tags) -> tuple[list, list, list]:
        """The parameters, their defaults and the steps that lay ``boxes`` out in ``lo..hi``."""
        if len(boxes) == 1 and _fills(boxes[0], lo, hi):
            return [], [], [n.Successor(self.box_rule(boxes[0]))]
        cut = _guillotine(boxes, lo, hi)
        if cut is None:
            self.notes.append(
                f"{owner}: its boxes are not a guillotine layout; they are placed as fractions "
                "of it and scale with it"
            )
            return [], [], self.fractions(boxes, lo, hi)
        axis, slabs = cut
        entries: list = []
        kinds = []
        targets = []
        for slab in slabs:
            tag, target = self.slab(axis, slab, lo, hi, owner)
            kinds.append(tag)
            targets.append(target)
        params, defaults, sizes = self.cascade(axis, slabs, kinds)
        for target, (kind, size, count) in zip(targets, sizes, strict=True):
            if target is None:
                body = n.Sequence([n.Nil()])
            elif count is None:
                body = n.Sequence([n.Successor(target)])
            else:
                body = n.Sequence([n.Successor(self.run(target, axis), [count])])
            entries.append(n.Entry(kind, size, body))
        op = n.Operation("split", [_name(AXES[axis])], n.Block(entries))
        return params, defaults, [op]

    def slab(self, axis: int, slab: Slab, lo, hi, owner: str) -> tuple[str, str | None]:
        """A slab's behaviour along the split and the rule it runs (None: empty)."""
        if not slab.boxes:
            return "S", None
        sub_lo, sub_hi = lo.copy(), hi.copy()
        sub_lo[axis], sub_hi[axis] = slab.lo, slab.hi
        if len(slab.boxes) == 1 and _fills(slab.boxes[0], sub_lo, sub_hi):
            box = slab.boxes[0]
            return box.tags[axis], self.box_rule(box)
        tags = {b.tags[axis] for b in slab.boxes}
        tag = tags.pop() if len(tags) == 1 else "S"
        if len(slab.boxes) > 1 and (
            tags
            or any(b.lo[axis] > slab.lo + EPS or b.hi[axis] < slab.hi - EPS for b in slab.boxes)
        ):
            self.notes.append(
                f"{owner}: a slab of {len(slab.boxes)} boxes along {AXES[axis]} "
                "(mixed behaviours or lengths) resizes as one"
            )
        key = (
            "slab",
            axis,
            tuple(round(v, 6) for v in sub_hi - sub_lo),
            tuple((tuple(round(v, 6) for v in b.lo - sub_lo), self.key(b)) for b in slab.boxes),
        )
        if key in self.by_key:
            return tag, self.by_key[key]
        name = self.by_key[key] = self.fresh(owner + "Part")
        params, defaults, steps = self.region(slab.boxes, sub_lo, sub_hi, name, None)
        self.rules.append(n.Rule(name, params, n.Sequence(steps), defaults=defaults))
        return tag, name

    def run(self, target: str, axis: int) -> str:
        """``XRun(n) --> split(a) { scope.sa / n: X }*``: n copies of X along the axis."""
        key = (target, axis)
        if key not in self.runs:
            name = self.runs[key] = self.fresh(target + "Run")
            size = _bin("/", _name("scope.s" + AXES[axis]), _name("n"))
            block = n.Block([n.Entry("abs", size, n.Sequence([n.Successor(target)]))], repeat=True)
            body = n.Sequence([n.Operation("split", [_name(AXES[axis])], block)])
            self.rules.append(n.Rule(name, ["n"], body, defaults=[None]))
        return self.runs[key]

    def cascade(self, axis: int, slabs: list[Slab], kinds: list[str]):
        """Parameters (``d``, ``u1``...), their defaults and each slab's (kind, size, count):
        the retargeting's cascade over the slabs' R units (retarget.cascade)."""
        lengths = [s.hi - s.lo for s in slabs]
        rs = sorted(
            (k for k in range(len(slabs)) if kinds[k] == "R"), key=lambda k: (-lengths[k], k)
        )
        has_s = any(k == "S" for k in kinds)
        sizes: list[tuple[str, n.Expr, n.Expr | None]] = []
        if not rs:
            for length, kind in zip(lengths, kinds, strict=True):
                sizes.append(("abs" if kind == "F" else "float", _num(length), None))
            return [], [], sizes
        self.uses_grow = True
        total = sum(lengths[k] for k in rs)
        params = ["d"]
        defaults: list = [_bin("-", _name("scope.s" + AXES[axis]), _num(sum(lengths)))]
        used: dict[int, n.Expr] = {}
        share = 0.0
        before: n.Expr = _num(0)
        for p, k in enumerate(rs, start=1):
            share += lengths[k]
            name = f"u{p}"
            params.append(name)
            # d * share / total, computed as retarget.cascade computes it (same floats)
            fraction = (
                _bin("/", _bin("*", _name("d"), _num(share)), _num(total))
                if share < total
                else _name("d")
            )
            defaults.append(n.Call("grow", [before, fraction, _num(lengths[k])]))
            # the slab's extra length: u_p - u_{p-1}
            used[k] = _name(name) if p == 1 else _bin("-", _name(name), before)
            before = _name(name)
        for k, (length, kind) in enumerate(zip(lengths, kinds, strict=True)):
            if kind != "R":
                sizes.append(("abs" if kind == "F" else "float", _num(length), None))
                continue
            size = _bin("+", _num(length), used[k])
            count = _bin("+", _num(1), n.Call("round", [_bin("/", used[k], _num(length))]))
            sizes.append(("abs" if has_s else "float", size, count))
        return params, defaults, sizes

    def fractions(self, boxes: list[Box], lo, hi) -> list[n.Step]:
        """Boxes that no split can lay out, each placed as fractions of the region."""
        steps: list[n.Step] = []
        size = hi - lo
        for b in boxes:
            t = [n.Relative(_num((b.lo[a] - lo[a]) / size[a])) for a in range(3)]
            s = [n.Relative(_num((b.hi[a] - b.lo[a]) / size[a])) for a in range(3)]
            steps.append(
                n.Push([n.Operation("t", t), n.Operation("s", s), n.Successor(self.box_rule(b))])
            )
        return steps

    # ---- the module ----------------------------------------------------------------------
    def module(self) -> Written:
        root = self.root
        top = self.box_rule(root)
        head: list = [n.Version(1)]
        for attr, value in zip(ATTRS, root.size, strict=True):
            head.append(n.Attr(attr, _num(value)))
        funcs = []
        if self.uses_grow:
            funcs.append(_grow())
        assets = list(self.assets.values())
        decls = [n.TerminalDecl(list(self.terminals))] if self.terminals else []
        lot = n.Rule(
            "Lot",
            [],
            n.Sequence(
                [
                    n.Operation("t", [_num(v) for v in root.lo]),
                    n.Operation("s", [_name(a) for a in ATTRS]),
                    n.Operation("i", [_name("cube")]),
                    n.Successor(top),
                ]
            ),
        )
        boxes = sum(1 for _ in root.walk())
        least = " x ".join(f"{min_length(root, a):g}" for a in range(3))
        header = [
            f"# Inferred by bgr infer --kind boxes from {_shown(self.source, 200) or 'boxes'}: "
            f"{boxes} boxes, {len(self.rules) + 1} rules.",
            "# Derive it at another size with --set width=W --set height=H --set length=L (x, y, z",
            "# in metres; y is up). R boxes replicate as bgr retarget replicates them, S boxes",
            "# scale, F boxes keep their size"
            + (" (except where an approximation below resizes them)." if self.notes else "."),
            f"# The fixed boxes need at least {least} m: bgr retarget refuses a smaller size,",
            "# this grammar squeezes them.",
        ]
        if self.collapsed:
            header += [
                "# A box that is its parent's only child and fills it is written in its",
                "# parent's rule: one rule per box would nest deeper than bgr derive's limit",
                f"# of {MAX_DEPTH}.",
            ]
        if self.notes:
            header.append("# Approximated (bgr retarget does better here):")
            header += [f"#   {note}" for note in dict.fromkeys(self.notes)]
        from bgr.inverse.schema.emit import _laid_out

        module = _laid_out(header, [head, funcs + assets + decls, [lot], self.rules])
        notes = list(dict.fromkeys(self.notes))
        return Written(
            module, exact=not notes, notes=notes, runs=set(self.runs.values()), ids=self.ids
        )


def _grow() -> n.Func:
    """``grow(used, share, size)``: the cascade's length used once one more R box of ``size``
    has taken ``share`` (cumulative): ``floor`` toward zero, at most one deletion."""
    ahead = _bin("/", _bin("-", _name("share"), _name("used")), _name("size"))
    behind = _bin("/", _bin("-", _name("used"), _name("share")), _name("size"))
    copies = n.Ternary(
        _bin(">=", _name("share"), _name("used")),
        n.Call("floor", [_bin("+", ahead, _num(_NUDGE))]),
        n.Unary("-", n.Call("floor", [_bin("+", behind, _num(_NUDGE))])),
    )
    body = _bin("+", _name("used"), _bin("*", _name("size"), n.Call("max", [_num(-1), copies])))
    return n.Func("grow", ["used", "share", "size"], body)


def _guillotine(boxes: list[Box], lo, hi) -> tuple[int, list[Slab]] | None:
    """The axis (y first, then x, then z on ties) with the most slabs, cut where no box
    straddles; None when no axis has a clean cut."""
    best: tuple[int, list[Slab]] | None = None
    for axis in (1, 0, 2):
        marks = sorted(
            {float(lo[axis]), float(hi[axis])}
            | {float(v) for b in boxes for v in (b.lo[axis], b.hi[axis])}
        )
        cuts = [
            c
            for c in marks
            if lo[axis] + EPS < c < hi[axis] - EPS
            and not any(b.lo[axis] < c - EPS and b.hi[axis] > c + EPS for b in boxes)
        ]
        merged: list[float] = []
        for c in cuts:
            if not merged or c - merged[-1] > EPS:
                merged.append(c)
        edges = [float(lo[axis]), *merged, float(hi[axis])]
        slabs = [
            Slab(a, b, [x for x in boxes if x.lo[axis] >= a - EPS and x.hi[axis] <= b + EPS])
            for a, b in zip(edges, edges[1:], strict=False)
        ]
        if len(slabs) >= 2 and (best is None or len(slabs) > len(best[1])):
            best = (axis, slabs)
    return best
