"""envelope() (CGA's building envelope) and split() of mesh solids, which it needs: the volume
checked against the planes' own arithmetic, closed, and derived on by comp(f) and split()."""

import pytest
import trimesh

import bgr
from bgr.grammar.errors import BgrError


def mesh(src: str, lot=(20, 30)) -> trimesh.Trimesh:
    result = bgr.derive(bgr.load(src), lot=lot)
    return result.mesh


def volume_of(src: str, lot=(20, 30)) -> float:
    m = mesh(src, lot)
    assert m.is_watertight
    return float(m.volume)


def test_right_angles_give_the_prism():
    src = "Lot --> envelope(world.up, 24, 0, 90) V\nterminal V\n"
    assert volume_of(src) == pytest.approx(20 * 30 * 24)


def test_a_front_plane_at_45_degrees():
    # from the street edge the height rises one metre per metre, to the 24 m ceiling:
    # 20 * (24 * 24 / 2 + 24 * 6)
    src = "Lot --> envelope(world.up, 24, 0, 45, 0, 90, 0, 90) V\nterminal V\n"
    assert volume_of(src) == pytest.approx(20 * (24 * 24 / 2 + 24 * 6))


def test_base_height_then_slope_on_every_side():
    # the reference's form (maxHeight, front, back, sides): 10 m walls with 45-degree planes
    # above them on all four sides, no ceiling reached: a hip roof on a 10 m box, whose volume
    # over a x b (a <= b) at slope 1 is a^2 (3b - a) / 12
    src = "Lot --> envelope(world.up, 100, 10, 45, 10, 45, 10, 45) V\nterminal V\n"
    assert volume_of(src) == pytest.approx(20 * 30 * 10 + 20**2 * (3 * 30 - 20) / 12)


def test_each_side_its_own_base_height_and_angle():
    # front 4 m at 90 (a wall), back 8 m then 45 degrees, sides 90: a shed-like cut from the
    # back, under a 12 m ceiling; the back plane reaches 12 m 4 m in from the back edge
    src = "Lot --> envelope(world.up, 12, 12, 90, 8, 45, 0, 90) V\nterminal V\n"
    assert volume_of(src) == pytest.approx(20 * (12 * 26 + (8 + 12) / 2 * 4))


def test_the_ceiling_seals_the_volume():
    src = "Lot --> envelope(world.up, 12, 10, 45, 10, 45, 10, 45) V\nterminal V\n"
    m = mesh(src)
    assert m.bounds[1][1] == pytest.approx(12)
    assert m.is_watertight


def test_it_derives_on_comp_and_split():
    src = (
        "Lot --> envelope(world.up, 18, 9, 45, 9, 45, 9, 45) comp(f) { aslant: Slope | side: Wall "
        "| top: Top }\nWall --> split(y) { 3: Floor }*\nterminal Slope, Floor, Top\n"
    )
    result = bgr.derive(bgr.load(src), lot=(20, 30))
    labels = [t for t in result.terminals.label]
    assert labels.count("Slope") == 4 and labels.count("Top") == 1
    assert labels.count("Floor") == 4 * 3  # 9 m walls in 3 m floors


def test_a_solid_splits_into_slabs():
    # an open roof cut into slabs along x: the pieces keep its surface, with no caps added
    src = "Lot --> roof(hip, 45) split(x) { ~2: R }*\nterminal R\n"
    whole = mesh("Lot --> roof(hip, 45) R\nterminal R\n", lot=(12, 8)).area
    assert len(bgr.derive(bgr.load(src), lot=(12, 8)).terminals.label) == 6
    assert mesh(src, lot=(12, 8)).area == pytest.approx(whole, rel=1e-6)
    # a closed solid's slabs are closed again: their volumes add up to the whole's
    env = "Lot --> envelope(world.up, 30, 6, 45, 6, 45, 6, 45) {}\nterminal B\n"
    whole = volume_of(env.format("B"))
    pieces = bgr.derive(bgr.load(env.format("split(x) { ~3: B }*")), lot=(20, 30)).mesh
    assert pieces.volume == pytest.approx(whole, rel=1e-6)


def test_bad_arguments_are_errors():
    with pytest.raises(BgrError, match="envelope"):
        bgr.derive(bgr.load("Lot --> envelope(world.up, 20, 5) V\nterminal V\n"), lot=(10, 10))
