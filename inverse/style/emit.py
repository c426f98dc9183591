"""A captured style sheet written as ``.bgr``: the shape layer as blocks and walls, the texture
layer as per-face splitting rules whose pieces carry texture crops.

Derived on a lot, the grammar extrudes it to the source's height (``attr height``), cuts it
into the source's blocks at their relative heights, sets each block back as the source's was
(``t`` and ``s`` in fractions of the lot), and decorates each of its four walls (comp(f)'s
front, right, back and left): the wall's levels at their relative heights, each level's faces at
their relative widths, a face set back from the block's outer boundary recessed by its depth.

Each face is cut along y by its level group's vertical rule and each window row along x by its
stack group's horizontal rule, both **exactly as equations 8 and 9** (section 5.2.3), in the
grammar's own terms so that any mass can take it.  The equations are written once per number m
of insertable pieces, the sizes and crops being parameters:

    SplitX2(a0, a1, a2, b0, b1, p, c1, c2, d0, d1, d2, s0, s1, s2, i0, i1) -->
        SplitX2Fit(.., floor(scope.sx / p))                 x whole patterns of length p
    SplitX2Fit(.., x) --> SplitX2Y(.., x, (scope.sx - x * p >= c1 ? 1 : 0) + (.. >= c2 ? 1 : 0))
    SplitX2Y(.., x, y) --> case (a tie, y = 0): .. | else: SplitX2Run(a.., b.., s.., i.., x, y, Sr)
    SplitX2Run(.., x, y, sr) --> case x > 0: split(x) { a0 * sr: Wall(s0) | b0: Window(i0) | ..
                                                        | ~1: SplitX2Run(.., x - 1, y, sr) }
        | else: split(x) { ~a0: Wall(s0) | (y > 0 ? b0 : 0): Window(i0) | .. }   the tail

(c_y and d_y the sums of b0 .. b(y-1) and a0 .. ay, see :func:`split_rules`).  A group's rule
is one line of its numbers (``Bays3(s0, s1, i0) --> SplitX1(0.8, 0.8, 1.2, 2.8, 1.2, 0.8, 1.6,
s0, s1, i0)``), and a face one line of its crops per window row (``F7Row0 --> Bays3("..", "..",
"..")``; along y the window rows are rules handed to the group's rule).  So the text grows with
the crops, not with faces x pieces x tail cases: PLATEAU's 10 buildings took 22,900 lines
(parsing and formatting them was most of a capture's time) and take 4,300, deriving the same
meshes (benchmarked in bench/style.py, docs/benchmarks.md).

Sizes are metres: windows (insertable pieces) keep the size they had, walls (scalable pieces)
stretch by Sr.  Every piece shows its crop of the face's own texture (``Window("...")`` or
``Wall("...")``), one PNG per distinct crop in the assets folder, named by content so that two
faces cutting the same pixels share one file.
"""

from __future__ import annotations

import hashlib
import io
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from bgr.grammar.formatter import (
    HEAD_WIDTH,
    INDENT,
    WIDTH,
    format_number,
    format_source,
    format_string,
)
from bgr.grammar.safe_text import comment_line, comment_text

from .groups import RIGHTWARD, Groups, along
from .model import OUTWARD, WALLS, Block, Capture, Face
from .rules import Rule

MIN_PIECE = 0.001  # metres: a scalable piece this short still takes its share (no 0 / 0)
RECESS = 0.02  # metres: a face set back less than this is flush with its wall
PART = 0.98  # a comp(f) face narrower than this share of its side is one of several faces
ROOF = "#9a9a9a"  # a roof's colour when the source's is unknown (a textured roof)


def num(x: float, digits: int = 4) -> str:
    """A .bgr number rounded to ``digits`` decimals (millimetres for metres)."""
    return format_number(round(float(x), digits) + 0.0)


