"""Textures (issue 26): CGA's setupProjection / projectUV / texture / *UV operations, checked
against texture coordinates computed by hand, and the textured GLB round trip.

Every case derives a façade of known size whose terminals are unit squares or rectangles; the
texture coordinates of a terminal's unit-scope corner (cx, cy) are ``M @ [cx, cy, 0, 1]`` with
M the terminal's map in the frozen table (``tex_uv``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import bgr


@pytest.fixture
def folder(tmp_path):
    """A folder with an 8x8 PNG whose four quadrants are red, green, blue and yellow (rows from
    the top: red | green over blue | yellow)."""
    pixels = np.zeros((8, 8, 3), np.uint8)
    pixels[:4, :4], pixels[:4, 4:] = (255, 0, 0), (0, 255, 0)
    pixels[4:, :4], pixels[4:, 4:] = (0, 0, 255), (255, 255, 0)
    Image.fromarray(pixels).save(tmp_path / "quad.png")
    return tmp_path


def derive(folder, body: str, seed: int = 0):
    """Derive a grammar (``body`` the rules after a 3 m x 2 m façade facing +z at the origin,
    its scope x along world x and y up) and return its frozen terminal table."""
    path = folder / "t.bgr"
    path.write_text(
        "version 1\nstart Lot\nterminal Tile\n"
        "Lot --> s(3, 0, 2) r(0, 0, 0) extrude(2) comp(f) { back: Facade }\n" + body
    )
    return bgr.derive(path, seed=seed).terminals.freeze()


def uv_at(table, row: int, cx: float, cy: float, which: int = 0) -> np.ndarray:
    k = int(np.flatnonzero(table.tex_rows == row)[0])
    m = table.tex_uv[k, which]
    return m[:, :3] @ np.array([cx, cy, 0.0]) + m[:, 3]


def world_at(table, row: int, cx: float, cy: float) -> np.ndarray:
    return table.origin[row] + np.array([cx, cy, 0.0]) * table.size[row] @ table.axes[row]


def corners_by_world(table):
    """Every terminal's four corners: (world point rounded, uv) pairs."""
    out = []
    for row in range(len(table)):
        for cx in (0.0, 1.0):
            for cy in (0.0, 1.0):
                key = tuple(np.round(world_at(table, row, cx, cy), 9))
                out.append((key, uv_at(table, row, cx, cy)))
    return out


def test_facade_tiles_are_continuous_across_every_cut(folder):
    # CGA's standard façade: setupProjection on the façade, then floors and tiles split off
    t = derive(
        folder,
        'Facade --> setupProjection(0, scope.xy, ~1.5, 1) texture("quad.png") projectUV(0)\n'
        "  split(y) { 1: Floor | 1: Floor }\n"
        "Floor --> split(x) { 1: Tile | 1.2: Tile | 0.8: Tile }\n",
    )
    assert len(t) == 6
    seen: dict = {}
    for key, uv in corners_by_world(t):
        if key in seen:  # a corner shared by neighbouring tiles has one texture coordinate
            np.testing.assert_allclose(uv, seen[key], atol=1e-12)
        seen[key] = uv
    # the façade's back face: width 3 along its scope x, ~1.5 is exactly 1.5 (two tiles)
    facade_x = t.axes[0][0]
    start = min((world_at(t, r, 0, 0) @ facade_x, r) for r in range(len(t)))[1]
    np.testing.assert_allclose(uv_at(t, start, 0, 0), [0, 0], atol=1e-12)
    np.testing.assert_allclose(uv_at(t, start, 1, 1), [1 / 1.5, 1], atol=1e-12)


def test_relative_one_stretches_the_image_once(folder):
    t = derive(
        folder,
        "Facade --> setupProjection(0, scope.xy, '1, '1) texture(\"quad.png\") projectUV(0)\n"
        "  split(x) { '0.5: Tile | '0.5: Tile }\n",
    )
    left = min(range(2), key=lambda r: world_at(t, r, 0, 0) @ t.axes[r][0])
    right = 1 - left
    np.testing.assert_allclose(uv_at(t, left, 0, 0), [0, 0], atol=1e-12)
    np.testing.assert_allclose(uv_at(t, left, 1, 1), [0.5, 1], atol=1e-12)
    np.testing.assert_allclose(uv_at(t, right, 1, 1), [1, 1], atol=1e-12)


def test_floating_size_tiles_a_whole_number_of_times(folder):
    # 3 m with ~1.4: round(3 / 1.4) = 2 tiles of 1.5 m; with ~0.7: 4 tiles of 0.75 m
    for w, tiles in ((1.4, 2), (0.7, 4), (5.0, 1)):
        t = derive(
            folder,
            f'Facade --> setupProjection(0, scope.xy, ~{w}, 2) texture("quad.png") projectUV(0)'
            "\n  Tile\n",
        )
        np.testing.assert_allclose(uv_at(t, 0, 1, 1), [tiles, 1], atol=1e-12)


