"""Textured OBJ+MTL and CityJSON (issue 26): texture coordinates computed by hand from the scope,
the images copied beside the file (once each, safe and unique names, all or nothing), the OBJ
read by trimesh with its ``vt`` and image, the CityJSON valid against the official 2.0.2 schema
with texture values that index its vertices-texture; PLY, STL and CityJSON sequences stay
untextured without failing.

A textured façade: the 3 m x 2 m back face of a box (scope x along world x, y up) with
``setupProjection(0, scope.xy, 1, 1) projectUV(0)``, so a point p of it has CGA texture
coordinates ((p - o) . x, (p - o) . y) for its scope origin o and axes x, y: one repeat of the
image per metre, v up the image.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT
from jsonschema import Draft7Validator
from PIL import Image

import bgr
from bgr.formats import write
from bgr.formats.meshes import mirrored
from bgr.interpreter.terminals import lot_tables

SCHEMAS = ROOT / "tests" / "data" / "cityjson-schemas"
PROJECTED = 'setupProjection(0, scope.xy, 1, 1) projectUV(0) texture("quad.png")'


@pytest.fixture
def folder(tmp_path):
    """A folder with an 8x8 PNG whose quadrants are red | green over blue | yellow."""
    pixels = np.zeros((8, 8, 3), np.uint8)
    pixels[:4, :4], pixels[:4, 4:] = (255, 0, 0), (0, 255, 0)
    pixels[4:, :4], pixels[4:, 4:] = (0, 0, 255), (255, 255, 0)
    Image.fromarray(pixels).save(tmp_path / "quad.png")
    return tmp_path


def derive(folder: Path, body: str, lot=None):
    """A 3 m x 2 m façade (the back face of a box), its rules ``body``; the frozen table."""
    path = folder / "t.bgr"
    path.write_text(
        "version 1\nstart Lot\nterminal Tile\n"
        "Lot --> s(3, 0, 2) r(0, 0, 0) extrude(2) comp(f) { back: Facade }\n" + body
    )
    return bgr.derive(path, seed=0, lot=lot).terminals.freeze()


def expected_uv(table, row: int, points: np.ndarray) -> np.ndarray:
    """CGA's uvs of world points on terminal ``row`` under setupProjection(scope.xy, 1, 1)."""
    rel = points - table.origin[row]
    return np.stack([rel @ table.axes[row][0], rel @ table.axes[row][1]], axis=-1)


def read_obj(path: Path):
    """(v, vt, faces as (v, vt or -1) corner lists, usemtl of each face): a plain reader."""
    v, vt, faces, mats = [], [], [], []
    current = None
    for line in path.read_text().splitlines():
        word, *rest = line.split() or [""]
        if word == "v":
            v.append([float(x) for x in rest])
        elif word == "vt":
            vt.append([float(x) for x in rest])
        elif word == "usemtl":
            current = rest[0]
        elif word == "f":
            corners = []
            for item in rest:
                a, b, _ = item.split("/")
                corners.append((int(a) - 1, int(b) - 1 if b else -1))
            faces.append(corners)
            mats.append(current)
    return np.array(v), np.array(vt).reshape(-1, 2), faces, mats


# ---------------------------------------------------------------------------------------------
# OBJ


def test_obj_vt_are_the_hand_computed_uvs(folder):
    table = derive(folder, f"Facade --> {PROJECTED} Tile\n")
    assert len(table) == 1
    out = folder / "out.obj"
    write(table, out, seed=0, attrs={})
    v, vt, faces, _ = read_obj(out)
    assert len(faces) == 2 and all(t >= 0 for f in faces for _, t in f)
    for face in faces:
        points = v[[i for i, _ in face]]
        uvs = vt[[t for _, t in face]]
        np.testing.assert_allclose(uvs, expected_uv(table, 0, points), atol=1e-5)
    corners = {tuple(np.round(uv, 6)) for uv in vt}
    assert corners == {(0.0, 0.0), (3.0, 0.0), (3.0, 2.0), (0.0, 2.0)}  # 3 x 2 repeats
    assert len(vt) == 4  # each distinct uv once
    text = out.read_text()
    assert "\nvt 3 2\n" in text
    mtl = (folder / "out.mtl").read_text()
    assert "map_Kd out_textures/quad.png" in mtl
    assert "map_d" not in mtl and "map_Bump" not in mtl  # no alpha, no normal map
    copy = folder / "out_textures" / "quad.png"
    assert copy.read_bytes() == (folder / "quad.png").read_bytes()


