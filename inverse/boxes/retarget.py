"""The online retargeting of a box hierarchy (Lin et al. 2011, section 6 and Algorithm 1).

One axis at a time, in the order asked for (the result depends on it: the paper's Figure 12).
For an axis, the hierarchy is analysed (:mod:`.analysis`) and walked depth first: at each node,
its sequences are retargeted in order, each followed by the recursive retargeting of its boxes.

A sequence gets the length between its anchors (the node's ends for the primary; for a
secondary, the boxes of earlier sequences it rests on and that rest on it, where they have moved
to) and distributes the change over its units in a cascade (:func:`cascade`): replicable units
first, taller first, each repeated ``floor(sigma'/sigma)`` times with the unused length passed
on; what is left goes to the scalable units in proportion; if there are none, the replicable
units are scaled.  Fixed units never change.  A contraction deletes instead of repeating, and a
deleted box keeps its place with no length (virtual deletion) until the output drops it.

The units are then placed from the bottom up.  A face goes where, in order of precedence, its
attachment puts it (the anchors; and any box of an earlier sequence it touched in the input: a
tessellation's neighbours must not come apart or overlap), then where its alignment group was
put by the first face of the group placed (a soft constraint: kept only if no box gets a negative
length, no fixed box must resize, and the rest of the sequence still fits), else where the
distributed lengths put it.  A run of fixed units is skipped: the face below it moves so that the
run's top lands aligned.  Faces that stacks of fixed children hold at a node's ends are aligned
first (:meth:`Retargeter.pin`), and an alignment may rescale a replicated unit only a little
(``RHO``).  A node whose placement does not fit, or opens a gap the input did not have, is
fitted (:mod:`.repair`).
"""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right
from collections.abc import Sequence as Seq

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic
from bgr.interpreter.limits import check_memory

from .analysis import Analysis, Sequence, Unit, analyse, check_analysable, min_length
from .model import AXES, EPS, MAX_BOXES, Box, shown
from .repair import RHO, Layout, Placed, fit, fits, valid

BOX_BYTES = 1000  # what a copy of a box costs (625 bytes measured) and its place in the output
LOOK_EVERY = 2000  # boxes made between two looks at the process's memory (--max-memory)
NUDGE = 1e-9  # floor(x + NUDGE): 2.9999999999 repeats are 3 (the grammar writes the same)


def retarget(root: Box, size: Seq[float], order: str = "xyz", max_boxes: int = MAX_BOXES) -> Box:
    """A retargeted copy of ``root`` whose size is ``size`` (x, y, z), one axis at a time in
    ``order`` (any arrangement of "xyz"; axes left out keep their size); a BgrError if the
    result would have more than ``max_boxes`` boxes."""
    check_order(order)
    out = root.copy()
    for name in order:
        axis = AXES.index(name)
        out = retarget_axis(out, axis, float(size[axis]), max_boxes=max_boxes)
    return out


def check_order(order: str) -> None:
    if not order or set(order) - set(AXES) or len(set(order)) != len(order):
        raise BgrError(f"--order {order!r}: write the axes to retarget in turn, such as xyz or yx")


def retarget_axis(
    root: Box,
    axis: int,
    length: float,
    analysis: Analysis | None = None,
    max_boxes: int = MAX_BOXES,
) -> Box:
    """``root`` (changed in place and returned) resized to ``length`` along ``axis``."""
    name = AXES[axis]
    if not (math.isfinite(length) and length > 0):
        raise BgrError(f"the size along {name} must be a length over 0 m (got {length:g})")
    now = float(root.size[axis])
    if abs(length - now) <= EPS:
        return root
    if root.tags[axis] == "F":
        raise BgrError(
            Diagnostic(
                "",
                0,
                0,
                f"box '{shown(root.id)}' is fixed (F) along {name}: it stays {now:g} m",
                f"give --size with {now:g} for {name}, or tag the root S",
            )
        )
    check_analysable(root, axis)  # min_length below walks the same pairs as the analysis
    shortest = min_length(root, axis)
    if length < shortest - EPS:
        raise BgrError(
            f"the fixed boxes along {name} need at least {shortest:g} m; {length:g} m is shorter"
        )
    Retargeter(root, axis, analysis or analyse(root, axis), max_boxes).run(
        root, float(root.lo[axis]), float(root.lo[axis]) + length
    )
    return root


