"""Inferred components that are footprints extruded: written as polygon() extrude(), checked
against the input, and the one assets file of the meshes that remain (issue 29)."""

from __future__ import annotations

import json
import re
import struct

import numpy as np
import pytest
import shapely
import trimesh
from test_city_infer import box, gable_house
from test_gltf_validator import clean, validate, validator  # noqa: F401  (a fixture)

import bgr
from bgr.inverse.city.components import fit
from bgr.inverse.city.container import pack
from bgr.inverse.city.cuts import Slab
from bgr.inverse.city.prisms import fit_prism, prism_mesh

TOL = 0.01
L_RING = [(0, 0), (12, 0), (12, 8), (5, 8), (5, 14), (0, 14)]


def component(mesh: trimesh.Trimesh):
    v, f = np.asarray(mesh.vertices, float), np.asarray(mesh.faces)
    return fit(Slab(v[:, 1].min(), v[:, 1].max(), v, f, np.arange(len(f))), 0, None)


def l_block(height: float = 9.0) -> trimesh.Trimesh:
    """An L-shaped block, y up, its walls cut into several triangles at odd heights."""
    made = trimesh.creation.extrude_polygon(shapely.Polygon(L_RING), height)
    made = made.subdivide()
    return trimesh.Trimesh(made.vertices[:, [0, 2, 1]], made.faces[:, ::-1])


def keep(mesh: trimesh.Trimesh, which) -> trimesh.Trimesh:
    return trimesh.Trimesh(mesh.vertices, mesh.faces[which(mesh.face_normals[:, 1])])


def test_a_closed_block_is_its_footprint_extruded():
    found = fit_prism(component(l_block()), TOL)
    assert found is not None
    assert found.bottom and found.top and found.height == pytest.approx(9.0)
    assert shapely.Polygon(found.ring).area == pytest.approx(126.0)
    assert len(found.ring) == 6  # the corners the walls were cut at are not corners


@pytest.mark.parametrize(
    ("which", "bottom", "top"),
    [
        (lambda up: up > -0.5, False, True),  # no floor (CityJSON LoD1 often has one, not all)
        (lambda up: up < 0.5, True, False),  # the walls under a roof, with the ground floor
        (lambda up: abs(up) < 0.5, False, False),  # walls alone
    ],
)
def test_the_faces_a_slab_lacks_are_left_out(which, bottom, top):
    found = fit_prism(component(keep(l_block(), which)), TOL)
    assert found is not None and (found.bottom, found.top) == (bottom, top)
    made = prism_mesh(found)
    assert made.area == pytest.approx(keep(l_block(), which).area)


@pytest.mark.parametrize(
    "mesh",
    [
        gable_house(8, 10, 6),  # a roof is no prism
        # a courtyard: polygon() writes no holes
        trimesh.Trimesh(
            *(lambda m: (m.vertices[:, [0, 2, 1]], m.faces[:, ::-1]))(
                trimesh.creation.extrude_polygon(
                    shapely.Polygon([(0, 0), (20, 0), (20, 20), (0, 20)]).difference(
                        shapely.box(5, 5, 15, 15)
                    ),
                    6,
                )
            )
        ),
    ],
    ids=["gable", "courtyard"],
)
def test_what_no_extrusion_makes_keeps_its_mesh(mesh):
    assert fit_prism(component(mesh), TOL) is None


def test_a_partial_cap_is_no_prism():
    """A slab whose top is half covered (a terrace beside a roof that starts there)."""
    block = box(0, 0, 0, 10, 4, 10)
    walls = keep(block, lambda up: up < 0.5)
    half = trimesh.Trimesh([[0, 4, 0], [5, 4, 0], [5, 4, 10], [0, 4, 10]], [[0, 2, 1], [0, 3, 2]])
    assert fit_prism(component(trimesh.util.concatenate([walls, half])), TOL) is None


