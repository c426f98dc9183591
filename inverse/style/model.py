"""Style sheets (Zhang et al., "Appearance Stylization of Manhattan World Buildings"): the data
the capture stage makes and the retargeting stage reads.

Frame, chosen once for every stage (the paper's "standard view"): **y up**, as in ``.bgr``; the
building's principal horizontal axis (PCA of its wall area) is x, the other z; its lowest point
is at y = 0 and the model is scaled to **unit height** (``Capture.scale`` metres a unit), so the
paper's thresholds (0.0005 of the height, kappa = 0.2 of the width) read as written.

The four walls of a block are named as comp(f) names a mass's faces (docs/language.md):
``front`` looks to -z, ``right`` to +x, ``back`` to +z, ``left`` to -x.  A wall's faces run
from left to right **as seen from outside** (a comp(f) face's own x axis), and so does every
face texture: a rectified RGB
image whose row 0 is the face's top and column 0 its left edge seen from outside.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

WALLS = ("front", "right", "back", "left")
"""The four walls of a block, in the paper's order (w1..w4), by their outward normal."""

OUTWARD = np.array([(0.0, -1.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0)])
"""(x, z) outward normal of each wall in WALLS."""


@dataclass
class Face:
    """One remeshed vertical face: an edge of a floor's contour projected down to the floor
    below it (section 4.1), so its bottom and top are two successive floors."""

    wall: int  # index into WALLS
    level: int  # the floor interval it spans: Capture.floors[level] .. floors[level + 1]
    start: np.ndarray  # (2,) x, z of its left end, seen from outside
    end: np.ndarray  # (2,) x, z of its right end
    bottom: float  # height of its lower floor (unit-height frame)
    top: float  # height of its upper floor
    texture: np.ndarray | None = None  # (h, w, 3) uint8, rectified; row 0 the top; None: untextured
    color: tuple[int, int, int] = (200, 200, 200)  # mean colour (the material's, untextured)

    @property
    def width(self) -> float:
        return float(np.hypot(*(self.end - self.start)))

    @property
    def height(self) -> float:
        return self.top - self.bottom


@dataclass
class Block:
    """A vertical extent of floors with similar area (section 4.2), extruded from the bounding
    box of the cut floor that starts it."""

    bottom: float  # height of its lowest floor
    top: float  # height of its highest floor
    box: tuple[float, float, float, float]  # xmin, xmax, zmin, zmax (unit-height frame)
    levels: list[int]  # the floor intervals it holds, bottom to top
    walls: list[list[Face]] = field(default_factory=lambda: [[], [], [], []])
    # walls[w]: the faces of wall WALLS[w], bottom level first, each level left to right

    @property
    def size(self) -> tuple[float, float, float]:
        """(width along x, height, depth along z): the paper's eta_1, eta_2, eta_3."""
        xmin, xmax, zmin, zmax = self.box
        return (xmax - xmin, self.top - self.bottom, zmax - zmin)


@dataclass
class Capture:
    """A remeshed textured building: its floors, their contours, its vertical faces and the
    blocks they form."""

    building: str  # the building's id in the input (a CityGML gml:id, an OBJ object, ...)
    scale: float  # metres a unit: the building's height in the input's units
    floors: np.ndarray  # (m,) heights, ascending, floors[0] == 0 and floors[-1] == 1
    contours: list[np.ndarray]  # contours[i]: (k, 2) x, z outer ring of the interval
    # floors[i] .. floors[i + 1] (len m - 1), counter-clockwise in (x, z) as shapely orients it
    blocks: list[Block]
    source: str = ""  # the input file, as given
    warnings: list[str] = field(default_factory=list)
    roof: tuple[int, int, int] | None = None  # the source roof's colour (None: unknown, grey)

    @property
    def faces(self) -> list[Face]:
        return [face for block in self.blocks for wall in block.walls for face in wall]
