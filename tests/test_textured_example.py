"""examples/textured_house.bgr as a user sees it: `bgr render` draws its shipped textures (issue
26: a rendered region compared against the texture's mean colour).

The renderer multiplies a pixel's texture colour (in linear light) by the shape's colour (white
here) and a grey light, so the chromaticity of a surface's pixels — each channel over their sum —
is the texture's, whatever the light.  The roof's pixels are found in the labels image; their mean
chromaticity must be the roof-tile image's, and far from the flat white an untextured roof has.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import bgr
from bgr.render import render, render_labels

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "textured_house.bgr"
TEXTURES = ROOT / "stdlib" / "textures"


def linear(srgb) -> np.ndarray:
    c = np.asarray(srgb, dtype=np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def chromaticity(rgb_linear: np.ndarray) -> np.ndarray:
    total = rgb_linear.sum(axis=-1, keepdims=True)
    return (rgb_linear / np.where(total > 0, total, 1)).reshape(-1, 3)


@pytest.fixture(scope="module")
def house():
    result = bgr.derive(bgr.load(EXAMPLE), seed=3)
    size = (480, 360)
    shaded = render(result, view="iso", size=size, backend="numpy")
    labels, legend = render_labels(result, view="iso", size=size, backend="numpy")
    return shaded, labels, legend["labels"]


def mask_of(labels: np.ndarray, legend: dict, suffix: str) -> np.ndarray:
    """Pixels whose label (a terminal's rule) ends with ``suffix``."""
    mask = np.zeros(labels.shape[:2], dtype=bool)
    for label, colour in legend.items():
        if label.split(".")[-1] == suffix:
            rgb = [int(colour[k : k + 2], 16) for k in (1, 3, 5)]
            mask |= (labels[..., :3] == rgb).all(axis=-1)
    return mask


@pytest.mark.parametrize(("label", "image"), [("Roof", "roof_tiles.png"), ("Glass", "window.png")])
def test_the_example_shows_its_shipped_textures(house, label, image):
    shaded, labels, legend = house
    mask = mask_of(labels, legend, label)
    assert mask.sum() > 2000, f"the iso view shows too little {label}: {mask.sum()} pixels"
    pixels = linear(shaded[..., :3][mask])
    texture = linear(np.asarray(Image.open(TEXTURES / image).convert("RGB")))
    seen = chromaticity(pixels.mean(axis=0))[0]
    expected = chromaticity(texture.reshape(-1, 3).mean(axis=0))[0]
    assert np.abs(seen - expected).max() < 0.03, (seen, expected)
    if np.abs(expected - 1 / 3).max() > 0.1:  # a coloured image (the roof's clay)
        assert np.abs(seen - 1 / 3).max() > 0.1  # a white untextured surface would be grey
    # textured, not one flat colour: the image's pattern shows in the pixels
    assert pixels.std(axis=0).mean() > 0.01
