"""The bulk helpers of the text and PLY writers: numbers formatted by numpy print exactly as
Python prints them (:mod:`bgr.formats.text`), and equal rows are numbered by first use however
they are found (:mod:`bgr.formats.sharing`)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bgr.formats import sharing
from bgr.formats.sharing import number_rows
from bgr.formats.text import decimal, integer, left_aligned, quantize, render, word


def reference(q: int) -> str:
    whole, frac = divmod(abs(q), 10**6)
    text = f"{whole}.{frac:06d}".rstrip("0").rstrip(".")
    return ("-" if q < 0 else "") + text


def lines(*columns: np.ndarray) -> list[str]:
    n = len(columns[0])
    cols = [np.full((n, 1), word(b"<")), *[c.reshape(n, -1) for c in columns]]
    return (
        render(np.concatenate([*cols, np.full((n, 1), word(b"\n"))], axis=1)).decode().splitlines()
    )


@pytest.mark.parametrize("prefix", [b" ", b"v ", b"vn "])
def test_decimals_print_as_python_does(prefix):
    rng = np.random.default_rng(3)
    edges = [0.0, -0.0, 4e-7, -4e-7, 6e-7, 1.5, -1, 0.1, 9999.9999995, 99999.999999, -99999.5]
    edges += [100000, 123456789.123456, -3e9, 1e-6, -1e-6, 10000, -10000]
    x = np.concatenate(
        [
            edges,
            rng.uniform(-2, 2, 500),
            rng.uniform(-5000, 5000, 500),
            10.0 ** rng.integers(-7, 10, 500) * rng.choice([-1, 1], 500),
        ]
    )
    q = quantize(x)
    assert lines(*decimal(q, prefix)) == ["<" + prefix.decode() + reference(int(v)) for v in q]
    assert q[1] == 0 and lines(*decimal(q[1:2]))[0] == "< 0"  # no "-0"


@pytest.mark.parametrize("prefix", [b" ", b"//", b"f "])
def test_integers_print_as_python_does(prefix):
    values = np.array([0, 1, 9, 10, 99, 9999, 10000, 99999, 999999, 10**7 - 1, 10**8, 10**12, 0])
    expected = ["<" + prefix.decode() + str(v) for v in values]
    assert lines(integer(values, prefix)) == expected
    assert lines(left_aligned(integer(values, prefix))) == expected
    many = np.arange(0, 2_000_000, 37)
    assert lines(integer(many, prefix)) == ["<" + prefix.decode() + str(v) for v in many]
    negative = values % 3 == 1
    signed = [
        "<" + prefix.decode() + ("-" if s else "") + str(v)
        for v, s in zip(values, negative, strict=True)
    ]
    assert lines(integer(values, prefix, negative)) == signed


def test_render_drops_only_the_padding():
    grid = np.array([[word(b"a\0b"), word(b"\0\0c\n")], [word(b""), word(b"d\n")]], dtype=np.uint64)
    assert render(grid) == b"abc\nd\n"
    assert render(np.zeros((0, 3), dtype=np.uint64)) == b""


# --- shared vertices --------------------------------------------------------------------------


def first_use(rows: list[tuple]) -> tuple[list[int], list[int]]:
    seen: dict[tuple, int] = {}
    ids = [seen.setdefault(r, len(seen)) for r in rows]
    firsts = [ids.index(j) for j in range(len(seen))]
    return ids, firsts


@pytest.mark.parametrize("layout", ["shuffled", "runs", "distinct"])
@pytest.mark.parametrize("scale", [1, 10**14])
def test_rows_are_numbered_by_first_use(scale, layout, monkeypatch):
    """Packed keys (small numbers) and hashed ones (large), rows repeated at random, in runs
    (as a quad's two normals) or never."""
    rng = np.random.default_rng(4)
    distinct = np.unique(rng.integers(-5, 5, (300, 3)), axis=0) * scale
    if layout == "distinct":
        rows = distinct[rng.permutation(len(distinct))]
    else:
        rows = distinct[rng.integers(0, len(distinct), 5000)]
        if layout == "runs":
            rows = np.repeat(rows, rng.integers(1, 4, len(rows)), axis=0)
    ids, firsts = first_use([tuple(r) for r in rows.tolist()])
    columns = [rows[:, 0], rows[:, 1], rows[:, 2]]
    got = number_rows(columns)
    assert got[0].tolist() == ids and got[1].tolist() == firsts
    # every row hashing alike: the check against the rows catches it, a full sort numbers them
    monkeypatch.setattr(sharing, "_hash", lambda cols: np.zeros(len(cols[0]), dtype=np.uint64))
    got = number_rows(columns)
    assert got[0].tolist() == ids and got[1].tolist() == firsts
    assert [a.tolist() for a in number_rows([np.zeros(0, dtype=np.int64)])] == [[], []]
    assert [a.tolist() for a in number_rows([np.array([7])])] == [[0], [0]]


def test_quantize_is_what_decimal_prints():
    x = np.array([1.0000004, 1.0000006, -2.5e-7, math.pi])
    assert quantize(x).tolist() == [1000000, 1000001, 0, 3141593]
