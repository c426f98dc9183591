"""Façade parsing, the first stage of the single-image module (issue 28, section 5 of
"Procedural building from a single image"): windows, floors and colour of a rectified façade."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from bgr.inverse.image.facade import (
    parse_facade,
    refine_boundaries,
    refine_grid,
    rows_of,
    runs,
    window_grid,
)
from bgr.inverse.image.pixels import WEIGHTS, load_weights, pitch

ROOT = Path(__file__).resolve().parent.parent
CMP = ROOT.parent / "shared/data/facades/cmp"
WALL = (196, 170, 140)


def _facade(floors: int, columns: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A rectified façade 600 px high: a sandstone wall with a little noise and dark glazed
    windows in a grid of ``floors`` x ``columns``, each with a light frame; and its window mask."""
    rng = np.random.default_rng(seed)
    height, width = 600, 120 * columns
    image = np.empty((height, width, 3))
    image[:] = WALL
    image += rng.normal(0, 6, image.shape)
    truth = np.zeros((height, width), dtype=bool)
    storey = height // floors
    for f in range(floors):
        for c in range(columns):
            top, left = f * storey + storey // 4, c * 120 + 35
            bottom, right = top + storey // 2, left + 50
            image[top - 3 : bottom + 3, left - 3 : right + 3] = (235, 230, 220)  # the frame
            image[top:bottom, left:right] = (40, 52, 60)  # the glass
            truth[top - 3 : bottom + 3, left - 3 : right + 3] = True
    return np.clip(image, 0, 255).astype(np.uint8), truth


def test_runs_are_the_stretches_at_or_above_the_level():
    profile = np.array([0, 1, 1, 0, 0, 1, 1, 1, 0, 1])
    assert runs(profile, 1, 1) == [(1, 3), (5, 8), (9, 10)]
    assert runs(profile, 1, 2) == [(1, 3), (5, 8)]


def test_extents_overlapping_by_more_than_half_are_one_row():
    extents = [(0.0, 1.0), (5.0, 6.0), (0.2, 1.1), (0.9, 2.0), (5.1, 6.1)]
    assert rows_of(extents) == [[0, 2], [3], [1, 4]]  # 0.9-2.0 overlaps the first by 0.1 only


def test_the_grid_of_a_window_mask_is_its_floors_and_windows():
    mask = np.zeros((90, 120), dtype=bool)
    for top in (10, 40, 70):
        for left in (10, 50, 90):
            mask[top : top + 12, left : left + 20] = True
    grid = window_grid(mask)
    assert [len(floor) for floor in grid] == [3, 3, 3]
    assert grid[1][2] == (40, 90, 52, 110)


def test_refined_boundaries_are_the_profiles_minima_near_them():
    profile = np.ones(80)
    profile[[10, 30, 50]] = 0
    assert refine_boundaries(profile, [11, 29, 52], 20).tolist() == [10, 30, 50]


def test_refined_boundaries_keep_the_spacing_within_75_to_140_percent():
    """Section 5.2: the deepest minima near 50 and 78 are 18 apart, under 75 % of 40; the pair
    kept is the best one 30 to 56 apart."""
    profile = np.ones(120)
    profile[[55, 73]] = 0
    profile[[45, 83]] = 0.2
    assert refine_boundaries(profile, [50, 78], 40).tolist() == [45, 83]


def test_a_window_a_mullion_splits_is_one_window_of_its_tile():
    """The refined grid has one window a tile (section 5.2): the two halves of a window whose
    floor's other windows, and the floors above and below, have it whole are one window."""
    grid = [[(10, 10, 20, 30), (10, 50, 20, 70)] for _ in range(3)]
    grid[1] = [(40, 10, 50, 18), (40, 22, 50, 30), (40, 50, 50, 70)]
    grid[2] = [(70, 10, 80, 30), (70, 50, 80, 70)]
    v, h = np.ones(100), np.ones(90)
    refined, bounds = refine_grid(grid, v, h)
    assert [len(f) for f in refined] == [2, 2, 2]
    assert refined[1][0] == (40, 10, 50, 30)
    assert len(bounds) == 2 and 20 < bounds[0] < 40 < bounds[1] < 70


def test_the_pitch_of_a_periodic_profile_is_its_period():
    profile = np.tile([0, 0, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0], 8).astype(float)
    assert pitch(profile, 4, 48) == 12


@pytest.mark.parametrize(("floors", "columns"), [(3, 4), (5, 2), (4, 6)])
def test_a_synthetic_facade_parses_into_its_floors_and_windows(floors, columns):
    image, truth = _facade(floors, columns)
    parse = parse_facade(image)
    assert parse.windows_per_floor() == [columns] * floors
    window = parse.label_map() == 3
    tp = (window & truth).sum()
    f1 = 2 * tp / (2 * tp + (window & ~truth).sum() + (~window & truth).sum())
    assert f1 > 0.8, f1
    assert np.all(np.diff(parse.floor_bounds) > 0) and len(parse.floor_bounds) == floors + 1
    assert np.abs(np.array(parse.color) - WALL).max() < 12, parse.color  # section 5.4


def test_the_shipped_weights_are_small_and_load():
    assert WEIGHTS.stat().st_size < 20_000_000  # issue 28: all shipped weights under 20 MB
    net = load_weights()
    assert 0 < float(net["threshold"]) < 1
    assert net["w1"].shape[1] == net["w2"].shape[0]


