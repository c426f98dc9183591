"""Numbers as ASCII text in bulk, with numpy: no Python call per number.

Text formats (OBJ) hold millions of numbers; formatting them one by one in Python (``"%g" % x``)
costs about 0.2 microseconds each, most of a writer's time.  Here a block of lines is built as a
grid of 8-byte words, one row per line, each field one or more words of ASCII padded with NUL
bytes; :func:`render` then drops every NUL of the grid at once, which leaves the text.  Digits come
four at a time from a 10,000-entry table, so a number costs a few numpy operations shared by the
whole column.  Dropping the NULs costs per run of NULs, so a field keeps its padding on the
outside: integers and the whole part of a number are right-aligned, decimals left-aligned, and the
padding of neighbouring fields merges into one run.

    grid = np.column_stack([word(b"v"), *map(decimal, q.T), word(b"\\n")])
    text = render(grid)

Numbers are written in fixed point: :func:`decimal` takes integers ``q = round(x * 10**6)`` and
writes `` x`` with at most six decimals, trailing zeros dropped (`` 1.5``, `` -0.25``, `` 3``),
as ``" %.6f"`` followed by stripping zeros would; equal ``q`` are equal text, which is how the
writers find vertices to share (:func:`quantize`).
"""

from __future__ import annotations

import functools

import numpy as np

DECIMALS = 6
SCALE = 10**DECIMALS
_ZERO = ord("0")
_CHUNK = 10_000  # four digits


