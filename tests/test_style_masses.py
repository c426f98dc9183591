"""bgr restyle on the three target masses of examples/style/ (issue 27), with style sheets captured
from the synthetic buildings of tests/style_synth.py: a mass of one block takes every source
block stacked, recesses stay inside the mass (an L's arms included), and wall bands keep the
texture's density on a face wider than the source's."""

import re
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT
from style_checks import bounds, outside, share_below, wall_cover
from style_synth import PX_PER_M, make_building

from bgr.cli import main
from bgr.formats.gltf_textured import read_gltf_textured
from bgr.inverse.style.restyle import restyle, thinnest

pytestmark = pytest.mark.xdist_group("style_masses")  # one worker: the sheets are made once

MASSES = ROOT / "examples" / "style"


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("masses")


class Sheets(dict):
    """Style sheets of the synthetic buildings, each captured from its GLB by bgr infer on first
    use: the podium and tower (1), the wedding cake (2), the L on a podium (4)."""

    def __init__(self, folder: Path) -> None:
        super().__init__()
        self.folder = folder

    def __missing__(self, kind: int) -> Path:
        glb, _ = make_building(kind, self.folder / "synth")
        out = self.folder / f"k{kind}.bgr"
        assert main(["infer", str(glb), "--kind", "style", "-o", str(out)]) == 0
        self[kind] = out
        return out


@pytest.fixture(scope="module")
def sheets(folder: Path) -> Sheets:
    return Sheets(folder)


def mass(folder: Path, name: str, *extra: str) -> Path:
    """examples/style/NAME.bgr derived to a GLB (``extra``: --set NAME=VALUE, --lot)."""
    tag = "".join(f"_{e.replace('=', '')}" for e in extra if "=" in e)
    out = folder / f"{name}{tag}.glb"
    if not out.exists():
        assert main(["derive", str(MASSES / f"{name}.bgr"), *extra, "-o", str(out)]) == 0
    return out


REPORTS: dict[Path, str] = {}


def styled(folder: Path, target: Path, sheet: Path) -> tuple[Path, str]:
    """bgr restyle TARGET --style SHEET, once a pair."""
    out = folder / f"{sheet.stem}_on_{target.stem}.glb"
    if out not in REPORTS:
        result, REPORTS[out] = restyle(str(target), str(sheet))
        result.save(out)
    return out, REPORTS[out]


def roof_colour(sheet: Path) -> np.ndarray:
    """The sheet's Roof colour (the source roof's, captured; inverse/style/emit.py), 0 .. 1."""
    found = re.search(r'^Roof --> color\("#([0-9a-f]{6})"\)', sheet.read_text(), re.M)
    assert found, "the sheet has no Roof rule"
    return np.array([int(found[1][k : k + 2], 16) for k in (0, 2, 4)]) / 255


def roof_heights(path: Path, sheet: Path) -> list[float]:
    """The heights of the upward faces in the sheet's roof colour: each block mass's top."""
    mesh = read_gltf_textured(path)
    corners = mesh.vertices[mesh.faces]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    up = normal[:, 1] > 0.99 * np.linalg.norm(normal, axis=1)
    colours = np.array([m.color[:3] for m in mesh.materials])
    roof = np.abs(colours[mesh.material] - roof_colour(sheet)).max(axis=1) < 0.01
    return sorted({round(float(y), 3) for y in corners[up & roof][:, 0, 1]})


# wedding_cake: blocks of 3 x 4, 4 x 3.5 and 3 x 3 m storeys (12, 14 and 9 m, 35 m in all);
# podium_tower: 4.5 + 3.5 m under 8 x 3 m (8 and 24 m)
@pytest.mark.parametrize(
    ("kind", "height", "roofs"),
    [
        # the bottom and top blocks keep 12 and 9 m
        pytest.param(2, 60, [12.0, 51.0, 60.0], marks=pytest.mark.slow),
        (1, 60, [8.0, 60.0]),  # two blocks: the podium keeps 8 m, the tower stretches
        # lower than 12 + 9 m: every block at its share of 35 m
        pytest.param(
            2, 15, [round(15 * 12 / 35, 3), round(15 * 26 / 35, 3), 15.0], marks=pytest.mark.slow
        ),
    ],
)
def test_a_mass_of_one_block_takes_every_source_block_stacked(
    folder: Path, sheets: Sheets, kind: int, height: int, roofs: list[float]
) -> None:
    slab = mass(folder, "slab", "--set", f"height={height}")
    out, report = styled(folder, slab, sheets[kind])
    assert report.startswith("1 blocks styled by source blocks (0<-all)")
    assert roof_heights(out, sheets[kind]) == pytest.approx(roofs, abs=1e-3)
    assert np.allclose(bounds(out), bounds(slab), atol=0.05)


@pytest.mark.slow
def test_a_mass_of_two_blocks_takes_the_bottom_and_top_blocks(folder: Path, sheets: Sheets) -> None:
    """Equations 6-7's forced matches: the podium takes block 0, the tower the top block 2."""
    out, report = styled(folder, mass(folder, "two_stack"), sheets[2])
    assert "(0<-0, 1<-2)" in report
    assert roof_heights(out, sheets[2]) == pytest.approx([15.0, 65.0])


