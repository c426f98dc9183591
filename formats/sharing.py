"""Shared vertices: equal rows numbered by first use, with numpy sorts instead of a dict per vertex.

The text and PLY writers write a vertex once however many triangles use it.  Which rows are equal
is decided on integer keys (positions and normals rounded to what the file says, :mod:`.text`):
:func:`number_rows` gives every row the number of the first row equal to it, counting only rows
that are firsts, so the numbers follow the order in which the file lists the vertices.
"""

from __future__ import annotations

import numpy as np

_MIX = np.uint64(0x9E3779B97F4A7C15)  # odd 64-bit constants of the splitmix64 generator
_FOLD = np.uint64(0xBF58476D1CE4E5B9)


def _numbered(
    order: np.ndarray, new: np.ndarray, rows_ascend: bool
) -> tuple[np.ndarray, np.ndarray]:
    """Numbers from a sort: ``order`` lists the rows with equal rows adjacent, ``new`` (over
    ``order``) marks where a run of equal rows starts.  The result does not depend on the order
    of the rows inside a run, so any sort will do; ``rows_ascend`` says that each run lists its
    rows in increasing order (its first is then its earliest)."""
    starts = np.flatnonzero(new)
    # each run's earliest row
    first = order[starts] if rows_ascend else np.minimum.reduceat(order, starts)
    is_first = np.zeros(len(order), dtype=bool)
    is_first[first] = True
    rank = np.cumsum(is_first) - 1  # a first row's number: how many firsts come before it
    ids = np.empty(len(order), dtype=np.int64)
    ids[order] = rank[first][np.cumsum(new) - 1]
    return ids, np.flatnonzero(is_first)


def number_keys(key: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(ids, firsts)`` for a 1-D integer key: ``ids[i]`` numbers the distinct keys in order of
    first occurrence, ``firsts[j]`` is the row where key number ``j`` first occurs."""
    n = len(key)
    if n == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    low = key.min()
    offset = key - low  # in the key's own type: no overflow
    bits = max(1, (n - 1).bit_length())
    packs = int(offset.max()) < 2 ** (63 - bits)
    if packs:  # key and row in one int64: sorted 3x faster, rows ascending among equal keys
        packed = np.sort((offset.astype(np.int64) << bits) | np.arange(n))
        order = packed & ((1 << bits) - 1)
        ordered = packed >> bits
    else:
        order = np.argsort(key)
        ordered = key[order]
    new = np.empty(len(key), dtype=bool)
    new[0] = True
    np.not_equal(ordered[1:], ordered[:-1], out=new[1:])
    return _numbered(order, new, rows_ascend=packs)


def _hash(columns: list[np.ndarray]) -> np.ndarray:
    """A 64-bit hash of each row of integer columns (wrapping arithmetic)."""
    h = np.zeros(len(columns[0]), dtype=np.uint64)
    for column in columns:
        h ^= column.astype(np.int64).view(np.uint64)
        h *= _MIX
        h ^= h >> np.uint64(31)
    h *= _FOLD
    h ^= h >> np.uint64(29)
    return h


def number_rows(columns: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """:func:`number_keys` for rows of several integer columns (equal rows: equal in every
    column).

    A row equal to the one before it (the two triangles of a quad have one normal) takes its
    number without being sorted: only the first row of each such run is.
    """
    cols = [np.asarray(c, dtype=np.int64) for c in columns]
    n = len(cols[0])
    if n > 1:
        repeats = cols[-1][1:] == cols[-1][:-1]
        for c in cols[-2::-1]:
            if not repeats.any():
                break
            repeats &= c[1:] == c[:-1]
        if repeats.any():
            head = np.concatenate([[True], ~repeats])
            at = np.flatnonzero(head)
            ids, firsts = _number_distinct([c[at] for c in cols])
            return ids[np.cumsum(head) - 1], at[firsts]
    return _number_distinct(cols)


def _number_distinct(cols: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """:func:`number_rows` by sorting every row.

    Columns whose ranges multiply to less than 2**63 are packed into one exact key.  Otherwise
    rows are numbered by a 64-bit hash, checked against the rows themselves; if two different
    rows ever shared a hash, a sort on all columns numbers them instead.
    """
    n = len(cols[0])
    if n == 0:
        return number_keys(np.zeros(0, dtype=np.int64))
    lows = [int(c.min()) for c in cols]
    spans = [int(c.max()) - lo + 1 for c, lo in zip(cols, lows, strict=True)]
    if np.prod([float(s) for s in spans]) < 2.0**62:
        key = np.zeros(n, dtype=np.int64)
        for c, lo, span in zip(cols, lows, spans, strict=True):
            key *= span
            key += c - lo
        return number_keys(key)
    ids, firsts = number_keys(_hash(cols))
    if all(np.array_equal(c[firsts][ids], c) for c in cols):
        return ids, firsts
    order = np.lexsort(cols[::-1])
    new = np.zeros(n, dtype=bool)
    new[0] = True
    for c in cols:
        ordered = c[order]
        new[1:] |= ordered[1:] != ordered[:-1]
    return _numbered(order, new, rows_ascend=True)  # lexsort is stable