def test_cmp_facades_are_parsed_as_cross_validation_measured():
    """Five CMP façades (research data, not shipped): the label map's pixel accuracy and window
    F1 (windows, doors and shops against the rest) near what five-fold cross-validation
    measured (docs/benchmarks.md)."""
    if not CMP.exists():
        pytest.skip("the shared CMP façades are not here")
    from PIL import Image

    tp = fp = fn = 0
    accuracy = []
    for k in (3, 21, 44, 67, 88):
        photo = CMP / f"cmp_b{k:04d}.jpg"
        labels = np.asarray(Image.open(photo.with_suffix(".png")))
        parse = parse_facade(np.asarray(Image.open(photo).convert("RGB")))
        truth, guess = np.isin(labels, (3, 4, 12)), parse.label_map() == 3
        accuracy.append((truth == guess).mean())
        tp += (truth & guess).sum()
        fp += (~truth & guess).sum()
        fn += (truth & ~guess).sum()
    assert np.mean(accuracy) > 0.75
    assert 2 * tp / (2 * tp + fp + fn) > 0.6


# -- bgr infer --kind facade -------------------------------------------------------------------


def _photo(tmp_path: Path, floors: int, columns: int) -> Path:
    from PIL import Image

    image, _ = _facade(floors, columns)
    path = tmp_path / "facade.png"
    Image.fromarray(image).save(path)
    return path


@pytest.mark.parametrize(("floors", "columns"), [(3, 4), (5, 2)])
def test_the_grammar_derives_the_photographs_floors_and_windows(tmp_path, floors, columns):
    import json

    from PIL import Image

    from bgr.cli import main

    photo, out, labels = _photo(tmp_path, floors, columns), tmp_path / "f.bgr", tmp_path / "l.png"
    args = ["infer", str(photo), "--kind", "facade", "-o", str(out), "--label-map", str(labels)]
    assert main(args) == 0
    text = out.read_text()
    assert "import stdlib.facade as fac" in text and "fac.Grid(" in text
    assert main(["fmt", "--check", str(out)]) == 0
    derived = tmp_path / "f.json"
    assert main(["derive", str(out), "-o", str(derived), "--format", "json"]) == 0
    glass = [t for t in json.loads(derived.read_text())["terminals"] if t["label"] == "Glass"]
    assert len(glass) == floors * columns
    heights = sorted({round(t["origin"][1], 3) for t in glass})
    assert len(heights) == floors and np.allclose(np.diff(heights), 3.2, atol=0.05)
    label_map = Image.open(labels)
    assert label_map.mode == "P" and label_map.size == (120 * columns, 600)
    assert set(np.unique(np.asarray(label_map))) == {2, 3}


@pytest.mark.parametrize(
    ("content", "words"),
    [
        (b"not an image at all", "cannot read the photograph"),
        (None, "no such file"),
        ("tiny", "too small to parse"),
    ],
)
def test_a_bad_photograph_is_a_located_error_and_nothing_is_written(
    tmp_path, capsys, content, words
):
    from PIL import Image

    from bgr.cli import main

    photo = tmp_path / "photo.png"
    if content == "tiny":
        Image.new("RGB", (8, 8), "white").save(photo)
    elif content is not None:
        photo.write_bytes(content)
    out, labels = tmp_path / "f.bgr", tmp_path / "l.png"
    args = ["infer", str(photo), "--kind", "facade", "-o", str(out), "--label-map", str(labels)]
    assert main(args) == 1
    err = capsys.readouterr().err
    assert f"{photo}: error:" in err and words in err and "hint:" in err
    assert "Traceback" not in err
    assert not out.exists() and not labels.exists()


def test_a_floor_height_that_is_not_positive_is_a_usage_error(tmp_path, capsys):
    from bgr.cli import main

    photo = _photo(tmp_path, 2, 2)
    assert main(["infer", str(photo), "--kind", "facade", "--floor-height", "0"]) == 2
    assert "--floor-height" in capsys.readouterr().err


def test_a_blank_wall_gives_a_grammar_that_derives(tmp_path):
    from PIL import Image

    from bgr.cli import main

    photo = tmp_path / "blank.png"
    Image.new("RGB", (300, 200), (150, 140, 130)).save(photo)
    out = tmp_path / "f.bgr"
    assert main(["infer", str(photo), "--kind", "facade", "-o", str(out)]) == 0
    assert main(["derive", str(out), "-o", str(tmp_path / "f.glb")]) == 0


def test_hostile_photographs_are_errors_not_tracebacks(tmp_path):
    """Bytes of a PNG cut, flipped or repeated (hypothesis): exit 0 or 1, never a traceback."""
    import io

    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st
    from PIL import Image

    from bgr.cli import main

    buffer = io.BytesIO()
    Image.fromarray(_facade(2, 2)[0]).save(buffer, format="PNG")
    seed = buffer.getvalue()

    @settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
    @given(st.integers(0, len(seed)), st.binary(max_size=64), st.integers(1, 3))
    def check(cut, junk, copies):
        photo = tmp_path / "photo.png"
        photo.write_bytes((seed[:cut] + junk + seed[cut + len(junk) :]) * copies)
        assert main(["infer", str(photo), "--kind", "facade", "-o", str(tmp_path / "f.bgr")]) in (
            0,
            1,
        )

    check()
