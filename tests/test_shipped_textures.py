"""The textures bgr ships (stdlib/textures, drawn by bgr.stdlib.make_textures), the stdlib rules
that use them (stdlib/textured.bgr) and the textured example (issue 26, points 2 and 6).

The committed images must be what the script draws (so they cannot drift from it), repeat without
a seam, and stay small; the example's brick courses must line up across every cut; its GLB and a
normal-mapped one must pass the Khronos validator with no error and no warning.
"""

from __future__ import annotations

import io
import json
import shutil
import struct
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT
from PIL import Image

import bgr
from bgr.stdlib import make_textures as mt

FOLDER = ROOT / "stdlib" / "textures"
EXAMPLE = ROOT / "examples" / "textured_house.bgr"


def committed(name: str) -> np.ndarray:
    with Image.open(FOLDER / f"{name}.png") as im:
        assert im.mode == "RGB" and im.size == (mt.SIZE, mt.SIZE)
        return np.asarray(im)


# ---- the images ------------------------------------------------------------------------------


def test_committed_images_are_what_the_script_draws():
    on_disk = sorted(p.stem for p in FOLDER.glob("*.png"))
    assert on_disk == sorted(mt.TEXTURES), "run python -m bgr.stdlib.make_textures"
    for name in mt.TEXTURES:
        drawn = mt.draw(name)
        assert np.array_equal(committed(name), drawn), f"{name}.png differs from what is drawn"


def test_the_script_writes_the_same_pixels_twice(tmp_path):
    for path in mt.write_all(tmp_path):
        with Image.open(path) as im:
            assert np.array_equal(np.asarray(im), committed(path.stem))


