"""CGA's material attributes opacity, metallic and roughness: set(material.opacity, v) reaches
the terminal list, glTF (baseColorFactor alpha, alphaMode BLEND, metallicFactor,
roughnessFactor) and OBJ's .mtl (d, Pm, Pr); a grammar that sets none writes what it did."""

import json
import struct

import numpy as np
import pytest

import bgr
from bgr.cga.files import translate_file
from bgr.interpreter.surfaces import Surface

GLASS = """terminal Glass, Wall
Lot --> extrude(6) comp(f) { front: Front | side: Wall }
Front --> split(x) { ~2: set(material.opacity, 0.35) set(material.roughness, 0.05)
    material("glass") color("#88aacc") Glass }*
"""


def gltf_json(path) -> dict:
    data = path.read_bytes()
    (length,) = struct.unpack("<I", data[12:16])
    return json.loads(data[20 : 20 + length])


def test_values_reach_the_terminal_list_and_stay_through_material():
    result = bgr.derive(bgr.load(GLASS), lot=(10, 8))
    glass = [
        m
        for m, label in zip(result.terminals.material, result.terminals.label, strict=True)
        if label == "Glass"
    ]
    assert len(glass) == 5  # five panes, the repeated subtree replayed with its material
    assert all(m == Surface("glass", 0.35, 0.0, 0.05) for m in glass)


def test_gltf_and_obj_carry_them(tmp_path):
    grammar = tmp_path / "glass.bgr"
    grammar.write_text(GLASS)
    result = bgr.derive(bgr.load(grammar), lot=(10, 8))
    result.save(tmp_path / "out.glb")
    materials = gltf_json(tmp_path / "out.glb")["materials"]
    glass = next(m for m in materials if m["extras"]["material"] == "glass")
    assert glass["alphaMode"] == "BLEND"
    assert glass["pbrMetallicRoughness"]["baseColorFactor"][3] == pytest.approx(0.35)
    assert glass["pbrMetallicRoughness"]["roughnessFactor"] == pytest.approx(0.05)
    wall = next(m for m in materials if m["extras"]["material"] is None)
    assert "alphaMode" not in wall and wall["pbrMetallicRoughness"]["baseColorFactor"][3] == 1.0
    result.save(tmp_path / "out.obj")
    mtl = (tmp_path / "out.mtl").read_text()
    block = mtl[mtl.index("newmtl glass") :].split("\n\n")[0]
    assert "d 0.35" in block and "Pr 0.05" in block and "Pm 0" in block
    result.save(tmp_path / "out.json")
    rows = json.loads((tmp_path / "out.json").read_text())["terminals"]
    pane = next(r for r in rows if r["label"] == "Glass")
    assert pane["material"] == "glass"
    assert pane["surface"] == {"opacity": 0.35, "metallic": 0.0, "roughness": 0.05}
    assert "surface" not in next(r for r in rows if r["label"] == "Wall")


def test_a_grammar_without_them_writes_plain_materials(tmp_path):
    result = bgr.derive(
        bgr.load('Lot --> extrude(3) material("brick") A\nterminal A\n'), lot=(4, 4)
    )
    assert list(result.terminals.material) == ["brick"]
    result.save(tmp_path / "plain.obj")
    assert "Pm " not in (tmp_path / "plain.mtl").read_text()


@pytest.mark.parametrize("value", ["1.5", "-0.1", '"half"', "true"])
def test_values_outside_0_to_1_are_errors(value):
    with pytest.raises(bgr.BgrError, match="takes a number from 0 to 1"):
        bgr.derive(bgr.load(f"Lot --> set(material.opacity, {value}) A\nterminal A\n"), lot=(4, 4))


def test_import_cga_translates_them(tmp_path):
    src = tmp_path / "glass.cga"
    src.write_text(
        "Lot --> extrude(6) set(material.opacity, 0.5) set(material.metallic, 1) Glass.\n"
    )
    result = translate_file(src, tmp_path / "glass.bgr")
    text = result.outputs[tmp_path / "glass.bgr"]
    assert "set(material.opacity, 0.5) set(material.metallic, 1)" in text
    assert [w for w in result.warnings if "material" in w.message] == []


