"""``bgr infer PHOTO --kind image --silhouette SIL``, end to end on a photograph bgr renders
itself (issue 28): the grammar derives, its camera file renders the photograph's view, and the
model covers the outline."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from bgr.inverse.image import camera as cam
from bgr.inverse.image.mass_fit import MassFit
from bgr.inverse.image.masses import BY_RULE
from bgr.inverse.image.outline import iou
from bgr.inverse.image.photo import PhotoFit, photo_grammar, render_camera
from bgr.inverse.image.preview import rendered

SIZE = (400, 300)


def bgr(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "bgr", *args], cwd=cwd, capture_output=True, text=True
    )


@pytest.fixture(scope="module")
def photo(tmp_path_factory) -> tuple[Path, Path, np.ndarray]:
    """A street view of a gabled house with a façade of windows, its outline as a mask PNG."""
    tmp = tmp_path_factory.mktemp("photo")
    family = BY_RULE["GableHouse"]
    truth = MassFit(
        family,
        np.array([0.5, 0.4, 0.6, 0.5]),
        cam.normalise([8.0, 35.0, 2.0, 55.0, 0.0, 0.1, 1.0, 4.0]),
    )
    text = photo_grammar(PhotoFit(truth, False, 1.0, None, (0, 0)), "truth.jpg", 3.2)
    shaded, covered = rendered(
        text, render_camera(PhotoFit(truth, False, 1.0, None, (0, 0)), *SIZE, (20, 20))
    )
    path = tmp / "house.png"
    Image.fromarray(shaded).save(path)
    mask = tmp / "house-outline.png"
    Image.fromarray(covered.astype(np.uint8) * 255).save(mask)
    return path, mask, covered


def test_a_rendered_house_is_fitted_and_its_camera_renders_the_view(photo, tmp_path):
    path, mask, covered = photo
    done = bgr(
        "infer",
        str(path),
        "--kind",
        "image",
        "--silhouette",
        str(mask),
        "-o",
        "house.bgr",
        "--preview",
        "preview.png",
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stderr
    for stage in ("fitting the mass", "mass:", "façade:", "preview"):
        assert stage in done.stderr  # a progress line per stage
    import bgr as api
    from bgr.render.camera import Camera

    grammar = (tmp_path / "house.bgr").read_text()
    assert "import stdlib.mass as mass" in grammar and "Lot --> mass." in grammar
    result = api.derive(tmp_path / "house.bgr")
    assert len(result.mesh.faces) > 0
    camera = Camera.from_json(tmp_path / "house.camera.json")
    assert camera.size == SIZE
    _, shown = rendered(grammar, camera)
    assert iou(shown, covered) >= 0.85
    preview = Image.open(tmp_path / "preview.png")
    assert preview.size == SIZE


def test_the_outline_is_required_and_bad_ones_are_located_errors(photo, tmp_path):
    path, _, _ = photo
    done = bgr("infer", str(path), "--kind", "image", cwd=tmp_path)
    assert done.returncode == 1 and "needs the building's outline" in done.stderr
    assert "Traceback" not in done.stderr
    (tmp_path / "line.json").write_text("[[1, 1], [50, 50]]")
    done = bgr(
        "infer",
        str(path),
        "--kind",
        "image",
        "--silhouette",
        "line.json",
        "-o",
        "x.bgr",
        cwd=tmp_path,
    )
    assert done.returncode == 1 and "line.json" in done.stderr and "at least 3" in done.stderr
    assert not (tmp_path / "x.bgr").exists()
