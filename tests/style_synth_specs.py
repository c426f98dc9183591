"""The five synthetic buildings of tests/style_synth.py, as numbers: each block's lot rectangle,
storeys and one window pattern a wall (issue 27).  Every size is a whole number of 2.5 cm pixels,
so a window edge is a pixel edge."""

from __future__ import annotations

from dataclasses import dataclass

# A wall's window pattern: grid(), pairs(), shop() below, or BLANK (no windows).
Pattern = tuple
BLANK: Pattern = ("blank",)


def grid(pitch: float, width: float) -> Pattern:
    """One window of ``width`` centred in each whole bay of ``pitch`` metres (a regular A)."""
    return ("grid", pitch, width)


def pairs(pitch: float, width: float, gap: float) -> Pattern:
    """Two windows ``gap`` apart in each bay: the irregular rhythm B of section 4.3.4."""
    return ("pairs", pitch, width, gap)


def shop(pitch: float, width: float, upper: Pattern) -> Pattern:
    """A row of wide shop windows on the block's ground storey, ``upper`` on the others."""
    return ("shop", pitch, width, upper)


@dataclass(frozen=True)
class Spec:
    """One block: its lot rectangle, storey heights, one pattern a wall (front, right, back,
    left; an L's two right and two back faces share theirs) and its wall colour."""

    x: float
    z: float
    w: float
    d: float
    storeys: tuple[float, ...]
    walls: tuple[Pattern, Pattern, Pattern, Pattern]
    colour: tuple[int, int, int]
    shape: tuple | None = None  # ("L", a, b): footprint(L, a, b)


# The buildings.  x is the long axis and every block is centred in x except the L (whose wall
# area tilts the PCA axes of section 4.1's standard view by 12.7 degrees), so PCA finds x.
_G4 = grid(4.0, 1.6)
_PODIUM = (shop(4, 3, _G4), _G4, shop(4, 3, _G4), BLANK)
_TIER = (grid(3.5, 1.4), grid(3.5, 1.4), pairs(5, 1.2, 0.6), BLANK)
_BASE = (shop(5, 4, grid(5, 2)), grid(5, 2), grid(5, 2), grid(5, 2))
_SHOPS = (shop(4.0, 3.2, grid(4.0, 1.8)),) + (grid(4.0, 1.8),) * 3
_L = (grid(3, 1.2), pairs(4.0, 0.9, 0.4), grid(3, 1.2), grid(3, 1.2))
SPECS: list[tuple[str, list[Spec]]] = [
    # one block, a regular grid on every wall
    ("box", [Spec(0, 0, 24, 12, (3.0,) * 6, (grid(3, 1.4), grid(3, 1.2)) * 2, (196, 170, 140))]),
    # shops under a grid and a blank side; a tower of window pairs
    (
        "podium_tower",
        [
            Spec(0, 0, 32, 16, (4.5, 3.5), _PODIUM, (176, 160, 150)),
            Spec(7, 3, 18, 10, (3.0,) * 8, (pairs(4.5, 1, 0.5), grid(2, 0.9)) * 2, (210, 206, 196)),
        ],
    ),
    # three tiers, narrower windows higher up; pairs at the back and a blank left wall mid-way
    (
        "wedding_cake",
        [
            Spec(0, 0, 36, 20, (4.0,) * 3, (grid(4.0, 2.0),) * 4, (150, 120, 100)),
            Spec(5, 3, 26, 14, (3.5,) * 4, _TIER, (190, 180, 160)),
            Spec(10, 6, 16, 8, (3.0,) * 3, (grid(2.5, 0.9),) * 4, (220, 214, 200)),
        ],
    ),
    # four blocks, each within the one below, a window width each
    (
        "four_stack",
        [
            Spec(0, 0, 30, 18, (4.5, 3.5), _BASE, (160, 150, 140)),
            Spec(3, 2, 24, 14, (3.2,) * 3, (grid(3.0, 1.5),) * 4, (200, 190, 170)),
            Spec(6, 4, 18, 10, (3.0,) * 4, (grid(2.0, 1.1),) * 4, (185, 195, 200)),
            Spec(9, 6, 12, 6, (3.0,) * 2, (grid(1.5, 0.8),) * 4, (215, 205, 185)),
        ],
    ),
    # an L (a bar along the front, a wing up the left side) on a podium with shops in front
    (
        "l_on_podium",
        [
            Spec(0, 0, 32, 22, (4.5, 4.0), _SHOPS, (170, 150, 135)),
            Spec(2, 2, 28, 18, (3.0,) * 7, _L, (205, 195, 180), ("L", 0.4, 0.45)),
        ],
    ),
]
KINDS = len(SPECS)