SHINY = """terminal Metal, Wall
Lot --> extrude(6) comp(f) { front: Front | side: Wall }
Front --> set(material.specular.r, 0.9) set(material.specular.g, 0.8) set(material.specular.b, 0.7)
    set(material.shininess, 64) set(material.reflectivity, 0.3) material("steel") Metal
"""


def test_specular_shininess_and_reflectivity_reach_every_file(tmp_path):
    """CGA's specular colour, shininess and reflectivity: glTF's KHR_materials_specular and
    extras, OBJ's Ks, Ns and illum 2, the terminal list's surface object."""
    grammar = tmp_path / "shiny.bgr"
    grammar.write_text(SHINY)
    result = bgr.derive(bgr.load(grammar), lot=(10, 8))
    result.save(tmp_path / "out.glb")
    gltf = gltf_json(tmp_path / "out.glb")
    assert gltf["extensionsUsed"] == ["KHR_materials_specular"]
    assert "extensionsRequired" not in gltf  # a reader without it shows the rest
    steel = next(m for m in gltf["materials"] if m["extras"]["material"] == "steel")
    factor = steel["extensions"]["KHR_materials_specular"]["specularColorFactor"]
    assert factor == pytest.approx([0.9, 0.8, 0.7])
    assert steel["extras"]["shininess"] == 64 and steel["extras"]["reflectivity"] == 0.3
    wall = next(m for m in gltf["materials"] if m["extras"]["material"] is None)
    assert "extensions" not in wall and "shininess" not in wall["extras"]
    result.save(tmp_path / "out.obj")
    mtl = (tmp_path / "out.mtl").read_text()
    block = mtl[mtl.index("newmtl steel") :].split("\n\n")[0]
    assert "Ks 0.9 0.8 0.7" in block and "Ns 64" in block and "illum 2" in block
    plain = next(b for b in mtl.split("\n\n") if "newmtl" in b and "steel" not in b)
    assert "Ks 0 0 0" in plain and "illum 1" in plain and "Ns" not in plain
    result.save(tmp_path / "out.json")
    rows = json.loads((tmp_path / "out.json").read_text())["terminals"]
    metal = next(r for r in rows if r["label"] == "Metal")
    assert metal["surface"] == {
        "opacity": 1.0,
        "metallic": 0.0,
        "roughness": 0.8,
        "specular.r": 0.9,
        "specular.g": 0.8,
        "specular.b": 0.7,
        "shininess": 64.0,
        "reflectivity": 0.3,
    }


def test_shininess_goes_to_128_and_no_further():
    ok = bgr.derive(bgr.load("Lot --> set(material.shininess, 128) A\nterminal A\n"), lot=(4, 4))
    assert ok.terminals.material[0].shininess == 128
    with pytest.raises(bgr.BgrError, match="takes a number from 0 to 128"):
        bgr.derive(bgr.load("Lot --> set(material.shininess, 129) A\nterminal A\n"), lot=(4, 4))


def test_set_material_color_changes_one_channel_of_the_colour():
    # CGA's set(material.color.r, v): the other channels stay as color() left them
    src = """terminal A, B
Lot --> [ color("#336699") set(material.color.r, 1) A ] [ set(material.color.g, 0.5) B ]
"""
    result = bgr.derive(bgr.load(src), lot=(4, 4))
    colours = dict(zip(result.terminals.label, result.terminals.color, strict=True))
    assert np.allclose(colours["A"], (1.0, 0x66 / 255, 0x99 / 255))
    assert np.allclose(colours["B"], (0.8, 0.5, 0.8))  # from the default #cccccc
    with pytest.raises(bgr.BgrError, match="takes a number from 0 to 1"):
        bgr.derive(bgr.load("Lot --> set(material.color.b, 2) A\nterminal A\n"), lot=(4, 4))
