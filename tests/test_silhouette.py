"""The user's outline of the target building (``bgr infer --kind image --silhouette``, issue 28):
JSON points or a mask image read into a Silhouette, every bad input a located BgrError."""

from __future__ import annotations

import contextlib
import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PIL import Image

from bgr.grammar.errors import BgrError
from bgr.inverse.image.silhouette import Silhouette, read_silhouette

ROOT = Path(__file__).resolve().parent.parent
PHOTOS = ROOT.parent / "shared/data/facades/photos"
SIZE = (100, 60)
SQUARE = [[10, 10], [90, 10], [90, 50], [10, 50]]


def _write(tmp_path: Path, content: str | bytes, name: str = "sil.json") -> str:
    path = tmp_path / name
    if isinstance(content, str):
        path.write_text(content, encoding="utf-8")
    else:
        path.write_bytes(content)
    return str(path)


def _png(tmp_path: Path, array: np.ndarray, name: str = "mask.png", mode: str | None = None) -> str:
    path = tmp_path / name
    image = Image.fromarray(array)
    if mode:
        image = image.convert(mode)
    image.save(path)
    return str(path)


def _error(path: str, size: tuple[int, int] = SIZE) -> BgrError:
    with pytest.raises(BgrError) as caught:
        read_silhouette(path, size)
    return caught.value


# --- polygons --------------------------------------------------------------------------


def test_points_give_the_polygon_its_mask_outline_and_bbox(tmp_path):
    sil = read_silhouette(_write(tmp_path, json.dumps(SQUARE)), SIZE)
    assert isinstance(sil, Silhouette)
    assert sil.polygon is not None and sil.polygon.shape == (4, 2)
    assert sil.bbox == (10.0, 10.0, 90.0, 50.0)
    mask = sil.mask(100, 60)
    assert mask.shape == (60, 100) and mask.dtype == bool
    # drawn as the fit draws a model (Pillow, its outline included): columns 9-89, rows 9-49
    assert mask.sum() == 81 * 41
    assert mask[10, 10] and mask[49, 89] and not mask[8, 10] and not mask[10, 90]
    outline = sil.outline(100, 60)
    assert outline.sum() == 2 * 81 + 2 * 39  # the ring of the rectangle, one pixel wide
    assert not (outline & ~mask).any()


def test_the_mask_scales_with_the_photograph(tmp_path):
    sil = read_silhouette(_write(tmp_path, json.dumps(SQUARE)), SIZE)
    half = sil.mask(50, 30)
    assert half.shape == (30, 50) and half.sum() == 41 * 21
    assert sil.mask(width=200).shape == (120, 200)
    assert sil.mask().shape == (60, 100)


def test_an_object_with_points_and_a_closing_point_read(tmp_path):
    text = json.dumps({"points": [*SQUARE, SQUARE[0]], "note": "drawn by hand"})
    sil = read_silhouette(_write(tmp_path, text, "outline.txt"), SIZE)
    assert sil.polygon is not None and len(sil.polygon) == 4  # the repeated first point dropped
    assert sil.area == pytest.approx(3200)


def test_points_a_little_outside_are_clipped_onto_the_border(tmp_path):
    points = [[-1.5, -1], [101, -0.5], [101.9, 61]]  # within 2 % of 100 x 60
    sil = read_silhouette(_write(tmp_path, json.dumps(points)), SIZE)
    assert sil.polygon is not None
    assert sil.polygon.tolist() == [[0, 0], [100, 0], [100, 60]]
    assert sil.bbox == (0.0, 0.0, 100.0, 60.0)