@pytest.mark.parametrize(
    ("kind", "target"),
    [
        (4, "l_block"),
        *(pytest.param(4, t, marks=pytest.mark.slow) for t in ("slab", "two_stack")),
        *(pytest.param(2, t, marks=pytest.mark.slow) for t in ("slab", "l_block", "two_stack")),
    ],
)
def test_the_styled_model_keeps_the_mass_and_images_cover_its_walls(
    folder: Path, sheets: Sheets, target: str, kind: int
) -> None:
    """The L on a podium (4) has recessed faces (its box's walls at the L's inner corner, 55 %
    of the block deep); on a 12 m slab or the L of examples/style their reveals stay inside."""
    lot = ("--lot", str(MASSES / "lot.geojson")) if target == "l_block" else ()
    plain = mass(folder, target, *lot)
    out, _ = styled(folder, plain, sheets[kind])
    assert np.allclose(bounds(out), bounds(plain), atol=0.05)
    assert len(outside(plain, out, tol=0.05)) == 0
    cover = wall_cover(plain, out)
    assert min(cover.values()) > 0.99, cover


def test_wall_bands_keep_the_texture_density_on_a_wider_face(folder: Path, sheets: Sheets) -> None:
    """The podium and tower's 18 m tower front on a 72 m slab: cut at the window columns, the
    bands between window rows repeat with them at the source's 40 px/m (at most 512 px a crop:
    a whole-width band of the tower, 720 px, was 512 px over 72 m, 7 px/m)."""
    slab = mass(folder, "slab", "--set", "length=72")
    out, _ = styled(folder, slab, sheets[1])
    assert share_below(out, PX_PER_M / 2) < 0.02


def test_thinnest_part_of_a_footprint() -> None:
    rectangle = np.array([(0, 0), (30, 0), (30, 12), (0, 12)], float)
    assert thinnest(rectangle) == pytest.approx((1.0, 1.0))
    # examples/style/l_block.bgr's footprint(L, 0.4, 0.5) on its 24 x 16 m lot: the wing is
    # 0.4 x 24 = 9.6 m wide (of 24 along x), the bar 0.5 x 16 = 8 m deep (of 16 along z)
    ell = np.array([(0, 0), (24, 0), (24, 8), (9.6, 8), (9.6, 16), (0, 16)], float)
    assert thinnest(ell) == pytest.approx((0.4, 0.5))
    assert thinnest(ell[::-1]) == pytest.approx((0.4, 0.5))  # either orientation


def fitted(scalable: tuple, insertable: tuple, width: float) -> list[tuple[str, float]]:
    """(piece, width) of the pieces a group's rule (emit_splits.py: its Split rule, or a repeat
    when it has no window) cuts a lot ``width`` wide into: W0, W1 .. the walls, B0 .. the
    windows, each named by its crop."""
    import io
    import json

    import bgr
    from bgr.formats import write_json
    from bgr.inverse.style.emit_splits import group_body, split_rules

    walls = [f"W{i}" for i in range(len(scalable))]
    windows = [f"B{i}" for i in range(len(insertable))]
    names = walls + windows
    pick = " | ".join(f'case f == "{t}": {t}' for t in names[:-1]) + f" | else: {names[-1]}"
    args = [f'"{t}"' for t in names] + ["1"]
    src = [
        "version 1",
        f"terminal {', '.join(names)}",
        f"Lot --> {group_body('x', scalable, insertable, args)}",
        f"Wall(f) --> {pick}" if len(names) > 1 else f"Wall(f) --> {names[0]}",
        "Bay(w, f) --> Wall(f)",
    ]
    if insertable:
        src += split_rules("x", len(insertable))
    result = bgr.derive(bgr.load("\n".join(src) + "\n"), lot=(width, 5.0))
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=result.seed, attrs=result.attrs)
    out = json.loads(buffer.getvalue())["terminals"]
    return [(t["label"], round(t["size"][0], 4)) for t in out if t["size"][0] > 1e-9]


@pytest.mark.parametrize(
    ("width", "expected"),
    [
        # the source's own width: equations 8-9 as printed, Sr = 1
        (13, [("W0", 0.5), ("B0", 12), ("W1", 0.5)]),
        # Sr = (24 - 12) / (0.5 + 0.5 + 0.5) = 8 > MAX_SR: two patterns, each piece x 24 / 26
        (24, [("W0", 0.4615), ("B0", 11.0769), ("W1", 0.4615)] * 2),
        # x = 0, y = 0 (12 m does not fit in 5): one pattern x 5 / 13, not a1 over 5 m
        (5, [("W0", 0.1923), ("B0", 4.6154), ("W1", 0.1923)]),
        # x = 2, y = 0, Sr = (29 - 2 x 12) / (2 x 1 + 0.5) = 2, not above MAX_SR: equation 9
        (29, [("W0", 1), ("B0", 12), ("W1", 1)] * 2 + [("W0", 1)]),
    ],
)
def test_a_face_far_from_whole_patterns_scales_the_pattern_alike(
    width: float, expected: list[tuple[str, float]]
) -> None:
    """A = (0.5, 0.5), B = (12,): PLATEAU's atlases give such rules (a whole wall a 'window')."""
    assert fitted((0.5, 0.5), (12.0,), width) == expected  # both rounded to 0.1 mm


def test_a_rule_with_no_insertable_repeats_its_piece() -> None:
    """m = 0: a 2 m plain piece on 9 m repeats 5 times (1.8 m each, scale 0.9, nearer 1 than
    4 times 2.25 m), where equations 8-9 stretch one piece over 9 m."""
    assert fitted((2.0,), (), 9) == [("W0", 1.8)] * 5