def test_trimesh_loads_the_obj_with_its_uvs_and_image(folder):
    import trimesh

    table = derive(folder, f"Facade --> {PROJECTED} Tile\n")
    out = folder / "out.obj"
    write(table, out, seed=0, attrs={})
    loaded = trimesh.load(out, process=False)
    meshes = list(loaded.geometry.values()) if hasattr(loaded, "geometry") else [loaded]
    (mesh,) = meshes
    assert mesh.visual.uv is not None and len(mesh.visual.uv) == len(mesh.vertices)
    assert mesh.visual.material.image.size == (8, 8)
    np.testing.assert_allclose(
        mesh.visual.uv, expected_uv(table, 0, np.asarray(mesh.vertices)), atol=1e-5
    )
    # the point 0.25 m right and up of the façade's corner samples the image's bottom-left
    # quadrant, blue: v runs up the image in OBJ as in CGA
    u, vv = 0.25, 0.25
    pixel = mesh.visual.material.image.convert("RGB").getpixel((int(u * 8), int((1 - vv) * 8)))
    assert pixel == (0, 0, 255)


def test_bgr_reads_its_textured_obj_back(folder):
    from bgr.formats.obj_textured import read_obj_textured

    table = derive(folder, f"Facade --> {PROJECTED} Tile\n")
    write(table, folder / "out.obj", seed=0, attrs={})
    model = read_obj_textured(folder / "out.obj")
    assert model.textured().all() and len(model.faces) == 2
    (k,) = set(model.material.tolist())
    assert model.materials[k].image == (folder / "out_textures" / "quad.png").resolve()
    np.testing.assert_allclose(
        model.uv.reshape(-1, 2),
        expected_uv(table, 0, model.vertices[model.faces].reshape(-1, 3)),
        atol=1e-5,
    )


def test_mixed_faces_normal_and_alpha_maps(folder):
    rgba = np.zeros((4, 4, 4), np.uint8)
    rgba[..., 3] = 128
    Image.fromarray(rgba).save(folder / "glass.png")
    Image.new("RGB", (4, 4), (128, 128, 255)).save(folder / "bumps.png")
    table = derive(
        folder,
        "Facade --> split(x) { 1: Plain | 1: Glass | 1: Bumpy }\n"
        "Plain --> color(0.5, 0.5, 0.5) Tile\n"
        'Glass --> setupProjection(0, scope.xy, 1, 1) projectUV(0) texture("glass.png") Tile\n'
        "Bumpy --> setupProjection(0, scope.xy, 1, 1) projectUV(0) "
        'texture("quad.png") normalMap("bumps.png") Tile\n',
    )
    out = folder / "mixed.obj"
    write(table, out, seed=0, attrs={})
    _, vt, faces, mats = read_obj(out)
    mtl = (folder / "mixed.mtl").read_text()
    blocks = {b.split("\n", 1)[0]: b for b in mtl.split("newmtl ")[1:]}
    for face, mat in zip(faces, mats, strict=True):
        textured = "map_Kd" in blocks[mat]
        assert all((t >= 0) == textured for _, t in face), (mat, face)
    glass = next(b for b in blocks.values() if "glass.png" in b)
    assert "map_d mixed_textures/glass.png" in glass  # the alpha channel is the opacity
    bumpy = next(b for b in blocks.values() if "bumps.png" in b)
    assert "map_Kd mixed_textures/quad.png" in bumpy
    assert "map_Bump mixed_textures/bumps.png" in bumpy and "bump mixed_textures/bumps.png" in bumpy
    # the grey tiles' faces are v//vn, with one untextured material
    assert len({m for f, m in zip(faces, mats, strict=True) if f[0][1] < 0}) == 1
    assert sorted(p.name for p in (folder / "mixed_textures").iterdir()) == [
        "bumps.png",
        "glass.png",
        "quad.png",
    ]