class Retargeter:
    def __init__(
        self, root: Box, axis: int, analysis: Analysis, max_boxes: int = MAX_BOXES
    ) -> None:
        self.max_boxes = max_boxes
        self.axis = axis
        self.analysis = analysis
        groups = sorted(analysis.groups.items(), key=lambda kv: kv[1][0])
        self.group_ids = [g for g, _ in groups]
        self.group_pos = [p for _, (p, _) in groups]
        self.aligned: dict[int, float] = {}  # alignment index -> where its first face went
        self.mins: dict = {}
        self.taken = {b.id for b in root.walk()}  # the input's ids: a copy gets a fresh one
        self.copied: dict[str, int] = {}  # source id -> the last copy number its ids used
        self.boxes = len(self.taken)  # boxes in the result so far
        self.look_at = self.boxes + LOOK_EVERY  # the count at which memory is measured next
        self.copying = True  # False while counting: fill() counts its copies but makes none

    def run(self, root: Box, lo: float, hi: float) -> None:
        """Resize ``root`` to ``[lo, hi]``, counting the result first.

        The walk is done once without its copies and undone, so a result over ``max_boxes`` or
        ``--max-memory`` is refused before any copy is made, leaving ``root`` as it was.  The
        copies are most of the work (a result refused at 200,000 boxes spent 4 s copying before
        it was counted); the walk without them is a few percent of it."""
        a = self.axis
        saved = [(b, float(b.lo[a]), float(b.hi[a]), b.children) for b in root.walk()]
        start = self.boxes
        self.copying = False
        try:
            self.resize(root, lo, hi)
            made = self.boxes - start
        finally:  # a refused result leaves the input as it was
            for b, was_lo, was_hi, children in saved:
                b.lo[a], b.hi[a], b.children = was_lo, was_hi, children
        self.boxes, self.aligned, self.copying = start, {}, True
        check_memory(f"retargeting along {AXES[a]} ({start + made:,} boxes)", BOX_BYTES * made)
        self.resize(root, lo, hi)

    # ---- alignment ---------------------------------------------------------------------
    def group(self, position: float) -> int | None:
        k = bisect_left(self.group_pos, position - EPS)
        if k < len(self.group_pos) and abs(self.group_pos[k] - position) <= EPS:
            return self.group_ids[k]
        return None

    def mark(self, position: float, new: float) -> None:
        g = self.group(position)
        if g is not None and g not in self.aligned:
            self.aligned[g] = new

    # ---- the walk ----------------------------------------------------------------------
    def resize(self, box: Box, lo: float, hi: float) -> int:
        """Resize ``box`` to ``[lo, hi]`` along the axis; the boxes its subtree then holds."""
        a = self.axis
        if box.tags[a] == "F":
            box.shift(a, lo - box.lo[a])
            return sum(1 for _ in box.walk())
        if not box.children:
            box.lo[a], box.hi[a] = lo, hi
            return 1
        node = self.analysis.of(box)
        kids = box.children
        old_lo = np.array([c.lo[a] for c in kids])
        old_hi = np.array([c.hi[a] for c in kids])
        ends = (float(box.lo[a]), float(box.hi[a]))
        layout = Layout(
            old_lo,
            old_hi,
            [k.tags[a] for k in kids],
            [float(k.size[a]) if k.tags[a] == "F" else min_length(k, a, self.mins) for k in kids],
            node.below,
            node.touch,
            (lo, hi),
            ends,
        )
        saved = [(b, float(b.lo[a]), float(b.hi[a]), b.children) for b in box.walk()]
        saved_counts = (dict(self.copied), self.boxes)
        box.lo[a], box.hi[a] = lo, hi
        placed: dict[int, Placed] = {}
        copies: dict[int, list[Box]] = {}
        grown: dict[int, int] = {}  # child -> the boxes it and its copies hold after resizing
        room = self.room(kids, node.touch, old_lo)
        self.pin(kids, node.touch, old_lo, old_hi, ends, (lo, hi))
        fitting = True  # no child placed out of the node or below its minimum so far
        for seq in node.sequences:
            self.place(seq, kids, node.touch, old_lo, old_hi, ends, (lo, hi), placed, room)
            for i in seq.boxes:
                p = placed[i]
                if p.hi - p.lo <= EPS and kids[i].tags[a] != "F":
                    p.count = 0  # squeezed to nothing: deleted, as a contraction deletes
                fitting = fitting and fits(layout, i, p)
                if fitting:
                    grown[i] = self.fill(kids, i, p, copies)
        slots = [placed[i] for i in range(len(kids))]
        if not (fitting and valid(layout, slots)):
            # the placement left boxes overlapping or outside: undo it and fit (repair.py)
            for b, was_lo, was_hi, children in saved:
                b.lo[a], b.hi[a], b.children = was_lo, was_hi, children
            self.copied, self.boxes = dict(saved_counts[0]), saved_counts[1]
            box.lo[a], box.hi[a] = lo, hi
            for i, p in enumerate(slots):
                if p.count == 0 and kids[i].tags[a] == "S":
                    p.count = 1  # squeezed by a placement that did not fit: may get room now
            slots = fit(layout, slots)
            copies, grown = {}, {}
            for seq in node.sequences:
                for i in seq.boxes:
                    p = slots[i]
                    if p.hi - p.lo <= EPS and kids[i].tags[a] != "F":
                        p.count = 0
                    grown[i] = self.fill(kids, i, p, copies)
        box.children = [
            b for i, k in enumerate(kids) if slots[i].count > 0 for b in [k, *copies[i]]
        ]
        return 1 + sum(grown.values())

    def fill(self, kids: list[Box], i: int, p: Placed, copies: dict[int, list[Box]]) -> int:
        """Resize child ``i`` into its first copy's place and make the other copies (only
        count them while counting); the boxes the child and its copies then hold."""
        copies[i] = []
        if p.count == 0:
            return 0
        step = (p.hi - p.lo) / p.count
        size = self.resize(kids[i], p.lo, p.lo + step)
        self.boxes += size * (p.count - 1)
        if self.boxes > self.max_boxes:
            raise BgrError(
                Diagnostic(
                    "",
                    0,
                    0,
                    f"the result would have more than {self.max_boxes:,} boxes "
                    f"('{shown(kids[i].source)}' repeated {p.count:,} times "
                    f"along {AXES[self.axis]})",
                    "ask a smaller size, or raise --max-boxes",
                )
            )
        if not self.copying:
            return size * p.count
        if self.boxes >= self.look_at:  # the copies are what grows: held to --max-memory
            check_memory(
                f"retargeting along {AXES[self.axis]} ({self.boxes:,} boxes)",
                BOX_BYTES * size * (p.count - 1),  # before they are made
            )
            self.look_at = self.boxes + LOOK_EVERY
        copies[i] = [self.replicate(kids[i], c * step, c) for c in range(1, p.count)]
        return size * p.count

    def replicate(self, box: Box, by: float, number: int) -> Box:
        """Copy ``number`` of a resized box, ``by`` further along the axis, with fresh ids."""
        out = box.copy()
        out.shift(self.axis, by)
        for b in out.walk():
            k = self.copied.get(b.source, 0) + 1
            while f"{b.source}~{k}" in self.taken:
                k += 1
            self.copied[b.source] = k
            b.id = f"{b.source}~{k}"
            b.replica = number
        return out

    def pin(self, kids: list[Box], touch, old_lo, old_hi, ends, new_ends) -> None:
        """Align first the faces that stacks of fixed children hold at the node's ends (a door
        on the ground holds its top at the door's height): a sequence placed earlier would
        otherwise set their alignment where the fixed boxes cannot follow, and open a gap over
        them (a deviation from the paper, which aligns to whichever face is placed first)."""
        a = self.axis
        fixed = [k.tags[a] == "F" for k in kids]
        order = sorted(range(len(kids)), key=lambda i: old_lo[i])
        up: dict[int, float] = {}  # a fixed child held from the bottom -> its new lo
        for i in order:
            under = [int(j) for j in np.nonzero(touch[:, i])[0] if int(j) in up]
            if fixed[i] and (old_lo[i] <= ends[0] + EPS or under):
                up[i] = (
                    new_ends[0] if not under else up[under[0]] + old_hi[under[0]] - old_lo[under[0]]
                )
                self.mark(old_lo[i], up[i])
                self.mark(old_hi[i], up[i] + old_hi[i] - old_lo[i])
        down: dict[int, float] = {}  # a fixed child held from the top -> its new hi
        for i in reversed(order):
            over = [int(j) for j in np.nonzero(touch[i, :])[0] if int(j) in down]
            if fixed[i] and (old_hi[i] >= ends[1] - EPS or over):
                down[i] = (
                    new_ends[1] if not over else down[over[0]] - (old_hi[over[0]] - old_lo[over[0]])
                )
                self.mark(old_hi[i], down[i])
                self.mark(old_lo[i], down[i] - (old_hi[i] - old_lo[i]))

    def unit_min(self, unit: Unit, kids: list[Box]) -> float:
        """The shortest one copy of a unit can be made without deleting it."""
        if unit.tag == "F":
            return unit.length
        return max((min_length(kids[i], self.axis, self.mins) for i in unit.boxes), default=0.0)

    # ---- one sequence ------------------------------------------------------------------
    def room(self, kids: list[Box], touch, old_lo) -> tuple[list[float], list[float]]:
        """For each child, the least length its stacks of neighbours need below and above it
        (fixed boxes their length, S boxes their minimum, R boxes nothing: they can go), so
        that a sequence never squeezes a box of a later sequence it does not contain."""
        a = self.axis
        need = [0.0 if k.tags[a] == "R" else min_length(k, a, self.mins) for k in kids]
        order = sorted(range(len(kids)), key=lambda i: old_lo[i])
        below = [0.0] * len(kids)
        above = [0.0] * len(kids)
        for i in order:
            for j in np.nonzero(touch[:, i])[0]:
                below[i] = max(below[i], below[j] + need[j])
        for i in reversed(order):
            for j in np.nonzero(touch[i, :])[0]:
                above[i] = max(above[i], above[j] + need[j])
        return below, above

    def place(
        self, seq: Sequence, kids, touch, old_lo, old_hi, ends, new_ends, placed, room
    ) -> None:
        units = list(seq.units)
        below_need, above_need = room

        def low(j: int) -> float:  # the lowest the face above unit j may go
            return new_ends[0] + max((below_need[i] for i in units[j + 1].boxes), default=0.0)

        def high(j: int) -> float:  # the highest it may go
            return new_ends[1] - max((above_need[i] for i in units[j].boxes), default=0.0)

        if seq.below:
            start_old = max(old_hi[j] for j in seq.below)
            start = max(placed[j].hi for j in seq.below)
        else:
            start_old, start = ends[0], new_ends[0]
        if seq.above:
            end_old = min(old_lo[j] for j in seq.above)
            end = min(placed[j].lo for j in seq.above)
        else:
            end_old, end = ends[1], new_ends[1]
        # empty space between an anchor and the sequence, or between two of its units, scales
        # like an S box
        spaced = [units[0]]
        for unit in units[1:]:
            if unit.lo - spaced[-1].hi > EPS:
                spaced.append(Unit([], spaced[-1].hi, unit.lo, "S"))
            spaced.append(unit)
        units = spaced
        if units[0].lo - start_old > EPS:
            units.insert(0, Unit([], start_old, units[0].lo, "S"))
        if end_old - units[-1].hi > EPS:
            units.append(Unit([], units[-1].hi, end_old, "S"))
        mins = [self.unit_min(u, kids) for u in units]
        counts, lengths = cascade(units, mins, end - start)
        members = set(seq.boxes)
        pos = start
        for k, unit in enumerate(units):
            if k == len(units) - 1:
                top = end if unit.tag != "F" and counts[k] > 0 else pos + lengths[k]
            elif unit.tag == "F" or counts[k] == 0:
                top = pos + lengths[k]
            else:
                natural = top = pos + lengths[k]
                # bounds on this unit's top, also through the run of fixed units above it
                least, most, offset, j = low(k), high(k), 0.0, k
                while j + 2 < len(units) and units[j + 1].tag == "F":
                    offset += units[j + 1].length
                    j += 1
                    least, most = max(least, low(j) - offset), min(most, high(j) - offset)
                want = self.wanted(units, k, kids, touch, old_lo, old_hi, placed, members)
                if (
                    want is not None
                    and abs(want - top) > EPS
                    and least - EPS <= want <= most + EPS
                    and self.fits(units, mins, counts, k, pos, want, end)
                ):
                    top = want
                elif top < least - EPS or (top > most + EPS and most >= least):
                    top = max(pos, least if top < least else most)
                    if unit.tag == "R" and top - pos < counts[k] * RHO * unit.length - EPS:
                        # held short by its bounds: fewer copies rather than squeezed ones
                        counts[k] = math.floor((top - pos) / (RHO * unit.length) + NUDGE)
                if top != natural:
                    rest = cascade(units[k + 1 :], mins[k + 1 :], end - top)
                    counts[k + 1 :], lengths[k + 1 :] = rest
            for i in unit.boxes:
                placed[i] = Placed(pos, top, counts[k])
                if counts[k]:
                    self.mark(old_lo[i], pos)
                    self.mark(old_hi[i], top)
            pos = top
            if k + 1 < len(units):
                # a box of an earlier sequence under the next unit ends higher (this unit could
                # not reach it: fixed, or held by its bounds): leave a gap rather than overlap
                under = [
                    placed[j].hi
                    for i in units[k + 1].boxes
                    for j in np.nonzero(touch[:, i])[0]
                    if j not in members and j in placed and placed[j].count
                ]
                if under and max(under) > pos + EPS:
                    pos = max(under)
                    counts[k + 1 :], lengths[k + 1 :] = cascade(
                        units[k + 1 :], mins[k + 1 :], end - pos
                    )

    def wanted(self, units, k, kids, touch, old_lo, old_hi, placed, members) -> float | None:
        """Where the top of unit ``k`` should go for an attachment or an alignment: its own top
        face's, or that of the run of fixed units above it, less the run's length."""
        offset = 0.0
        j = k
        while j < len(units) - 1:
            at = self.boundary(units[j], units[j + 1], kids, touch, old_lo, old_hi, placed, members)
            if at is not None:
                return at - offset
            if units[j + 1].tag != "F":
                return None
            offset += units[j + 1].length
            j += 1
        return None

    def boundary(self, below, above, kids, touch, old_lo, old_hi, placed, members):
        """Where the face between two units must go: on the boxes of earlier sequences it
        touched (attachment), else at its alignment group's position, else None."""
        under = [
            placed[j].hi
            for i in above.boxes
            for j in np.nonzero(touch[:, i])[0]
            if j not in members and j in placed and placed[j].count
        ]
        if under:
            return max(under)
        over = [
            placed[j].lo
            for i in below.boxes
            for j in np.nonzero(touch[i, :])[0]
            if j not in members and j in placed and placed[j].count
        ]
        if over:
            return min(over)
        g = self.group(below.hi)
        return self.aligned.get(g) if g is not None else None

    @staticmethod
    def fits(units, mins, counts, k, pos, want, end) -> bool:
        """Whether unit k may end at ``want``: no negative or below-minimum length, and the
        units above can still fill up to the end without resizing a fixed one."""
        length = want - pos
        if length < -EPS or length < (mins[k] * counts[k]) - EPS:
            return False
        if units[k].tag == "R" and counts[k] and units[k].length > EPS:
            # an alignment may rescale copies a little (the paper), not squeeze or stretch them
            per = length / counts[k] / units[k].length
            if not RHO - EPS <= per <= 1 / RHO + EPS:
                return False
        rest = units[k + 1 :]
        room = end - want
        if all(u.tag == "F" for u in rest):
            return abs(room - sum(u.length for u in rest)) <= EPS
        need = sum(
            u.length if u.tag == "F" else (0.0 if u.tag == "R" else m)
            for u, m in zip(rest, mins[k + 1 :], strict=True)
        )
        return room >= need - EPS


