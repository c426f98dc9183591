"""Inserted assets keep their own texture coordinates and image (issue 26, point 2).

An OBJ+MTL (map_Kd) or a glTF (baseColorTexture) asset with one image comes out of the GLB with
that image and its own uvs, wherever the shape puts and stretches it; a colour map the shape sets
itself overrides the asset's (CGA: "shape material attributes explicitly set in CGA override the
geometry's material"), and ``texture("")`` removes it again.  Expected uvs are the ones written
into the test's OBJ, looked up by each corner's position.
"""

from __future__ import annotations

import json
import shutil
import struct
from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image

import bgr
from bgr.formats import write

# the asset: a 1 x 2 quad in the z = 0 plane whose corners show the RIGHT half of the image,
# upside down: (x, y) -> (u, v) = (0.5 + 0.5 x, 1 - y / 2)
QUAD_UV = {(0, 0): (0.5, 1.0), (1, 0): (1.0, 1.0), (1, 2): (1.0, 0.0), (0, 2): (0.5, 0.0)}
OBJ = """\
mtllib window.mtl
o window
v 0 0 0
v 1 0 0
v 1 2 0
v 0 2 0
vt 0.5 1
vt 1 1
vt 1 0
vt 0.5 0
usemtl glass
f 1/1 2/2 3/3
f 1/1 3/3 4/4
"""
MTL = "newmtl glass\nKd 1 1 1\nmap_Kd quadrants.png\n"


def quadrants(path: Path) -> None:
    """8 x 8: red | green over blue | yellow (rows from the top)."""
    pixels = np.zeros((8, 8, 3), np.uint8)
    pixels[:4, :4], pixels[:4, 4:] = (255, 0, 0), (0, 255, 0)
    pixels[4:, :4], pixels[4:, 4:] = (0, 0, 255), (255, 255, 0)
    Image.fromarray(pixels).save(path)


@pytest.fixture
def folder(tmp_path):
    (tmp_path / "window.obj").write_text(OBJ)
    (tmp_path / "window.mtl").write_text(MTL)
    quadrants(tmp_path / "quadrants.png")
    Image.new("RGB", (4, 4), (10, 200, 30)).save(tmp_path / "green.png")
    return tmp_path


def derive(folder: Path, body: str, asset: str = "window.obj"):
    path = folder / "g.bgr"
    path.write_text(f'version 1\nasset win = "{asset}"\nterminal Window\n{body}')
    return bgr.derive(path, seed=0)


def glb_texcoords(path: Path):
    """(corner positions, uvs with v up, image) of the one textured primitive trimesh reads."""
    scene = trimesh.load(path, process=False)
    textured = [
        g
        for g in scene.geometry.values()
        if getattr(g.visual, "uv", None) is not None and len(g.visual.uv)
    ]
    assert len(textured) == 1
    (mesh,) = textured
    world = mesh.vertices
    for node in scene.graph.nodes_geometry:  # into world space, as the scene places it
        transform, name = scene.graph[node]
        if scene.geometry[name] is mesh:
            world = trimesh.transform_points(mesh.vertices, transform)
    return world, np.asarray(mesh.visual.uv), mesh.visual.material.baseColorTexture


def obj_corners(table, world: np.ndarray) -> list[tuple[int, int]]:
    """The OBJ corner (x, y) each world point of the one terminal is: its unit scope
    coordinates, scaled back to the 1 x 2 quad."""
    size = table.size[0]
    unit = (world - table.origin[0]) @ table.axes[0].T / np.where(size > 0, size, 1)
    return [(round(x), round(y * 2)) for x, y, _ in unit]


def test_an_obj_asset_keeps_its_uvs_and_image_in_the_glb(folder):
    # placed at x = 3, stretched to 2 x 4 m: the texture stretches with it
    result = derive(folder, "Lot --> t(3, 0, 0) s(2, 4, 0.1) i(win) Window\n")
    table = result.terminals.freeze()
    assert table.tex_own.tolist() == [True]
    assert [Path(im.path).name for im in table.images] == ["quadrants.png"]
    out = folder / "out.glb"
    write(table, out, seed=0, attrs={})
    world, uv, image = glb_texcoords(out)
    assert image.size == (8, 8)
    assert len(uv) == 6  # two triangles, three corners each
    for key, (u, v) in zip(obj_corners(table, world), uv, strict=True):
        assert (u, v) == pytest.approx(QUAD_UV[key], abs=1e-6), key
    # the whole quad shows the image's right half: green above, yellow below
    rgb = image.convert("RGB")
    for u, v in uv:
        inward = np.clip([u, v], 0.55, 0.95)
        colour = rgb.getpixel((int(inward[0] * 8), int((1 - inward[1]) * 8)))
        assert colour in ((0, 255, 0), (255, 255, 0))