def test_negative_sizes_mirror(folder):
    t = derive(
        folder,
        'Facade --> setupProjection(0, scope.xy, -1.5, 2) texture("quad.png") projectUV(0) Tile\n',
    )
    np.testing.assert_allclose(uv_at(t, 0, 0, 0), [0, 0], atol=1e-12)
    np.testing.assert_allclose(uv_at(t, 0, 1, 1), [-2, 1], atol=1e-12)


def test_offsets_and_uw_factor(folder):
    t = derive(
        folder,
        'Facade --> setupProjection(0, scope.xy, 1.5, 2, 0.75, 1) texture("quad.png")\n'
        "  projectUV(0) Tile\n",
    )
    # u = (x + 0.75) / 1.5, v = (y + 1) / 2
    np.testing.assert_allclose(uv_at(t, 0, 0, 0), [0.5, 0.5], atol=1e-12)
    np.testing.assert_allclose(uv_at(t, 0, 1, 1), [2.5, 1.5], atol=1e-12)


def test_world_xy(folder):
    # the façade's back face runs from world x = 3 to 0 (its scope x is world -x), y 0..2
    t = derive(
        folder,
        'Facade --> setupProjection(0, world.xy, 2, 4) texture("quad.png") projectUV(0) Tile\n',
    )
    for cx in (0.0, 1.0):
        for cy in (0.0, 1.0):
            x, y, _ = world_at(t, 0, cx, cy)
            np.testing.assert_allclose(uv_at(t, 0, cx, cy), [x / 2, y / 4], atol=1e-12)
    assert {round(world_at(t, 0, c, 0)[0], 9) for c in (0.0, 1.0)} == {0.0, 3.0}


def test_tile_uv(folder):
    # projected once over the façade ('1), then tiled 1 m x 0.5 m: u = x / 1, v = y / 0.5
    t = derive(
        folder,
        "Facade --> setupProjection(0, scope.xy, '1, '1) projectUV(0) tileUV(0, 1, 0.5)\n"
        '  texture("quad.png") Tile\n',
    )
    np.testing.assert_allclose(uv_at(t, 0, 1, 1), [3, 4], atol=1e-12)
    # ~1.4 over 3 m: 2 tiles; '0.25 of 2 m: 4 tiles; 0 keeps v
    t = derive(
        folder,
        "Facade --> setupProjection(0, scope.xy, 1, 1) projectUV(0) tileUV(0, ~1.4, 0)\n"
        '  texture("quad.png") Tile\n',
    )
    np.testing.assert_allclose(uv_at(t, 0, 1, 1), [2, 2], atol=1e-12)
    t = derive(
        folder,
        "Facade --> setupProjection(0, scope.xy, 1, 1) projectUV(0) tileUV(0, 0, '0.25)\n"
        '  texture("quad.png") Tile\n',
    )
    np.testing.assert_allclose(uv_at(t, 0, 1, 1), [3, 4], atol=1e-12)


def test_rotate_scale_translate_normalize(folder):
    base = "Facade --> setupProjection(0, scope.xy, 1, 1) projectUV(0) "
    # rotateUV(0, 90): (u, v) -> (-v, u); the corner (3, 2) goes to (-2, 3)
    t = derive(folder, base + 'rotateUV(0, 90) texture("quad.png") Tile\n')
    np.testing.assert_allclose(uv_at(t, 0, 1, 1), [-2, 3], atol=1e-12)
    np.testing.assert_allclose(uv_at(t, 0, 1, 0), [0, 3], atol=1e-12)
    t = derive(
        folder, base + 'scaleUV(0, 2, 0.5) translateUV(0, 0.5, 1) texture("quad.png") Tile\n'
    )
    np.testing.assert_allclose(uv_at(t, 0, 1, 1), [6.5, 2], atol=1e-12)
    t = derive(folder, base + 'translateUV(0, 7, 7) normalizeUV(0, uv) texture("quad.png") Tile\n')
    np.testing.assert_allclose(uv_at(t, 0, 1, 1), [1, 1], atol=1e-12)
    np.testing.assert_allclose(uv_at(t, 0, 0, 0), [0, 0], atol=1e-12)
    t = derive(folder, base + 'normalizeUV(0, uvUniform) texture("quad.png") Tile\n')
    np.testing.assert_allclose(uv_at(t, 0, 1, 1), [1, 2 / 3], atol=1e-12)


def test_projection_follows_a_moved_shape(folder):
    # set up on the façade, then the shape moves 1 m along x and turns a quarter: the texture
    # sticks to the geometry, so every corner keeps the uv it had where the projection was set
    t = derive(
        folder,
        "Facade --> setupProjection(0, scope.xy, 1, 1) t(1, 0, 0) r(0, 0, 90) s(6, '1, 0)\n"
        '  projectUV(0) texture("quad.png") Tile\n',
    )
    np.testing.assert_allclose(uv_at(t, 0, 0, 0), [0, 0], atol=1e-12)
    np.testing.assert_allclose(uv_at(t, 0, 1, 0), [3, 0], atol=1e-12)  # s() stretched it
    np.testing.assert_allclose(uv_at(t, 0, 1, 1), [3, 2], atol=1e-12)
    assert np.allclose(t.axes[0][0], [0, 1, 0])  # it did turn: its x is world up


