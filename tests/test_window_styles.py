"""Window style recognition (bgr.inverse.image.windows, issue 28 section 6): the shipped
classifier recognises renders of stdlib windows on façades it was not trained on (several
windows a floor, the stdlib's fac.Grid, sizes past the training range and wall colours chosen
here), and the vote's contract holds.  A broken or untrained classifier fails the first test:
chance is one rule in fourteen."""

from __future__ import annotations

import time

import numpy as np
import pytest

import bgr
from bgr.inverse.image.windows import DEFAULT_RULE, RULES, classify, load_weights, window_style
from bgr.render import Camera, image_of, load_scene, rasterise

FACADE = """version 1
import stdlib.window as win
import stdlib.facade as fac
Lot --> s({W}, 0, 0.3) extrude({H}) comp(f) {{
    front: fac.Grid(floor_h = {floor}, tile_w = {tile}, win_w = {ww}, win_h = {wh}, sill_h = {sill},
        margin = {margin}, wall_color = "{wall}", window = {window})
    | all: NIL
}}
"""


def facade(
    window: str,
    ww: float,
    wh: float,
    wall: str,
    floors: int = 2,
    tiles: int = 3,
    px_per_m: float = 40.0,
) -> tuple[np.ndarray, np.ndarray]:
    """(image, window boxes (top, left, bottom, right)) of a fac.Grid of ``window``: the boxes
    are the openings projected by the camera, as a parse would find them."""
    floor, tile, sill, margin = 3.2, ww + 1.6, 0.8, 0.4
    w, h = tiles * tile + 2 * margin, floors * floor
    text = FACADE.format(
        W=w,
        H=h,
        floor=floor,
        tile=tile,
        ww=ww,
        wh=wh,
        sill=sill,
        margin=margin,
        wall=wall,
        window=window,
    )
    result = bgr.derive(bgr.load(text))
    scene = load_scene(result)
    size = (int(w * px_per_m), int(h * px_per_m))
    camera = Camera.preset("front", np.zeros(3), np.array([w, h, 0.12]), size, front=scene.front)
    image, _ = image_of(rasterise(scene, camera, "auto", on_fallback=None), scene, "shaded")
    boxes = []
    for f in range(floors):
        for t in range(tiles):
            x0 = margin + t * tile + (tile - ww) / 2
            y0 = f * floor + sill
            px, _ = camera.project(np.array([[x0, y0, 0.0], [x0 + ww, y0 + wh, 0.0]]))
            boxes.append([px[:, 1].min(), px[:, 0].min(), px[:, 1].max(), px[:, 0].max()])
    return np.asarray(image), np.array(boxes)


CASES = [
    ("Arched", "win.Arched", 1.7, 2.6, "#8fa3b8"),
    ("Oculus", "win.Oculus", 1.3, 1.3, "#b5544a"),
    ("Louvre", "win.Louvre", 1.0, 1.4, "#d9cfb0"),
    ("Georgian", "win.Georgian", 1.7, 2.6, "#7d4a3a"),
    ("Cross", "win.Cross", 1.7, 2.2, "#e8e2d0"),
    ("Shutters", "win.Shutters", 1.1, 1.8, "#efe6d2"),
]


@pytest.mark.parametrize("rule,window,ww,wh,wall", CASES, ids=[c[0] for c in CASES])
def test_renders_not_trained_on_are_recognised(
    rule: str, window: str, ww: float, wh: float, wall: str
) -> None:
    image, boxes = facade(window, ww, wh, wall)
    style, votes = window_style(image, boxes)
    assert style == rule, votes
    assert votes[rule] > len(boxes) / 2, votes


def test_no_boxes_is_plain() -> None:
    image = np.full((60, 80, 3), 200, dtype=np.uint8)
    assert window_style(image, np.zeros((0, 4))) == (DEFAULT_RULE, {})
    assert DEFAULT_RULE == "Plain"
    assert classify(image, np.zeros((0, 4))) == []


def test_votes_count_every_box_and_are_deterministic() -> None:
    rng = np.random.default_rng(3)
    image = rng.integers(0, 256, (300, 400, 3), dtype=np.uint8)
    tops = rng.uniform(0, 250, 17)
    lefts = rng.uniform(0, 350, 17)
    boxes = np.stack(
        [tops, lefts, tops + rng.uniform(5, 60, 17), lefts + rng.uniform(5, 60, 17)], 1
    )
    boxes[0] = [-20, -20, 40, 30]  # past the image's edge: clamped, still counted
    style, votes = window_style(image, boxes)
    assert sum(votes.values()) == len(boxes)
    assert style in votes and votes[style] == max(votes.values())
    assert set(votes) <= set(RULES)
    assert window_style(image, boxes) == (style, votes)
    _, rules = load_weights()
    assert rules == RULES


def test_sixty_windows_are_fast() -> None:
    image, boxes = facade("win.Plain", 1.2, 1.6, "#c8b89a", floors=5, tiles=12, px_per_m=25)
    assert len(boxes) == 60
    window_style(image, boxes)  # weights loaded
    start = time.perf_counter()
    window_style(image, boxes)
    assert time.perf_counter() - start < 1.0  # about 0.03 s; loose for busy test machines
