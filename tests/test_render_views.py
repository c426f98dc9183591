"""bgr render's fitted views (issue 24): they look at the lots' fronts, they frame a model far
from the origin or spread wide, and the documented Python camera example shows the building."""

import json
import math
import os
import re
from collections import Counter

import numpy as np
import pytest
from conftest import ROOT

import bgr
from bgr.cli import main
from bgr.render import Camera, image_of, make_camera, rasterise, render_labels
from bgr.render.camera import facing_yaw
from bgr.render.scene import Scene, load_scene, lots_front

# each side of the mass in its own label, so an image says which sides it shows
FACES = """version 1

Lot --> extrude(6) comp(f) { front: Front | back: Back | side: Side | top: Top | bottom: NIL }
Front --> color("#ff0000")
Back --> color("#0000ff")
Side --> color("#00ff00")
Top --> color("#888888")
"""
CUBE = 'version 1\n\nLot --> extrude(20) color("#888888")\n'
BACKENDS = ["numpy", "gl"]


def seen(image: np.ndarray, legend: dict) -> Counter:
    """Pixels of each label in a labels image (the background left out)."""
    name = {colour: label for label, colour in legend["labels"].items()}
    hexes = Counter("#{:02x}{:02x}{:02x}".format(*p) for p in image.reshape(-1, 3))
    return Counter({name[h]: n for h, n in hexes.items() if h in name})


def lots_file(path, *rings) -> str:
    features = [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [r]}}
        for r in rings
    ]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return str(path)


def fill(mask: np.ndarray) -> tuple[float, float]:
    """The share of the width and of the height that the model's pixels span."""
    ys, xs = np.nonzero(mask)
    if not len(xs):
        return 0.0, 0.0
    return (np.ptp(xs) + 1) / mask.shape[1], (np.ptp(ys) + 1) / mask.shape[0]


@pytest.fixture
def faces(tmp_path):
    path = tmp_path / "faces.bgr"
    path.write_text(FACES)
    return path


# --- the views look at the front ----------------------------------------------------------------


@pytest.mark.parametrize("lot", ["block.geojson", "l_lot.geojson", None])
def test_front_view_sees_the_front_facades(faces, lot):
    """GeoJSON lots face south (+z; north is -z); the W x D default lot faces -z: either way
    `--view front` shows the fronts, and no back."""
    lot = str(ROOT / "examples" / lot) if lot else None
    image, legend = render_labels(faces, "front", (160, 100), "numpy", lot=lot)
    count = seen(image, legend)
    assert count["Back"] == 0, count
    assert count["Front"] > 0.9 * sum(count.values()), count


@pytest.mark.parametrize("how", ["first", "longest"])
def test_front_view_follows_the_front_option(faces, tmp_path, how):
    """One lot, a 6 x 20 m rectangle turned 30 degrees, listed from a short edge: the camera looks
    at whichever edge --front chose."""
    a = math.radians(30)
    u, v = np.array([math.cos(a), math.sin(a)]), np.array([-math.sin(a), math.cos(a)])
    ring = [list(6 * s * u + 20 * t * v) for s, t in ((0, 0), (1, 0), (1, 1), (0, 1), (0, 0))]
    lots = lots_file(tmp_path / "lot.geojson", ring)
    out = tmp_path / "front.png"
    args = ["render", str(faces), "--lot", lots, "--front", how, "--view", "front"]
    args += ["--mode", "labels", "--legend", "--size", "120x90", "--backend", "numpy"]
    assert main([*args, "-o", str(out)]) == 0
    from PIL import Image

    image = np.asarray(Image.open(out).convert("RGB"))
    count = seen(image, json.loads(out.with_suffix(".legend.json").read_text()))
    assert count["Back"] == 0 and count["Front"] > 0.9 * sum(count.values()), count
    width = fill(image.any(axis=2))[0]
    # the long front fills the width; the short one (with its 6 m height) a narrower frame
    assert (width > 0.85) if how == "longest" else (width < 0.85), width


def test_lots_front_weighs_front_length_and_ignores_the_far_side():
    def lot(z, width):
        return {"axes": [[1, 0, 0], [0, 1, 0], z], "size": [width, 0, 10]}

    assert lots_front([]) is None
    assert np.allclose(lots_front([lot([0, 0, 1], 10)]), [0, 0, -1])
    # two sides of a street: the longer side's front is the one looked at, not a mean of zero
    assert np.allclose(lots_front([lot([0, 0, 1], 30), lot([0, 0, -1], 20)]), [0, 0, -1])
    assert np.allclose(lots_front([lot([0, 0, 1], 20), lot([0, 0, -1], 30)]), [0, 0, 1])
    # facing -z and -x equally: half-way between them
    mean = lots_front([lot([0, 0, 1], 10), lot([1, 0, 0], 10)])
    assert np.allclose(mean, [-math.sqrt(0.5), 0, -math.sqrt(0.5)])
    assert facing_yaw(None) == 0 and facing_yaw([0, 0, -1]) == 0
    assert math.isclose(abs(facing_yaw([0, 0, 1])), 180) and math.isclose(
        facing_yaw([-1, 0, 0]), 90
    )


