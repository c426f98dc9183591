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
opposite wall.

Each face is cut along y by its level's vertical rule and each window row along x by its
stack's horizontal rule, both **exactly as equations 8 and 9** (section 5.2.3), in the
grammar's own terms so that any mass can take it:

    F --> FFit(floor(scope.sx / P))                 x: whole repeats of the pattern
    FFit(x) --> case scope.sx - x * P >= b1 + b2: FRun(x, 2, Sr) | ... | else: FRun(x, 0, Sr)
    FRun(x, y, sr) --> case x > 0: split(x) { a1 * sr: .. | b1: .. | .. | ~1: FRun(x - 1, y, sr) }
                     | case y == 2: split(x) { ~a1: .. | b1: .. | ~a2: .. | b2: .. | ~a3: .. }
                     | ...                          the tail [b1 .. by] with [a1 .. a(y+1)]

Sizes are metres: windows (insertable pieces) keep the size they had, walls (scalable pieces)
stretch by Sr.  Every piece shows its crop of the face's own texture (``Window("...")`` or
``Wall("...")``), one PNG per distinct crop in the assets folder, named by content so that two
faces cutting the same pixels share one file.
"""

from __future__ import annotations

import hashlib
import io
from dataclasses import dataclass, field

import numpy as np

from bgr.grammar.formatter import format_number, format_source, format_string
from bgr.grammar.safe_text import comment_text

from .groups import Groups, along
from .model import OUTWARD, WALLS, Block, Capture, Face

MIN_PIECE = 0.001  # metres: a scalable piece this short still takes its share (no 0 / 0)
RECESS = 0.02  # metres: a face set back less than this is flush with its wall
MAX_SR = 2.0  # walls between windows stretch at most this much (or shrink to 1 / MAX_SR)
MIN_REPEAT = 0.5  # metres: a repeated plain piece (a rule with no insertable) is at least this
DEEPEST = 0.9  # a recess is at most this fraction of the block's extent behind its wall


def num(x: float, digits: int = 4) -> str:
    """A .bgr number rounded to ``digits`` decimals (millimetres for metres)."""
    return format_number(round(float(x), digits) + 0.0)


@dataclass
class Crops:
    """The texture crops of a style sheet: PNG bytes by file name, each distinct crop once."""

    folder: str  # how the grammar names the assets folder (relative to the grammar)
    max_size: int = 512  # each side at most this many pixels (--max-texture-size)
    files: dict[str, bytes] = field(default_factory=dict)
    _names: dict[str, str] = field(default_factory=dict)

    def add(self, image: np.ndarray) -> str:
        """The grammar's path of the PNG of ``image`` ((h, w, 3) uint8), written once."""
        from PIL import Image

        pil = Image.fromarray(np.ascontiguousarray(image), "RGB")
        if max(pil.size) > self.max_size:
            k = self.max_size / max(pil.size)
            pil = pil.resize(
                (max(1, round(pil.width * k)), max(1, round(pil.height * k))),
                Image.Resampling.LANCZOS,
            )
        out = io.BytesIO()
        pil.save(out, "PNG", optimize=False)
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


