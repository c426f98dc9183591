"""Face snapping (section 5.2.1, inverse/style/snap.py): dynamic time warping of the face ends
of two floors within kappa = 0.2 of the building's width, upper ends moved onto lower ones,
faces squeezed to nothing removed."""

from __future__ import annotations

import numpy as np
import pytest

from bgr.inverse.style.model import Block, Capture, Face
from bgr.inverse.style.snap import KAPPA, snap_faces, warp


def test_warp_hand_computed():
    """Lower ends 0, 4, 10; upper 0, 4.3, 9.8: each upper end's nearest along the one monotone
    path of least cost (0-0, 4.3-4, 9.8-10: cost 0.5)."""
    got = warp(np.array([0.0, 4.3, 9.8]), np.array([0.0, 4.0, 10.0]), window=2.0)
    np.testing.assert_allclose(got, [0.0, 4.0, 10.0])


def test_warp_squeezes_an_extra_end_onto_its_neighbour():
    """An upper end with no partner below (5.1 between 4 and 10) is matched with the lower end
    that keeps the path cheapest: 4 (1.1 away) rather than 10 (4.9)."""
    got = warp(np.array([0.0, 4.0, 5.1, 10.0]), np.array([0.0, 4.0, 10.0]), window=6.0)
    np.testing.assert_allclose(got, [0.0, 4.0, 4.0, 10.0])


def test_warp_respects_the_window():
    """No monotone matching keeps 7 within 1 of a lower end: nothing is snapped (None), and an
    empty side has nothing to match."""
    assert warp(np.array([0.0, 7.0, 10.0]), np.array([0.0, 4.0, 10.0]), window=1.0) is None
    assert warp(np.zeros(0), np.array([1.0]), window=1.0) is None


def _face(level: int, x0: float, x1: float) -> Face:
    """A front-wall face (looking to -z at z = 0) from x0 to x1 seen from outside: the front's
    left is +x (model.py), so it starts at the larger x."""
    return Face(0, level, np.array([x1, 0.0]), np.array([x0, 0.0]), level * 0.5, level * 0.5 + 0.5)


def _capture(faces: list[Face], width: float) -> Capture:
    ring = np.array([[0.0, 0.0], [width, 0.0], [width, 1.0], [0.0, 1.0]])
    block = Block(0.0, 1.0, (0.0, width, 0.0, 1.0), [0, 1])
    block.walls[0] = faces
    return Capture("b", 10.0, np.array([0.0, 0.5, 1.0]), [ring, ring], [block])


def test_the_upper_level_lines_up_with_the_lower_one():
    """Level 0: faces [0, 2] and [2, 5]; level 1 digitised off by a few centimetres: [0, 2.03]
    and [2.03, 5].  Width 5: kappa * 5 = 1 is the reach; 2.03 moves to 2."""
    lower = [_face(0, 0.0, 2.0), _face(0, 2.0, 5.0)]
    upper = [_face(1, 0.0, 2.03), _face(1, 2.03, 5.0)]
    capture = _capture(lower + upper, 5.0)
    assert snap_faces(capture) == 1
    ends = sorted(
        {round(float(p[0]), 9) for f in capture.blocks[0].walls[0] for p in (f.start, f.end)}
    )
    assert ends == [0.0, 2.0, 5.0]
    assert [round(f.width, 9) for f in capture.blocks[0].walls[0]] == [2.0, 3.0, 2.0, 3.0]


def test_a_sliver_is_squeezed_out_and_removed():
    """Level 1 has a 0.05-wide sliver [2, 2.05] the level below has not: its two ends are
    matched with the same lower end, 2, so it has no width left and goes."""
    lower = [_face(0, 0.0, 2.0), _face(0, 2.0, 5.0)]
    upper = [_face(1, 0.0, 2.0), _face(1, 2.0, 2.05), _face(1, 2.05, 5.0)]
    capture = _capture(lower + upper, 5.0)
    snap_faces(capture)
    kept = capture.blocks[0].walls[0]
    assert len(kept) == 4
    assert sorted(round(f.width, 9) for f in kept if f.level == 1) == [2.0, 3.0]


@pytest.mark.parametrize("offset", [0.9, 1.2])
def test_an_end_beyond_kappa_stays(offset):
    """kappa = 0.2 of the width: on a 5-wide side an end 0.9 off moves, 1.2 off stays."""
    lower = [_face(0, 0.0, 2.0), _face(0, 2.0, 5.0)]
    upper = [_face(1, 0.0, 2.0 + offset), _face(1, 2.0 + offset, 5.0)]
    capture = _capture(lower + upper, 5.0)
    moved = snap_faces(capture)
    assert moved == (1 if offset < KAPPA * 5.0 else 0)