# --- framing ------------------------------------------------------------------------------------


def house_at(offset) -> Scene:
    scene = load_scene(bgr.derive(ROOT / "examples" / "house.bgr", seed=3))
    a = math.radians(17)  # walls off the axes, so their normals are rounded
    turn = np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])
    return Scene(
        scene.triangles @ turn.T + np.asarray(offset, dtype=np.float64),
        scene.colors,
        scene.part,
        scene.label,
        scene.labels,
    )


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_model_in_utm_coordinates_fills_the_frame(backend):
    """A house at some 6e6 m (as UTM eastings and northings are) is framed and drawn as it is at
    the origin, in every mode: the lines too (plane offsets at 6e6 m used to split its walls)."""
    near, far = house_at([0, 0, 0]), house_at([6.1e6, 400.0, -5.3e6])
    for view in ("front", "iso", "top"):
        cams = [make_camera(view, s, (160, 120)) for s in (near, far)]
        try:
            frames = [
                rasterise(s, c, backend, on_fallback=None)
                for s, c in zip((near, far), cams, strict=True)
            ]
        except bgr.BgrError as exc:
            pytest.skip(str(exc))
        assert max(fill(frames[1].mask)) > 0.8, view
        assert (frames[0].triangle == frames[1].triangle).mean() > 0.999, view
        for mode in ("lines", "shaded"):
            a, b = (image_of(f, s, mode)[0] for f, s in zip(frames, (near, far), strict=True))
            differ = (a != b).reshape(a.shape[0], a.shape[1], -1).any(axis=2).sum()
            assert differ <= 4, (view, mode, differ)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_wide_sparse_city_fills_the_frame(backend):
    """Four 20 m blocks in a diamond 3 km across, far from the origin: the iso view fits the
    blocks, not the empty corners of their bounding box (which framed them in half the width)."""
    cube = load_scene(bgr.derive(bgr.load(CUBE), lot=(20, 20)))
    corners = [(1500.0, 0.0, 0.0), (0.0, 0.0, 1500.0), (3000.0, 0.0, 1500.0), (1500.0, 0.0, 3000.0)]
    scene = Scene(
        np.concatenate([cube.triangles + np.array(c) + [2.6e6, 0, -1.2e6] for c in corners]),
        np.tile(cube.colors, (4, 1)),
        np.tile(cube.part, 4),
        np.tile(cube.label, 4),
        cube.labels,
    )
    try:
        frame = rasterise(scene, make_camera("iso", scene, (200, 150)), backend, on_fallback=None)
    except bgr.BgrError as exc:
        pytest.skip(str(exc))
    assert frame.mask.any()
    assert max(fill(frame.mask)) > 0.85, fill(frame.mask)


# --- the documented camera ----------------------------------------------------------------------


def test_the_python_camera_example_of_cli_md_renders_the_house(tmp_path, monkeypatch):
    """docs/cli.md's "In Python" block run as written (beside examples/ and the house.glb its
    console example derives): the silhouette shows the whole house."""
    text = (ROOT / "docs" / "cli.md").read_text(encoding="utf-8")
    start = text.index("### In Python", text.index("## bgr render"))
    block = re.search(r"```python\n(.*?)```", text[start:], re.S)
    assert block and "Camera.from_angles" in block.group(1)
    os.symlink(ROOT / "examples", tmp_path / "examples")
    monkeypatch.chdir(tmp_path)
    bgr.derive("examples/house.bgr", seed=3).save("house.glb")
    # the same code, at a tenth of the pixels to keep the test fast
    code = block.group(1).replace("(800, 600)", "(160, 120)").replace("(640, 480)", "(160, 120)")
    space: dict = {}
    exec(compile(code, "docs/cli.md", "exec"), space)  # noqa: S102 - the documentation's own code
    mask = space["mask"]
    assert isinstance(space["camera"], Camera) and mask.shape == (120, 160)
    on = mask > 0
    assert on.mean() > 0.15
    assert not (on[0].any() or on[-1].any() or on[:, 0].any() or on[:, -1].any())  # all in frame