def fit_rules(
    name: str,
    axis: str,
    scalable: tuple[float, ...],
    insertable: tuple[float, ...],
    scalable_piece: list[str],
    insertable_piece: list[str],
    params: tuple[str, ...] = (),
) -> list[str]:
    """Rules realising split_h / split_v (equations 8-9) of a rule A (scalable), B (insertable)
    along ``axis``: ``name(params)`` fills its scope with x whole patterns and the tail.

    Two deviations, both for the texture's sake where the equations leave a piece stretched
    far beyond the density it was photographed at (PLATEAU: a crop of 2 pixels over 8 m).
    When not one insertable fits (x = 0 and y = 0) equation 8 leaves a1 alone stretched over
    the whole face, and when equation 9's Sr is above MAX_SR or below 1 / MAX_SR (a pattern of
    a 12.45 m "window" and 0.45 m of wall on a 24 m face: Sr = 12.7) the walls between windows
    swell or vanish; in both cases the face takes the nearest whole number of patterns (at
    least one), every piece scaled alike (``Scaled``: a floating repeat of a1 b1 .. a(m+1)), so
    it shows the source's pieces in their order and proportions.  And a rule with no insertable
    (m = 0) repeats its one scalable piece, each about a1 long (a floating repeat; MIN_REPEAT at
    least), rather than stretching it once over the scope."""
    a = [max(MIN_PIECE, v) for v in scalable]
    b = list(insertable)
    m = len(b)
    size = f"scope.s{axis}"
    head = ", ".join(params)
    lead = head + ", " if head else ""
    if m == 0:  # no insertable element: the scalable piece, repeated (see the docstring)
        return [
            f"{name}{_params(params)} --> split({axis}) "
            f"{{ ~{num(max(a[0], MIN_REPEAT))}: {scalable_piece[0]} }}*"
        ]
    pattern = num(sum(a) + sum(b))
    cases = []
    for y in range(m, -1, -1):
        rest = f"{size} - x * {pattern}"
        fill = f"{size} - x * {num(sum(b))} - {num(sum(b[:y]))}"
        sr = f"({fill}) / (x * {num(sum(a))} + {num(sum(a[: y + 1]))})"
        if y == 0:  # a tie in the window count: the layout whose walls stretch least
            alt = f"({size} - x * {num(sum(b))}) / (x * {num(sum(a))})"
            cases.append(
                f"case x > 0 and abs({alt} - 1) < abs({sr} - 1): {name}Run({lead}x - 1, {m}, {alt})"
            )
        if not y:  # not one insertable fits: the whole pattern scaled (see the docstring)
            cases.append(f"case x == 0: {name}Scaled{_params(params)}")
        guard = f"case {rest} >= {num(sum(b[:y]))}: " if y else "else: "
        cases.append(f"{guard}{name}Run({lead}x, {y}, {sr})")
    whole = [f"{num(a[0])} * sr: {scalable_piece[0]}"]
    for i in range(m):
        whole += [
            f"{num(b[i])}: {insertable_piece[i]}",
            f"{num(a[i + 1])} * sr: {scalable_piece[i + 1]}",
        ]
    runs = [
        f"case sr > {num(MAX_SR)} or sr < {num(1 / MAX_SR)}: {name}Scaled{_params(params)}",
        f"case x > 0: split({axis}) {{ {' | '.join(whole)} | ~1: {name}Run({lead}x - 1, y, sr) }}",
    ]
    for y in range(m, -1, -1):
        tail = [f"~{num(a[0])}: {scalable_piece[0]}"]
        for i in range(y):
            tail += [
                f"{num(b[i])}: {insertable_piece[i]}",
                f"~{num(a[i + 1])}: {scalable_piece[i + 1]}",
            ]
        guard = f"case y == {y}: " if y else "else: "
        runs.append(f"{guard}split({axis}) {{ {' | '.join(tail)} }}")
    scaled = [f"~{num(a[0])}: {scalable_piece[0]}"]
    for i in range(m):
        scaled += [
            f"~{num(b[i])}: {insertable_piece[i]}",
            f"~{num(a[i + 1])}: {scalable_piece[i + 1]}",
        ]
    return [
        f"{name}{_params(params)} --> {name}Fit({lead}floor({size} / {pattern}))",
        f"{name}Scaled{_params(params)} --> split({axis}) {{ {' | '.join(scaled)} }}*",
        f"{name}Fit({lead}x) --> " + " | ".join(cases),
        f"{name}Run({lead}x, y, sr) --> " + " | ".join(runs),
    ]


def _params(params: tuple[str, ...]) -> str:
    return f"({', '.join(params)})" if params else ""


def _hex(color: tuple[int, int, int]) -> str:
    return "#" + "".join(f"{int(c):02x}" for c in color)