@dataclass
class Crops:
    """The texture crops of a style sheet: PNG bytes by file name, each distinct crop once."""

    folder: str  # how the grammar names the assets folder (relative to the grammar)
    max_size: int = 512  # each side at most this many pixels, on its own (--max-texture-size)
    files: dict[str, bytes] = field(default_factory=dict)
    _names: dict[str, str] = field(default_factory=dict)

    def add(self, image: np.ndarray) -> str:
        """The grammar's path of the PNG of ``image`` ((h, w, 3) uint8), written once.

        Each side longer than ``max_size`` is shrunk on its own, by area averaging: a crop is
        stretched once over its piece, so its aspect need not be kept, and a wall strip as wide
        as its face and a few rows high (1,200 x 37 pixels) scaled as a whole would lose its
        rows (16 left: a window frame's line smeared over the wall); averaging, unlike Lanczos,
        rings no halo beside such a line."""
        from PIL import Image

        pil = Image.fromarray(np.ascontiguousarray(image), "RGB")
        if max(pil.size) > self.max_size:
            size = (min(pil.width, self.max_size), min(pil.height, self.max_size))
            pil = pil.resize(size, Image.Resampling.BOX)
        out = io.BytesIO()
        pil.save(out, "PNG", compress_level=1)  # 5 % larger than zlib 6, half the time
        data = out.getvalue()
        key = hashlib.sha256(data).hexdigest()
        if key not in self._names:
            name = f"crop{len(self._names):04d}.png"
            self._names[key] = name
            self.files[name] = data
        return f"{self.folder}/{self._names[key]}" if self.folder else self._names[key]


def _pixels(cuts: list[tuple[str, float, float]], n: int) -> list[tuple[str, int, int]]:
    """Fractional sections as pixel spans of an image n pixels long, each at least 1 pixel."""
    out = []
    for kind, a, b in cuts:
        first = min(n - 1, int(round(a * n)))
        out.append((kind, first, max(first + 1, min(n, int(round(b * n))))))
    return out


def split_sizes(scalable: Sequence[float], insertable: Sequence[float]) -> list[str]:
    """The numbers a group hands its Split rule: A (a0 .. am, each at least MIN_PIECE), B (b0 ..
    b(m-1)), the pattern's length P, the sums c1 .. cm of b0 .. b(y-1) and d0 .. dm of a0 ..
    ay.  The sums are rounded here, once, like the sizes: summed by the grammar they would
    carry float error, and a target exactly as wide as a sum (the source's own mass) would
    fall on either side of an equation 8 comparison."""
    a = [max(MIN_PIECE, v) for v in scalable]
    b = list(insertable)
    sums = [sum(a) + sum(b)] + [sum(b[:y]) for y in range(1, len(b) + 1)]
    sums += [sum(a[: y + 1]) for y in range(len(a))]
    return [num(v) for v in a + b + sums]


