"""Readers of textured models (issue 26, part 5): CityGML 2.0 with appearances, into TexturedMesh.

The real test is PLATEAU's ten Tokyo buildings (../shared/data, skipped when absent): every
building read with its wall and roof surfaces, every textured face's UVs inside its image, and
the image sampled there.  Small hand-written files check exact UVs, triangulation and refusals.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import SHARED
from PIL import Image

from bgr.formats.citygml_read import read_citygml
from bgr.formats.textured_model import pixels, wrapped
from bgr.grammar.errors import BgrError

PLATEAU = SHARED / "data" / "textured" / "plateau_tokyo" / "53392633_bldg_6697_2_op.gml"

# a 4 m x 3 m wall in the xz plane, textured with the whole image; the file uses prefixes it
# never declares (bldg:, app:, gml:), as CityGML files in the wild do
WALL = """<?xml version="1.0" encoding="UTF-8"?>
<core:CityModel xmlns:core="http://www.opengis.net/citygml/2.0">
 <gml:boundedBy><gml:Envelope srsName="EPSG:6677" srsDimension="3">
  <gml:lowerCorner>0 0 0</gml:lowerCorner><gml:upperCorner>4 0 3</gml:upperCorner>
 </gml:Envelope></gml:boundedBy>
 <core:cityObjectMember><bldg:Building gml:id="B1">
  <bldg:boundedBy><bldg:WallSurface gml:id="W1"><bldg:lod2MultiSurface><gml:MultiSurface>
   <gml:surfaceMember><gml:Polygon gml:id="P1"><gml:exterior><gml:LinearRing gml:id="R1">
    <gml:posList>0 0 0 4 0 0 4 0 3 0 0 3 0 0 0</gml:posList>
   </gml:LinearRing></gml:exterior>{hole}</gml:Polygon></gml:surfaceMember>
  </gml:MultiSurface></bldg:lod2MultiSurface></bldg:WallSurface></bldg:boundedBy>
  <bldg:boundedBy><bldg:RoofSurface gml:id="S1"><bldg:lod2MultiSurface><gml:MultiSurface>
   <gml:surfaceMember><gml:Polygon gml:id="P2"><gml:exterior><gml:LinearRing gml:id="R2">
    <gml:posList>0 0 3 4 0 3 4 -2 3 0 -2 3 0 0 3</gml:posList>
   </gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>
  </gml:MultiSurface></bldg:lod2MultiSurface></bldg:RoofSurface></bldg:boundedBy>
  <bldg:lod1Solid><gml:Solid><gml:exterior><gml:CompositeSurface><gml:surfaceMember>
   <gml:Polygon><gml:exterior><gml:LinearRing>
    <gml:posList>0 0 0 4 0 0 4 -2 0 0 0 0</gml:posList>
   </gml:LinearRing></gml:exterior></gml:Polygon>
  </gml:surfaceMember></gml:CompositeSurface></gml:exterior></gml:Solid></bldg:lod1Solid>
 </bldg:Building></core:cityObjectMember>
 <app:appearanceMember><app:Appearance><app:theme>rgbTexture</app:theme>
  <app:surfaceDataMember><app:ParameterizedTexture>
   <app:imageURI>{image}</app:imageURI>
   <app:target uri="#P1"><app:TexCoordList>
    <app:textureCoordinates ring="#R1">0 0 1 0 1 1 0 1 0 0</app:textureCoordinates>{hole_uv}
   </app:TexCoordList></app:target>
  </app:ParameterizedTexture></app:surfaceDataMember>
  <app:surfaceDataMember><app:X3DMaterial gml:id="M1">
   <app:diffuseColor>0.5 0.25 1</app:diffuseColor><app:transparency>0.25</app:transparency>
   <app:target>#S1</app:target>
  </app:X3DMaterial></app:surfaceDataMember>
 </app:Appearance></app:appearanceMember>
