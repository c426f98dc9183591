"""bgr infer --kind style on bad input: a located error, exit 1, nothing written (issue 27)."""

from __future__ import annotations

from pathlib import Path

import pytest

from bgr.cli import main

ROOT = Path(__file__).resolve().parent.parent
WINDOW = ROOT / "stdlib" / "textures" / "window.png"

# a 10 x 6 x 8 box, y up, faces wound outward (the front, z = 0, faces -z), each wall mapped
# once onto the image of its material
BOX = [(0, 0, 0), (10, 0, 0), (10, 6, 0), (0, 6, 0), (0, 0, 8), (10, 0, 8), (10, 6, 8), (0, 6, 8)]
QUADS = [(4, 3, 2, 1), (3, 7, 6, 2), (7, 8, 5, 6), (8, 4, 1, 5), (8, 7, 3, 4), (1, 2, 6, 5)]


def _obj(folder: Path, name: str, material: str | None, quads=QUADS, points=BOX) -> Path:
    lines = [f"v {x} {y} {z}" for x, y, z in points] + ["vt 0 0", "vt 1 0", "vt 1 1", "vt 0 1"]
    if material is not None:
        lines = ["mtllib wall.mtl", *lines, f"usemtl {material}"]
    for quad in quads:
        corners = list(quad)
        lines.append("f " + " ".join(f"{v}/{4 - k}" for k, v in enumerate(corners)))
    path = folder / f"{name}.obj"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture
def models(tmp_path: Path) -> Path:
    (tmp_path / "tex.png").write_bytes(WINDOW.read_bytes())
    (tmp_path / "broken.png").write_bytes(b"not an image at all")
    (tmp_path / "wall.mtl").write_text(
        "newmtl brick\nKd 1 1 1\nmap_Kd tex.png\nnewmtl broken\nKd 1 1 1\nmap_Kd broken.png\n"
    )
    return tmp_path


def _refused(capsys, folder: Path, model: Path, *words: str) -> None:
    out = folder / "out.bgr"
    assert main(["infer", str(model), "--kind", "style", "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert f"{model}: error:" in err  # located at the model
    assert "hint:" in err
    for word in words:
        assert word in err
    assert "Traceback" not in err
    assert not out.exists() and not (folder / "out.assets").exists()  # nothing written


def test_a_textured_box_captures(models: Path, capsys) -> None:
    out = models / "out.bgr"
    assert (
        main(["infer", str(_obj(models, "box", "brick")), "--kind", "style", "-o", str(out)]) == 0
    )
    text = out.read_text()
    assert "const block0_width = 10" in text and "const block0_height = 6" in text
    crops = list((models / "out.assets").glob("*.png"))
    assert crops and all(f'"out.assets/{p.name}"' in text for p in crops)


def test_an_untextured_model_is_refused(models: Path, capsys) -> None:
    _refused(capsys, models, _obj(models, "plain", None), "no textured face")


def test_a_building_with_no_vertical_faces_is_refused(models: Path, capsys) -> None:
    flat = _obj(models, "flat", "brick", quads=[(1, 2, 6, 5)])  # the ground quad alone
    _refused(capsys, models, flat, "no vertical faces")


def test_a_texture_that_cannot_be_read_is_refused(models: Path, capsys) -> None:
    model = _obj(models, "broken", "broken")
    _refused(capsys, models, model, "broken.png cannot be read", "not a PNG or JPEG")


def test_an_unknown_building_is_refused(models: Path, capsys) -> None:
    out = models / "out.bgr"
    model = _obj(models, "box", "brick")
    args = ["infer", str(model), "--kind", "style", "--building", "nope", "-o", str(out)]
    assert main(args) == 1
    assert "no building 'nope' in the model" in capsys.readouterr().err
    assert not out.exists()


def test_a_file_of_another_kind_is_refused(models: Path, capsys) -> None:
    model = models / "city.ply"
    model.write_text("ply\n")
    _refused(capsys, models, model, "reads a textured model")
