"""A captured style sheet written as ``.bgr``: the shape layer as blocks and walls, the texture
layer as per-face splitting rules whose pieces carry texture crops.

Derived on a lot, the grammar extrudes it to the source's height (``attr height``), cuts it
into the source's blocks at their relative heights, sets each block back as the source's was
(``t`` and ``s`` in fractions of the lot), and decorates each of its four walls (comp(f)'s
front, right, back and left): the wall's levels at their relative heights, each level's faces at
their relative widths, a face set back from the block's outer boundary recessed by its depth.

A recess keeps its depth in metres, as a window keeps its size, but shrinks with the block's
extent across the wall (``k``: the target block's depth behind the wall over the source's, at
most 1; times ``recess_x`` / ``recess_z``, which bgr restyle lowers on a mass that is not a box
to its thinnest part over its extent), and reaches at most DEEPEST of the block: so a reveal
stays inside any target.  Scaled by the wall's height or width instead, a 1 m recess of a 7 m
block became 8.5 m on a 60 m slab and its reveal ran through the building and out of the
opposite wall.  A reveal's sides take the recessed face's colour, and only where needed: no
ceiling at the block's top or floor at its bottom (the roofs close them), jambs only beside a
shallower neighbour (see :meth:`_Sheet.wall`).

Each face is cut along y by its level group's vertical rule into rows (window rows and the wall
bands between them) and each row along x by its stack group's horizontal rule, both **exactly
as equations 8 and 9** (section 5.2.3, with the two deviations of emit_splits.py), in the
grammar's own terms so that any mass can take it.  The equations are written once per number m
of insertable pieces (emit_splits.py), a group's rule is one line of its sizes and a face's row
one line of its crops (``F7Row0 --> Bays3(1, "..", "..", "..")``), so the text grows with the
crops, not with faces x pieces x tail cases.

Sizes are metres: windows (insertable pieces) keep the size they had, walls (scalable pieces)
stretch by Sr.  Every piece shows its crop of the face's own texture (``Window("...")`` or
``Wall("...")``), one PNG per distinct crop in the assets folder, named by content so that two
faces cutting the same pixels share one file.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import numpy as np

from bgr.formats.png import png_bytes
from bgr.grammar.formatter import (
    HEAD_WIDTH,
    INDENT,
    WIDTH,
    format_source,
    format_string,
)
from bgr.grammar.safe_text import comment_line, comment_text

from .emit_splits import group_body, num, split_rules, split_sizes
from .groups import RIGHTWARD, Groups, along
from .model import OUTWARD, WALLS, Block, Capture, Face
from .rules import Rule

__all__ = ["Crops", "num", "split_rules", "split_sizes", "style_text"]

RECESS = 0.02  # metres: a face set back less than this is flush with its wall
PART = 0.98  # a comp(f) face narrower than this share of its side is one of several faces
DEEPEST = 0.9  # a recess is at most this fraction of the block's extent behind its wall
ROOF = "#9a9a9a"  # a roof's colour when the source's is unknown (a textured roof)


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
        image = np.ascontiguousarray(image, dtype=np.uint8)
        if max(image.shape[:2]) > self.max_size:
            from PIL import Image

            pil = Image.fromarray(image, "RGB")
            size = (min(pil.width, self.max_size), min(pil.height, self.max_size))
            image = np.asarray(pil.resize(size, Image.Resampling.BOX))
        key = hashlib.sha256(repr(image.shape).encode() + image.tobytes()).hexdigest()
        if key not in self._names:
            name = f"crop{len(self._names):04d}.png"
            self._names[key] = name
            self.files[name] = png_bytes(image)  # zlib level 1: the crops are small
        return f"{self.folder}/{self._names[key]}" if self.folder else self._names[key]


def _pixels(cuts: list[tuple[str, float, float]], n: int) -> list[tuple[str, int, int]]:
    """Fractional sections as pixel spans of an image n pixels long, each at least 1 pixel."""
    out = []
    for kind, a, b in cuts:
        first = min(n - 1, int(round(a * n)))
        out.append((kind, first, max(first + 1, min(n, int(round(b * n))))))
    return out


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


def _block_rule(head: str, entries: list[str], repeat: str = "") -> _Raw:
    """``head { e1 | e2 .. }`` in the formatter's layout: one line when it fits in its width,
    else one entry a line, each after the first behind ``| ``.  ``head`` is a rule head of at
    most HEAD_WIDTH columns and one operation that takes the block, the entries formatted;
    ``repeat`` "*" makes the split a floating repeat."""
    line = f"{head} {{ {' | '.join(entries)} }}{repeat}"
    if len(line) <= WIDTH:
        return _Raw(line)
    rows = [f"{head} {{", f"{INDENT}{entries[0]}"]
    rows += [f"{INDENT}| {e}" for e in entries[1:]]
    return _Raw("\n".join(rows + ["}" + repeat]))


def _short(line: str) -> str:
    """A rule of one line whose head is short and whose expressions are written as bgr fmt
    prints them: kept as it is when it fits the width (the formatter would not break it), else
    left to the formatter."""
    head = line.split(" --> ", 1)[0] + " -->"
    return _Raw(line) if len(line) <= WIDTH and len(head) <= HEAD_WIDTH else line


def _negated(depth: str) -> str:
    """``-(depth)`` as bgr fmt prints it, for the three forms a recess takes: ``0``, a product
    ``a * min(1, k)`` (which keeps its parentheses) and a call ``min(..)`` (which needs none).
    A difference ``a - b`` of two of them needs no parentheses either."""
    if depth == "0":
        return "0"
    return f"-{depth}" if depth.startswith("min(") else f"-({depth})"


def _case_rule(head: str, alts: list[str]) -> str:
    """``head alt1 | alt2 ..`` (``case c: steps`` / ``else: steps``, steps without a block) in
    the formatter's layout: one line when it fits, else the head alone and one alternative a
    line, each after the first behind ``| ``.  A head too long for HEAD_WIDTH, which the
    formatter breaks one parameter a line, is left to the formatter."""
    if len(head) > HEAD_WIDTH:
        return f"{head} {' | '.join(alts)}"
    line = f"{head} {' | '.join(alts)}"
    if len(line) <= WIDTH:
        return _Raw(line)
    rows = [head, f"{INDENT}{alts[0]}"] + [f"{INDENT}| {a}" for a in alts[1:]]
    return _Raw("\n".join(rows))


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
        Split<axis><m>(its sizes, s0 .., i0 ..)`` (along x ``name(w, s0 .., i0 ..)``), the
        crops (along y, the face's rows) being the face's parameters (emit_splits.py)."""
        if name in self.written:
            return name
        self.written.add(name)
        m = len(rule.insertable)
        args = [f"s{k}" for k in range(m + 1)] + [f"i{k}" for k in range(m)]
        if m:
            self.splits.add((axis, m))
        flag = ["w"] if axis == "x" else []
        params = flag + args
        head = f"{name}({', '.join(params)}) -->"
        if len(head) > HEAD_WIDTH:  # bgr fmt's layout: one parameter a line
            head = "\n".join([f"{name}("] + [f"{INDENT}{v}," for v in params[:-1]])
            head += f"\n{INDENT}{params[-1]}\n) -->"
        body = group_body(axis, rule.scalable, rule.insertable, args + flag)
        self.shared.append(_Raw(f"{head} {body}"))
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
        walls = [(c0, c1) for kind, c0, c1 in col_px if kind == "scalable"]
        bays = [(c0, c1) for kind, c0, c1 in col_px if kind == "insertable"]

        def crop(r: tuple[int, int], c: tuple[int, int]) -> str:
            return format_string(self.crops.add(texture[r[0] : r[1], c[0] : c[1]]))

        # Every row, window row or wall band, is cut by the stack's columns (a band's pieces
        # all walls: w = 0): a band cropped whole and stretched over a wider face smeared (a
        # 29-pixel band of a 7 m face over a 30 m slab is 1 pixel a metre); cut at the window
        # columns, it repeats with them at the density it was photographed at.
        bays_rule = self.group_rule(f"{self.p}Bays{v}", "x", columns)
        row_lines = []
        for j, (kind, r0, r1) in enumerate(row_px):
            flag = "1" if kind == "insertable" else "0"
            crops = [crop((r0, r1), c) for c in walls] + [crop((r0, r1), c) for c in bays]
            row_lines.append(_Raw(f"{name}Row{j} --> {bays_rule}({', '.join([flag, *crops])})"))
        if rows.insertable:
            args = [f"{name}Row{j}" for j, r in enumerate(row_px) if r[0] == "scalable"]
            args += [f"{name}Row{j}" for j, r in enumerate(row_px) if r[0] == "insertable"]
            rows_rule = self.group_rule(f"{self.p}Rows{h}", "y", rows)
            self.lines.append(_Raw(f"{name} --> {rows_rule}({', '.join(args)})"))
        else:  # the face's own height repeats, as a rule of m = 0 does (emit_splits.py)
            repeat = f"~{num(face.height * metres)}: {name}Row0"
            self.lines.append(_block_rule(f"{name} --> split(y)", [repeat], "*"))
        self.lines += row_lines
        return name

    def wall(self, b: int, block: Block, w: int, below_gap: float | None) -> str:
        """Rules of one wall of a block: levels, then faces at relative widths, recessed (see
        the module's docstring); ``name(k)``, k the block's stretch across the wall."""
        name = f"{self.p}B{b}{WALLS[w].capitalize()}"
        faces = block.walls[w]
        metres = self.capture.scale
        xmin, xmax, zmin, zmax = block.box
        outer = (-zmin, xmax, zmax, -xmin)[w]  # the outer boundary along OUTWARD[w]
        behind = ((zmax - zmin) if w in (0, 2) else (xmax - xmin)) * metres
        levels = []
        for at, level in enumerate(block.levels):
            on = [f for f in faces if f.level == level and along(f)[1] - along(f)[0] > 1e-9]
            on.sort(key=lambda f: along(f)[0])
            depths = []  # each face's recess: (metres at the source, its .bgr expression)
            for f in on:
                # a level wider than the box that starts its block can put a face beyond
                # the opposite wall: no recess reaches past DEEPEST of the block
                depth = min((outer - float(f.start @ OUTWARD[w])) * metres, DEEPEST * behind)
                d = f"{num(depth)} * min(1, k)"
                if below_gap is not None and depth < below_gap:  # the overhang fix (5.1.2)
                    d = f"min({d}, 0.9 * {num(below_gap)} * k)"
                depths.append((depth, d) if depth > RECESS else (0.0, "0"))
            pieces = []
            for j, f in enumerate(on):
                span = along(f)[1] - along(f)[0]
                rule = self.face(f)
                depth, d = depths[j]
                if not depth:
                    pieces.append(f"~{num(span * metres)}: {rule}")
                    continue
                # The notch's ceiling (floor) at the block's top (bottom) would lie in the roof
                # (the block below's roof, or the bottom block's floor), which closes it, and
                # two coplanar faces flicker in any renderer that draws both sides.  Its sides
                # (jambs) run from the neighbour face's depth to its own, and only where the
                # neighbour is shallower: at the wall's end the next wall closes it, and the
                # deeper of two neighbours alone has the wall between them.
                colour = f'"{_hex(f.color)}"'
                top, bottom = int(at < len(block.levels) - 1), int(at > 0)
                parts = [f"[ {self.p}Reveal({d}, {top}, {bottom}, {colour}) ]"]
                for side, n in (("L", j - 1), ("R", j + 1)):
                    if 0 <= n < len(on) and depths[n][0] < depth - RECESS:
                        near = depths[n][1]
                        parts.append(
                            f"[ t(0, 0, {_negated(near)}) "
                            f"{self.p}Jamb{side}({d} - {near}, {colour}) ]"
                        )
                pieces.append(
                    f"~{num(span * metres)}: {' '.join(parts)} t(0, 0, {_negated(d)}) {rule}"
                )
            if not pieces:
                pieces = ["~1: Plain"]
            lname = f"{name}L{level}"
            self.lines.append(_block_rule(f"{lname}(k) --> split(x)", pieces))
            span = (self.capture.floors[level + 1] - self.capture.floors[level]) * metres
            levels.append(f"~{num(span)}: {lname}(k)")
        self.lines.append(_block_rule(f"{name}(k) --> split(y)", levels))
        return name

    def stack(self) -> str:
        """The body of ``Stack``: every source block on one target block, without setbacks (bgr
        restyle gives it to a mass of one block; see restyle.py).  The bottom block keeps its
        height in metres, and so does the top one when there are three or more; the blocks
        between them stretch to fill the rest, or, with two blocks, the top one does (the
        storeys a taller building repeats are its middle ones).  A target lower than the
        kept heights takes every block at its relative height instead."""
        cap, p = self.capture, self.p
        heights = [(b.top - b.bottom) * cap.scale for b in cap.blocks]
        n = len(heights)
        if n == 1:
            return f"{p}Block0Mass"
        kept = [0, n - 1] if n > 2 else [0]
        fixed = sum(heights[j] for j in kept)
        absolute = " | ".join(
            f"{'' if j in kept else '~'}{num(h)}: {p}Block{j}Mass" for j, h in enumerate(heights)
        )
        relative = " | ".join(f"~{num(h)}: {p}Block{j}Mass" for j, h in enumerate(heights))
        return (
            f"case scope.sy > {num(fixed)}: split(y) {{ {absolute} }} "
            f"| else: split(y) {{ {relative} }}"
        )

    def side(self, block: Block, w: int, wall: str, k: str) -> str:
        """The selector of comp(f)'s faces looking the way of wall ``w``: ``wall(k)`` (the
        whole wall, faces at relative widths, set-back ones recessed) for a face as wide as the
        block's side, as a box mass or the lot's block gives; else, where the block's outline is
        not a rectangle, one of its captured faces looking that way (a jog of an L included,
        whichever wall section 4.3.1 filed it under), chosen by its share of the side's width.

        Our addition: the paper maps a target's faces onto the source's by the blocks'
        similarity transforms (5.1.3); comp(f) hands a rule one face at a time, which knows its
        width and not its place, so the width share is what a rule can match on.  On the
        source's own mass (bgr restyle onto it) every face finds itself; on another L the
        nearest share."""
        columns = side_columns(block, w)
        metres = self.capture.scale
        xmin, xmax, zmin, zmax = block.box
        full = (xmax - xmin) if w in (0, 2) else (zmax - zmin)
        shares = [float(np.hypot(*(first.end - first.start))) / full for first, _ in columns]
        if len(columns) <= 1 and all(r >= PART for r in shares):
            return f"{wall}({k})"
        cases = [f"case scope.sx >= {num(PART)} * full: {wall}(k)"]
        order = np.argsort(shares, kind="stable")
        for n_, j in enumerate(order):
            part = f"{wall}Part{n_}"
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
        self.lines.append(_case_rule(f"{wall}Side(full, k) -->", cases))
        return f"{wall}Side({('bw', 'bd')[w % 2]}, {k})"

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
                across = "kz" if w in (0, 2) else "kx"  # front and back recess along z
                walls.append(
                    f"{WALLS[w]}: {self.side(block, w, self.wall(k, block, w, gap), across)}"
                )
            xmin, xmax, zmin, zmax = block.box
            fx, fz = (xmin - x0) / (x1 - x0), (zmin - z0) / (z1 - z0)
            sx, sz = (xmax - xmin) / (x1 - x0), (zmax - zmin) / (z1 - z0)
            self.lines.append(
                _short(
                    f"{p}Block{k} --> t('{num(fx)}, 0, '{num(fz)}) "
                    f"s('{num(sx)}, '1, '{num(sz)}) {p}Block{k}Mass"
                )
            )
            floor = f"{p}Roof" if k == 0 else "NIL"  # the ground closes the notches at its foot
            walls += [f"top: {p}Roof", f"bottom: {floor}"]
            # k of the walls: the block's stretch across them; bw, bd: its sides' widths
            width, _, depth = block.size
            ks = [
                f"scope.sx / {num(width * cap.scale)} * recess_x",
                f"scope.sz / {num(depth * cap.scale)} * recess_z",
            ]
            params = ["kx", "kz"]
            if any("Side(" in w for w in walls):
                ks, params = ks + ["scope.sx", "scope.sz"], params + ["bw", "bd"]
            self.lines.append(_short(f"{p}Block{k}Mass --> {p}Block{k}Walls({', '.join(ks)})"))
            head = f"{p}Block{k}Walls({', '.join(params)}) --> comp(f)"
            self.lines.append(_block_rule(head, walls))
            parts.append(f"~{num((block.top - block.bottom) * cap.scale)}: {p}Block{k}")
            for what, size in zip(("width", "height", "depth"), block.size, strict=True):
                self.consts.append(_Raw(f"const {p}block{k}_{what} = {num(size * cap.scale)}"))
        self.lines.append(_block_rule(f"{p}Building --> split(y)", parts))
        self.lines.append(_short(f"{p}Stack --> {self.stack()}"))
        self.lines.append(
            _short(
                f"{p}Reveal(d, t, b, c) --> extrude(-d) comp(f) {{ front: {p}RevealSide(t, c) "
                f"| back: {p}RevealSide(b, c) | all: NIL }}"
            )
        )
        for side, which in (("L", "left"), ("R", "right")):
            self.lines.append(
                _short(
                    f"{p}Jamb{side}(d, c) --> extrude(-max(d, 0)) comp(f) {{ {which}: "
                    f"{p}RevealSide(1, c) | all: NIL }}"
                )
            )
        self.lines.append(  # in the recessed face's mean colour, which its sides continue
            _case_rule(
                f"{p}RevealSide(keep, c) -->",
                ["case keep == 1: reverseNormals() color(c) Plain", "else: NIL"],
            )
        )
        roof = _hex(cap.roof) if cap.roof is not None else ROOF
        self.lines.append(_Raw(f'{p}Roof --> color("{roof}") Plain'))


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

    facing: dict[int, list[Face]] = {level: [] for level in block.levels}
    for faces in block.walls:
        for f in faces:
            if f.level in facing and looks(f):
                facing[f.level].append(f)

    out: list[tuple[Face, list[Face | None]]] = []
    for first in sorted(facing[block.levels[0]], key=lambda f: span(f)[0]):
        a0, a1 = span(first)
        column: list[Face | None] = []
        for level in block.levels:
            best, most = None, 0.0
            for f in facing[level]:
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
    if len(sheets) > 1:  # a lot takes its building's own height unless one is set
        out.append("attr height = 0  # metres; 0: the building's own, below")
        out += [_Raw(f"const S{k}height = {num(c.scale, 2)}") for k, (c, _) in enumerate(sheets)]
    else:
        out.append(f"attr height = {num(first.scale, 2)}  # metres; the source's height")
    out.append(
        "# bgr restyle: the source block a target block takes (-1: the whole building on the "
        "lot, -2: all its blocks stacked on the target block)"
    )
    out.append("attr block = -1")
    out.append("attr block_base = 0")
    out.append("attr block_height = 1")
    out.append(
        "# bgr restyle: the thinnest part of a target block that is not a box, over its extent"
    )
    out.append("attr recess_x = 1")
    out.append("attr recess_z = 1")
    out.append("")
    out.append("terminal WallTile, WindowTile, Plain")
    starts = []
    for k, (capture, _) in enumerate(sheets):
        p = f"S{k}" if len(sheets) > 1 else ""
        blocks = [
            f"case block == {j}: t(0, block_base, 0) extrude(block_height) {p}Block{j}Mass"
            for j in range(len(capture.blocks))
        ]
        blocks.append(f"case block == -2: t(0, block_base, 0) extrude(block_height) {p}Stack")
        height = f"height > 0 ? height : {p}height" if p else "height"
        starts.append((p, blocks + [f"else: extrude({height}) {p}Building"]))
    if len(starts) == 1:
        out.append(_case_rule("Lot -->", starts[0][1]))
    else:
        cases = [f"case style == {k}: {p}Lot" for k, (p, _) in enumerate(starts[:-1])]
        out.append(_case_rule("Lot -->", cases + [f"else: {starts[-1][0]}Lot"]))
        for p, body in starts:
            out.append(_case_rule(f"{p}Lot -->", body))
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
    out.append("# a piece of a window column: a window in a window row (w = 1), else a wall")
    out.append("Bay(w, file) --> case w == 1: Window(file) | else: Wall(file)")
    out.append(
        "# equations 8 and 9: a group's sizes, then its pieces' crops (along y: the face's rows)"
    )
    for axis, m in sorted(splits):
        out += [_Raw(rule) for rule in split_rules(axis, m)]  # printed by the formatter
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
