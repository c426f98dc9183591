"""The split solver of LANGUAGE.md section 6, as a pure function on sizes.

``solve(items, length)`` takes the entries of a split block with their sizes already evaluated
and returns where each piece goes.  It knows nothing of shapes or geometry, so that every row of
the contract's example table is a direct test of it.

Items are :class:`Piece` (one entry: ``abs``, ``rel`` or ``float`` with a size) and :class:`Repeat`
(a repeat group ``{ ... }*`` holding pieces and nested repeats).  A nested repeat group takes part
in the enclosing solve as one floating item of its nominal length (one repetition; an
absolute-only nested group as an absolute item), and is then solved again inside the length it
received.  That reading is ours: the contract is silent on nested groups.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

EPS = 1e-9
MAX_GROUPS_EXACT = 8  # up to 2**8 extra-repetition patterns are searched exhaustively


@dataclass(frozen=True)
class Piece:
    kind: str  # abs | rel | float
    size: float
    payload: Any = field(default=None, compare=False, hash=False)  # handed back: the tree's entry


@dataclass(frozen=True)
class Repeat:
    items: tuple[Item, ...]


Item = Piece | Repeat


@dataclass(frozen=True)
class Placed:
    payload: Any
    offset: float
    size: float


class SplitError(ValueError):
    """A size the solver cannot use (not finite), or more pieces than ``limit`` (``count`` is
    then how many); the interpreter reports it at the split."""

    count: int | None = None


def solve(
    items: list[Item] | tuple[Item, ...], length: float, limit: int | None = None
) -> list[Placed]:
    """Place the pieces of a split of ``length``; see LANGUAGE.md section 6.

    ``limit`` bounds the number of pieces: the repetitions are counted before any is laid out,
    so a runaway repeat (``{ 0.001: A }*`` on 10 km) is a SplitError at once, not gigabytes of
    pieces made first and counted afterwards.
    """
    for piece in _pieces(items):
        if not math.isfinite(piece.size):
            raise SplitError(f"a split size is {piece.size}")
    limit = _NO_LIMIT if limit is None else max(int(limit), 0)
    sized = _resolve([_to_absolute(it, length) for it in items], length, limit)
    out: list[Placed] = []
    _lay_out(sized, 0.0, length, out, limit)
    return out


_NO_LIMIT = 1 << 62


def _too_many(count: int, limit: int) -> SplitError:
    error = SplitError(
        f"this split would make {count:,} pieces, more than {limit:,} shapes (what the shape "
        "budget has left)"
    )
    error.count = count
    return error


def _pieces(items):
    for item in items:
        if isinstance(item, Repeat):
            yield from _pieces(item.items)
        else:
            yield item


# ---- step 1-3: sizes ----------------------------------------------------------------------------


def _to_absolute(item: Item, length: float) -> Item:
    """Step 1: relative sizes become absolute (fractions of the whole split's length)."""
    if isinstance(item, Repeat):
        return Repeat(tuple(_to_absolute(it, length) for it in item.items))
    if item.kind == "rel":
        return Piece("abs", item.size * length, item.payload)
    return item


def _absolute(piece: Piece, length: float = 0.0) -> tuple[bool, float]:
    """(is it floating, its nominal size)."""
    return piece.kind == "float", piece.size


def _nominal(group: Repeat, length: float) -> tuple[float, float]:
    """(absolute, floating) length of one repetition of a group."""
    a = f = 0.0
    for item in group.items:
        if isinstance(item, Repeat):
            ga, gf = _nominal(item, length)
            if gf > 0:
                f += ga + gf  # a nested floating group stretches as a whole
            else:
                a += ga
        else:
            floating, size = _absolute(item, length)
            if floating:
                f += max(size, 0.0)
            else:
                a += max(size, 0.0)
    return a, f


def _resolve(items: list[Item], length: float, limit: int = _NO_LIMIT) -> list[tuple[Item, float]]:
    """Every item of one level with its final size (a group is expanded into its repetitions)."""
    groups = [it for it in items if isinstance(it, Repeat)]
    abs_out = sum(
        max(_absolute(it, length)[1], 0.0)
        for it in items
        if isinstance(it, Piece) and not _absolute(it, length)[0]
    )
    float_out = sum(
        max(_absolute(it, length)[1], 0.0)
        for it in items
        if isinstance(it, Piece) and _absolute(it, length)[0]
    )
    avail = length - abs_out
    counts: dict[int, int] = {}
    scale = 1.0
    if groups:
        counts, scale = _repetitions(groups, avail, float_out, length)
        pieces = sum(1 for it in items if isinstance(it, Piece)) + sum(
            counts[id(g)] * max(len(g.items), 1) for g in groups
        )
        if pieces > limit:
            raise _too_many(pieces, limit)
    elif float_out > 0:
        scale = max(avail, 0.0) / float_out
    sized: list[tuple[Item, float]] = []
    for item in items:
        if isinstance(item, Piece):
            floating, size = _absolute(item, length)
            sized.append((item, size * scale if floating else size))
        else:
            a, f = _nominal(item, length)
            for _ in range(counts[id(item)]):
                sized.append((item, a + f * scale))
    if groups and all(_nominal(g, length)[1] <= 0 for g in groups) and float_out <= 0:
        sized = _fill_remainder(sized, items, groups, avail)
    return sized


def _repetitions(groups: list[Repeat], avail: float, float_out: float, length: float):
    """Counts n_g = k or k + 1 and the floating scale s closest to 1 (ties: more repetitions)."""
    nominal = [_nominal(g, length) for g in groups]
    per_rep = sum(a + f for a, f in nominal)
    floating = float_out + sum(f for _, f in nominal) > 0
    if avail <= EPS or per_rep <= EPS:
        return {id(g): (1 if avail > EPS else 0) for g in groups}, (
            max(avail, 0.0) / (float_out + sum(f for _, f in nominal))
            if floating and avail > EPS
            else 0.0
        )
    if not floating:  # absolute repeats: as many whole repetitions as fit
        k = max(int(math.floor(avail / per_rep + EPS)), 0)
        return {id(g): k for g in groups}, 1.0
    patterns = (
        itertools.product((0, 1), repeat=len(groups))
        if len(groups) <= MAX_GROUPS_EXACT
        else [tuple([0] * len(groups)), tuple([1] * len(groups))]
    )
    best = None
    for extra in patterns:
        extra_len = sum(e * (a + f) for e, (a, f) in zip(extra, nominal, strict=True))
        k_star = (avail - float_out - extra_len) / per_rep
        # floating pieces outside the groups can take the whole length, so a group may vanish
        # there, as in CGA (`{ ~w: Window | 0.25: Wall }* | ~w: Window` in w metres is one
        # Window); with nothing else floating, every group keeps one repetition
        least = 0 if float_out > EPS else 1
        for k in {max(least, math.floor(k_star)), max(least, math.ceil(k_star))}:
            counts = [k + e for e in extra]
            fixed = sum(c * a for c, (a, _) in zip(counts, nominal, strict=True))
            flo = float_out + sum(c * f for c, (_, f) in zip(counts, nominal, strict=True))
            if flo <= 0:
                continue
            s = (avail - fixed) / flo
            if s <= 0:
                continue
            key = (abs(s - 1.0), -sum(counts))
            if best is None or key < best[0]:
                best = (key, counts, s)
    if best is None:  # the absolute parts of one repetition alone overflow: one, cut later
        return {id(g): 1 for g in groups}, 0.0
    _, counts, s = best
    return {id(g): c for g, c in zip(groups, counts, strict=True)}, s


def _fill_remainder(sized, items, groups, avail):
    """Absolute repeats: after the whole repetitions, one more repetition cut at the end of the
    room the groups have (rule 4), so `{ 3: A }*` in 10 gives A 3, A 3, A 3, A 1, and a tile
    longer than its scope (`{ 30: A }*` in 10) gives one A cut to 10."""
    used = sum(size for item, size in sized if isinstance(item, Repeat))
    left = avail - used
    if left <= EPS:
        return sized
    last = (
        max(i for i, (item, _) in enumerate(sized) if isinstance(item, Repeat))
        if used > 0
        else None
    )
    group = groups[-1] if last is None else sized[last][0]
    if last is not None:
        insert_at = last + 1
    else:  # no whole repetition fitted anywhere: the cut one stands where the group is written
        before = items[: next(i for i, it in enumerate(items) if it is group)]
        insert_at = sum(1 for it in before if isinstance(it, Piece))
    return sized[:insert_at] + [(_Cut(group, left), left)] + sized[insert_at:]


@dataclass(frozen=True)
class _Cut:
    """A repetition of an absolute group cut short to ``room``."""

    group: Repeat
    room: float


# ---- steps 4-6: placing -------------------------------------------------------------------------


def _lay_out(sized, start: float, end: float, out: list[Placed], limit: int = _NO_LIMIT) -> float:
    """Place items from ``start``; pieces overflowing ``end`` are cut, later ones not created."""
    at = start
    for item, size in sized:
        if at >= end - EPS:
            break
        if isinstance(item, _Cut):
            _lay_out(_resolve_cut(item.group), at, min(at + item.room, end), out, limit)
            at = min(at + item.room, end)
            continue
        if size <= EPS:
            continue
        size = min(size, end - at)
        if isinstance(item, Repeat):
            inner = _resolve(list(item.items), size, limit - len(out))
            _lay_out(inner, at, at + size, out, limit)
        else:
            if len(out) >= limit:
                raise _too_many(len(out) + 1, limit)
            out.append(Placed(item.payload, at, size))
        at += size
    return at


def _resolve_cut(group: Repeat):
    """The items of one repetition at their nominal sizes (floating ones unscaled)."""
    return [(it, _nominal(it, 0.0)[0] if isinstance(it, Repeat) else it.size) for it in group.items]