class _Sheet:
    """Writes one building's section; ``p`` prefixes its rule names."""

    def __init__(self, capture: Capture, groups: Groups, crops: Crops, p: str) -> None:
        self.capture, self.groups, self.crops, self.p = capture, groups, crops, p
        self.index = {id(f): i for i, f in enumerate(groups.faces)}
        self.lines: list[str] = []
        self.consts: list[str] = []  # the source blocks' sizes, which bgr restyle matches

    def face(self, face: Face) -> str:
        """Rules of one face; returns its rule name."""
        i = self.index[id(face)]
        name = f"{self.p}F{i}"
        g = self.groups
        rows, columns = g.rows[g.horizontal[i]], g.columns[g.vertical[i]]
        metres = self.capture.scale
        self.lines.append(
            f"# {WALLS[face.wall]} wall, level {face.level}: {num(face.width * metres, 2)} x "
            f"{num(face.height * metres, 2)} m, {len(rows.insertable)} window rows of "
            f"{len(columns.insertable)} bays (rows: group {g.horizontal[i]}, bays: group "
            f"{g.vertical[i]})"
        )
        texture = face.texture
        if texture is None:
            self.lines.append(f'{name} --> color("{_hex(face.color)}") Plain')
            return name
        h, w = texture.shape[:2]
        row_px = _pixels(g.row_cuts[g.horizontal[i]], h)[::-1]  # bottom to top, as C and D
        col_px = _pixels(g.column_cuts[g.vertical[i]], w)
        if not rows.insertable:  # no window row: the bays run the face's full height
            row_px = [("insertable", 0, h)]

        def crop(r: tuple[int, int], c: tuple[int, int]) -> str:
            return format_string(self.crops.add(texture[r[0] : r[1], c[0] : c[1]]))

        walls = [(c0, c1) for kind, c0, c1 in col_px if kind == "scalable"]
        bays = [(c0, c1) for kind, c0, c1 in col_px if kind == "insertable"]
        cols = f"{name}Bays"
        many = len(row_px) > 1

        def piece(kind: str, c: tuple[int, int], k: int) -> str:
            if many:
                return f"{cols}{kind}{k}(row)"
            return f"{kind}({crop(row_px[0][1:], c)})"

        if rows.insertable:
            # Every row, window row or wall band, is cut by the stack's columns: a band cropped
            # whole and stretched over a wider face smeared (a 29-pixel band of a 7 m face
            # over a 30 m slab is 1 pixel a metre); cut at the window columns, it repeats
            # with them at the density it was photographed at.
            row_pieces = [f"{cols}({j})" for j, r in enumerate(row_px) if r[0] == "scalable"]
            line_pieces = [f"{cols}({j})" for j, r in enumerate(row_px) if r[0] == "insertable"]
            self.lines += fit_rules(
                name, "y", rows.scalable, rows.insertable, row_pieces, line_pieces
            )
        else:  # no window row: the face's own height repeats (as fit_rules does with m = 0)
            self.lines.append(f"{name} --> split(y) {{ ~{num(face.height * metres)}: {cols} }}*")
        params = ("row",) if many else ()
        wall_pieces = [piece("Wall", c, k) for k, c in enumerate(walls)]
        bay_pieces = [piece("Window", c, k) for k, c in enumerate(bays)]
        self.lines += fit_rules(
            cols, "x", columns.scalable, columns.insertable, wall_pieces, bay_pieces, params
        )
        if many:  # one rule per piece of the pattern, choosing its crop by row
            for kind, spans in (("Wall", walls), ("Window", bays)):
                for k, c in enumerate(spans):
                    options = [  # a wall band's pieces are all wall
                        f"{kind if what == 'insertable' else 'Wall'}({crop((r0, r1), c)})"
                        for what, r0, r1 in row_px
                    ]
                    cases = [f"case row == {j}: {o}" for j, o in enumerate(options[:-1])]
                    self.lines.append(
                        f"{cols}{kind}{k}(row) --> " + " | ".join([*cases, f"else: {options[-1]}"])
                    )
        return name

    def wall(self, b: int, block: Block, w: int, below_gap: float | None) -> str:
        """Rules of one wall of a block: levels, then faces at relative widths, recessed."""
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
                            f"[ t(0, 0, -({near})) {self.p}Jamb{side}(({d}) - ({near}), {colour}) ]"
                        )
                pieces.append(f"~{num(span * metres)}: {' '.join(parts)} t(0, 0, -({d})) {rule}")
            if not pieces:
                pieces = ["~1: Plain"]
            lname = f"{name}L{level}"
            self.lines.append(f"{lname}(k) --> split(x) {{ {' | '.join(pieces)} }}")
            span = (self.capture.floors[level + 1] - self.capture.floors[level]) * metres
            levels.append(f"~{num(span)}: {lname}(k)")
        self.lines.append(f"{name}(k) --> split(y) {{ {' | '.join(levels)} }}")
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
                walls.append(f"{WALLS[w]}: {self.wall(k, block, w, gap)}({across})")
            xmin, xmax, zmin, zmax = block.box
            fx, fz = (xmin - x0) / (x1 - x0), (zmin - z0) / (z1 - z0)
            sx, sz = (xmax - xmin) / (x1 - x0), (zmax - zmin) / (z1 - z0)
            self.lines.append(
                f"{p}Block{k} --> t('{num(fx)}, 0, '{num(fz)}) "
                f"s('{num(sx)}, '1, '{num(sz)}) {p}Block{k}Mass"
            )
            width, _, depth = block.size
            self.lines.append(  # k of the walls: the block's stretch across them
                f"{p}Block{k}Mass --> {p}Block{k}Walls(scope.sx / {num(width * cap.scale)} "
                f"* recess_x, scope.sz / {num(depth * cap.scale)} * recess_z)"
            )
            floor = f"{p}Roof" if k == 0 else "NIL"  # the ground closes the notches at its foot
            self.lines.append(
                f"{p}Block{k}Walls(kx, kz) --> comp(f) {{ {' | '.join(walls)} | top: {p}Roof "
                f"| bottom: {floor} }}"
            )
            parts.append(f"~{num((block.top - block.bottom) * cap.scale)}: {p}Block{k}")
            for what, size in zip(("width", "height", "depth"), block.size, strict=True):
                self.consts.append(f"const {p}block{k}_{what} = {num(size * cap.scale)}")
        self.lines.append(f"{p}Building --> split(y) {{ {' | '.join(parts)} }}")
        self.lines.append(f"{p}Stack --> {self.stack()}")
        self.lines.append(
            f"{p}Reveal(d, t, b, c) --> extrude(-d) comp(f) {{ front: {p}RevealSide(t, c) "
            f"| back: {p}RevealSide(b, c) | all: NIL }}"
        )
        for side, which in (("L", "left"), ("R", "right")):
            self.lines.append(
                f"{p}Jamb{side}(d, c) --> extrude(-max(d, 0)) comp(f) {{ {which}: "
                f"{p}RevealSide(1, c) | all: NIL }}"
            )
        self.lines.append(  # in the recessed face's mean colour, which its sides continue
            f"{p}RevealSide(keep, c) --> case keep == 1: reverseNormals() color(c) Plain "
            "| else: NIL"
        )
        self.lines.append(f'{p}Roof --> color("#9a9a9a") Plain')


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
    for k, (capture, groups) in enumerate(sheets):
        sheet = _Sheet(capture, groups, crops, f"S{k}" if len(sheets) > 1 else "")
        sheet.building()
        sections.append(sheet.lines)
        sheet_consts.append(sheet.consts)
    first = sheets[0][0]
    if len(sheets) > 1:
        out.append("# which captured building a lot takes (0 .. n - 1)")
    if len(sheets) > 1:
        out.append("attr style = 0")
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
        starts.append((p, " | ".join(blocks) + f" | else: extrude(height) {p}Building"))
    if len(starts) == 1:
        out.append(f"Lot --> {starts[0][1]}")
    else:
        cases = [f"case style == {k}: {p}Lot" for k, (p, _) in enumerate(starts[:-1])]
        out.append("Lot --> " + " | ".join(cases) + f" | else: {starts[-1][0]}Lot")
        for p, body in starts:
            out.append(f"{p}Lot --> {body}")
    out.append("# a crop of a face's texture stretched once over the piece")
    out.append(
        "Wall(file) --> setupProjection(0, scope.xy, '1, '1) projectUV(0) texture(file) WallTile"
    )
    out.append(
        "Window(file) --> setupProjection(0, scope.xy, '1, '1) projectUV(0) texture(file) "
        "WindowTile"
    )
    for k, lines in enumerate(sections):
        capture = sheets[k][0]
        out.append("")
        out.append(
            f"# ---- {comment_text(capture.building)}: {len(capture.blocks)} blocks, "
            f"{num(capture.scale, 2)} m high"
        )
        out.append(
            "# the source's blocks in metres, bottom to top (bgr restyle matches a mass to them)"
        )
        out += sheet_consts[k]
        out += lines
    text = "\n".join(line for line in out if line is not None) + "\n"
    return format_source(text, "<style sheet>")