def cascade(units: list[Unit], mins: list[float], length: float) -> tuple[list[int], list[float]]:
    """Copies and lengths of each unit when the units together are to take ``length``.

    The change goes to the R units first, taller first (ties: lower first), each getting its
    share in proportion to its length plus what the previous one left, and repeated (or
    deleted) ``floor(share / length)`` times; the rest goes to the S units in proportion, none
    going below its minimum; what no S unit can take scales the R units left.  F units keep
    their length, so the sum may differ from ``length`` when nothing can take the change.
    """
    m = len(units)
    counts = [1] * m
    lengths = [u.length for u in units]
    change = length - sum(lengths)
    rs = sorted((k for k in range(m) if units[k].tag == "R"), key=lambda k: (-units[k].length, k))
    total = sum(units[k].length for k in rs)
    used = 0.0
    if rs and total > 0:
        covered = 0.0  # the R lengths so far: this box's share is change * covered / total
        for k in rs:
            sigma = units[k].length
            covered += sigma
            share = change * covered / total if covered < total else change
            extra = repeats((share - used) / sigma)
            used += extra * sigma
            counts[k] = 1 + extra
            lengths[k] = counts[k] * sigma
    rest = change - used
    free = [k for k in range(m) if units[k].tag == "S"]
    while free and abs(rest) > EPS * 1e-3:
        weight = sum(units[k].length for k in free)
        clamped = [k for k in free if lengths[k] + rest * units[k].length / weight < mins[k] - EPS]
        if not clamped:
            for k in free:
                lengths[k] += rest * units[k].length / weight
            rest = 0.0
            break
        for k in clamped:
            rest -= mins[k] - lengths[k]
            lengths[k] = mins[k]
            free.remove(k)
    if abs(rest) > EPS * 1e-3:
        scalable = [k for k in rs if counts[k] > 0]
        weight = sum(lengths[k] for k in scalable)
        for k in scalable:
            lengths[k] = max(lengths[k] + rest * lengths[k] / weight, counts[k] * mins[k])
    return counts, lengths