def test_images_are_copied_once_with_unique_safe_names(folder):
    other = folder / "other"
    other.mkdir()
    Image.new("RGB", (2, 2), (9, 9, 9)).save(other / "quad.png")  # same name, other image
    Image.new("RGB", (2, 2), (7, 7, 7)).save(folder / "a b#c.png")
    table = derive(
        folder,
        "Facade --> split(x) { 1: A | 1: B | 1: C | 1: A }\n"
        f"A --> {PROJECTED} Tile\n"
        'B --> setupProjection(0, scope.xy, 1, 1) projectUV(0) texture("other/quad.png") Tile\n'
        'C --> setupProjection(0, scope.xy, 1, 1) projectUV(0) texture("a b#c.png") Tile\n',
    )
    write(table, folder / "x.obj", seed=0, attrs={})
    copies = sorted(p.name for p in (folder / "x_textures").iterdir())
    assert copies == ["a_b_c.png", "quad.png", "quad_2.png"]
    sources = {folder / "quad.png", other / "quad.png", folder / "a b#c.png"}
    assert {p.read_bytes() for p in (folder / "x_textures").iterdir()} == {
        s.read_bytes() for s in sources
    }
    mtl = (folder / "x.mtl").read_text()
    named = {line.split()[1] for line in mtl.splitlines() if line.startswith("map_Kd")}
    assert named == {f"x_textures/{n}" for n in copies}


def test_a_mirrored_terminal_keeps_its_uvs_at_its_corners(folder):
    # a textured box whose frame is made left-handed by hand: the writers re-wind its
    # triangles, and each corner must keep its own texture coordinate (OBJ and CityJSON)
    path = folder / "box.bgr"
    path.write_text(
        "version 1\nstart Lot\nterminal Tile\n"
        f"Lot --> s(3, 0, 2) r(0, 0, 0) extrude(2) {PROJECTED} Tile\n"
    )
    table = bgr.derive(path, seed=0).terminals.freeze()
    table.axes[0, 2] *= -1
    assert mirrored(table).tolist() == [True]
    write(table, folder / "m.obj", seed=0, attrs={})
    v, vt, faces, _ = read_obj(folder / "m.obj")
    assert len(faces) == 12
    for face in faces:
        points = v[[i for i, _ in face]]
        np.testing.assert_allclose(
            vt[[t for _, t in face]], expected_uv(table, 0, points), atol=1e-5
        )
    write(table, folder / "m.city.json", seed=0, attrs={})
    doc = json.loads((folder / "m.city.json").read_text())
    uvs, points = np.asarray(doc["appearance"]["vertices-texture"]), cityjson_points(doc)
    (obj,) = doc["CityObjects"].values()
    geom = obj["geometry"][0]
    for surface, value in zip(geom["boundaries"], geom["texture"]["bgr"]["values"], strict=True):
        p = points[surface[0]]
        world = np.stack([p[:, 0], p[:, 2], -p[:, 1]], axis=1)
        np.testing.assert_allclose(uvs[value[0][1:]], expected_uv(table, 0, world), atol=2e-3)


def test_untextured_obj_is_unchanged_by_a_projection(folder):
    plain = derive(folder, "Facade --> Tile\n")
    projected = derive(folder, "Facade --> setupProjection(0, scope.xy, 1, 1) projectUV(0) Tile\n")
    write(plain, folder / "a.obj", seed=0, attrs={})
    write(projected, folder / "b.obj", seed=0, attrs={})
    a, b = (folder / "a.obj").read_text(), (folder / "b.obj").read_text()
    assert a.replace("a.mtl", "b.mtl") == b and "vt" not in a and " 1//1" in a
    assert (folder / "a.mtl").read_bytes() == (folder / "b.mtl").read_bytes()
    assert not (folder / "a_textures").exists()


