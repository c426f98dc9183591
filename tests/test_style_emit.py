"""The style sheet's text (inverse/style/emit.py, issue 27): equations 8-9 written once as
SplitX<m> / SplitY<m> must lay pieces out exactly as rules.layout (the Python split_h of section
5.2.3) does, and the sheet, written mostly without the formatter, must be what bgr fmt prints."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import bgr
from bgr.grammar.formatter import format_source
from bgr.inverse.style.capture import infer_style
from bgr.inverse.style.emit import split_rules, split_sizes
from bgr.inverse.style.emit_splits import MAX_SR
from bgr.inverse.style.rules import layout

sys.path.insert(0, str(Path(__file__).parent))
from style_synth import make_building  # noqa: E402

HEADER = """version 1
attr w = 10
terminal WallTile, WindowTile
Wall(file) --> color("#ff0000") WallTile
Window(file) --> color("#0000ff") WindowTile
Bay(w, file) --> case w == 1: Window(file) | else: Wall(file)
Lot --> s(w, 0, 1) extrude(3) comp(f) { back: Face | all: NIL }
"""


def _windows(grammar: str, width: float) -> np.ndarray:
    """(n, 2) x extents of the blue (Window) quads of the back face (its x axis is world x)."""
    mesh = bgr.derive(bgr.load(grammar), attrs={"w": width}, start="Lot").mesh
    blue = np.all(mesh.visual.face_colors[:, :3] == (0, 0, 255), axis=1)
    xs = mesh.vertices[mesh.faces[blue]][:, :, 0]
    spans = np.unique(np.round(np.column_stack([xs.min(1), xs.max(1)]), 6), axis=0)
    return spans[np.argsort(spans[:, 0])]


def _expected(A: tuple, B: tuple, width: float) -> np.ndarray:
    """The windows of rules.layout (equations 8-9), or, where not one window fits or Sr passes
    MAX_SR (or 1 / MAX_SR), of the nearest whole number n >= 1 of patterns scaled alike
    (emit_splits.py's deviation)."""
    pieces = layout(A, B, width)
    sr = pieces[0][2] / A[0]
    if not any(kind == "insertable" for kind, _, _ in pieces) or not 1 / MAX_SR <= sr <= MAX_SR:
        n = max(1, round(width / (sum(A) + sum(B))))
        k = width / (n * (sum(A) + sum(B)))
        pattern = [("scalable", A[0] * k)]
        for a, b in zip(A[1:], B, strict=True):
            pattern += [("insertable", b * k), ("scalable", a * k)]
        pieces = [(kind, 0, size) for kind, size in pattern * n]
    at, out = 0.0, []
    for kind, _, size in pieces:
        if kind == "insertable":
            out.append((at, at + size))
        at += size
    return np.array(out).reshape(-1, 2)


@pytest.mark.parametrize(
    ("A", "B", "widths"),
    [
        # hand-computed: P = 4; W = 9: x = 2, y = 0, Sr = 1, windows at 1-3 and 5-7;
        # W = 10.5: x = 2, the tail b1 fits (y = 1), Sr = 0.75, windows at 0.75, 4.25, 7.5;
        # W = 1.5: no window fits (x = y = 0), one pattern x 1.5 / 4; W = 12.5: Sr = 2.25
        ((1.0, 1.0), (2.0,), (9.0, 10.5, 4.0, 3.0, 1.5, 12.5)),
        ((0.5, 1.2, 0.8), (1.0, 0.6), (2.0, 6.1, 10.0, 13.3)),
        ((1.15, 1.8, 1.8, 1.15), (0.7, 0.7, 0.7), (3.6, 8.0, 14.0, 20.0)),
    ],
)
def test_split_rules_lay_out_windows_as_split_h(A, B, widths):
    m = len(B)
    crops = [f'"s{k}"' for k in range(m + 1)] + [f'"i{k}"' for k in range(m)]
    call = f"Face --> SplitX{m}({', '.join(split_sizes(A, B) + crops)}, 1)\n"
    grammar = HEADER + call + "\n".join(split_rules("x", m)) + "\n"
    for width in widths:
        got = _windows(grammar, width)
        assert got.shape == _expected(A, B, width).shape, width
        assert np.allclose(got, _expected(A, B, width), atol=1e-6), width


def test_split_rules_hand_computed():
    """P = 4.  W = 9: x = 2, b1 does not fit the 1 left (y = 0), Sr = 5 / 5 = 1.  W = 10.5:
    x = 2, the tail takes b1 (2.5 >= 2, y = 1), Sr = (10.5 - 4 - 2) / (2 * 2 + 2) = 0.75:
    patterns of 3.5, the tail's window after 7 + 0.75."""
    grammar = HEADER + 'Face --> SplitX1(1, 1, 2, 4, 2, 1, 2, "s0", "s1", "i0", 1)\n'
    grammar += "\n".join(split_rules("x", 1)) + "\n"
    assert np.allclose(_windows(grammar, 9.0), [[1, 3], [5, 7]])
    assert np.allclose(_windows(grammar, 10.5), [[0.75, 2.75], [4.25, 6.25], [7.75, 9.75]])


def test_a_tail_of_no_window_makes_no_empty_piece():
    """The tail is one split whose pieces beyond y have size 0: none of them becomes a shape.
    W = 5: x = 1, the 1 m left holds no window (y = 0), Sr = 3 / 3 = 1: the pattern's three
    quads and the tail's one wall, the tail's window and last wall (size 0) dropped."""
    grammar = HEADER + 'Face --> SplitX1(1, 1, 2, 4, 2, 1, 2, "s0", "s1", "i0", 1)\n'
    grammar += "\n".join(split_rules("x", 1)) + "\n"
    mesh = bgr.derive(bgr.load(grammar), attrs={"w": 5.0}, start="Lot").mesh
    assert len(mesh.faces) == 8
    assert np.allclose(np.ptp(mesh.vertices[:, 0]), 5.0)


def test_a_face_narrower_than_a_window_takes_the_pattern_scaled():
    """W = 1.5 < b1 = 2: equation 8 would stretch a1 over the face; the pattern scaled by
    1.5 / 4 keeps its window (0.375 .. 1.125), and a wall band's row (w = 0) shows the same
    piece as a wall."""
    grammar = HEADER + 'Face --> SplitX1(1, 1, 2, 4, 2, 1, 2, "s0", "s1", "i0", 1)\n'
    grammar += "\n".join(split_rules("x", 1)) + "\n"
    assert np.allclose(_windows(grammar, 1.5), [[0.375, 1.125]])
    band = grammar.replace('"i0", 1)', '"i0", 0)')
    assert _windows(band, 1.5).shape == (0, 2)


@pytest.mark.parametrize("kind", range(5))
def test_the_sheet_is_what_bgr_fmt_prints(tmp_path, kind):
    """Most of the sheet is written in the formatter's layout without it (emit._Raw): the
    formatter must leave the whole text unchanged, on every synthetic building (recessed
    levels, set-backs, L outlines, window rows)."""
    glb, _ = make_building(kind, tmp_path)
    text, files, _ = infer_style(str(glb), assets=f"k{kind}.assets")
    assert format_source(text) == text
    assert len(files) > 10


@pytest.mark.parametrize("axis", ["x", "y"])
def test_split_rules_are_built_as_trees_bgr_fmt_prints(axis):
    """The Split rules are syntax trees printed by the formatter, not parsed text: what they
    print parses back to the same trees and is what bgr fmt prints, for rules of 1 to 80
    windows (PLATEAU's and the tessellated model's reach 74)."""
    from bgr.grammar.parser import parse
    from bgr.inverse.style.emit_splits import split_rule_nodes

    for m in (*range(1, 12), 37, 74, 80):
        text = "\n".join(split_rules(axis, m)) + "\n"
        assert format_source(text) == text, m
        parsed = parse(text).rules()
        built = split_rule_nodes(axis, m)
        assert [(r.name, r.params) for r in parsed] == [(r.name, r.params) for r in built]
        assert [_shape(r.body) for r in parsed] == [_shape(r.body) for r in built], m


def _shape(node):
    """A node without its source positions, for comparing a parsed tree with a built one."""
    import dataclasses

    if isinstance(node, list):
        return [_shape(v) for v in node]
    if dataclasses.is_dataclass(node):
        return (type(node).__name__,) + tuple(
            _shape(getattr(node, f.name)) for f in dataclasses.fields(node) if f.name != "pos"
        )
    return node