def split_rules(axis: str, m: int) -> list[str]:
    """Equations 8-9 (split_h along x, split_v along y) once for every rule of ``m >= 1``
    insertable pieces: ``SplitX<m>(a0 .. am, b0 .. b(m-1), p, c1 .. cm, d0 .. dm, s0 .. sm,
    i0 .. i(m-1))`` takes the sizes of A (scalable, metres) and B (insertable) and their sums
    (:func:`split_sizes`), the crops of the scalable pieces (``Wall(s)``) and the insertable
    pieces: crops of windows along x (``Window(i)``), the window rows' rules along y.  A group's
    rule is then one line of its numbers, and a face's one line of its crops.

    ``..Fit`` takes x = floor(W / P) whole patterns; ``..Y`` the largest tail y whose insertable
    pieces b0 .. b(y-1) fit what is left (the count of the sums c_k the rest holds: they grow
    with k), Sr filling the scope, and a tie in the window count when no tail fits goes to the
    layout whose walls stretch least; ``..Run`` lays the whole patterns one by one, then the
    tail [a0 b0 .. a(y-1) b(y-1) ay] as one split whose pieces beyond y have size 0 (a split
    makes no shape of size 0).  Every choice is one expression rather than a case per y, so the
    text grows with m, not m^2 (the rules pass every parameter on: a case per y made a rule
    of 74 windows 70,000 tokens long)."""
    a = [f"a{k}" for k in range(m + 1)]
    b = [f"b{k}" for k in range(m)]
    c = [f"c{k}" for k in range(1, m + 1)]  # c_y = b0 + .. + b(y-1)
    d = [f"d{k}" for k in range(m + 1)]  # d_y = a0 + .. + ay
    s = [f"s{k}" for k in range(m + 1)]
    i = [f"i{k}" for k in range(m)]
    scalable = [f"Wall({v})" for v in s]
    inserted = [f"Window({v})" for v in i] if axis == "x" else i
    name = f"Split{axis.upper()}{m}"
    every = ", ".join(a + b + ["p"] + c + d + s + i)
    pieces = ", ".join(a + b + s + i)  # what laying the pieces out needs
    size = f"scope.s{axis}"
    sum_a, sum_b = d[m], c[m - 1]
    # y: how many of c1 <= c2 <= .. <= cm the rest holds, i.e. the largest y with c_y <= rest
    y = _balanced([f"({size} - x * p >= {v} ? 1 : 0)" for v in c])
    tail_b = _balanced([f"(y == {k} ? {v} : 0)" for k, v in enumerate(c, 1)])
    tail_a = _balanced([f"(y == {k} ? {v} : 0)" for k, v in enumerate(d)])
    sr = f"({size} - x * {sum_b} - {tail_b}) / (x * {sum_a} + {tail_a})"
    alt = f"({size} - x * {sum_b}) / (x * {sum_a})"
    sr0 = f"({size} - x * {sum_b}) / (x * {sum_a} + {d[0]})"
    whole = [f"{a[0]} * sr: {scalable[0]}"]
    tail = [f"~{a[0]}: {scalable[0]}"]
    for k in range(m):
        whole += [f"{b[k]}: {inserted[k]}", f"{a[k + 1]} * sr: {scalable[k + 1]}"]
        tail += [
            f"(y > {k} ? {b[k]} : 0): {inserted[k]}",
            f"~(y > {k} ? {a[k + 1]} : 0): {scalable[k + 1]}",
        ]
    whole.append(f"~1: {name}Run({pieces}, x - 1, y, sr)")
    fewer = f"{name}Run({pieces}, x - 1, {m}, {alt})"
    return [
        f"{name}({every}) --> {name}Fit({every}, floor({size} / p))",
        f"{name}Fit({every}, x) --> {name}Y({every}, x, {y})",
        # a tie in the window count (no tail fits): the layout whose walls stretch least
        f"{name}Y({every}, x, y) --> "
        f"case y == 0 and x > 0 and abs({alt} - 1) < abs({sr0} - 1): {fewer} "
        f"| else: {name}Run({pieces}, x, y, {sr})",
        f"{name}Run({pieces}, x, y, sr) --> "
        f"case x > 0: split({axis}) {{ {' | '.join(whole)} }} "
        f"| else: split({axis}) {{ {' | '.join(tail)} }}",
    ]


def _balanced(terms: list[str]) -> str:
    """A sum of terms nested log2(n) deep: the checker limits an expression's depth."""
    if len(terms) == 1:
        return terms[0]
    half = len(terms) // 2
    return f"({_balanced(terms[:half])} + {_balanced(terms[half:])})"


def _params(params: tuple[str, ...]) -> str:
    return f"({', '.join(params)})" if params else ""


def _hex(color: tuple[int, int, int]) -> str:
    return "#" + "".join(f"{int(c):02x}" for c in color)


class _Raw(str):
    """A line already in the formatter's layout (bgr fmt): a declaration, a comment or a rule of
    one successor whose head is within HEAD_WIDTH columns (the formatter keeps such a rule on
    one line however long).  The style sheet's bulk -- the faces' crop lines -- is written so,
    and only the other rules go through the parser and the formatter: parsing the bulk back
    was most of a capture's time.  tests/test_style_emit.py checks that bgr fmt leaves the
    whole sheet unchanged."""


def _comment(text: str) -> _Raw:
    return _Raw(comment_line(text))


def _render(lines: list[str]) -> str:
    """The sheet's text: runs of lines that are not _Raw formatted by format_source, the _Raw
    ones as they are."""
    out: list[str] = []
    run: list[str] = []

    def flush() -> None:
        if run:
            out.append(format_source("\n".join(run) + "\n", "<style sheet>").rstrip("\n"))
            run.clear()

    for line in lines:
        if isinstance(line, _Raw):
            flush()
            out.append(line)
        else:
            run.append(line)
    flush()
    return "\n".join(out) + "\n"