def test_a_glb_asset_keeps_its_uvs_and_embedded_image(folder):
    # the GLB asset is the OBJ's quad as bgr writes it: the image embedded, uvs its own
    first = derive(folder, "Lot --> s(1, 2, 0) i(win) Window\n")
    write(first.terminals, folder / "window.glb", seed=0, attrs={})
    result = derive(folder, "Lot --> s(3, 3, 0) i(win) Window\n", asset="window.glb")
    table = result.terminals.freeze()
    assert table.tex_own.tolist() == [True]
    (image,) = table.images
    assert "window.glb#" in image.path
    assert image.data == (folder / "quadrants.png").read_bytes()  # embedded once, as given
    out = folder / "out.glb"
    write(table, out, seed=0, attrs={})
    world, uv, _ = glb_texcoords(out)
    for key, (u, v) in zip(obj_corners(table, world), uv, strict=True):
        assert (u, v) == pytest.approx(QUAD_UV[key], abs=1e-6), key


def test_the_shapes_own_colour_map_overrides_the_assets_and_texture_empty_clears_it(folder):
    over = derive(folder, 'Lot --> s(1, 2, 0) texture("green.png") i(win) Window\n')
    t = over.terminals.freeze()
    assert t.tex_own.tolist() == [False]
    assert Path(t.images[t.tex_maps[0, 0]].path).name == "green.png"
    cleared = derive(folder, 'Lot --> s(1, 2, 0) texture("green.png") texture("") i(win) Window\n')
    t = cleared.terminals.freeze()
    assert t.tex_own.tolist() == [True]
    assert Path(t.images[t.tex_maps[0, 0]].path).name == "quadrants.png"


def test_an_untextured_asset_is_read_as_before(folder):
    (folder / "plain.obj").write_text(
        OBJ.replace("mtllib window.mtl\n", "").replace("usemtl glass\n", "")
    )
    t = derive(folder, "Lot --> s(1, 2, 0) i(win) Window\n", asset="plain.obj").terminals.freeze()
    assert len(t.tex_rows) == 0 and t.images == []
    assert t.library.meshes[t.mesh[0]].uv is None


def test_an_asset_with_two_images_is_inserted_untextured_with_a_warning(folder):
    (folder / "two.mtl").write_text(MTL + "newmtl frame\nKd 1 1 1\nmap_Kd green.png\n")
    text = OBJ.replace("window.mtl", "two.mtl").replace(
        "f 1/1 3/3 4/4", "usemtl frame\nf 1/1 3/3 4/4"
    )
    (folder / "two.obj").write_text(text)
    result = derive(folder, "Lot --> s(1, 2, 0) i(win) Window\n", asset="two.obj")
    assert len(result.terminals.freeze().tex_rows) == 0
    messages = [d.message for d in result.warnings]
    assert any("uses 2 images: inserted without its textures" in m for m in messages), messages


def test_a_glb_with_an_inserted_textured_asset_validates(folder):
    from test_gltf_validator import clean, validate

    node = shutil.which("node")
    modules = Path(__file__).parent / "gltf_validator" / "node_modules" / "gltf-validator"
    if node is None or not modules.is_dir():
        pytest.skip("the Khronos glTF validator is not installed (test_gltf_validator installs it)")
    result = derive(
        folder,
        "Lot --> s(4, 0, 1) extrude(3) comp(f) { front: Facade | all: NIL }\n"
        "Facade --> split(x) { ~1: s('1, '1, 0.1) i(win) Window }*\n",
    )
    out = folder / "out.glb"
    write(result.terminals, out, seed=0, attrs={})
    doc = json.loads(out.read_bytes()[20 : 20 + struct.unpack_from("<I", out.read_bytes(), 12)[0]])
    assert len(doc["images"]) == 1
    report = validate(Path(node), [out])[str(out)]
    assert report["errors"] == 0 and report["warnings"] == 0, clean(report)
