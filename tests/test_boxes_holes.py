"""bgr retarget leaves no hole in a wall the input closed, repeats R boxes at about their own
size, and writes models whose parts read apart (issue 24).

Holes are checked two ways: exactly, on the boxes (:func:`model.holes`: every box whose
children filled it in the input is filled in the result), and as the issue saw them, on a small
front render of the documented commands (no background pixel inside the façade's outline).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT
from test_boxes import box

from bgr.cli import main
from bgr.inverse.boxes import model
from bgr.inverse.boxes.command import COLOURS, _load_part, _pieces, colour, kind
from bgr.inverse.boxes.repair import RHO
from bgr.inverse.boxes.retarget import retarget

EXAMPLES = ROOT / "examples" / "boxes"

# the documented commands (README, docs/inverse-boxes.md, docs/cli.md) and the 250 %
COMMANDS = [
    ("irregular_facade", (30, 16, 0.4), "yx"),
    ("irregular_facade", (50, 32.5, 0.4), "yx"),
    ("irregular_facade", (50, 32.5, 0.4), "xy"),
    ("regular_facade", (30, 20, 0.5), "xyz"),
    ("building", (36, 19, 14), "xyz"),
]


def parse(root: dict) -> model.Box:
    return model.parse(json.dumps({"root": root}), "test")


# ---- the boxes ----------------------------------------------------------------------------


def test_uncovered_measures_the_space_children_leave():
    kids = [box("a", (0, 0, 0), (2, 4, 1)), box("b", (3, 0, 0), (4, 3, 1))]
    root = parse(box("root", (0, 0, 0), (4, 4, 1), "SSS", kids))
    # x 2-3 (4 m2) and b's top, x 3-4 y 3-4 (1 m2), 1 deep
    assert model.uncovered(root) == pytest.approx(5)
    assert model.uncovered(root.children[0]) == 0  # a leaf: its part fills it
    closed = parse(box("root", (0, 0, 0), (4, 4, 1), "SSS", [box("a", (0, 0, 0), (4, 4, 1))]))
    assert model.uncovered(closed) == 0
    # the input's own gaps are not holes of the result
    assert model.holes(root, root) == []


def test_a_door_on_the_ground_holds_the_storey_line_over_it():
    # the case in small: wall (S) | door (F along y, 0-4) | wall, a storey above resting
    # on all three. Stretched to 15 m the walls took the primary's share (0-6) and the storey
    # rested on them, leaving 4-6 open over the door; now the door's top holds the line
    kids = [
        box("wall-l", (0, 0, 0), (3, 4, 1)),
        box("door", (3, 0, 0), (5, 4, 1), "FFS"),
        box("wall-r", (5, 0, 0), (8, 4, 1)),
        box("storey", (0, 4, 0), (8, 10, 1)),
    ]
    root = parse(box("root", (0, 0, 0), (8, 10, 1), "SSS", kids))
    result = retarget(root, (8, 15, 1), "y")
    got = {c.id: (round(c.lo[1], 9), round(c.hi[1], 9)) for c in result.children}
    assert got == {"wall-l": (0, 4), "door": (0, 4), "wall-r": (0, 4), "storey": (4, 15)}
    assert model.holes(root, result) == []


@pytest.mark.parametrize("name, size, order", COMMANDS)
def test_documented_retargetings_leave_no_hole_and_keep_r_boxes_their_size(name, size, order):
    root = model.read(EXAMPLES / f"{name}.json")
    result = retarget(root, size, order)
    assert model.check(result) == []
    assert model.holes(root, result) == []
    # stretched, every R box is repeated at about its own size (not squeezed, not a panel)
    source = {b.id: b for b in root.walk()}
    for b in result.walk():
        was = source[b.source]
        for a in range(3):
            if was.tags[a] == "R":
                assert RHO - 1e-9 <= b.size[a] / was.size[a] <= 1 / RHO + 1e-9, (b.id, a)


@pytest.mark.parametrize("name", ["regular_facade", "irregular_facade", "building"])
@pytest.mark.parametrize(
    "factors", [(0.6, 0.6, 0.6), (2.5, 2.5, 2.5), (0.6, 2.5, 1), (1.37, 0.8, 1.9)]
)
def test_examples_at_60_to_250_percent_leave_no_hole(name, factors):
    root = model.read(EXAMPLES / f"{name}.json")
    size = [v * f if t != "F" else v for v, f, t in zip(root.size, factors, root.tags, strict=True)]
    for order in ("xyz", "yxz"):
        assert model.holes(root, retarget(root, size, order)) == [], order


# ---- the pictures -------------------------------------------------------------------------


def see_through(image: np.ndarray, background, flat: bool) -> tuple[int, float]:
    """Background pixels seen through the model, and the share of the picture the model's
    bounding rectangle takes.  A flat façade seen from the front is a rectangle: any background
    pixel inside the rectangle of its pixels counts.  A building (its porch, nearer the camera,
    sticks out below the front in perspective): background pixels the model encloses."""
    from scipy import ndimage

    empty = np.all(image == np.array(background, dtype=image.dtype), axis=2)
    rows, cols = np.nonzero(~empty)
    box = empty[rows.min() : rows.max() + 1, cols.min() : cols.max() + 1]
    share = box.size / empty.size
    if flat:
        return int(box.sum()), share
    parts, _ = ndimage.label(empty)
    outside = set(np.unique(np.r_[parts[0], parts[-1], parts[:, 0], parts[:, -1]]))
    return int(np.sum(empty & ~np.isin(parts, list(outside)))), share


@pytest.mark.parametrize("name, size, order", COMMANDS)
def test_documented_commands_render_a_closed_wall(tmp_path, capsys, name, size, order):
    from bgr.render import render
    from bgr.render.images import BACKGROUND

    out = tmp_path / "out.glb"
    args = ["retarget", str(EXAMPLES / f"{name}.json"), "--size", ",".join(map(str, size))]
    assert main([*args, "--order", order, "-o", str(out)]) == 0
    capsys.readouterr()
    image = render(str(out), "shaded", "front", (200, 150))
    holes, share = see_through(image, BACKGROUND, flat=name != "building")
    assert holes == 0
    assert share > 0.3  # the façade, not a speck


def test_the_picture_check_sees_a_hole():
    # the check itself: a façade with a hole, and the building's front outline with a notch
    image = np.full((40, 60, 3), 242, dtype=np.uint8)
    image[5:35, 5:55] = (200, 150, 100)
    assert see_through(image, (242, 242, 242), flat=True) == (0, 30 * 50 / (40 * 60))
    image[10:14, 20:24] = 242
    assert see_through(image, (242, 242, 242), flat=True)[0] == 16
    assert see_through(image, (242, 242, 242), flat=False)[0] == 16
    image[30:35, 5:10] = 242  # a notch at the outline: not see-through for a building
    assert see_through(image, (242, 242, 242), flat=False)[0] == 16


# ---- the colours --------------------------------------------------------------------------


def test_parts_get_kinds_by_their_names():
    def leaf(id, mesh=None):
        b = model.Box(id, np.zeros(3), np.ones(3))
        b.mesh = mesh
        return b

    assert kind(leaf("door-0-1")) == "door"
    assert kind(leaf("door-bay-cornice")) == "trim"  # the last word names the part
    assert kind(leaf("door-bay-storey-1", "parts/window.obj")) == "window"  # the mesh first
    assert kind(leaf("narrow-3-1~2")) == "window"
    assert kind(leaf("shop-0-3")) == "shop"
    assert kind(leaf("sill-1-1")) == "trim"
    assert kind(leaf("wall-0-0")) == "wall"
    assert kind(leaf("bay-1-0")) == "wall"


def test_window_door_and_wall_colours_are_clearly_apart():
    names = ["wall", "window", "door", "shop", "trim"]
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            assert math.dist(COLOURS[a], COLOURS[b]) > 0.2, (a, b)
    # neighbours of a kind (a window and its copy) are shaded apart
    one = model.Box("w", np.array([0.0, 0, 0]), np.array([1.5, 2, 1]))
    two = model.Box("w~1", np.array([1.5, 0, 0]), np.array([3.0, 2, 1]), source="w", replica=1)
    assert colour(one) != colour(two)


def test_a_window_part_splits_into_its_frame_and_its_pane():
    base = EXAMPLES.resolve()
    pieces = {
        name: _pieces(_load_part((base,), base, f"parts/{name}.obj"))
        for name in ("window", "door", "shop", "porch")
    }
    for name in ("window", "door", "shop"):
        assert [infill for _, infill in pieces[name]] == [False, True], name
        pane = pieces[name][1][0]
        z = pane.vertices[pane.faces][:, :, 2]
        assert z.min() > 0 and z.max() < 1  # recessed: touches neither face of the wall
    assert [infill for _, infill in pieces["porch"]] == [True]  # nothing recessed: one piece


def test_the_model_shows_windows_in_glass_and_the_door_in_wood(tmp_path, capsys):
    from bgr.render import render

    out = tmp_path / "f.glb"
    args = ["retarget", str(EXAMPLES / "irregular_facade.json"), "--size", "30,16,0.4"]
    assert main([*args, "--order", "yx", "-o", str(out)]) == 0
    capsys.readouterr()
    image = render(str(out), "shaded", "front", (200, 150)).reshape(-1, 3).astype(float)
    # the shaded colours are darker than the base ones; compare hues: blue glass, brown wood
    blue = (image[:, 2] > image[:, 0] + 25).mean()
    brown = ((image[:, 0] > image[:, 2] + 40) & (image.sum(axis=1) < 300)).mean()
    assert blue > 0.05 and brown > 0.003
    assert Path(out).stat().st_size > 0