BAD_POINTS = [
    ("[[10, 10], [90, 10]", (1, 20), "not valid JSON"),
    ("[[10, 10], [90, 10]]", (1, 1), "2 distinct points"),
    ("[[10, 10], [10, 10], [10, 10], [10, 10]]", (1, 1), "1 distinct point"),
    ('[[10, 10],\n [90, "a"], [90, 50]]', (2, 7), "point 2's y is a string"),
    ("[[10, 10], [90, true], [90, 50]]", (1, 17), "point 2's y is true, not"),
    ("[[10, 10],\n  [NaN, 10], [90, 50]]", (2, 4), "point 2's x is nan"),
    ("[[10, 10], [90, 1e999], [90, 50]]", (1, 17), "not a finite number"),
    ("[[10, 10], [90, 10, 3], [90, 50]]", (1, 12), "point 2 is 3 values"),
    ('[[10, 10], {"x": 1}, [90, 50]]', (1, 12), "point 2 is an object"),
    ("[[10, 10], [50, 10], [90, 10]]", (1, 1), "no area"),
    ("[[10, 10], [90, 10], [10, 50], [90, 50]]", (1, 12), "crosses itself at (50.0, 30.0)"),
    ("[[10, 10], [190, 10], [90, 50]]", (1, 12), "point 2 (190, 10) is outside"),
    ("[[10, 10], [90, -5], [90, 50]]", (1, 12), "is outside"),
    ("[[0, 0], [100, 0], [100, 60], [0, 60]]", (1, 1), "covers 100% of the photograph"),
    ('{"pts": [[1, 2]]}', (1, 1), 'has no "points"'),
    ('{"points": 3}', (1, 1), '"points" is not a list'),
    ('"hello"', (1, 1), "JSON is a string, not a list"),
    ("[[1, 2]] [3]", (1, 10), "Extra data"),
    ("[" * 50_000, None, "nested too deeply"),
]


@pytest.mark.parametrize("text, where, message", BAD_POINTS)
def test_bad_points_are_located_errors(tmp_path, text, where, message):
    error = _error(_write(tmp_path, text))
    assert message in error.message, error.render()
    if where is not None:
        assert (error.line, error.column) == where, error.render()
    assert error.hint


def test_not_utf8_is_located(tmp_path):
    error = _error(_write(tmp_path, b'[[1, 2],\n [3, "\xff"]]'))
    assert "not UTF-8" in error.message and error.line == 2


def test_neither_json_nor_an_image(tmp_path):
    error = _error(_write(tmp_path, b"\x00\x01\x02\x89garbage", "sil.bin"))
    assert "neither JSON points nor an image" in error.message


def test_a_missing_file(tmp_path):
    assert "no such file" in _error(str(tmp_path / "none.json")).message


# --- masks -----------------------------------------------------------------------------


def _rect_mask(size=SIZE, box=(10, 10, 90, 50)) -> np.ndarray:
    mask = np.zeros((size[1], size[0]), dtype=np.uint8)
    x0, y0, x1, y1 = box
    mask[y0:y1, x0:x1] = 255
    return mask


@pytest.mark.parametrize("mode", [None, "1", "RGB", "P", "I;16"])
def test_a_mask_in_any_mode_reads(tmp_path, mode):
    sil = read_silhouette(_png(tmp_path, _rect_mask(), mode=mode), SIZE)
    assert sil.polygon is None
    assert sil.bbox == (10.0, 10.0, 90.0, 50.0)
    assert sil.mask().sum() == 80 * 40
    assert sil.mask(50, 30).sum() == 40 * 20
    assert sil.outline().sum() == 2 * 80 + 2 * 38


