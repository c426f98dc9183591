"""Synthetic textured Manhattan-world buildings with known answers, for the style-sheet round trip
(issue 27: "capture recovers the block cuts, the floors and the window count per group exactly").

:func:`make_building` draws every wall's façade with numpy, writes a ``.bgr`` grammar that stacks
the blocks and stretches each image once over its wall, derives it to a GLB beside them and
returns the :class:`Truth` that drew them.  Everything is chosen, not measured: block boxes,
storey heights and window rectangles are numbers on a 1/40 m grid (:data:`PX_PER_M` pixels a
metre), so a window edge is a pixel edge and a capture can be asserted exactly.

Frame: bgr's world, y up, the ground at y = 0; x is the long horizontal axis of every building
(so the standard view of section 4.1, PCA of the wall area, finds x as bgr writes it).  Walls are
named as comp(f) names them (inverse/style/model.py): ``front`` looks to -z, ``right`` to +x,
``back`` to +z, ``left`` to -x, and a face runs from its left to its right *seen from outside*
(the front face's left end is at its largest x).

Every storey is its own face in the mesh (``split(y)`` under one projection), so the remeshed
floors of section 4.1 are the storey lines, the floor-area ratio r_i of section 4.2 is 1 inside a
block and above 1 at a cut (a strict local maximum: every block has two storeys or more), and a
horizontally consistent group (section 4.3.3: the faces between two floors) is one storey band.
``storey_faces=False`` makes one face per wall instead, as many hand-made models are.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from PIL import Image
from style_synth_specs import SPECS, Pattern

import bgr
from bgr.grammar.formatter import format_source

PX_PER_M = 40
"""Texture resolution: a 2.5 cm pixel, every size in the specs a whole number of pixels."""

FRAME_M = 0.1  # a window's frame, inside its rectangle
GLASS = np.array([46, 58, 74], np.uint8)
FRAME = np.array([236, 234, 226], np.uint8)
ROOF = "#7d7d7d"
KINDS = len(SPECS)


@dataclass
class Band:
    """One storey of one wall face: a face between two floors, as section 4.1 remeshes it."""

    bottom: float  # metres, world y
    top: float
    columns: np.ndarray  # (n, 2) left and right edge of each window, metres from the face's left
    sill: float  # window bottom above the band's bottom, metres (0 when there are no windows)
    head: float  # window top above the band's bottom

    @property
    def windows(self) -> int:
        return len(self.columns)


@dataclass
class WallFace:
    """One planar wall face of a block (a rectangle has one a wall, an L's back and right two)."""

    wall: str  # front, right, back or left, as comp(f) names it
    index: int  # the face's index in the block's comp(f) (the footprint's edge order)
    start: tuple[float, float]  # (x, z) of its left end seen from outside
    end: tuple[float, float]  # (x, z) of its right end
    bottom: float
    top: float
    image: Path  # its façade, stretched once over it: row 0 at the top, column 0 at the left
    bands: list[Band]

    @property
    def width(self) -> float:
        return float(np.hypot(self.end[0] - self.start[0], self.end[1] - self.start[1]))

    @property
    def height(self) -> float:
        return self.top - self.bottom

    @property
    def window_count(self) -> int:
        return sum(band.windows for band in self.bands)

    def stacks(self) -> list[tuple[int, int]]:
        """Its vertically consistent groups (section 4.3.3), as (first, last) band indices:
        runs of storeys with the same window columns (their rows may differ with the storey's
        height).  Equal widths give phi_shape = 1 (eq. 1); equal columns correlate over 0.99
        (eq. 2), a shop row and the grid above it 0.29 to 0.36 and a blank storey (noise) about
        0 with anything, under the paper's 0.5; across a cut no wall's storeys correlate over
        0.32 (tests/test_style_synth.py measures it all on the images)."""
        runs: list[tuple[int, int]] = []
        for i, band in enumerate(self.bands):
            below = self.bands[i - 1] if i else None
            if below and band.windows and np.array_equal(band.columns, below.columns):
                runs[-1] = (runs[-1][0], i)
            else:
                runs.append((i, i))
        return runs

    def rows(self) -> np.ndarray:
        """(k, 2) bottom and top of each window row, world y, metres: one a storey that has
        windows (what a vertical splitting rule C, D of section 4.3.4 finds)."""
        rows = [(b.bottom + b.sill, b.bottom + b.head) for b in self.bands if b.windows]
        return np.array(rows, dtype=float).reshape(-1, 2)

    def windows(self) -> np.ndarray:
        """(n, 4) every window as x0, x1 (from the face's left) and y0, y1 (world), metres."""
        rows = [
            (c0, c1, b.bottom + b.sill, b.bottom + b.head)
            for b in self.bands
            for c0, c1 in b.columns
        ]
        return np.array(rows, dtype=float).reshape(-1, 4)


@dataclass
class BlockTruth:
    """A block of section 4.2: a vertical extent of equal floors, its box and its faces."""

    bottom: float
    top: float
    box: tuple[float, float, float, float]  # xmin, xmax, zmin, zmax, metres
    storeys: np.ndarray  # (k + 1,) storey lines, world y, bottom to top
    outline: np.ndarray  # (n, 2) x, z, the footprint ring in comp(f)'s edge order
    faces: list[WallFace]

    def wall(self, name: str) -> list[WallFace]:
        """The faces of one wall, in the footprint's order."""
        return [face for face in self.faces if face.wall == name]


@dataclass
class Truth:
    """What a synthetic building is made of, in metres (divide by ``height`` for the unit frame)."""

    kind: int
    name: str
    grammar: Path
    glb: Path
    mass: Path  # the same blocks untextured, one face a wall (a restyle target)
    blocks: list[BlockTruth]
    storey_faces: bool = True
    images: list[Path] = field(default_factory=list)

    @property
    def cuts(self) -> np.ndarray:
        """Block boundaries, world y: 0, the top of each block, the building's height."""
        return np.array([self.blocks[0].bottom] + [b.top for b in self.blocks])

    @property
    def floors(self) -> np.ndarray:
        """The heights at which the mesh has vertices (section 4.1's floors), ascending."""
        if not self.storey_faces:
            return self.cuts
        return np.unique(np.concatenate([b.storeys for b in self.blocks]))

    @property
    def height(self) -> float:
        return float(self.blocks[-1].top)

    @property
    def footprint(self) -> tuple[float, float]:
        """(size along x, size along z) of the whole building's plan."""
        boxes = np.array([b.box for b in self.blocks])
        return float(boxes[:, 1].max() - boxes[:, 0].min()), float(
            boxes[:, 3].max() - boxes[:, 2].min()
        )

    @property
    def textured_triangles(self) -> int:
        """Two triangles a face (or a storey of one, with storey faces)."""
        per = (lambda f: 2 * len(f.bands)) if self.storey_faces else (lambda f: 2)
        return sum(per(f) for b in self.blocks for f in b.faces)


def _q(value: float) -> float:
    """Snap to the pixel grid (1/PX_PER_M m), so a window edge is a pixel edge."""
    return round(value * PX_PER_M) / PX_PER_M


def _columns(pattern: Pattern, width: float) -> np.ndarray:
    """(n, 2) window edges of one storey of a face ``width`` metres wide: whole bays of
    ``pitch`` centred on the face, the margin shared by both ends."""
    if pattern[0] == "blank":
        return np.zeros((0, 2))
    pitch, size = pattern[1], pattern[2]
    bays = int((width + 1e-9) // pitch)
    centres = (width - bays * pitch) / 2 + pitch * (np.arange(bays) + 0.5)
    if pattern[0] == "pairs":
        gap = pattern[3]
        left = np.stack([centres - gap / 2 - size, centres - gap / 2], axis=1)
        cols = np.concatenate([left, left + size + gap], axis=1).reshape(-1, 2)
    else:
        cols = np.stack([centres - size / 2, centres + size / 2], axis=1)
    return np.vectorize(_q)(cols) if cols.size else cols.reshape(0, 2)


def _vertical(pattern: Pattern, height: float) -> tuple[float, float]:
    """A storey's window sill and head above its floor, metres: a shop window from 0.4 m to
    0.8 m under the ceiling; others 0.3 of the storey high from 0.3 of it up (0.9 to 1.8 m of
    3 m), on the pixel grid."""
    if pattern[0] == "blank":
        return 0.0, 0.0
    if pattern[0] == "shop":
        return 0.4, _q(height - 0.8)
    return _q(0.3 * height), _q(0.3 * height) + _q(0.5 * height)


def _outline(x: float, z: float, w: float, d: float, shape: tuple | None) -> np.ndarray:
    """The footprint ring as bgr builds it (front edge first, along +x at the lot's z), so
    face(i) of comp(f) is the wall on edge i (docs/language.md, comp(f) face order)."""
    if shape is None:
        ring = [(0, 0), (w, 0), (w, d), (0, d)]
    else:  # footprint(L, a, b): a bar of depth b*d along the front, a wing a*w wide on the left
        a, b = _q(shape[1] * w), _q(shape[2] * d)
        ring = [(0, 0), (w, 0), (w, b), (a, b), (a, d), (0, d)]
    return np.array(ring, dtype=float) + (x, z)


def _wall_name(p: np.ndarray, q: np.ndarray) -> str:
    """comp(f)'s name of the wall on ring edge p -> q: its outward normal is (e_z, -e_x)."""
    e = q - p
    n = (e[1], -e[0])
    if abs(n[0]) >= abs(n[1]):
        return "right" if n[0] > 0 else "left"
    return "back" if n[1] > 0 else "front"


def _draw(face: WallFace, colour: tuple[int, int, int], rng: np.random.Generator) -> np.ndarray:
    """The façade image: the wall colour with +-4 levels of grey noise, each window a
    FRAME_M frame round dark glass; row 0 the top, column 0 the face's left seen from outside."""
    h = round((face.top - face.bottom) * PX_PER_M)
    w = round(face.width * PX_PER_M)
    # grain of 2 x 2 pixels: it compresses (PNG encoding and decoding dominate the build time)
    grain = rng.integers(-4, 5, size=((h + 1) // 2, (w + 1) // 2, 1), dtype=np.int16)
    noise = grain.repeat(2, axis=0).repeat(2, axis=1)[:h, :w]
    img = np.clip(np.array(colour, np.int16) + noise, 0, 255).astype(np.uint8)
    f = round(FRAME_M * PX_PER_M)
    for x0, x1, y0, y1 in face.windows():
        c0, c1 = round(x0 * PX_PER_M), round(x1 * PX_PER_M)
        r0, r1 = round((face.top - y1) * PX_PER_M), round((face.top - y0) * PX_PER_M)
        img[r0:r1, c0:c1] = FRAME
        img[r0 + f : r1 - f, c0 + f : c1 - f] = GLASS
    return img


def _blocks(kind: int, folder: Path) -> list[tuple[BlockTruth, tuple[int, int, int]]]:
    """The truth of each block of building ``kind`` (its images not drawn yet)."""
    name, specs = SPECS[kind]
    out, bottom = [], 0.0
    for b, spec in enumerate(specs):
        x, z, w, d, storeys = spec.x, spec.z, spec.w, spec.d, spec.storeys
        lines = bottom + np.concatenate([[0.0], np.cumsum(storeys)])
        ring = _outline(x, z, w, d, spec.shape)
        faces = []
        for i in range(len(ring)):
            p, q = ring[i], ring[(i + 1) % len(ring)]
            wall = _wall_name(p, q)
            pattern = spec.walls[("front", "right", "back", "left").index(wall)]
            width = float(np.hypot(*(q - p)))
            bands = []
            for k in range(len(storeys)):
                here = pattern[3] if pattern[0] == "shop" and k > 0 else pattern
                sill, head = _vertical(here, storeys[k])
                bands.append(Band(lines[k], lines[k + 1], _columns(here, width), sill, head))
            image = folder / f"k{kind}_{name}_b{b}_f{i}_{wall}.png"
            # seen from outside a face runs against the ring (docs/language.md, comp(f))
            faces.append(
                WallFace(wall, i, (q[0], q[1]), (p[0], p[1]), bottom, lines[-1], image, bands)
            )
        box = (float(x), float(x + w), float(z), float(z + d))
        out.append((BlockTruth(bottom, float(lines[-1]), box, lines, ring, faces), spec.colour))
        bottom = float(lines[-1])
    return out


def _num(v: float) -> str:
    return f"{v:g}"


def _grammar(kind: int, blocks: list[BlockTruth], textured: bool, storey_faces: bool) -> str:
    """The building as .bgr: each block a lot rectangle moved and sized with t() and s() (and
    footprint(L) for an L), extruded; each wall face one projection stretched once over it
    (setupProjection(0, scope.xy, '1, '1): u along the face's x, left to right seen from
    outside, v up), split into its storeys, which keep that projection."""
    name, specs = SPECS[kind]
    kinds = "textured" if textured else "untextured mass"
    rules = [
        f"# {name}: synthetic building {kind} of tests/style_synth.py ({kinds}; issue 27)",
        "version 1",
        "",
        "terminal Storey" if textured else "terminal Wall",
        "",
    ]
    lot = []
    for b, (block, spec) in enumerate(zip(blocks, specs, strict=True)):
        x, z, w, d, shape = spec.x, spec.z, spec.w, spec.d, spec.shape
        form = f" footprint(L, {_num(shape[1])}, {_num(shape[2])})" if shape else ""
        lot.append(
            f"[ t({_num(x)}, {_num(block.bottom)}, {_num(z)}) s({_num(w)}, 0, {_num(d)}){form}"
            f" extrude({_num(block.top - block.bottom)}) B{b} ]"
        )
    rules.append("Lot --> " + " ".join(lot))
    for b, block in enumerate(blocks):
        sel = " | ".join(f"face({f.index}): B{b}F{f.index}" for f in block.faces)
        rules.append(f"B{b} --> comp(f) {{ {sel} | top: Roof | bottom: NIL }}")
        for f in block.faces:
            head = f"B{b}F{f.index} --> "
            if textured:
                head += (
                    f"color(\"#ffffff\") setupProjection(0, scope.xy, '1, '1) "
                    f'texture("{f.image.name}") projectUV(0) '
                )
            else:
                head += 'color("#c8c8c8") '
            piece = "Storey" if textured else "Wall"
            if storey_faces:
                parts = " | ".join(f"{_num(bd.top - bd.bottom)}: {piece}" for bd in f.bands)
                rules.append(head + f"split(y) {{ {parts} }}")
            else:
                rules.append(head + piece)
    rules.append(f'Roof --> color("{ROOF}")')
    return format_source("\n".join(rules) + "\n")  # in `bgr fmt`'s layout, to be read


def make_building(
    kind: int, folder: str | Path, *, storey_faces: bool = True
) -> tuple[Path, Truth]:
    """Draw building ``kind`` (0 .. KINDS - 1) into ``folder``: its façade PNGs, its grammar
    ``k<kind>_<name>.bgr`` derived to ``k<kind>_<name>.glb``, and the untextured mass
    (``..._mass.bgr``/``.glb``, one face a wall).  Returns the textured GLB and the truth.

    Deterministic: the noise of each image comes from np.random.default_rng(a seed made of
    kind, block and face), and the same call writes the same bytes."""
    if not 0 <= kind < KINDS:
        raise ValueError(f"kind {kind}: there are {KINDS} synthetic buildings (0 .. {KINDS - 1})")
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    name = SPECS[kind][0]
    drawn = _blocks(kind, folder)
    blocks = [block for block, _ in drawn]
    images = []
    for b, (block, colour) in enumerate(drawn):
        for face in block.faces:
            rng = np.random.default_rng(1000 * kind + 10 * b + face.index)
            Image.fromarray(_draw(face, colour, rng)).save(face.image, compress_level=1)
            images.append(face.image)
    stem = folder / f"k{kind}_{name}"
    grammar, mass = stem.with_suffix(".bgr"), Path(f"{stem}_mass.bgr")
    grammar.write_text(_grammar(kind, blocks, True, storey_faces))
    mass.write_text(_grammar(kind, blocks, False, False))
    glb = stem.with_suffix(".glb")
    bgr.derive(grammar).save(glb)
    bgr.derive(mass).save(mass.with_suffix(".glb"))
    truth = Truth(kind, name, grammar, glb, mass.with_suffix(".glb"), blocks, storey_faces, images)
    return glb, truth
