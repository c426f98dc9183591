"""formats/png.py: the style sheets' crops as PNG files any reader takes, pixel for pixel."""

import io

import numpy as np
import pytest
from PIL import Image

from bgr.formats.png import png_bytes


@pytest.mark.parametrize("shape", [(1, 1), (1, 7), (9, 1), (37, 1200), (64, 48)])
def test_pillow_reads_back_every_pixel(shape):
    rng = np.random.default_rng(sum(shape))
    image = rng.integers(0, 256, (*shape, 3), dtype=np.uint8)
    image[shape[0] // 2 :] = image[: shape[0] - shape[0] // 2]  # repeated rows, as façades have
    data = png_bytes(image)
    Image.open(io.BytesIO(data)).verify()  # chunk CRCs and structure
    with Image.open(io.BytesIO(data)) as im:
        assert im.mode == "RGB" and im.size == (shape[1], shape[0])
        np.testing.assert_array_equal(np.asarray(im), image)


def test_a_plain_wall_compresses():
    wall = np.full((200, 300, 3), (120, 110, 100), dtype=np.uint8)
    assert len(png_bytes(wall)) < 2_000  # 180,000 bytes of pixels


def test_it_refuses_what_is_not_an_rgb_byte_image():
    for bad in (np.zeros((4, 4), np.uint8), np.zeros((4, 4, 4), np.uint8), np.zeros((4, 4, 3))):
        with pytest.raises(ValueError):
            png_bytes(bad)
    with pytest.raises(ValueError):
        png_bytes(np.zeros((0, 4, 3), np.uint8))