def repeats(x: float) -> int:
    """How many more copies (negative: deletions) a share of ``x`` lengths buys: floor toward
    zero, and at most one deletion (a box is deleted once)."""
    n = math.floor(x + NUDGE) if x >= 0 else -math.floor(-x + NUDGE)
    return max(n, -1)


# ---- measuring a result -----------------------------------------------------------------


def alignments(source: Box, result: Box, axis: int | None = None) -> tuple[int, int]:
    """(kept, total): pairs of input leaves with a face in the same alignment group, whose
    faces still line up in ``result`` (the leaves of the same ids, copies left aside: a copy
    has an id not in the input, or another replica number)."""
    axes = range(3) if axis is None else [axis]
    replicas = {b.id: b.replica for b in source.walk()}
    placed = {b.id: b for b in result.leaves() if replicas.get(b.id, -1) == b.replica}
    kept = total = 0
    for a in axes:
        groups = analyse_groups(source, a)
        for members in groups:
            alive = [(b, side) for b, side in members if b.id in placed]
            total += len(members) - 1
            if len(alive) < 2:
                continue
            where = [(placed[b.id].lo if side == 0 else placed[b.id].hi)[a] for b, side in alive]
            ref = where[0]
            kept += sum(1 for w in where[1:] if abs(w - ref) <= 1e-6)
    return kept, total


def analyse_groups(root: Box, axis: int) -> list[list[tuple[Box, int]]]:
    """The leaf faces of each alignment group of ``root`` along ``axis``: (box, 0 lo / 1 hi)."""
    from .analysis import alignment_groups

    groups = alignment_groups(root, axis)
    out: list[list[tuple[Box, int]]] = [[] for _ in groups]
    # the groups by position: a face looks at the few near it, not at every group
    positions = [p for p, _ in groups.values()]  # the k-th group's (dict order, as out)
    order = sorted(range(len(positions)), key=positions.__getitem__)
    at = [positions[k] for k in order]
    for leaf in root.leaves():
        for side, where in ((0, float(leaf.lo[axis])), (1, float(leaf.hi[axis]))):
            near = order[bisect_left(at, where - 2 * EPS) : bisect_right(at, where + 2 * EPS)]
            for k in sorted(near):
                if abs(positions[k] - where) <= EPS:
                    out[k].append((leaf, side))
    return out
