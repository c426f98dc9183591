"""The ``site`` declaration (issue 29): an inferred city's output lands where the input was.

A city far from the origin (Swiss LV95 coordinates) is inferred and derived again; every output
is loaded by trimesh (CityJSON by its transform) and must overlay the input within 1 cm with
no offset applied by hand.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import trimesh
from test_cityjson import schema_errors

import bgr
from bgr.cli import main
from bgr.grammar.errors import BgrError

EAST, NORTH, HEIGHT = 2682812.25, 1247000.75, 410.3  # LV95 metres: Zurich


def _city_obj(path: Path) -> trimesh.Trimesh:
    """Three z-up boxes (two alike) at LV95 coordinates, as an OBJ of three objects."""
    boxes = []
    for x, y, h in ((0.0, 0.0, 10.0), (30.0, 5.0, 14.0), (60.0, -8.0, 10.0)):
        box = trimesh.creation.box(extents=[12.0, 9.0, h])
        box.apply_translation([EAST + x, NORTH + y, HEIGHT + h / 2])
        boxes.append(box)
    lines, first = [], 1
    for i, box in enumerate(boxes):
        lines.append(f"o b{i}")
        lines += [f"v {x:.3f} {y:.3f} {z:.3f}" for x, y, z in box.vertices]
        lines += [f"f {a + first} {b + first} {c + first}" for a, b, c in box.faces]
        first += len(box.vertices)
    path.write_text("\n".join(lines) + "\n")
    return trimesh.util.concatenate(boxes)


def _distance(a: trimesh.Trimesh, points: np.ndarray) -> float:
    """The largest distance from ``points`` to the surface ``a`` (trimesh, point to surface)."""
    _, distance, _ = trimesh.proximity.closest_point(a, points)
    return float(distance.max())


def _overlay(truth: trimesh.Trimesh, out: trimesh.Trimesh) -> float:
    """Symmetric: the output's vertices and face centres to the input, and the input's to it."""
    there = np.vstack([out.vertices, out.triangles_center])
    back = np.vstack([truth.vertices, truth.triangles_center])
    return max(_distance(truth, there), _distance(out, back))


@pytest.fixture(scope="module")
def inferred(tmp_path_factory) -> tuple[Path, trimesh.Trimesh]:
    folder = tmp_path_factory.mktemp("site")
    truth = _city_obj(folder / "city.obj")
    assert main(["infer", str(folder / "city.obj"), "--up", "z", "-o", str(folder / "c.bgr")]) == 0
    return folder, truth


def test_inferred_grammar_declares_the_exact_offset(inferred):
    folder, _ = inferred
    grammar = bgr.load(folder / "c.bgr")
    assert grammar.site is not None
    assert grammar.site.up == "z"
    # whole metres near the input's centre, exactly (no %g rounding)
    assert grammar.site.origin == (2682842.0, 1246999.0, 410.0)
    text = (folder / "c.bgr").read_text()
    assert "site origin (2682842, 1246999, 410) up z" in text


@pytest.mark.parametrize("ext", ["obj", "ply", "glb"])
def test_derived_city_overlays_the_input(inferred, ext):
    folder, truth = inferred
    out = folder / f"out.{ext}"
    assert main(["derive", str(folder / "c.bgr"), "-o", str(out)]) == 0
    mesh = trimesh.load(out, force="mesh", process=False)  # the GLB through its node transform
    if ext == "glb":  # glTF is y up: (east, up, -north)
        v = mesh.vertices
        mesh = trimesh.Trimesh(np.column_stack([v[:, 0], -v[:, 2], v[:, 1]]), mesh.faces)
    assert _overlay(truth, mesh) < 0.01


def test_derived_cityjson_overlays_the_input_and_is_valid(inferred):
    folder, truth = inferred
    out = folder / "out.city.json"
    assert main(["derive", str(folder / "c.bgr"), "-o", str(out)]) == 0
    assert schema_errors(out) == []
    doc = json.loads(out.read_text())
    t = doc["transform"]
    vertices = np.array(doc["vertices"]) * t["scale"] + t["translate"]
    assert _distance(truth, vertices) < 0.01
    lo = vertices.min(axis=0)
    assert lo == pytest.approx([EAST - 6, NORTH - 8 - 4.5, HEIGHT], abs=0.002)


def test_glb_positions_stay_local(inferred):
    """float32 positions near 0; the root's translation carries the offset (glTF's axes)."""
    folder, _ = inferred
    out = folder / "local.glb"
    assert main(["derive", str(folder / "c.bgr"), "-o", str(out)]) == 0
    scene = trimesh.load(out)
    root = next(iter(scene.graph.transforms.children[scene.graph.base_frame]))
    matrix, _ = scene.graph.get(root)
    assert matrix[:3, 3] == pytest.approx([2682842.0, 410.0, -1246999.0], abs=1e-6)
    for geometry in scene.geometry.values():
        assert np.abs(geometry.vertices).max() < 100


def test_crs_reaches_cityjson(tmp_path):
    source = tmp_path / "g.bgr"
    source.write_text(
        'site "EPSG:2056" origin (2682812, 1247000, 400) up z\n'
        'Lot --> extrude(10) Mass\nMass --> color("#c0a080")\n'
    )
    out = tmp_path / "g.city.json"
    assert main(["derive", str(source), "--lot", "20,10", "-o", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["metadata"]["referenceSystem"].endswith("/EPSG/0/2056")
    t = doc["transform"]
    v = np.array(doc["vertices"]) * t["scale"] + t["translate"]
    # the lot's local x, -z, y: east 0..20, north -10..0 from the origin, 10 m tall
    assert v.min(axis=0) == pytest.approx([2682812, 1247000 - 10, 400], abs=0.002)
    assert v.max(axis=0) == pytest.approx([2682812 + 20, 1247000, 410], abs=0.002)


def test_up_y_site_keeps_the_axes(tmp_path):
    source = tmp_path / "g.bgr"
    source.write_text(
        "site origin (1000, 20, -3000) up y\nterminal Mass\nLot --> extrude(10) Mass\n"
    )
    out = tmp_path / "g.obj"
    assert main(["derive", str(source), "--lot", "20,10", "-o", str(out)]) == 0
    mesh = trimesh.load(out, force="mesh", process=False)
    assert mesh.bounds[0] == pytest.approx([1000, 20, -3000], abs=1e-6)
    assert mesh.bounds[1] == pytest.approx([1020, 30, -3000 + 10], abs=1e-6)


@pytest.mark.parametrize(
    "line, message",
    [
        ("site origin (0, 0, 0) up x", "'up x' is not an up axis"),
        ('site "EPSG:99999999" origin (0, 0, 0) up z', "is not one pyproj knows"),
        ("site origin (1e9, 0, 0) up z", "beyond"),
    ],
)
def test_bad_site_is_a_located_error(tmp_path, line, message):
    source = tmp_path / "g.bgr"
    source.write_text(f"{line}\nterminal A\nLot --> extrude(1) A\n")
    with pytest.raises(BgrError) as caught:
        bgr.load(source)
    text = str(caught.value)
    assert message in text
    assert "g.bgr:1:" in text


def test_two_sites_are_an_error(tmp_path):
    source = tmp_path / "g.bgr"
    source.write_text(
        "site origin (0, 0, 0) up z\nsite origin (1, 0, 0) up z\nterminal A\nLot --> A\n"
    )
    with pytest.raises(BgrError, match="more than one 'site'"):
        bgr.load(source)


def test_site_words_stay_names_elsewhere(tmp_path):
    """Only ``site`` is a keyword: ``origin`` and ``up`` still name attrs and shapes."""
    source = tmp_path / "g.bgr"
    source.write_text(
        'attr origin = 3\nLot --> extrude(world.up, origin) up\nup --> color("#ffffff")\n'
    )
    grammar = bgr.load(source)
    assert grammar.site is None
    assert len(bgr.derive(grammar, lot=(4, 4)).terminals) == 1


def test_format_keeps_every_digit():
    text = 'site "EPSG:2056" origin (2682812.123456, -1247000.5, 0.001) up z\n'
    assert bgr.format_source(text) == text


def test_site_and_placed_lots_conflict(tmp_path):
    """Lots in longitude/latitude carry their own site: a grammar may not declare another."""
    lots = tmp_path / "lots.geojson"
    ring = [[8.54, 47.37], [8.5402, 47.37], [8.5402, 47.3701], [8.54, 47.3701], [8.54, 47.37]]
    polygon = {"type": "Polygon", "coordinates": [ring]}
    feature = {"type": "Feature", "properties": {}, "geometry": polygon}
    lots.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    source = tmp_path / "g.bgr"
    source.write_text("site origin (1, 2, 3) up z\nterminal Mass\nLot --> extrude(10) Mass\n")
    with pytest.raises(BgrError, match="only one can say where the output lies") as caught:
        bgr.derive(source, lot=str(lots))
    assert "g.bgr:1:" in str(caught.value)
    plain = tmp_path / "plain.bgr"
    plain.write_text("terminal Mass\nLot --> extrude(10) Mass\n")
    site = bgr.derive(plain, lot=str(lots)).terminals.site
    assert site["up"] == "z" and site["crs"].startswith("EPSG:326")


def test_cityjson_input_keeps_its_crs(tmp_path):
    """A CityJSON tile in EPSG:2056 comes back in EPSG:2056, schema-valid, where it was."""
    corners = [[x, y, z] for z in (0, 1) for x, y in ((0, 0), (1, 0), (1, 1), (0, 1))]
    # outward rings of a unit cube: bottom, top, then the four sides
    rings = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
    doc = {
        "type": "CityJSON",
        "version": "2.0",
        "transform": {"scale": [0.001, 0.001, 0.001], "translate": [EAST, NORTH, HEIGHT]},
        "metadata": {"referenceSystem": "https://www.opengis.net/def/crs/EPSG/0/2056"},
        "CityObjects": {
            "b1": {
                "type": "Building",
                "geometry": [{"type": "Solid", "lod": "2", "boundaries": [[[r] for r in rings]]}],
            }
        },
        "vertices": [[x * 12000, y * 9000, z * 10000] for x, y, z in corners],
    }
    source = tmp_path / "tile.city.json"
    source.write_text(json.dumps(doc))
    assert main(["infer", str(source), "-o", str(tmp_path / "t.bgr")]) == 0
    assert bgr.load(tmp_path / "t.bgr").site.crs == "EPSG:2056"
    out = tmp_path / "out.city.json"
    assert main(["derive", str(tmp_path / "t.bgr"), "-o", str(out)]) == 0
    assert schema_errors(out) == []
    back = json.loads(out.read_text())
    assert back["metadata"]["referenceSystem"] == "https://www.opengis.net/def/crs/EPSG/0/2056"
    t = back["transform"]
    v = np.array(back["vertices"]) * t["scale"] + t["translate"]
    assert v.min(axis=0) == pytest.approx([EAST, NORTH, HEIGHT], abs=0.001)
    assert v.max(axis=0) == pytest.approx([EAST + 12, NORTH + 9, HEIGHT + 10], abs=0.001)