def test_lots_written_as_they_come_give_the_same_files(folder):
    from bgr.formats.sinks import open_sink

    geo = folder / "lots.geojson"
    rings = [[[0, 0], [10, 0], [10, 8], [0, 8], [0, 0]], [[20, 0], [30, 0], [30, 8], [20, 8]]]
    rings[1].append(rings[1][0])
    features = [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [r]}}
        for r in rings
    ]
    geo.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    table = derive(folder, f"Facade --> {PROJECTED} Tile\n", lot=str(geo))
    assert len(table.lots) == 2 and len(table.tex_rows) == 2
    for name in ("whole", "lots"):
        (folder / name).mkdir()
    for ext in ("obj", "city.json"):
        write(table, folder / "whole" / f"out.{ext}", seed=0, attrs={})
        with open_sink(folder / "lots" / f"out.{ext}", seed=0, attrs={}) as sink:
            for part in lot_tables(table):
                sink.add(part)
    for name in ("out.obj", "out.mtl", "out.city.json", "out_textures/quad.png"):
        assert (folder / "whole" / name).read_bytes() == (folder / "lots" / name).read_bytes()
    _, vt, faces, _ = read_obj(folder / "lots" / "out.obj")
    assert len(faces) == 4 and all(t >= 0 for f in faces for _, t in f)


def test_a_failed_write_leaves_no_copies(folder, monkeypatch):
    import bgr.formats as writers

    def explode(*args, **kwargs):
        args[1].write(b"partial")
        raise RuntimeError("disk on fire")

    table = derive(folder, f"Facade --> {PROJECTED} Tile\n")
    before = sorted(p.name for p in folder.iterdir())
    monkeypatch.setattr(writers, "write_obj", explode)
    monkeypatch.setitem(writers.FORMATS, "city.json", explode)
    for name in ("out.obj", "out.city.json"):
        with pytest.raises(RuntimeError, match="disk on fire"):
            write(table, folder / name, seed=0, attrs={})
        assert sorted(p.name for p in folder.iterdir()) == before


# ---------------------------------------------------------------------------------------------
# CityJSON


def cityjson_points(doc: dict) -> np.ndarray:
    t = doc["transform"]
    return np.asarray(doc["vertices"], dtype=np.float64) * t["scale"] + t["translate"]


def test_cityjson_appearance_is_valid_and_indexes_hand_computed_uvs(folder):
    table = derive(
        folder,
        "Facade --> split(x) { 1: Plain | 2: Textured }\n"
        "Plain --> color(0.2, 0.4, 0.6) Tile\n"
        f"Textured --> {PROJECTED} Tile\n",
    )
    out = folder / "f.city.json"
    write(table, out, seed=0, attrs={})
    doc = json.loads(out.read_text())
    schema = Draft7Validator(json.loads((SCHEMAS / "cityjson.min.schema.json").read_text()))
    assert [e.message for e in schema.iter_errors(doc)] == []
    look = doc["appearance"]
    assert look["textures"] == [{"type": "PNG", "image": "f_textures/quad.png", "wrapMode": "wrap"}]
    assert (folder / "f_textures" / "quad.png").read_bytes() == (folder / "quad.png").read_bytes()
    uvs = np.asarray(look["vertices-texture"])
    points = cityjson_points(doc)
    textured_row = int(table.tex_rows[0])
    plain_row = 1 - textured_row
    seen = {"textured": 0, "plain": 0}
    for obj in doc["CityObjects"].values():
        for geom in obj.get("geometry", []):
            values = geom["texture"]["bgr"]["values"]
            material = geom["material"]["bgr"]
            mats = material.get("values") or [material["value"]] * len(geom["boundaries"])
            for surface, value, mat in zip(geom["boundaries"], values, mats, strict=True):
                ring = surface[0]
                colour = look["materials"][mat]["diffuseColor"]
                if value == [[None]]:
                    seen["plain"] += 1
                    assert colour == [round(c / 255, 6) for c in (51, 102, 153)]
                    continue
                seen["textured"] += 1
                tex, *corners = value[0]
                assert tex == 0 and len(corners) == len(ring)
                assert all(0 <= c < len(uvs) for c in corners)
                # CityJSON (x, y, z) is bgr (x, -z, y)
                p = points[ring]
                world = np.stack([p[:, 0], p[:, 2], -p[:, 1]], axis=1)
                np.testing.assert_allclose(
                    uvs[corners], expected_uv(table, textured_row, world), atol=2e-3
                )
    assert seen == {"textured": 2, "plain": 2}
    assert table.color[plain_row].tolist() == pytest.approx([0.2, 0.4, 0.6])
    got = {tuple(np.round(uv, 6)) for uv in uvs}
    assert got == {(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)}


