"""Every bundled example derives, writes a GLB that loads back, and does so identically twice."""

import json
import subprocess
import sys

import pytest
from conftest import ROOT

from bgr.formats import read_glb

EXAMPLES = [
    ("house.bgr", []),
    ("tower.bgr", []),
    ("city_block.bgr", []),
    ("textured_house.bgr", []),
    ("l_building.bgr", ["--lot", str(ROOT / "examples" / "l_lot.geojson")]),
    ("house.bgr", ["--lot", str(ROOT / "examples" / "block.geojson")]),
]


def derive(tmp_path, name, extra, out="out.glb"):
    target = tmp_path / out
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "bgr",
            "derive",
            str(ROOT / "examples" / name),
            "--seed",
            "3",
            "-o",
            str(target),
            *extra,
        ],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr
    return target


@pytest.mark.parametrize(
    "name, extra", EXAMPLES, ids=[f"{n}{'+lot' if e else ''}" for n, e in EXAMPLES]
)
def test_example_derives_to_a_glb_that_loads(tmp_path, name, extra):
    first = derive(tmp_path, name, extra, "a.glb")
    second = derive(tmp_path, name, extra, "b.glb")
    assert first.read_bytes() == second.read_bytes()
    mesh = read_glb(first)
    assert len(mesh.faces) > 100
    assert mesh.bounds[1][1] > 5  # buildings have height


def test_house_terminal_list_is_byte_identical_and_labelled(tmp_path):
    a = derive(tmp_path, "house.bgr", [], "a.json")
    b = derive(tmp_path, "house.bgr", [], "b.json")
    assert a.read_bytes() == b.read_bytes()
    data = json.loads(a.read_text())
    labels = {t["label"] for t in data["terminals"]}
    assert {"Roof", "Glass", "Wall", "Door"} <= labels
    assert data["seed"] == 3 and data["attrs"]["height"] == 11


def test_geojson_lots_get_their_own_heights(tmp_path):
    out = derive(
        tmp_path, "house.bgr", ["--lot", str(ROOT / "examples" / "block.geojson")], "block.json"
    )
    data = json.loads(out.read_text())
    tops = {}
    for t in data["terminals"]:
        lot = t["path"].split("/")[0]
        tops[lot] = max(tops.get(lot, 0), t["origin"][1])
    assert len(tops) == 3
    assert tops["Lot.0"] < tops["Lot.2"] < tops["Lot.1"]  # heights 9, 15, 12