def test_a_zero_one_mask_and_one_with_alpha(tmp_path):
    sil = read_silhouette(_png(tmp_path, _rect_mask() // 255), SIZE)  # values 0 and 1
    assert sil.mask().sum() == 3200
    rgba = np.zeros((60, 100, 4), dtype=np.uint8)  # black paint on a transparent layer
    rgba[10:50, 10:90, 3] = 255
    sil = read_silhouette(_png(tmp_path, rgba, "alpha.png"), SIZE)
    assert sil.mask().sum() == 3200


def test_a_mask_is_decided_by_its_bytes_not_its_name(tmp_path):
    path = tmp_path / "mask.json"
    Image.fromarray(_rect_mask()).save(path, format="PNG")
    assert read_silhouette(str(path), SIZE).mask().sum() == 3200


def test_a_mask_of_the_same_aspect_is_resized(tmp_path):
    big = _rect_mask((200, 120), (20, 20, 180, 100))
    sil = read_silhouette(_png(tmp_path, big), SIZE)
    assert sil.mask().shape == (60, 100) and sil.bbox == (10.0, 10.0, 90.0, 50.0)


def test_holes_are_filled_and_specks_dropped(tmp_path):
    mask = _rect_mask()
    mask[20:30, 30:40] = 0  # a window left unpainted
    mask[2, 2] = 255  # a speck of the brush
    sil = read_silhouette(_png(tmp_path, mask), SIZE)
    assert sil.mask().sum() == 3200 and sil.bbox == (10.0, 10.0, 90.0, 50.0)


def test_bad_masks_are_errors(tmp_path):
    assert "empty" in _error(_png(tmp_path, np.zeros((60, 100), np.uint8))).message
    wrong = _error(_png(tmp_path, _rect_mask((100, 100), (10, 10, 50, 50))))
    assert "100 x 100 pixels, the photograph 100 x 60" in wrong.message
    two = _rect_mask()
    two[:, 45:55] = 0
    error = _error(_png(tmp_path, two))
    assert "2 separate parts" in error.message and "x 10-44" in error.message, error.message
    assert "covers 100%" in _error(_png(tmp_path, np.full((60, 100), 255, np.uint8))).message


def test_a_broken_image_is_an_error(tmp_path):
    path = tmp_path / "mask.png"
    Image.fromarray(_rect_mask()).save(path)
    data = path.read_bytes()
    error = _error(_write(tmp_path, data[: len(data) // 2], "cut.png"))
    assert "cannot read the silhouette mask" in error.message


# --- hostile input ---------------------------------------------------------------------

JSON = st.recursive(
    st.none() | st.booleans() | st.floats() | st.integers() | st.text(max_size=5),
    lambda children: (
        st.lists(children, max_size=6) | st.dictionaries(st.text(max_size=6), children, max_size=3)
    ),
    max_leaves=40,
)
POINTS = st.lists(
    st.lists(st.floats(-20, 130) | st.integers(-20, 130), min_size=2, max_size=2),
    max_size=12,
)


def _png_bytes() -> bytes:
    import io

    out = io.BytesIO()
    Image.fromarray(_rect_mask()).save(out, format="PNG")
    return out.getvalue()


PNG = _png_bytes()
# a mask PNG with bytes overwritten: headers, chunk lengths and pixels that lie
BROKEN_PNG = st.builds(
    lambda edits: bytes(dict(edits).get(i, b) for i, b in enumerate(PNG)),
    st.lists(st.tuples(st.integers(0, len(PNG) - 1), st.integers(0, 255)), max_size=4),
)


@settings(max_examples=150, deadline=None, database=None, suppress_health_check=list(HealthCheck))
@given(
    data=st.binary(max_size=300) | st.builds(lambda v: json.dumps(v).encode(), JSON) | BROKEN_PNG
)
def test_random_bytes_and_json_are_a_silhouette_or_a_bgr_error(tmp_path_factory, data):
    path = tmp_path_factory.mktemp("fuzz") / "sil"
    path.write_bytes(data)
    with contextlib.suppress(BgrError):
        read_silhouette(str(path), SIZE)


@settings(max_examples=150, deadline=None, database=None, suppress_health_check=list(HealthCheck))
@given(points=POINTS | st.builds(lambda p: {"points": p}, POINTS))
def test_random_polygons_are_a_silhouette_or_a_bgr_error(tmp_path_factory, points):
    path = tmp_path_factory.mktemp("fuzz") / "sil.json"
    path.write_text(json.dumps(points))
    try:
        sil = read_silhouette(str(path), SIZE)
    except BgrError:
        return
    mask = sil.mask(37, 22)
    assert mask.shape == (22, 37)
    assert sil.outline().shape == (60, 100)


# --- the bench outlines ----------------------------------------------------------------


@pytest.mark.parametrize(
    "name, size", [("building", (868, 600)), ("leuvenA", (751, 563)), ("leuvenB", (751, 563))]
)
def test_the_bench_outlines_read(name, size):
    path = ROOT / "bench/photos" / f"{name}.json"
    sil = read_silhouette(str(path), size)
    assert sil.polygon is not None and 15 <= len(sil.polygon) <= 40
    assert 0.03 < sil.mask().mean() < 0.9
    if PHOTOS.exists():
        with Image.open(PHOTOS / f"{name}.jpg") as photo:
            assert photo.size == size
