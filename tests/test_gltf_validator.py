"""Every glTF bgr writes passes the official Khronos glTF validator with no error and no warning,
and every reader counts the same triangles (issue 11).

The validator is the npm package ``gltf-validator`` (pinned in tests/gltf_validator/package.json)
run by tests/gltf_validator/validate.js on Node.  When Node is present but the package is not
installed yet, the first test installs it from the npm registry (``npm install`` in that folder);
the tests skip, saying why, only where Node or npm is absent.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pygltflib
import pytest
import trimesh
from conftest import ROOT

import bgr
from bgr.formats import read_glb, write

VALIDATOR = ROOT / "tests" / "gltf_validator"
SHARED = ROOT.parent / "shared"
HELSINKI = SHARED / "data" / "footprints" / "helsinki_osm_buildings.geojson"
GRID_CITY = SHARED / "bench" / "grid_city.bgr"
EXAMPLES = ROOT / "examples"

# (name, grammar, lot, seed, attrs): every example as the README and docs derive it
CASES = [
    ("house", EXAMPLES / "house.bgr", None, 3, {}),
    ("textured_house", EXAMPLES / "textured_house.bgr", None, 3, {}),
    ("tower", EXAMPLES / "tower.bgr", None, 1, {}),
    ("city_block", EXAMPLES / "city_block.bgr", None, 2, {}),
    ("l_building", EXAMPLES / "l_building.bgr", str(EXAMPLES / "l_lot.geojson"), 1, {}),
    ("house_block", EXAMPLES / "house.bgr", str(EXAMPLES / "block.geojson"), 1, {}),
    ("stdlib_street", EXAMPLES / "stdlib_street.bgr", str(EXAMPLES / "block.geojson"), 5, {}),
    ("corner_shop", EXAMPLES / "captured" / "corner_shop.bgr", None, 1, {}),
]


@pytest.fixture(scope="module")
def validator() -> Path:
    node, npm = shutil.which("node"), shutil.which("npm")
    if node is None or npm is None:
        pytest.skip("Node.js and npm are not installed: the Khronos glTF validator runs on Node")
    wanted = json.loads((VALIDATOR / "package.json").read_text())["dependencies"]
    if not all((VALIDATOR / "node_modules" / name).is_dir() for name in wanted):
        proc = subprocess.run(
            [npm, "install", "--no-audit", "--no-fund", "--loglevel=error"],
            cwd=VALIDATOR,
            capture_output=True,
            text=True,
            timeout=600,
        )
        assert proc.returncode == 0, f"npm install in {VALIDATOR} failed:\n{proc.stderr}"
    return Path(node)


def validate(node: Path, paths: list[Path]) -> dict[str, dict]:
    """The validator's report of each file, by path."""
    proc = subprocess.run(
        [str(node), str(VALIDATOR / "validate.js"), *map(str, paths)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr
    reports = [json.loads(line) for line in proc.stdout.splitlines()]
    return {r["file"]: r for r in reports}


def pygltflib_triangles(path: Path) -> int:
    """Triangles by pygltflib's reading of the JSON: POSITION counts / 3, times instances."""
    doc = pygltflib.GLTF2().load(str(path))
    total = 0
    for node in doc.nodes:
        if node.mesh is None:
            continue
        copies = 1
        ext = (node.extensions or {}).get("EXT_mesh_gpu_instancing")
        if ext:
            copies = doc.accessors[next(iter(ext["attributes"].values()))].count
        for prim in doc.meshes[node.mesh].primitives:
            total += doc.accessors[prim.attributes.POSITION].count // 3 * copies
    return total


def clean(report: dict) -> str:
    """The validator's messages, for an assertion's explanation."""
    return "\n".join(f"{m['code']} {m['pointer']}: {m['message']}" for m in report["messages"])


def test_every_example_validates_and_readers_agree(validator, tmp_path):
    written, triangles = [], {}
    for name, grammar, lot, seed, attrs in CASES:
        result = bgr.derive(grammar, seed=seed, lot=lot, attrs=attrs)
        for variant, options in (
            ("", {}),
            ("-instanced", {"instancing": "auto"}),
            ("-by-label", {"group_by": "label"}),
            ("-flat", {"group_by": "none"}),
        ):
            path = tmp_path / f"{name}{variant}.glb"
            write(result.terminals, path, seed=seed, attrs=result.attrs, gltf=options)
            written.append(path)
            triangles[str(path)] = result.terminals.triangle_count()
        gltf = tmp_path / f"{name}.gltf"
        write(result.terminals, gltf, seed=seed, attrs=result.attrs)
        written.append(gltf)
        triangles[str(gltf)] = result.terminals.triangle_count()

    reports = validate(validator, written)
    for path in written:
        report = reports[str(path)]
        assert report["errors"] == 0 and report["warnings"] == 0, f"{path.name}:\n{clean(report)}"
        expected = triangles[str(path)]
        if "instanced" not in path.name:  # the validator does not count instances
            assert report["totalTriangleCount"] == expected, path.name
            # a reader that knows no extension at all sees everything
            assert len(trimesh.load(path, force="mesh", process=False).faces) == expected
        assert pygltflib_triangles(path) == expected, path.name
        assert len(read_glb(path).faces) == expected, path.name


def test_grid_city_validates(validator, tmp_path):
    if not GRID_CITY.exists():
        pytest.skip(f"{GRID_CITY} is absent (the shared benchmark inputs)")
    result = bgr.derive(GRID_CITY, seed=0, attrs={"n": 4})
    path = tmp_path / "grid.glb"
    write(result.terminals, path, seed=0, attrs=result.attrs)
    report = validate(validator, [path])[str(path)]
    assert report["errors"] == 0 and report["warnings"] == 0, clean(report)
    assert report["totalTriangleCount"] == result.terminals.triangle_count()
    doc = pygltflib.GLTF2().load(str(path))
    (lot,) = (doc.nodes[i] for i in doc.nodes[0].children)  # one lot, split into a grid
    assert lot.name == "lot-0" and len(lot.children) >= 3  # its labels


@pytest.mark.slow
def test_helsinki_street_validates_with_a_node_per_footprint(validator, tmp_path):
    if not HELSINKI.exists():
        pytest.skip(f"{HELSINKI} is absent (the shared real-data folder)")
    result = bgr.derive(EXAMPLES / "house.bgr", seed=1, lot=str(HELSINKI))
    path = tmp_path / "helsinki.glb"
    write(result.terminals, path, seed=1, attrs=result.attrs)
    report = validate(validator, [path])[str(path)]
    assert report["errors"] == 0 and report["warnings"] == 0, clean(report)
    assert report["totalTriangleCount"] == result.terminals.triangle_count()
    doc = pygltflib.GLTF2().load(str(path))
    lots = [doc.nodes[i] for i in doc.nodes[0].children]
    assert len(lots) == len(result.terminals.lots) > 400
    features = json.loads(HELSINKI.read_text())["features"]
    ids = {str(f["properties"]["id"]) for f in features if f["properties"].get("id") is not None}
    # a MultiPolygon's parts are lots of their own, named "ID-PART"
    assert {lot.name.rsplit("-", 1)[0] if lot.name not in ids else lot.name for lot in lots} <= ids
    assert len({lot.name for lot in lots}) == len(lots)
    assert all("properties" in lot.extras and "attrs" in lot.extras for lot in lots)


def test_the_stdlib_street_has_one_named_node_per_footprint_with_its_attrs(tmp_path):
    """`bgr derive examples/stdlib_street.bgr --lot examples/block.geojson -o s.glb`: the root
    ``bgr`` (grammar, seed, attrs), a node per footprint named ``lot-N`` whose extras hold its
    attrs and properties, and under each a node per terminal label."""
    result = bgr.derive(EXAMPLES / "stdlib_street.bgr", seed=5, lot=str(EXAMPLES / "block.geojson"))
    path = tmp_path / "s.glb"
    write(result.terminals, path, seed=5, attrs=result.attrs)
    doc = pygltflib.GLTF2().load(str(path))
    (root,) = doc.scenes[doc.scene].nodes
    root = doc.nodes[root]
    assert root.name == "bgr"
    assert root.extras["grammar"].endswith("stdlib_street.bgr")
    assert root.extras["seed"] == 5 and root.extras["attrs"] == result.attrs
    features = json.loads((EXAMPLES / "block.geojson").read_text())["features"]
    lots = [doc.nodes[i] for i in root.children]
    assert [lot.name for lot in lots] == [f"lot-{i}" for i in range(len(features))]
    for lot, feature in zip(lots, features, strict=True):
        assert lot.extras["properties"] == feature["properties"]
        assert lot.extras["attrs"]["height"] == feature["properties"]["height"]
        labels = [doc.nodes[i].name for i in lot.children]
        assert labels == sorted(set(labels)) and "Wall" in labels
        assert all(doc.nodes[i].mesh is not None for i in lot.children)
    # every terminal is under exactly one label node of its own lot
    table = result.terminals
    per_lot = [
        sum(
            doc.accessors[p.attributes.POSITION].count // 3
            for i in lot.children
            for p in doc.meshes[doc.nodes[i].mesh].primitives
        )
        for lot in lots
    ]
    faces = np.array([len(m.faces) for m in table.library.meshes])[table.mesh]
    assert per_lot == [int(faces[slice(*lot["rows"])].sum()) for lot in table.lots]
    # materials are shared across the file, not repeated per lot
    keys = [(m.name, tuple(m.pbrMetallicRoughness.baseColorFactor)) for m in doc.materials]
    assert len(keys) == len(set(keys))