def test_cjio_finds_the_materials_textures_and_their_folder(folder):
    import subprocess
    import sys

    table = derive(folder, f"Facade --> {PROJECTED} Tile\n")
    out = folder / "c.city.json"
    write(table, out, seed=0, attrs={})
    script = (
        "import json, sys\nfrom cjio import cityjson\n"
        "cm = cityjson.reader(open(sys.argv[1]))\ncm.check_version()\n"
        "print(json.dumps([cm.get_info(), cm.get_textures_location()]))\n"
    )
    run = subprocess.run(
        [sys.executable, "-c", script, str(out)], capture_output=True, text=True, check=False
    )
    assert run.returncode == 0, run.stderr
    info, location = json.loads(run.stdout.splitlines()[-1])
    assert "materials = True" in info and "textures = True" in info
    assert Path(location) == folder / "c_textures"


def test_a_jpeg_is_copied_as_given_and_typed_jpg(folder):
    Image.new("RGB", (4, 4), (200, 100, 50)).save(folder / "photo.JPEG", format="JPEG")
    table = derive(
        folder,
        'Facade --> setupProjection(0, scope.xy, 1, 1) projectUV(0) texture("photo.JPEG") Tile\n',
    )
    write(table, folder / "j.city.json", seed=0, attrs={})
    doc = json.loads((folder / "j.city.json").read_text())
    assert doc["appearance"]["textures"][0]["type"] == "JPG"
    assert doc["appearance"]["textures"][0]["image"] == "j_textures/photo.jpeg"
    copy = folder / "j_textures" / "photo.jpeg"
    assert copy.read_bytes() == (folder / "photo.JPEG").read_bytes()


def test_untextured_cityjson_has_materials_but_no_textures(folder):
    table = derive(folder, "Facade --> color(1, 0, 0) Tile\n")
    out = folder / "p.city.json"
    write(table, out, seed=0, attrs={})
    doc = json.loads(out.read_text())
    look = doc["appearance"]
    assert look["materials"] == [{"name": "#ff0000", "diffuseColor": [1.0, 0.0, 0.0]}]
    assert "textures" not in look and "vertices-texture" not in look
    (obj,) = doc["CityObjects"].values()
    assert obj["geometry"][0]["material"] == {"bgr": {"value": 0}}
    assert "texture" not in obj["geometry"][0]
    assert not (folder / "p_textures").exists()


def test_textured_cityjson_to_standard_output_is_refused(folder):
    table = derive(folder, f"Facade --> {PROJECTED} Tile\n")
    with pytest.raises(bgr.BgrError, match="standard output"):
        write(table, Path("-"), seed=0, attrs={}, fmt="city.json")


# ---------------------------------------------------------------------------------------------
# the formats without textures


@pytest.mark.parametrize("ext", ["ply", "stl", "city.jsonl"])
def test_untextured_formats_write_a_textured_table_as_a_plain_one(folder, ext):
    textured = derive(folder, f"Facade --> {PROJECTED} Tile\n")
    plain = derive(folder, "Facade --> Tile\n")
    write(textured, folder / f"t.{ext}", seed=0, attrs={})
    write(plain, folder / f"p.{ext}", seed=0, attrs={})
    assert (folder / f"t.{ext}").read_bytes() == (folder / f"p.{ext}").read_bytes()
    assert not (folder / "t_textures").exists()