def test_images_repeat_exactly():
    """Drawn from half an image further on, each image is itself rolled: the pattern carries on
    across the right and bottom edges into the next copy, pixel for pixel."""
    for name in mt.TEXTURES:
        base = mt.draw(name)
        for dx, dy in ((mt.SIZE // 2, 0), (0, mt.SIZE // 2), (37, 101)):
            shifted = mt.draw(name, dx, dy)
            assert np.array_equal(shifted, np.roll(base, (-dy, -dx), axis=(0, 1))), (name, dx, dy)


def seam_ratio(pixels: np.ndarray, axis: int) -> float:
    """How much the edge pair (last and first row or column, the pair that meets when the image
    repeats) differs, over the mean difference of neighbouring pairs inside the image."""
    p = pixels.astype(np.float64)
    inside = np.abs(np.diff(p, axis=axis)).mean()
    last, first = np.take(p, -1, axis=axis), np.take(p, 0, axis=axis)
    return float(np.abs(last - first).mean() / max(inside, 1e-9))


def test_edges_continue_like_the_inside():
    """The edge pair differs less than an average neighbouring pair inside (the edges run through
    brick faces and tiles, not joints): measured 0.01 to 0.26."""
    for name in mt.TEXTURES:
        pixels = committed(name)
        for axis in (0, 1):
            assert seam_ratio(pixels, axis) < 1.0, (name, axis, seam_ratio(pixels, axis))
    # the measure does catch a seam: a ramp that does not repeat, and the brick cut short by 8
    # to 24 pixels (the bond no longer meets itself: 1.1 to 7.7)
    ramp = np.repeat(np.linspace(0, 255, 64)[None, :, None], 64, axis=0).repeat(3, axis=2)
    assert seam_ratio(ramp, 1) > 10
    brick = committed("brick")
    for cut in (8, 12, 16, 20, 24):
        assert seam_ratio(brick[:, : mt.SIZE - cut], 1) > 1.0, cut
        assert seam_ratio(brick[: mt.SIZE - cut], 0) > 1.0, cut


def test_images_are_small():
    total = sum(p.stat().st_size for p in FOLDER.glob("*.png"))
    assert total < 400_000, total


def test_brick_normal_map_follows_the_gltf_convention():
    """x right, y up the image, z out, stored (n + 1) / 2: unit vectors; a brick's face looks
    out, its top bevel (just under a bed joint) up, its left bevel (just right of a head joint)
    left.  Bed joints are rows 8-9 of every 16; in odd courses head joints are columns 23-24."""
    n = committed("brick_normal").astype(np.float64) / 127.5 - 1.0
    length = np.sqrt((n * n).sum(axis=-1))
    assert np.abs(length - 1).max() < 0.02 and (n[..., 2] > 0.3).all()
    face, top, left = n[17, 40], n[11, 40], n[17, 25]
    assert face[2] > 0.95
    assert top[1] > 0.3 and abs(top[0]) < 0.15
    assert left[0] < -0.3 and abs(left[1]) < 0.15
    # the colour map agrees: those joints are mortar (light grey), the face brick (red)
    rgb = committed("brick").astype(int)
    assert rgb[9, 40].min() > 140 and rgb[17, 24].min() > 140
    assert rgb[17, 40][0] > rgb[17, 40][2] + 40


def test_textures_ship_with_the_package():
    text = (ROOT / "pyproject.toml").read_text()
    assert '"bgr.stdlib" = ["*.bgr", "textures/*.png"]' in text
    import bgr.stdlib

    assert (Path(bgr.stdlib.__file__).parent / "textures" / "brick.png").is_file()


# ---- stdlib.textured and the example -----------------------------------------------------------


def _world_uv(table, rows):
    """(world point, uv) of the four unit corners of each row (uv-set 0), in bulk."""
    slot = {int(r): k for k, r in enumerate(table.tex_rows)}
    points, uvs = [], []
    for r in rows:
        m = table.tex_uv[slot[int(r)], 0]
        for cx, cy in ((0, 0), (1, 0), (0, 1), (1, 1)):
            unit = np.array([cx, cy, 0.0])
            points.append(table.origin[r] + (unit * table.size[r]) @ table.axes[r])
            uvs.append(m[:, :3] @ unit + m[:, 3])
    return np.array(points), np.array(uvs)


@pytest.fixture(scope="module")
def house():
    return bgr.derive(EXAMPLE, seed=3)


def image_rows(table, stem: str) -> np.ndarray:
    index = [k for k, im in enumerate(table.images) if Path(im.path).stem == stem]
    assert index, f"no {stem} image"
    return table.tex_rows[table.tex_maps[:, 0] == index[0]]


def test_example_brick_courses_line_up_across_every_cut(house):
    """Every brick piece of the street front (walls beside, between, above and below the windows
    of every floor) takes its texture coordinates from one affine map of world points: the
    projection set up on the whole front, so the courses run on across all the cuts."""
    table = house.terminals.freeze()
    brick = image_rows(table, "brick")
    front = [r for r in brick if "/Front." in table.path[r]]
    assert len(front) > 20
    points, uvs = _world_uv(table, front)
    design = np.hstack([points, np.ones((len(points), 1))])
    fit, *_ = np.linalg.lstsq(design, uvs, rcond=None)
    assert np.abs(design @ fit - uvs).max() < 1e-9
    # about 2 m x 1.2 m a tile: u grows 1 per ~2 m along the front, v 1 per ~1.2 m up
    assert 1.8 < 1 / np.linalg.norm(fit[:3, 0]) < 2.2
    assert 1.1 < 1 / np.linalg.norm(fit[:3, 1]) < 1.3
    assert fit[1, 1] > 0  # v runs up (world y)


def test_example_windows_stretch_their_image_once(house):
    table = house.terminals.freeze()
    rows = image_rows(table, "window")
    assert len(rows) >= 8
    _, uvs = _world_uv(table, rows)
    corners = uvs.reshape(len(rows), 4, 2)
    np.testing.assert_allclose(corners.min(axis=1), 0, atol=1e-9)
    np.testing.assert_allclose(corners.max(axis=1), 1, atol=1e-9)


def test_example_roof_rows_run_along_the_eaves(house):
    """On each roof plane v grows up the slope (world y) and u does not change with height."""
    table = house.terminals.freeze()
    rows = image_rows(table, "roof_tiles")
    assert len(rows) >= 2
    slot = {int(r): k for k, r in enumerate(table.tex_rows)}
    for r in rows:
        m = table.tex_uv[slot[int(r)], 0]
        # the map from world points: unit maps divided back by the scope (M_unit = L A^T S)
        lin = m[:, :3] / np.where(table.size[r] > 0, table.size[r], 1.0)
        world = lin @ table.axes[r]  # (2, 3): du/dworld, dv/dworld
        assert world[1, 1] > 0.1, "v must grow up the slope"
        assert abs(world[0, 1]) < 1e-9, "u must not change with height"


def glb_json(path: Path) -> dict:
    data = path.read_bytes()
    (length,) = struct.unpack_from("<I", data, 12)
    return json.loads(data[20 : 20 + length])


def test_example_glb_embeds_each_image_once_and_trimesh_sees_the_textures(house, tmp_path):
    import trimesh

    from bgr.formats import write

    path = tmp_path / "house.glb"
    write(house.terminals, path, seed=3, attrs=house.attrs)
    doc = glb_json(path)
    assert len(doc["images"]) == 5  # brick, its normal map, render, window, roof tiles
    normal = [m for m in doc["materials"] if "normalTexture" in m]
    assert normal and all(m["normalTexture"]["texCoord"] == 1 for m in normal)
    scene = trimesh.load(path, process=False)
    textured = [
        g
        for g in scene.geometry.values()
        if getattr(g.visual, "uv", None) is not None
        and getattr(g.visual.material, "baseColorTexture", None) is not None
    ]
    assert textured
    sizes = {g.visual.material.baseColorTexture.size for g in textured}
    assert sizes == {(mt.SIZE, mt.SIZE)}


def _validator():
    node = shutil.which("node")
    modules = ROOT / "tests" / "gltf_validator" / "node_modules" / "gltf-validator"
    if node is None or not modules.is_dir():
        pytest.skip("the Khronos glTF validator is not installed (test_gltf_validator installs it)")
    return Path(node)


def test_example_and_a_normal_mapped_facade_validate(house, tmp_path):
    """The textured example, and a façade with a normal map whose coordinates are its own
    (uv-set 5 scaled apart from the colour map's): the material's normalTexture names
    TEXCOORD_1, the primitive has it, and the validator reports no error and no warning."""
    from test_gltf_validator import clean, validate

    from bgr.formats import write

    node = _validator()
    (tmp_path / "b.png").write_bytes((FOLDER / "brick.png").read_bytes())
    (tmp_path / "n.png").write_bytes((FOLDER / "brick_normal.png").read_bytes())
    grammar = tmp_path / "n.bgr"
    grammar.write_text(
        "version 1\nterminal Tile\n"
        "Lot --> s(4, 0, 1) extrude(3) comp(f) { front: Facade | all: NIL }\n"
        "Facade --> setupProjection(0, scope.xy, ~2, ~1.2) setupProjection(5, scope.xy, 1, 1)\n"
        '  texture("b.png") normalMap("n.png") projectUV(0) projectUV(5) scaleUV(5, 2, 2)\n'
        "  split(x) { ~1: Tile }*\n"
    )
    facade = bgr.derive(grammar, seed=0)
    paths = {"house.glb": house, "normal.glb": facade, "normal.gltf": facade}
    for name, result in paths.items():
        write(result.terminals, tmp_path / name, seed=0, attrs=result.attrs)
    doc = glb_json(tmp_path / "normal.glb")
    (material,) = [m for m in doc["materials"] if "normalTexture" in m]
    assert material["normalTexture"]["texCoord"] == 1
    assert "baseColorTexture" in material["pbrMetallicRoughness"]
    prims = [p for mesh in doc["meshes"] for p in mesh["primitives"]]
    assert prims and all({"TEXCOORD_0", "TEXCOORD_1"} <= set(p["attributes"]) for p in prims)
    # uv-set 5 was scaled by 2 after projecting 1 x 1 m tiles: its coordinates span twice the
    # metres, the colour map's 4 m / 2 m = 2 tiles across
    bin_start = 20 + struct.unpack_from("<I", (tmp_path / "normal.glb").read_bytes(), 12)[0] + 8
    data = (tmp_path / "normal.glb").read_bytes()

    def accessor(index: int, width: int = 2) -> np.ndarray:
        acc = doc["accessors"][index]
        view = doc["bufferViews"][acc["bufferView"]]
        start = bin_start + view.get("byteOffset", 0)
        return np.frombuffer(data[start : start + view["byteLength"]], "<f4").reshape(-1, width)

    uv0 = np.vstack([accessor(p["attributes"]["TEXCOORD_0"]) for p in prims])
    uv1 = np.vstack([accessor(p["attributes"]["TEXCOORD_1"]) for p in prims])
    assert np.ptp(uv0[:, 0]) == pytest.approx(2.0, abs=1e-5)
    assert np.ptp(uv1[:, 0]) == pytest.approx(8.0, abs=1e-5)
    assert np.ptp(uv1[:, 1]) == pytest.approx(6.0, abs=1e-5)
    # a TANGENT per corner for the normal map: along the façade, the way u grows (its scope x:
    # the front face looks down -z, so its x, rightwards seen from outside, is world -x), and
    # w = +1 as cross(normal, tangent) = (0, 0, -1) x (-1, 0, 0) = +y is the way v grows
    tangent = np.vstack([accessor(p["attributes"]["TANGENT"], 4) for p in prims])
    expected = np.tile([-1.0, 0.0, 0.0, 1.0], (len(tangent), 1))
    np.testing.assert_allclose(tangent, expected, atol=1e-6)
    reports = validate(node, [tmp_path / n for n in paths])
    for name in paths:
        report = reports[str(tmp_path / name)]
        assert report["errors"] == 0 and report["warnings"] == 0, f"{name}:\n{clean(report)}"


def test_every_textured_stdlib_rule_derives_with_its_images(tmp_path):
    """Each public rule of stdlib.textured on a wall (with the projection a caller sets up) or on
    a top face (the roofs) gives textured terminals; the images are the shipped files."""
    from bgr.grammar.stdlib_reference import public_rules

    _, rules = public_rules("textured")
    names = [r.name for r, _ in rules]
    assert {"Brick", "Render", "RoofTiles", "Glazed", "Facade", "Gable"} <= set(names)
    lines = ["import stdlib.textured as tx"]
    for name in names:
        if name == "Gable":
            lines.append(
                f"T_{name} --> s(10, 0, 8) extrude(6) comp(f) {{ top: tx.{name} | all: NIL }}"
            )
        else:
            lines.append(
                f"T_{name} --> s(12, 0, 1) extrude(10) comp(f) {{ front: "
                f"setupProjection(0, scope.xy, ~2, ~1.2) tx.{name} | all: NIL }}"
            )
    grammar = bgr.load("\n".join(lines) + "\n", path=tmp_path / "wrap.bgr")
    for name in names:
        table = bgr.derive(grammar, seed=1, start=f"T_{name}").terminals.freeze()
        assert len(table.tex_rows) > 0, name
        for im in table.images:
            assert Path(im.path).parent == FOLDER.resolve(), (name, im.path)
            with Image.open(io.BytesIO(im.data)) as decoded:
                assert decoded.size == (mt.SIZE, mt.SIZE)


def test_stdlib_textures_resolve_from_any_working_folder(tmp_path, monkeypatch):
    """A stdlib module's texture paths start from the stdlib's real folder, not from the name
    messages show for it (stdlib/textured.bgr, which resolved from the working folder)."""
    monkeypatch.chdir(tmp_path)
    table = bgr.derive(EXAMPLE, seed=3).terminals
    assert {Path(im.path).name for im in table.images} == {f"{n}.png" for n in mt.TEXTURES}