def _four_digits() -> np.ndarray:
    """(3, 10000) uint32: the four ASCII bytes of 0..9999 as one word, in three spellings.

    0: with leading zeros (``0042``); 1: without trailing zeros, 0 as nothing (``42`` for 4200,
    NUL-padded); 2: without leading zeros, 0 as ``0`` (right-aligned, NUL-padded).
    """
    n = np.arange(_CHUNK)
    chars = (np.stack([n // 1000, n // 100 % 10, n // 10 % 10, n % 10], axis=1) + _ZERO).astype(
        np.uint8
    )
    zero = chars == _ZERO
    trail = np.logical_and.accumulate(zero[:, ::-1], axis=1)[:, ::-1]
    lead = np.logical_and.accumulate(zero, axis=1)
    lead[:, 3] = False
    spellings = np.stack([chars, np.where(trail, 0, chars), np.where(lead, 0, chars)])
    return np.ascontiguousarray(spellings.astype(np.uint8)).view(np.uint32).reshape(3, _CHUNK)


_WORDS = _four_digits()
FULL, NO_TRAIL, NO_LEAD = range(3)
_FULL64 = _WORDS[FULL].astype(np.uint64)


@functools.cache
def _leading(prefix: bytes) -> np.ndarray:
    """(10000,) uint64: ``prefix + str(i)`` right-aligned in 8 bytes (at most 4 prefix bytes)."""
    n = np.arange(_CHUNK)
    count = 1 + (n >= 10) + (n >= 100) + (n >= 1000)
    out = np.zeros((_CHUNK, 8), dtype=np.uint8)
    out[:, 4:] = _WORDS[NO_LEAD].view(np.uint8).reshape(_CHUNK, 4)
    for k, byte in enumerate(reversed(prefix), start=1):
        out[n, 8 - count - k] = byte
    return out.reshape(-1).view(np.uint64)


def word(text: bytes) -> np.uint64:
    """``text`` (at most 8 bytes) as one word, NUL-padded on the right."""
    return np.uint64(int.from_bytes(text.ljust(8, b"\0"), "little"))


def integer(
    values: np.ndarray, prefix: bytes = b" ", negative: np.ndarray | None = None
) -> np.ndarray:
    """(n, k) uint64: ``prefix + str(v)`` for non-negative integers, right-aligned in ``k`` words
    (as few as the longest needs); where ``negative`` is true the prefix is followed by ``-``."""
    v = np.asarray(values, dtype=np.int64)
    signs = 0 if negative is None else 1
    width = len(prefix) + signs + len(str(int(v.max(initial=0))))
    if width > 8:
        return _wide(v, prefix, negative)
    lead = _leading(prefix)
    signed: np.ndarray | int = 0
    if negative is not None:  # one table of both spellings: v, then -v at 10000 + v
        lead = np.concatenate([lead, _leading(prefix + b"-")])
        signed = _CHUNK * negative
    if width - len(prefix) - signs <= 4:
        return lead[v + signed][:, None]
    high = v // _CHUNK
    low = v - high * _CHUNK
    # the prefix and the high digits fit in four bytes: they move to the low half of the word
    two = (lead[high + signed] >> np.uint64(32)) | (_FULL64[low] << np.uint64(32))
    return np.where(high > 0, two, lead[low + signed])[:, None]


def _wide(v: np.ndarray, prefix: bytes, negative: np.ndarray | None) -> np.ndarray:
    """:func:`integer` for texts longer than a word, digit by digit (seldom needed: positions
    beyond 100 km, a million vertices)."""
    digits = len(str(int(v.max(initial=0))))
    signs = 0 if negative is None else 1
    size = -(-(len(prefix) + signs + digits) // 8) * 8
    out = np.zeros((len(v), size), dtype=np.uint8)
    count = np.ones(len(v), dtype=np.int64)
    rest = v
    for col in range(size - 1, size - 1 - digits, -1):
        high = rest // 10
        out[:, col] = np.where((rest > 0) | (col == size - 1), rest - high * 10 + _ZERO, 0)
        count += (high > 0) & (col > size - digits)
        rest = high
    at = np.arange(len(v)) * size + (size - count)
    flat = out.reshape(-1)
    if negative is not None:
        at = at - negative
        flat[at[negative]] = ord("-")
    for k, byte in enumerate(reversed(prefix), start=1):
        flat[at - k] = byte
    return out.view(np.uint64)


def _fraction_tables() -> tuple[np.ndarray, np.ndarray]:
    """uint64 words for ``.dddddd``: (20000,) the point and the first four decimals, without
    trailing zeros (and nothing for 0) at ``i``, with them at ``10000 + i``; (100,) the last two
    decimals without trailing zeros, at bytes 5 and 6."""
    dot = np.uint64(ord("."))
    eight = np.uint64(8)
    trimmed = np.where(
        np.arange(_CHUNK) > 0, dot | (_WORDS[NO_TRAIL].astype(np.uint64) << eight), 0
    )
    first = np.concatenate([trimmed, dot | (_FULL64 << eight)]).astype(np.uint64)
    last = (_WORDS[NO_TRAIL, np.arange(100) * 100] & 0xFFFF).astype(np.uint64) << np.uint64(40)
    return first, last


_FIRST4, _LAST2 = _fraction_tables()


def fraction(frac: np.ndarray) -> np.ndarray:
    """(n,) uint64: ``.`` and six decimals of ``frac / 10**6`` (``0 <= frac < 10**6``), without
    trailing zeros, left-aligned; nothing for 0."""
    high = frac // 100  # the first four decimals
    low = frac - high * 100  # the last two
    return _FIRST4[high + _CHUNK * (low > 0)] | _LAST2[low]


def decimal(q: np.ndarray, prefix: bytes = b" ") -> tuple[np.ndarray, np.ndarray]:
    """`` -12.5`` for the numbers ``q / 10**6`` (``q`` integers): ``prefix`` (at most 3 bytes),
    ``-`` if negative, the whole part as (n, k) words (:func:`integer`), and up to six decimals
    without trailing zeros as (n,) words."""
    q = np.asarray(q, dtype=np.int64)
    mag = np.abs(q)
    whole = mag // SCALE
    return integer(whole, prefix, q < 0), fraction(mag - whole * SCALE)


def quantize(x: np.ndarray) -> np.ndarray:
    """``round(x * 10**6)`` as int64: the integers :func:`decimal` writes; equal ones print
    equal text."""
    return np.rint(np.asarray(x, dtype=np.float64) * SCALE).astype(np.int64)


def left_aligned(words: np.ndarray) -> np.ndarray:
    """Rows of right-aligned, NUL-padded words (n, k), with their padding moved to the right."""
    if words.shape[1] == 1:  # one word: a shift (bytes are little-endian, padding is low)
        w = words[:, 0]
        pad = np.zeros(len(w), dtype=np.uint64)
        for k in range(1, 8):
            pad += (w & np.uint64((1 << (8 * k)) - 1)) == 0
        return (w >> (pad * np.uint64(8)))[:, None]
    grid = np.ascontiguousarray(words).view(np.uint8).reshape(len(words), -1)
    width = grid.shape[1]
    col = np.arange(width)[None, :] + np.argmax(grid != 0, axis=1)[:, None]
    moved = np.where(col < width, np.take_along_axis(grid, np.minimum(col, width - 1), 1), 0)
    return np.ascontiguousarray(moved.astype(np.uint8)).view(np.uint64)


def gather(table: np.ndarray, index: np.ndarray) -> np.ndarray:
    """``table[index]`` for a (N, k) uint64 table, one row copied as one item (a plain row
    gather of a 2-D array is several times slower)."""
    rows = np.ascontiguousarray(table).view(np.dtype((np.void, 8 * table.shape[1])))
    return rows.reshape(-1)[index].view(np.uint64).reshape(len(index), table.shape[1])


def render(grid: np.ndarray) -> bytes:
    """The text of a (lines, words) uint64 grid: its bytes, every NUL dropped."""
    flat = np.ascontiguousarray(grid).view(np.uint8).reshape(-1)
    return flat[flat != 0].tobytes()


def line_starts(text: bytes) -> np.ndarray:
    """(lines + 1,) byte offsets at which each line of ``text`` starts (every line ends in a
    newline), then its length."""
    ends = np.flatnonzero(np.frombuffer(text, dtype=np.uint8) == ord("\n")) + 1
    return np.concatenate([[0], ends]).astype(np.int64)