def _block_rule(head: str, entries: list[str]) -> _Raw:
    """``head { e1 | e2 .. }`` in the formatter's layout: one line when it fits in its width,
    else one entry a line, each after the first behind ``| ``.  ``head`` is a rule head of at
    most HEAD_WIDTH columns and one operation that takes the block, the entries formatted."""
    line = f"{head} {{ {' | '.join(entries)} }}"
    if len(line) <= WIDTH:
        return _Raw(line)
    rows = [f"{head} {{", f"{INDENT}{entries[0]}"]
    rows += [f"{INDENT}| {e}" for e in entries[1:]]
    return _Raw("\n".join(rows + ["}"]))


class _Sheet:
    """Writes one building's section; ``p`` prefixes its rule names."""

    def __init__(
        self, capture: Capture, groups: Groups, crops: Crops, p: str, splits: set[tuple[str, int]]
    ) -> None:
        self.capture, self.groups, self.crops, self.p = capture, groups, crops, p
        self.index = {id(f): i for i, f in enumerate(groups.faces)}
        self.lines: list[str] = []
        self.consts: list[str] = []  # the source blocks' sizes, which bgr restyle matches
        self.shared: list[str] = []  # the groups' rules, each written once
        self.written: set[str] = set()
        self.splits = splits  # (axis, m) of every Split rule the groups call
        self.named: dict[int, str] = {}  # id(face) -> its rule, written once

    def group_rule(self, name: str, axis: str, rule: Rule) -> str:
        """One group's rule, written once for all its faces: ``name(s0 .., i0 ..) -->
        Split<axis><m>(its sizes, s0 .., i0 ..)``, the crops (or, along y, the window rows'
        rules) being the face's parameters.  Along x a group without windows is one wall."""
        if name in self.written:
            return name
        self.written.add(name)
        m = len(rule.insertable)
        s = [f"s{k}" for k in range(m + 1)]
        i = [f"i{k}" for k in range(m)]
        if m == 0:
            self.shared.append(_Raw(f"{name}(s0) --> Wall(s0)"))
            return name
        self.splits.add((axis, m))
        args = ", ".join(split_sizes(rule.scalable, rule.insertable) + s + i)
        head = f"{name}({', '.join(s + i)})"
        line = f"{head} --> Split{axis.upper()}{m}({args})"
        self.shared.append(_Raw(line) if len(head + " -->") <= HEAD_WIDTH else line)
        return name

    def face(self, face: Face) -> str:
        """Rules of one face (written on first use: a wall and a side of an L may both show
        it); returns its rule name."""
        if id(face) not in self.named:
            self.named[id(face)] = self._face(face)
        return self.named[id(face)]

    def _face(self, face: Face) -> str:
        """The face calls its level group's rows rule with its own crops, each window row
        calling its stack group's bays rule with that row's crops: the face's text is its
        crops, the splitting is its groups'."""
        i = self.index[id(face)]
        name = f"{self.p}F{i}"
        g = self.groups
        h, v = g.horizontal[i], g.vertical[i]
        rows, columns = g.rows[h], g.columns[v]
        metres = self.capture.scale
        self.lines.append(
            _comment(
                f"# {WALLS[face.wall]} wall, level {face.level}: {num(face.width * metres, 2)} x "
                f"{num(face.height * metres, 2)} m, {len(rows.insertable)} window rows of "
                f"{len(columns.insertable)} bays (rows: group {h}, bays: group {v})"
            )
        )
        texture = face.texture
        if texture is None:
            self.lines.append(_Raw(f'{name} --> color("{_hex(face.color)}") Plain'))
            return name
        th, tw = texture.shape[:2]
        row_px = _pixels(g.row_cuts[h], th)[::-1]  # bottom to top, as C and D
        col_px = _pixels(g.column_cuts[v], tw)
        if not rows.insertable:  # no window row: the bays run the face's full height
            row_px = [("insertable", 0, th)]
        bands = [(r0, r1) for kind, r0, r1 in row_px if kind == "scalable"]
        lines = [(r0, r1) for kind, r0, r1 in row_px if kind == "insertable"]
        walls = [(c0, c1) for kind, c0, c1 in col_px if kind == "scalable"]
        bays = [(c0, c1) for kind, c0, c1 in col_px if kind == "insertable"]

        def crop(r: tuple[int, int], c: tuple[int, int]) -> str:
            return format_string(self.crops.add(texture[r[0] : r[1], c[0] : c[1]]))

        bays_rule = self.group_rule(f"{self.p}Bays{v}", "x", columns)
        calls = [
            f"{bays_rule}({', '.join([crop(r, c) for c in walls] + [crop(r, c) for c in bays])})"
            for r in lines
        ]
        if not rows.insertable:
            self.lines.append(_Raw(f"{name} --> {calls[0]}"))
            return name
        args = [crop(r, (0, tw)) for r in bands] + [f"{name}Row{j}" for j in range(len(lines))]
        rows_rule = self.group_rule(f"{self.p}Rows{h}", "y", rows)
        self.lines.append(_Raw(f"{name} --> {rows_rule}({', '.join(args)})"))
        self.lines += [_Raw(f"{name}Row{j} --> {call}") for j, call in enumerate(calls)]
        return name

    def wall(self, b: int, block: Block, w: int, below_gap: float | None) -> str:
        """Rules of one wall of a block: levels, then faces at relative widths, recessed."""
        name = f"{self.p}B{b}{WALLS[w].capitalize()}"
        faces = block.walls[w]
        metres = self.capture.scale
        xmin, xmax, zmin, zmax = block.box
        outer = (-zmin, xmax, zmax, -xmin)[w]  # the outer boundary along OUTWARD[w]
        width = (xmax - xmin) if w in (0, 2) else (zmax - zmin)
        levels = []
        for level in block.levels:
            on = [f for f in faces if f.level == level and along(f)[1] - along(f)[0] > 1e-9]
            on.sort(key=lambda f: along(f)[0])
            pieces = []
            for f in on:
                span = along(f)[1] - along(f)[0]
                depth = (outer - float(f.start @ OUTWARD[w])) * metres
                rule = self.face(f)
                if depth > RECESS:
                    d = f"{num(depth)} * kh"
                    if below_gap is not None and depth < below_gap:  # the overhang fix (5.1.2)
                        d = f"min({d}, 0.9 * {num(below_gap)} * kw)"
                    back = f"-{d}" if d.startswith("min(") else f"-({d})"
                    pieces.append(
                        f"~{num(span * metres)}: [ {self.p}Reveal({d}) ] t(0, 0, {back}) {rule}"
                    )
                else:
                    pieces.append(f"~{num(span * metres)}: {rule}")
            if not pieces:
                pieces = ["~1: Plain"]
            lname = f"{name}L{level}"
            self.lines.append(_block_rule(f"{lname}(kh, kw) --> split(x)", pieces))
            span = (self.capture.floors[level + 1] - self.capture.floors[level]) * metres
            levels.append(f"~{num(span)}: {lname}(kh, kw)")
        height = (block.top - block.bottom) * metres
        scales = f"scope.sy / {num(height)}, scope.sx / {num(width * metres)}"
        self.lines.append(_Raw(f"{name} --> {name}Levels({scales})"))
        self.lines.append(_block_rule(f"{name}Levels(kh, kw) --> split(y)", levels))
        return name

    def side(self, b: int, block: Block, w: int, full_rule: str) -> str:
        """The selector of comp(f)'s faces looking the way of wall ``w``: ``full_rule`` (the
        whole wall, faces at relative widths, set-back ones recessed) for a face as wide as the
        block's side, as a box mass or the lot's block gives; else, where the block's outline is
        not a rectangle, one of its captured faces looking that way (a jog of an L included,
        whichever wall section 4.3.1 filed it under), chosen by its share of the side's width.

        Our addition: section 5.1.3 snaps a target's faces to the source's by dynamic time
        warping along the wall; comp(f) hands a rule one face at a time, which knows its width
        and not its place, so the width share is what a rule can match on.  On the source's own
        mass (bgr restyle onto it) every face finds itself; on another L the nearest share."""
        columns = side_columns(block, w)
        metres = self.capture.scale
        xmin, xmax, zmin, zmax = block.box
        full = (xmax - xmin) if w in (0, 2) else (zmax - zmin)
        shares = [float(np.hypot(*(first.end - first.start))) / full for first, _ in columns]
        if len(columns) <= 1 and all(r >= PART for r in shares):
            return full_rule
        name = f"{full_rule}Side"
        cases = [f"case scope.sx >= {num(PART)} * full: {full_rule}"]
        order = np.argsort(shares, kind="stable")
        for n_, j in enumerate(order):
            part = f"{full_rule}Part{n_}"
            pieces = []
            for level, face in zip(block.levels, columns[j][1], strict=True):
                span = (self.capture.floors[level + 1] - self.capture.floors[level]) * metres
                pieces.append(f"~{num(span)}: {self.face(face) if face is not None else 'Plain'}")
            self.lines.append(_block_rule(f"{part} --> split(y)", pieces))
            if n_ + 1 < len(order):
                limit = (shares[j] + shares[order[n_ + 1]]) / 2.0
                cases.append(f"case scope.sx < {num(limit)} * full: {part}")
            else:
                cases.append(f"else: {part}")
        self.lines.append(f"{name}(full) --> " + " | ".join(cases))
        return f"{name}({('bw', 'bd')[w % 2]})"

    def building(self) -> None:
        cap, p = self.capture, self.p
        xs = [v for b in cap.blocks for v in b.box[:2]]
        zs = [v for b in cap.blocks for v in b.box[2:]]
        x0, x1, z0, z1 = min(xs), max(xs), min(zs), max(zs)
        parts = []
        for k, block in enumerate(cap.blocks):
            above = cap.blocks[k + 1] if k + 1 < len(cap.blocks) else None
            walls = []
            for w in range(4):
                gap = None
                if above is not None:
                    mine = (-block.box[2], block.box[1], block.box[3], -block.box[0])[w]
                    theirs = (-above.box[2], above.box[1], above.box[3], -above.box[0])[w]
                    gap = (mine - theirs) * cap.scale if mine > theirs else None
                walls.append(f"{WALLS[w]}: {self.side(k, block, w, self.wall(k, block, w, gap))}")
            xmin, xmax, zmin, zmax = block.box
            fx, fz = (xmin - x0) / (x1 - x0), (zmin - z0) / (z1 - z0)
            sx, sz = (xmax - xmin) / (x1 - x0), (zmax - zmin) / (z1 - z0)
            self.lines.append(
                f"{p}Block{k} --> t('{num(fx)}, 0, '{num(fz)}) "
                f"s('{num(sx)}, '1, '{num(sz)}) {p}Block{k}Mass"
            )
            walls += [f"top: {p}Roof", "bottom: NIL"]
            if any("(bw)" in w or "(bd)" in w for w in walls):  # the sides' widths for ``side``
                self.lines.append(_Raw(f"{p}Block{k}Mass --> {p}Block{k}Faces(scope.sx, scope.sz)"))
                self.lines.append(_block_rule(f"{p}Block{k}Faces(bw, bd) --> comp(f)", walls))
            else:
                self.lines.append(_block_rule(f"{p}Block{k}Mass --> comp(f)", walls))
            parts.append(f"~{num((block.top - block.bottom) * cap.scale)}: {p}Block{k}")
            for what, size in zip(("width", "height", "depth"), block.size, strict=True):
                self.consts.append(_Raw(f"const {p}block{k}_{what} = {num(size * cap.scale)}"))
        self.lines.append(_block_rule(f"{p}Building --> split(y)", parts))
        self.lines.append(
            f"{p}Reveal(d) --> extrude(-d) comp(f) {{ side: reverseNormals() "
            'color("#8c8c8c") Plain | all: NIL }'
        )
        roof = _hex(cap.roof) if cap.roof is not None else ROOF
        self.lines.append(f'{p}Roof --> color("{roof}") Plain')