</core:CityModel>
"""
HOLE = """<gml:interior><gml:LinearRing gml:id="H1">
    <gml:posList>1 0 1 1 0 2 2 0 2 2 0 1 1 0 1</gml:posList></gml:LinearRing></gml:interior>"""
HOLE_UV = """
    <app:textureCoordinates ring="#H1">0.25 0.333 0.25 0.667 0.5 0.667 0.5 0.333 0.25 0.333
    </app:textureCoordinates>"""


def _write(tmp_path, hole: bool = False, image: str = "tex/wall.png", text: str | None = None):
    """The wall file in ``tmp_path`` beside a 4x2 image: left half red, right half blue."""
    (tmp_path / "tex").mkdir(exist_ok=True)
    pixels_ = np.zeros((2, 4, 3), dtype=np.uint8)
    pixels_[:, :2] = (255, 0, 0)
    pixels_[:, 2:] = (0, 0, 255)
    Image.fromarray(pixels_).save(tmp_path / "tex" / "wall.png")
    if text is None:
        text = WALL.format(hole=HOLE if hole else "", hole_uv=HOLE_UV if hole else "", image=image)
    path = tmp_path / "wall.gml"
    path.write_text(text, encoding="utf-8")
    return path


def _areas(mesh, mask) -> float:
    tri = mesh.vertices[mesh.faces[mask]]
    return float(
        np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum() / 2
    )


def test_wall_uvs_are_the_texture_coordinates_of_each_corner(tmp_path):
    mesh = read_citygml(_write(tmp_path))
    wall = mesh.mask(semantic="WallSurface")
    assert wall.sum() == 2 and mesh.mask(semantic="RoofSurface").sum() == 2
    assert mesh.object_ids == ["B1"] and mesh.crs == "EPSG:6677" and mesh.up == "z"
    assert _areas(mesh, wall) == pytest.approx(12.0)
    corners = mesh.vertices[mesh.faces[wall]]  # (2, 3, 3)
    # the texture spans the wall: u = x / 4, v = z / 3 at every corner
    np.testing.assert_allclose(mesh.uv[wall][..., 0], corners[..., 0] / 4)
    np.testing.assert_allclose(mesh.uv[wall][..., 1], corners[..., 2] / 3)
    assert mesh.textured().tolist() == wall.tolist()
    texture = mesh.materials[mesh.material[wall][0]]
    assert texture.image == (tmp_path / "tex" / "wall.png").resolve()
    assert texture.image_size() == (4, 2) and texture.wrap == "none"


def test_x3d_material_colours_the_surface_it_targets(tmp_path):
    mesh = read_citygml(_write(tmp_path))
    roof = mesh.materials[mesh.material[mesh.mask(semantic="RoofSurface")][0]]
    assert roof.name == "M1" and roof.color == (0.5, 0.25, 1.0, 0.75) and roof.image is None


def test_highest_lod_per_building_unless_one_is_asked_for(tmp_path):
    path = _write(tmp_path)
    assert len(read_citygml(path).faces) == 4  # the LoD 2 wall and roof, not the LoD 1 base
    lod1 = read_citygml(path, lod=1)
    assert len(lod1.faces) == 1 and lod1.semantic_names == [""] and lod1.material[0] == -1
    with pytest.raises(BgrError, match="no LoD 3 geometry"):
        read_citygml(path, lod=3)


def test_hole_is_cut_and_its_ring_has_its_own_uvs(tmp_path):
    mesh = read_citygml(_write(tmp_path, hole=True))
    wall = mesh.mask(semantic="WallSurface")
    assert _areas(mesh, wall) == pytest.approx(12.0 - 1.0)
    corners = mesh.vertices[mesh.faces[wall]]
    np.testing.assert_allclose(mesh.uv[wall][..., 0], corners[..., 0] / 4)
    np.testing.assert_allclose(mesh.uv[wall][..., 1], corners[..., 2] / 3, atol=1e-3)


def test_uvs_sample_the_image_where_the_corner_is(tmp_path):
    mesh = read_citygml(_write(tmp_path))
    wall = mesh.mask(semantic="WallSurface")
    texture = mesh.materials[mesh.material[wall][0]]
    image = np.asarray(Image.open(texture.image).convert("RGB"))
    # a point at x = 3 m on the wall is in the right (blue) half of the image; x = 1 m: red
    for x, colour in ((3.0, (0, 0, 255)), (1.0, (255, 0, 0))):
        col, row = pixels(np.array([x / 4, 0.5]), texture.image_size(), texture.wrap)
        assert tuple(image[row, col]) == colour


def test_wrapping_uvs_outside_the_unit_square():
    uv = np.array([[1.25, -0.25], [2.0, 0.5], [-1.5, 3.0]])
    np.testing.assert_allclose(wrapped(uv, "wrap"), [[0.25, 0.75], [1.0, 0.5], [0.5, 1.0]])
    np.testing.assert_allclose(wrapped(uv, "mirror"), [[0.75, 0.25], [0.0, 0.5], [0.5, 1.0]])
    np.testing.assert_allclose(wrapped(uv, "none"), [[1.0, 0.0], [1.0, 0.5], [0.0, 1.0]])
    # v counts from the image's bottom, rows from its top; u = v = 1 stays in the last pixel
    assert pixels(np.array([[0.0, 0.0], [1.0, 1.0]]), (4, 2)).tolist() == [[0, 1], [3, 0]]


# --------------------------------------------------------------------------------------------
# PLATEAU: the real test


@pytest.fixture(scope="module")
def plateau():
    if not PLATEAU.is_file():
        pytest.skip(f"the PLATEAU buildings are not here ({PLATEAU})")
    return read_citygml(PLATEAU)


def test_plateau_every_building_is_read_with_its_surfaces(plateau):
    assert len(plateau.object_ids) == 10
    assert all(i.startswith("BLD_") for i in plateau.object_ids)
    assert plateau.crs == "http://www.opengis.net/def/crs/EPSG/0/6697"
    assert {"WallSurface", "RoofSurface", "GroundSurface"} <= set(plateau.semantic_names)
    # the LoD 2 surfaces (the data README: 652 walls and 538 roofs), one polygon each
    walls = set(plateau.surface[plateau.mask(semantic="WallSurface")].tolist())
    roofs = set(plateau.surface[plateau.mask(semantic="RoofSurface")].tolist())
    assert (len(walls), len(roofs)) == (652, 538)
    for b in plateau.object_ids:  # each building has walls and roofs of its own
        assert (plateau.mask("WallSurface", b)).any() and (plateau.mask("RoofSurface", b)).any()
    assert plateau.warnings == []


def test_plateau_textured_faces_sample_their_images(plateau):
    textured = plateau.textured()
    assert textured.sum() > 0.9 * len(plateau.faces)  # all but the ground surfaces
    used = np.unique(plateau.material[textured])
    assert len(used) == 10  # the ten photographs
    for m in used.tolist():
        material = plateau.materials[m]
        faces = textured & (plateau.material == m)
        uv = plateau.uv[faces]
        assert ((uv >= 0) & (uv <= 1)).all()  # PLATEAU's coordinates all lie inside the image
        image = np.asarray(Image.open(material.image).convert("RGB"))
        assert material.image_size() == (image.shape[1], image.shape[0])
        px = pixels(uv.mean(axis=1), material.image_size(), material.wrap)  # face centres
        assert (px >= 0).all() and (px[:, 0] < image.shape[1]).all()
        assert (px[:, 1] < image.shape[0]).all()
        colours = image[px[:, 1], px[:, 0]]
        if len(colours) > 20:  # a photograph: the faces do not all sample one colour
            assert len(np.unique(colours, axis=0)) > 1


# --------------------------------------------------------------------------------------------
# refusals: each a located error


def _error(tmp_path, text: str) -> BgrError:
    with pytest.raises(BgrError) as info:
        read_citygml(_write(tmp_path, text=text))
    return info.value


def _wall_with(old: str, new: str) -> str:
    text = WALL.format(hole="", hole_uv="", image="tex/wall.png")
    assert old in text
    return text.replace(old, new, 1)


def test_malformed_xml_is_located(tmp_path):
    err = _error(tmp_path, _wall_with("</bldg:Building>", "</bldg:Buildin>"))
    assert "not well-formed" in err.message and err.line == 22


def test_doctype_and_entity_expansion_are_refused(tmp_path):
    laughs = (
        '<?xml version="1.0"?>\n<!DOCTYPE lolz [<!ENTITY lol "lol">'
        '<!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">]>\n'
        "<core:CityModel>&lol2;</core:CityModel>\n"
    )
    err = _error(tmp_path, laughs)
    assert "DOCTYPE is refused" in err.message and err.line == 2


@pytest.mark.parametrize(
    ("old", "new", "message", "line"),
    [
        ("<gml:posList>0 0 0 4 0 0 4 0 3 0 0 3 0 0 0</gml:posList>", "", "no gml:posList", 8),
        (
            "4 0 3 0 0 3 0 0 0</gml:posList>",
            "4 0 3 0 0 3 0 0</gml:posList>",
            "whole coordinates",
            9,
        ),
        ("4 0 3 0 0 3 0 0 0</gml:posList>", "4 0 nan 0 0 3 0 0 0</gml:posList>", "not a finite", 9),
        ("4 0 3 0 0 3 0 0 0</gml:posList>", "4 0 1e9 0 0 3 0 0 0</gml:posList>", "beyond", 9),
        ("4 0 3 0 0 3 0 0 0</gml:posList>", "4 0 x 0 0 3 0 0 0</gml:posList>", "'x' is not a", 9),
        ("<gml:posList>0 0 0 4", '<gml:posList srsDimension="2">0 0 0 4', "3D coordinates", 9),
        ("tex/wall.png", "../wall.png", "outside the model's folder", 25),
        ("tex/wall.png", "https://example.com/wall.png", "is a URL", 25),
        ("tex/wall.png", "/etc/passwd", "not a relative path", 25),
    ],
)
def test_bad_input_is_a_located_error(tmp_path, old, new, message, line):
    err = _error(tmp_path, _wall_with(old, new))
    assert message in err.message and err.line == line and err.path.endswith("wall.gml")


def test_depth_is_limited(tmp_path):
    deep = "<a>" * 300 + "</a>" * 300
    err = _error(tmp_path, f"<core:CityModel>{deep}</core:CityModel>")
    assert "nest deeper than 256" in err.message


def test_missing_image_is_a_warning(tmp_path):
    mesh = read_citygml(_write(tmp_path, image="tex/absent.png"))
    assert not mesh.textured().any()
    assert "absent.png' is missing" in mesh.warnings[0].message and mesh.warnings[0].line == 25


# --------------------------------------------------------------------------------------------
# glTF / GLB


def _quad_glb(tmp_path, name: str = "quad.glb"):
    """A unit quad in the xy plane whose UVs are its x and y, textured with the 4x2 image."""
    import trimesh

    _write(tmp_path)  # makes tex/wall.png
    image = Image.open(tmp_path / "tex" / "wall.png")
    verts = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    mesh = trimesh.Trimesh(
        verts,
        [[0, 1, 2], [0, 2, 3]],
        visual=trimesh.visual.TextureVisuals(uv=verts[:, :2], image=image),
        process=False,
    )
    path = tmp_path / name
    path.write_bytes(trimesh.Scene(mesh).export(file_type="glb"))
    return path


def test_glb_texture_and_uvs(tmp_path):
    from bgr.formats.gltf_textured import read_gltf_textured

    mesh = read_gltf_textured(_quad_glb(tmp_path))
    assert mesh.up == "y" and len(mesh.faces) == 2 and mesh.textured().all()
    corners = mesh.vertices[mesh.faces]
    # v runs up the image, as in CityGML and OBJ: the file's flipped v is flipped back
    np.testing.assert_allclose(mesh.uv, corners[..., :2], atol=1e-6)
    texture = mesh.materials[0]
    assert texture.image is None and texture.data is not None  # the GLB's own bufferView
    assert texture.image_size() == (4, 2)
    col, row = pixels(np.array([0.75, 0.5]), texture.image_size(), texture.wrap)
    assert tuple(
        np.asarray(Image.open(__import__("io").BytesIO(texture.image_bytes())))[row, col][:3]
    ) == (0, 0, 255)


def test_gltf_image_outside_its_folder_is_refused_and_a_missing_one_warned(tmp_path):
    import json

    import trimesh

    from bgr.formats.gltf_textured import read_gltf_textured

    files = trimesh.load(_quad_glb(tmp_path)).export(file_type="gltf", embed_buffers=True)
    gltf = json.loads(files["model.gltf"])
    gltf["images"] = [{"uri": "../outside.png"}]
    path = tmp_path / "quad.gltf"
    path.write_text(json.dumps(gltf))
    with pytest.raises(BgrError, match="outside the model's folder") as info:
        read_gltf_textured(path)
    assert info.value.path == str(path)
    gltf["images"] = [{"uri": "absent.png"}]
    path.write_text(json.dumps(gltf))
    mesh = read_gltf_textured(path)
    assert not mesh.textured().any() and "absent.png' is missing" in mesh.warnings[0].message


# --------------------------------------------------------------------------------------------
# OBJ + MTL

# two triangles sharing the edge 1-3, each with its own vt at the shared corners (per corner)
OBJ = """mtllib wall.mtl
v 0 0 0
v 2 0 0
v 2 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vt 0.5 0.5
o quad
usemtl brick
f 1/1 2/2 3/3
usemtl plain
f 1/5 3/5 4/4
"""
MTL = """newmtl brick
Kd 1 1 1
map_Kd -s 1 1 1 {image}
newmtl plain
Kd 0.5 0.25 0
d 0.5
"""


def _obj(tmp_path, obj: str = OBJ, image: str = "tex/wall.png"):
    _write(tmp_path)  # tex/wall.png
    (tmp_path / "wall.mtl").write_text(MTL.format(image=image))
    path = tmp_path / "wall.obj"
    path.write_text(obj)
    return path


def test_obj_keeps_each_corners_texture_coordinates(tmp_path):
    from bgr.formats.obj_textured import read_obj_textured

    mesh = read_obj_textured(_obj(tmp_path))
    assert mesh.faces.tolist() == [[0, 1, 2], [0, 2, 3]] and mesh.object_ids == ["quad"]
    np.testing.assert_allclose(mesh.uv[0], [[0, 0], [1, 0], [1, 1]])
    np.testing.assert_allclose(mesh.uv[1], [[0.5, 0.5], [0.5, 0.5], [0, 1]])
    brick, plain = (mesh.materials[k] for k in mesh.material)
    assert brick.image == (tmp_path / "tex" / "wall.png").resolve() and plain.image is None
    assert plain.color == (0.5, 0.25, 0.0, 0.5)
    assert mesh.textured().tolist() == [True, False]


def test_obj_quads_are_fanned_and_negative_indices_count_back(tmp_path):
    from bgr.formats.obj_textured import read_obj_textured

    obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nf -4/1 -3/1 -2/1 -1/1\n"
    mesh = read_obj_textured(_obj(tmp_path, obj))
    assert mesh.faces.tolist() == [[0, 1, 2], [0, 2, 3]] and (mesh.material == -1).all()


@pytest.mark.parametrize(
    ("obj", "message", "line"),
    [
        ("v 0 0 0\nf 1 2 3\n", "vertex 2 does not exist", 2),
        ("v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n", "not finite", 3),
        ("v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n", "is not 3 numbers", 3),
        ("mtllib ../x.mtl\nv 0 0 0\n", "outside the model's folder", 1),
    ],
)
def test_obj_bad_input_is_located(tmp_path, obj, message, line):
    from bgr.formats.obj_textured import read_obj_textured

    with pytest.raises(BgrError, match=message) as info:
        read_obj_textured(_obj(tmp_path, obj))
    assert info.value.line == line


def test_obj_image_outside_is_refused_and_a_missing_one_warned(tmp_path):
    from bgr.formats.obj_textured import read_obj_textured

    with pytest.raises(BgrError, match="outside the model's folder") as info:
        read_obj_textured(_obj(tmp_path, image="../../etc/passwd"))
    assert info.value.path.endswith("wall.mtl") and info.value.line == 3
    mesh = read_obj_textured(_obj(tmp_path, image="tex/absent.png"))
    assert not mesh.textured().any() and "is missing" in mesh.warnings[0].message


def test_uvs_far_outside_the_image_are_kept_and_wrap_into_it(tmp_path):
    text = _wall_with("0 0 1 0 1 1 0 1 0 0", "-2 0 1 0 1 7.5 -2 7.5 -2 0").replace(
        "</app:imageURI>", "</app:imageURI><app:wrapMode>wrap</app:wrapMode>"
    )
    mesh = read_citygml(_write(tmp_path, text=text))
    wall = mesh.mask(semantic="WallSurface")
    corners = mesh.vertices[mesh.faces[wall]]
    np.testing.assert_allclose(mesh.uv[wall][..., 0], corners[..., 0] * 3 / 4 - 2)
    np.testing.assert_allclose(mesh.uv[wall][..., 1], corners[..., 2] * 7.5 / 3)
    texture = mesh.materials[mesh.material[wall][0]]
    assert texture.wrap == "wrap"
    px = pixels(mesh.uv[wall], texture.image_size(), texture.wrap)
    assert (px >= 0).all() and (px < [4, 2]).all()
    # u = -1.75 repeats to 0.25: the red half; u = 0.75 the blue half
    assert pixels(np.array([[-1.75, 0.5], [0.75, 0.5]]), (4, 2), "wrap")[:, 0].tolist() == [1, 3]
