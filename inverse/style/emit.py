"""A captured style sheet written as ``.bgr``: the shape layer as blocks and walls, the texture
layer as per-face splitting rules whose pieces carry texture crops.

Derived on a lot, the grammar extrudes it to the source's height (``attr height``), cuts it
into the source's blocks at their relative heights, sets each block back as the source's was
(``t`` and ``s`` in fractions of the lot), and decorates each of its four walls (comp(f)'s
front, right, back and left): the wall's levels at their relative heights, each level's faces at
their relative widths, a face set back from the block's outer boundary recessed by its depth.

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

from .groups import RIGHTWARD, Groups, along
from .model import OUTWARD, WALLS, Block, Capture, Face

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
    along ``axis``: ``name(params)`` fills its scope with x whole patterns and the tail."""
    a = [max(MIN_PIECE, v) for v in scalable]
    b = list(insertable)
    m = len(b)
    size = f"scope.s{axis}"
    head = ", ".join(params)
    lead = head + ", " if head else ""
    if m == 0:  # no insertable element: one scalable piece stretched over the whole scope
        return [f"{name}{_params(params)} --> {scalable_piece[0]}"]
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
        guard = f"case {rest} >= {num(sum(b[:y]))}: " if y else "else: "
        cases.append(f"{guard}{name}Run({lead}x, {y}, {sr})")
    whole = [f"{num(a[0])} * sr: {scalable_piece[0]}"]
    for i in range(m):
        whole += [
            f"{num(b[i])}: {insertable_piece[i]}",
            f"{num(a[i + 1])} * sr: {scalable_piece[i + 1]}",
        ]
    runs = [
        f"case x > 0: split({axis}) {{ {' | '.join(whole)} | ~1: {name}Run({lead}x - 1, y, sr) }}"
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
    return [
        f"{name}{_params(params)} --> {name}Fit({lead}floor({size} / {pattern}))",
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
        self.named: dict[int, str] = {}  # id(face) -> its rule, written once

    def face(self, face: Face) -> str:
        """Rules of one face (written on first use); returns its rule name."""
        if id(face) not in self.named:
            self.named[id(face)] = self._face(face)
        return self.named[id(face)]

    def _face(self, face: Face) -> str:
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
        bands = [(r0, r1) for kind, r0, r1 in row_px if kind == "scalable"]
        lines = [(r0, r1) for kind, r0, r1 in row_px if kind == "insertable"]

        def crop(r: tuple[int, int], c: tuple[int, int]) -> str:
            return format_string(self.crops.add(texture[r[0] : r[1], c[0] : c[1]]))

        walls = [(c0, c1) for kind, c0, c1 in col_px if kind == "scalable"]
        bays = [(c0, c1) for kind, c0, c1 in col_px if kind == "insertable"]
        cols = f"{name}Bays"
        many = len(lines) > 1

        def piece(kind: str, c: tuple[int, int], k: int) -> str:
            if many:
                return f"{cols}{kind}{k}(row)"
            return f"{kind}({crop(lines[0], c)})"

        if rows.insertable:
            row_pieces = [f"Wall({crop(r, (0, w))})" for r in bands]
            line_pieces = [f"{cols}({j})" if many else cols for j in range(len(lines))]
            self.lines += fit_rules(
                name, "y", rows.scalable, rows.insertable, row_pieces, line_pieces
            )
        else:
            self.lines.append(f"{name} --> {cols}")
        params = ("row",) if many else ()
        wall_pieces = [piece("Wall", c, k) for k, c in enumerate(walls)]
        bay_pieces = [piece("Window", c, k) for k, c in enumerate(bays)]
        self.lines += fit_rules(
            cols, "x", columns.scalable, columns.insertable, wall_pieces, bay_pieces, params
        )
        if many:  # one rule per piece of the pattern, choosing its crop by window row
            for kind, spans in (("Wall", walls), ("Window", bays)):
                for k, c in enumerate(spans):
                    options = [
                        f"case row == {j}: {kind}({crop(r, c)})" for j, r in enumerate(lines[:-1])
                    ]
                    options.append(f"else: {kind}({crop(lines[-1], c)})")
                    self.lines.append(f"{cols}{kind}{k}(row) --> " + " | ".join(options))
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
                    pieces.append(
                        f"~{num(span * metres)}: [ {self.p}Reveal({d}) ] t(0, 0, -({d})) {rule}"
                    )
                else:
                    pieces.append(f"~{num(span * metres)}: {rule}")
            if not pieces:
                pieces = ["~1: Plain"]
            lname = f"{name}L{level}"
            self.lines.append(f"{lname}(kh, kw) --> split(x) {{ {' | '.join(pieces)} }}")
            span = (self.capture.floors[level + 1] - self.capture.floors[level]) * metres
            levels.append(f"~{num(span)}: {lname}(kh, kw)")
        height = (block.top - block.bottom) * metres
        self.lines.append(
            f"{name} --> {name}Levels(scope.sy / {num(height)}, scope.sx / {num(width * metres)})"
        )
        self.lines.append(f"{name}Levels(kh, kw) --> split(y) {{ {' | '.join(levels)} }}")
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
            self.lines.append(f"{part} --> split(y) {{ {' | '.join(pieces)} }}")
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
            faces = f"comp(f) {{ {' | '.join(walls)} | top: {p}Roof | bottom: NIL }}"
            if "(bw)" in faces or "(bd)" in faces:  # the sides' full widths for ``side``
                self.lines.append(f"{p}Block{k}Mass --> {p}Block{k}Faces(scope.sx, scope.sz)")
                self.lines.append(f"{p}Block{k}Faces(bw, bd) --> {faces}")
            else:
                self.lines.append(f"{p}Block{k}Mass --> {faces}")
            parts.append(f"~{num((block.top - block.bottom) * cap.scale)}: {p}Block{k}")
            for what, size in zip(("width", "height", "depth"), block.size, strict=True):
                self.consts.append(f"const {p}block{k}_{what} = {num(size * cap.scale)}")
        self.lines.append(f"{p}Building --> split(y) {{ {' | '.join(parts)} }}")
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