def side_columns(block: Block, w: int) -> list[tuple[Face, list[Face | None]]]:
    """The faces of ``block`` whose own outward normal is wall ``w``'s, as columns: one per such
    face of its lowest level (left to right), with the face of every level (bottom first) that
    overlaps it most along the wall (None where none does)."""
    axis = RIGHTWARD[w]

    def looks(f: Face) -> bool:
        e = f.end - f.start
        length = float(np.hypot(*e))
        return length > 0 and float(e @ axis) / length > 0.99

    def span(f: Face) -> tuple[float, float]:
        a, b = float(f.start @ axis), float(f.end @ axis)
        return (min(a, b), max(a, b))

    def on(level: int) -> list[Face]:
        return [f for faces in block.walls for f in faces if f.level == level and looks(f)]

    out: list[tuple[Face, list[Face | None]]] = []
    for first in sorted(on(block.levels[0]), key=lambda f: span(f)[0]):
        a0, a1 = span(first)
        column: list[Face | None] = []
        for level in block.levels:
            best, most = None, 0.0
            for f in on(level):
                b0, b1 = span(f)
                overlap = min(a1, b1) - max(a0, b0)
                if overlap > most:
                    best, most = f, overlap
            column.append(best)
        out.append((first, column))
    return out


HEADER = """\
# A style sheet captured by bgr infer --kind style (issue 27; docs/inverse-style.md).
# Derive it on a lot (bgr derive STYLE.bgr --lot L.geojson) or put it on a mass
# (bgr restyle MASS.glb --style STYLE.bgr). Window(file) pieces keep their size; Wall(file)
# pieces stretch; every face splits by equations 8 and 9 of Zhang et al. 2013."""


