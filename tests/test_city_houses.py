"""Inferred buildings that are houses, walls on a footprint under a roof: written as
``polygon() extrude() comp(f) { top: roof(kind, pitch, overhang) }``, checked against the input
(issue 29: "roofs by roof(kind, pitch, overhang) on that footprint")."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh
from test_city_infer import gable_house
from test_city_prisms import component

from bgr.inverse.city.houses import fit_house, house_mesh

TOL = 0.01

# one house a lot: each roof kind, with and without eaves, on rectangles, an L and a square
HOUSES = [
    ("rect", "gable", 35, 0.4, 6),
    ("rect", "hip", 30, 0.4, 9),
    ("L", "gable", 40, 0.0, 6),
    ("L", "hip", 25, 0.3, 6),
    ("square", "pyramid", 45, 0.0, 7),
    ("rect", "shed", 15, 0.0, 4),
    ("square", "gable", 30, 0.5, 5),
]


def street_grammar() -> str:
    cases = []
    for i, (shape, kind, pitch, overhang, height) in enumerate(HOUSES):
        plan = {"rect": "", "L": "footprint(L, 0.5, 0.5) ", "square": "s(10, 0, 10) "}[shape]
        body = f"{plan}extrude({height}) comp(f) {{ side: Wall | top: roof({kind}, {pitch}, "
        body += f"{overhang}) Roof }}"
        cases.append(f"n == {i}: {body}")
    rules = "Lot --> case " + "\n    | case ".join(cases) + "\n    | else: NIL\n"
    return "version 1\nterminal Wall, Roof\nattr n = 0\n" + rules


def lots_geojson(path: Path) -> None:
    features = []
    for i, _ in enumerate(HOUSES):
        x, y = 1000.0 + 30 * i, 1000.0
        ring = [[x, y], [x + 16, y], [x + 16, y + 12], [x, y + 12], [x, y]]
        features.append(
            {
                "type": "Feature",
                "properties": {"n": i},
                "geometry": {"type": "Polygon", "coordinates": [ring]},
            }
        )
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))


def bgr(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "bgr", *args], check=True, capture_output=True)


def surface_distance(a: trimesh.Trimesh, b: trimesh.Trimesh) -> float:
    worst = 0.0
    for x, y in ((a, b), (b, a)):
        points, _ = trimesh.sample.sample_surface(x, 5000, seed=0)
        points = np.vstack([points, x.vertices])
        _, distance, _ = trimesh.proximity.closest_point(y, points)
        worst = max(worst, float(distance.max()))
    return worst


@pytest.fixture(scope="module")
def street(tmp_path_factory):
    """A street of bgr's own houses derived to OBJ, inferred, and the grammar derived back."""
    folder = tmp_path_factory.mktemp("houses")
    (folder / "street.bgr").write_text(street_grammar())
    lots_geojson(folder / "lots.geojson")
    bgr("derive", str(folder / "street.bgr"), "--lot", str(folder / "lots.geojson"), "-o",
        str(folder / "street.obj"))  # fmt: skip
    bgr("infer", str(folder / "street.obj"), "--kind", "city", "-o", str(folder / "city.bgr"))
    bgr("derive", str(folder / "city.bgr"), "-o", str(folder / "back.obj"))
    return folder


def test_every_house_is_written_as_its_operations(street):
    text = (street / "city.bgr").read_text()
    written = re.findall(r"roof\((\w+), ([\d.]+)(?:, ([\d.]+))?\)", text)
    got = sorted((kind, float(pitch), float(over or 0)) for kind, pitch, over in written)
    # a square's pyramid is its hip roof: either name makes it
    kinds = {("square", "pyramid"): "hip"}
    want = sorted(
        (kinds.get((shape, kind), kind), float(pitch), float(over))
        for shape, kind, pitch, over, _ in HOUSES
    )
    assert got == want
    assert "asset " not in text and not (street / "city.assets" / "meshes.glb").exists()
    assert "7 houses (polygon, extrude, roof)" in text


def test_the_grammar_derives_back_onto_the_street(street):
    given = trimesh.load(street / "street.obj", force="mesh", process=False)
    back = trimesh.load(street / "back.obj", force="mesh", process=False)
    assert surface_distance(given, back) <= TOL
    assert back.area == pytest.approx(given.area, rel=0.01)


def test_a_house_fit_carries_its_colours_and_rebuilds_the_mesh():
    fitted = fit_house(_derived_house(), TOL)
    assert fitted is not None
    found = fitted.house
    assert found.kind == "gable"
    assert found.height == pytest.approx(5.0) and found.overhang == pytest.approx(0.3)
    assert found.pitch == pytest.approx(33.0)
    assert found.colors == {"side": "#d8cbb0", "roof": "#8a4b3c"}
    mesh = trimesh.Trimesh(fitted.vertices, fitted.faces, process=False)
    assert surface_distance(mesh, house_mesh(found)) <= TOL


def _derived_house():
    """A gable house with 0.3 m eaves as bgr derives it, its faces coloured, as a component."""
    import bgr as package

    src = (
        'version 1\nterminal Wall, Roof\nLot --> extrude(5) comp(f) { side: color("#d8cbb0") '
        'Wall | top: roof(gable, 33, 0.3) color("#8a4b3c") Roof }\n'
    )
    mesh = package.derive(package.load(src), lot=(10.0, 8.0)).mesh
    made = component(trimesh.Trimesh(mesh.vertices, mesh.faces, process=False))
    made.colors = np.asarray(mesh.visual.face_colors, dtype=np.uint8)
    return made


@pytest.mark.parametrize(
    "mesh",
    [
        gable_house(10, 8, 5),  # its box keeps a flat top under the roof: not a bgr house
        trimesh.creation.box(bounds=[[0, 0, 0], [10, 20, 10]]),  # no roof: a prism
        trimesh.creation.icosphere(),  # nothing upright
    ],
)
def test_what_is_not_a_house_keeps_its_components(mesh):
    assert fit_house(component(mesh), TOL) is None