def test_untextured_shapes_carry_nothing(folder):
    t = derive(folder, "Facade --> setupProjection(0, scope.xy, 1, 1) projectUV(0) Tile\n")
    assert len(t.tex_rows) == 0 and t.images == []


@pytest.mark.parametrize(
    "body, message",
    [
        ('Facade --> texture("missing.png") Tile\n', "texture file 'missing.png' not found"),
        ('Facade --> texture("t.bgr") Tile\n', "is not a readable image"),
        ("Facade --> setupProjection(0, scope.ab, 1, 1) Tile\n", "unknown projection axes"),
        ("Facade --> tileUV(0, ~1, 1) t(~1, 0, 0) Tile\n", "floating size (~w) is not allowed"),
    ],
)
def test_bad_input_is_a_located_check_error(folder, body, message):
    with pytest.raises(bgr.BgrError) as e:
        derive(folder, body)
    assert message in e.value.render()
    assert e.value.line == 5


@pytest.mark.parametrize(
    "body, message",
    [
        ('Facade --> texture("miss" + "ing.png") Tile\n', "not found"),
        ("Facade --> projectUV(0) Tile\n", "projectUV(0) has no projection"),
        ("Facade --> setupProjection(10, scope.xy, 1, 1) Tile\n", "uv-set number 0..9"),
        ("Facade --> setupProjection(0, scope.xy, 0, 1) Tile\n", "other than 0"),
        ("Facade --> rotateUV(0, 10) Tile\n", "needs the texture coordinates of uv-set 0"),
    ],
)
def test_bad_values_are_located_derive_errors(folder, body, message):
    with pytest.raises(bgr.BgrError) as e:
        derive(folder, body)
    assert message in e.value.render()
    assert e.value.line == 5


TEXTURED_FACADE = (
    "Facade --> setupProjection(0, scope.xy, '1, '1) texture(\"quad.png\") projectUV(0)\n"
    "  split(y) { '0.5: Row | '0.5: Row }\n"
    "Row --> split(x) { '0.5: Tile | '0.5: Tile }\n"
)


def test_glb_embeds_the_image_once_and_samples_it_the_cga_way_up(folder):
    import trimesh

    from bgr.formats import write

    table = derive(folder, TEXTURED_FACADE)
    path = folder / "t.glb"
    write(table, path, seed=0, attrs={})
    scene = trimesh.load(path, process=False)
    (mesh,) = scene.geometry.values()
    image = mesh.visual.material.baseColorTexture
    assert image.size == (8, 8)
    # the bottom-left tile of the façade (CGA uv 0..0.5 both ways) shows the image's
    # bottom-left quadrant, blue: trimesh reads glTF's flipped v back to CGA's way up
    uv = mesh.visual.uv
    centre = mesh.triangles_center
    facade_x = table.axes[0][0]
    along = centre @ facade_x
    low = (centre[:, 1] < 1.0) & (along < along.min() + 1.5 - 1e-9)
    assert low.any()
    for face in np.flatnonzero(low):
        u, v = uv[mesh.faces[face]].mean(axis=0)
        assert 0 < u < 0.5 and 0 < v < 0.5
        pixel = image.convert("RGB").getpixel((int(u * 8), int((1 - v) * 8)))
        assert pixel == (0, 0, 255)


def test_textured_glb_validates(folder):
    import shutil

    from test_gltf_validator import clean, validate

    from bgr.formats import write

    node = shutil.which("node")
    modules = Path(__file__).parent / "gltf_validator" / "node_modules" / "gltf-validator"
    if node is None or not modules.is_dir():
        pytest.skip("the Khronos glTF validator is not installed (test_gltf_validator installs it)")
    table = derive(folder, TEXTURED_FACADE)
    paths = [folder / "t.glb", folder / "t.gltf"]
    for path in paths:
        write(table, path, seed=0, attrs={})
    reports = validate(Path(node), paths)
    for path in paths:
        report = reports[str(path)]
        assert report["errors"] == 0 and report["warnings"] == 0, clean(report)


def test_untextured_output_is_unchanged_by_a_projection(folder):
    from bgr.formats import write

    plain = derive(folder, "Facade --> Tile\n")
    projected = derive(folder, "Facade --> setupProjection(0, scope.xy, 1, 1) projectUV(0) Tile\n")
    a, b = folder / "a.glb", folder / "b.glb"
    write(plain, a, seed=0, attrs={})
    write(projected, b, seed=0, attrs={})
    assert a.read_bytes() == b.read_bytes()