def style_text(sheets: list[tuple[Capture, Groups]], crops: Crops) -> str:
    """The formatted .bgr of one or more captured buildings (the first is the default)."""
    out = [HEADER, "version 1", ""]
    sections: list[list[str]] = []
    sheet_consts: list[list[str]] = []
    splits: set[tuple[str, int]] = set()
    for k, (capture, groups) in enumerate(sheets):
        sheet = _Sheet(capture, groups, crops, f"S{k}" if len(sheets) > 1 else "", splits)
        sheet.building()
        sections.append(sheet.shared + sheet.lines)
        sheet_consts.append(sheet.consts)
    first = sheets[0][0]
    if len(sheets) > 1:
        out.append("# which captured building a lot takes (0 .. n - 1)")
    if len(sheets) > 1:
        out.append("attr style = 0")
    out.append(f"attr height = {num(first.scale, 2)}  # metres; the source's height")
    out.append(
        "# bgr restyle: the source block a target block takes (-1: the whole building on the lot)"
    )
    out.append("attr block = -1")
    out.append("attr block_base = 0")
    out.append("attr block_height = 1")
    out.append("")
    out.append("terminal WallTile, WindowTile, Plain")
    starts = []
    for k, (capture, _) in enumerate(sheets):
        p = f"S{k}" if len(sheets) > 1 else ""
        blocks = [
            f"case block == {j}: t(0, block_base, 0) extrude(block_height) {p}Block{j}Mass"
            for j in range(len(capture.blocks))
        ]
        starts.append((p, " | ".join(blocks) + f" | else: extrude(height) {p}Building"))
    if len(starts) == 1:
        out.append(f"Lot --> {starts[0][1]}")
    else:
        cases = [f"case style == {k}: {p}Lot" for k, (p, _) in enumerate(starts[:-1])]
        out.append("Lot --> " + " | ".join(cases) + f" | else: {starts[-1][0]}Lot")
        for p, body in starts:
            out.append(f"{p}Lot --> {body}")
    out.append(
        "# a crop of a face's texture stretched once over the piece, in its own colours (a "
        "shape's colour multiplies its texture, and bgr's default is a light grey)"
    )
    out.append(
        "Wall(file) --> color(\"#ffffff\") setupProjection(0, scope.xy, '1, '1) projectUV(0) "
        "texture(file) WallTile"
    )
    out.append(
        "Window(file) --> color(\"#ffffff\") setupProjection(0, scope.xy, '1, '1) projectUV(0) "
        "texture(file) WindowTile"
    )
    out.append(
        "# equations 8 and 9: a group's sizes, then its pieces' crops (along y: its window rows)"
    )
    for axis, m in sorted(splits):
        out += split_rules(axis, m)
    for k, lines in enumerate(sections):
        capture = sheets[k][0]
        out.append(_Raw(""))
        out.append(
            f"# ---- {comment_text(capture.building)}: {len(capture.blocks)} blocks, "
            f"{num(capture.scale, 2)} m high"
        )
        out.append(
            "# the source's blocks in metres, bottom to top (bgr restyle matches a mass to them)"
        )
        out += sheet_consts[k]
        out += lines
    return _render(out)