def test_a_wall_a_few_centimetres_off_the_outline_is_no_prism():
    block = l_block()
    v = block.vertices.copy()
    v[(v[:, 0] > 11.9) & (v[:, 1] > 8.9), 0] += 0.03  # the top of one wall leans out 3 cm
    assert fit_prism(component(trimesh.Trimesh(v, block.faces)), TOL) is None


def test_an_inferred_block_derives_back_from_its_polygon(tmp_path):
    src = tmp_path / "l.obj"
    l_block().export(src)
    out = tmp_path / "city.bgr"
    assert bgr.cli.main(["infer", str(src), "--up", "y", "-o", str(out), "--no-progress"]) == 0
    text = out.read_text()
    assert "polygon(" in text and "asset " not in text
    assert not (tmp_path / "city.assets" / "meshes.glb").exists()
    baked = bgr.formats.meshes.bake(bgr.derive(bgr.load(out)).terminals)
    made = trimesh.Trimesh(baked.vertices, baked.faces)
    ref = l_block()
    for a, b in ((made, ref), (ref, made)):
        points = np.vstack([a.vertices, a.sample(2000, seed=1)])
        assert trimesh.proximity.closest_point(b, points)[1].max() < TOL


# ---- the assets file --------------------------------------------------------------------------


def meshes() -> list[tuple[str, np.ndarray, np.ndarray]]:
    roof = gable_house(8, 10, 6)
    return [
        ("type1", roof.vertices, roof.faces),
        ("object2", box(0, 0, 0, 2, 1, 3).vertices, box(0, 0, 0, 2, 1, 3).faces),
    ]


def test_the_assets_file_holds_a_named_node_per_mesh(tmp_path):
    path = tmp_path / "meshes.glb"
    path.write_bytes(pack(meshes()))
    scene = trimesh.load(path, force="scene", process=False)
    found = {str(node): scene.geometry[scene.graph[node][1]] for node in scene.graph.nodes_geometry}
    assert sorted(found) == ["object2", "type1"]
    for name, vertices, faces in meshes():
        got = found[name]
        assert len(got.faces) == len(faces)
        assert got.area == pytest.approx(trimesh.Trimesh(vertices, faces).area)
    head = json.loads(path.read_bytes()[20 : 20 + struct.unpack("<I", path.read_bytes()[12:16])[0]])
    assert len(head["bufferViews"]) == 2  # every mesh's indices in one view, positions in the other
    assert {a["componentType"] for a in head["accessors"] if a["type"] == "SCALAR"} == {5123}


def test_the_assets_file_is_valid_gltf(validator, tmp_path):  # noqa: F811
    path = tmp_path / "meshes.glb"
    path.write_bytes(pack(meshes()))
    report = validate(validator, [path])[str(path)]
    assert report["errors"] == 0 and report["warnings"] == 0, clean(report)


def test_a_block_without_its_floor_derives_back_through_the_shared_rule(tmp_path):
    """An LoD1 block with walls and a roof but no ground face: ``WallsAndRoof(h)``, shared by
    every such block, keeps the walls and the roof and makes no floor."""
    src = tmp_path / "l.obj"
    keep(l_block(), lambda up: up > -0.5).export(src)  # the floor left out
    out = tmp_path / "city.bgr"
    assert bgr.cli.main(["infer", str(src), "--up", "y", "-o", str(out), "--no-progress"]) == 0
    text = out.read_text()
    assert re.search(r"Type1 --> polygon\([^)]*\) WallsAndRoof\(9\)", text)
    assert "WallsAndRoof(h) --> extrude(h) comp(f) { side: Wall | top: Roof }" in text
    result = bgr.derive(bgr.load(out))
    assert set(result.terminals.label) == {"Wall", "Roof"}
    baked = bgr.formats.meshes.bake(result.terminals)
    made = trimesh.Trimesh(baked.vertices, baked.faces)
    assert made.area == pytest.approx(keep(l_block(), lambda up: up > -0.5).area, rel=1e-6)
