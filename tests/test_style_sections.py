"""``bgr restyle --section N`` loads and checks the sheet's section N alone
(inverse/style/sections.py), where the sheet is laid out as bgr infer writes it, and the whole
sheet otherwise.  What a user relies on: the same styled model, byte for byte, as with the whole
sheet; messages that point at the file's own lines; a sheet edited by hand still works."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import ROOT
from style_synth import make_building

import bgr
from bgr.cli import main
from bgr.grammar.loader import load
from bgr.inverse.style.capture import capture_building, read_model
from bgr.inverse.style.emit import Crops, style_text
from bgr.inverse.style.restyle import restyle
from bgr.inverse.style.sections import load_section, section_text

pytestmark = pytest.mark.xdist_group("style_sections")  # one worker: the sheet is made once
MASS: list[Path] = []  # the two-block mass, derived once


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """A sheet of two captured buildings (the podium tower, kind 1, and the wedding cake,
    kind 2: sections 0 and 1) with its crops, and a two-block mass."""
    folder = tmp_path_factory.mktemp("sections")
    captured = []
    for kind in (1, 2):
        glb, _ = make_building(kind, folder / f"synth{kind}")
        captured.append(capture_building(read_model(str(glb)), None))
    crops = Crops("style.assets", 512)
    text = style_text([(c.capture, c.groups) for c in captured], crops)
    (folder / "style.bgr").write_text(text)
    (folder / "style.assets").mkdir()
    for name, data in crops.files.items():
        (folder / "style.assets" / name).write_bytes(data)
    mass = ROOT / "examples" / "style" / "two_stack.bgr"
    assert main(["derive", str(mass), "-o", str(folder / "mass.glb")]) == 0
    MASS[:] = [folder / "mass.glb"]
    return folder


def styled_bytes(folder: Path, style, section: int, name: str) -> bytes:
    result, _ = restyle(str(MASS[0]), style, section=section)
    out = folder / name
    result.save(out)
    return out.read_bytes()


@pytest.mark.parametrize("section", [0, 1])
def test_one_section_styles_the_mass_as_the_whole_sheet_does(folder, section):
    sheet = folder / "style.bgr"
    text = sheet.read_text()
    cut = section_text(text, section)
    assert cut is not None
    # same lines, numbered as in the file; the other section's rules gone
    assert cut.count("\n") == text.count("\n")
    other = 1 - section
    assert f"S{other}block0_width" in text and f"S{other}block0_width" not in cut
    grammar, alone = load_section(sheet, section)
    assert alone and f"S{other}block0_width" not in grammar.consts
    whole = styled_bytes(folder, load(sheet), section, f"whole{section}.glb")
    assert styled_bytes(folder, str(sheet), section, f"cut{section}.glb") == whole
    # and the command: the same file
    out = folder / f"command{section}.glb"
    args = ["restyle", str(folder / "mass.glb"), "--style", str(sheet), "-o", str(out)]
    assert main([*args, "--section", str(section)]) == 0
    assert out.read_bytes() == whole


def test_an_error_in_a_section_points_at_the_file_line(folder, tmp_path):
    text = (folder / "style.bgr").read_text()
    lines = text.split("\n")
    # section 1's first crop file is one that does not exist
    k = next(i for i, line in enumerate(lines) if line.startswith("S1") and "style.assets/" in line)
    at = lines[k].index("style.assets/")
    lines[k] = lines[k][:at] + "style.assets/missing" + lines[k][at + len("style.assets/") :]
    sheet = tmp_path / "style.bgr"
    sheet.write_text("\n".join(lines))
    shutil.copytree(folder / "style.assets", tmp_path / "style.assets")
    assert section_text(sheet.read_text(), 1) is not None
    with pytest.raises(bgr.BgrError) as cut:
        restyle(str(MASS[0]), str(sheet), section=1)
    with pytest.raises(bgr.BgrError) as whole:
        restyle(str(MASS[0]), load(sheet), section=1)
    assert "not found" in cut.value.render() and "missing" in cut.value.render()
    assert cut.value.render() == whole.value.render()
    # the texture() of the Wall rule that read it, at its line in the file
    wall = next(i for i, line in enumerate(lines) if line.startswith("Wall(file) -->"))
    assert cut.value.line == wall + 1


def edited(text: str, old: str, new: str) -> str:
    assert old in text
    return text.replace(old, new, 1)


@pytest.mark.parametrize(
    "edit",
    [
        # Lot's cases by hand: another order
        lambda t: edited(
            t, "case style == 0: S0Lot | else: S1Lot", "case style != 1: S0Lot | else: S1Lot"
        ),
        # a section whose rule calls the other's
        lambda t: edited(t, "S1Lot -->\n", "S1Lot -->\n    case block == 99: S0Building\n    | "),
        # a rule of the user's own added to the header, used by section 1 (kept: it checks)
        lambda t: edited(t, "Wall(file) -->", "Mine --> Plain\nWall(file) -->"),
        # a section marker removed: one building's rules under the other's heading
        lambda t: edited(t, "# ---- ", "# --- "),
    ],
)
def test_a_sheet_edited_by_hand_still_styles_the_mass(folder, tmp_path, edit):
    text = edit((folder / "style.bgr").read_text())
    sheet = tmp_path / "style.bgr"
    sheet.write_text(text)
    shutil.copytree(folder / "style.assets", tmp_path / "style.assets")
    for section in (0, 1):
        expected = styled_bytes(tmp_path, load(sheet), section, "whole.glb")
        assert styled_bytes(tmp_path, str(sheet), section, "cut.glb") == expected


def test_not_a_sheet_of_several_buildings_is_not_cut(folder):
    text = (folder / "style.bgr").read_text()
    assert section_text(text, 2) is None  # no such section: the whole sheet says so
    assert section_text(text, -1) is None
    assert section_text(text.replace("\n", "\r\n"), 0) is None
    one = text.split("# ---- ")[0]  # no section at all
    assert section_text(one, 0) is None
    with pytest.raises(bgr.BgrError, match="--section 2: the style sheet holds no captured"):
        restyle(str(MASS[0]), str(folder / "style.bgr"), section=2)
