"""An inferred city as small as its input allows (issue 29): buildings that no cut helps kept
whole, the objects that are not buildings one mesh a kind, and the assets file quantized and
meshopt-compressed, read back by bgr and by an independent reader (glTF-Transform with
meshoptimizer's own decoder) as it was written."""

from __future__ import annotations

import json
import shutil
import struct
import subprocess
import sys

import numpy as np
import pytest
import trimesh
from test_city_infer import box, gable_house, infer_scene
from test_gltf_validator import VALIDATOR, clean, validate, validator  # noqa: F401  (a fixture)

from bgr.formats.glb_read import load, named_meshes
from bgr.grammar.errors import BgrError
from bgr.inverse.city.container import Mesh, pack
from bgr.inverse.city.model import CityObject, CityScene
from bgr.inverse.city.pipeline import rebuilt

STEP = 0.001


def terrain(size: float = 500.0, cells: int = 25) -> trimesh.Trimesh:
    """A bumpy square of ``size`` metres: too large for 16 bits of millimetres."""
    xs = np.linspace(0, size, cells + 1)
    gx, gz = np.meshgrid(xs, xs)
    gy = np.round(0.5 * np.sin(gx / 37) * np.cos(gz / 23), 3)
    vertices = np.column_stack([gx.ravel(), gy.ravel(), gz.ravel()])
    k = np.arange(cells * (cells + 1)).reshape(cells, cells + 1)[:, :cells].ravel()
    faces = np.concatenate(
        [
            np.column_stack([k, k + cells + 1, k + 1]),
            np.column_stack([k + 1, k + cells + 1, k + cells + 2]),
        ]
    )
    return trimesh.Trimesh(vertices, faces, process=False)


def meshes() -> list[Mesh]:
    roof = gable_house(8, 10, 6)
    ground = terrain()
    return [
        Mesh("type1", np.round(roof.vertices, 3), roof.faces),
        Mesh("object2", box(0, 0, 0, 2, 1, 3).vertices, box(0, 0, 0, 2, 1, 3).faces),
        Mesh("object3", ground.vertices, ground.faces, extras={"objects": [["ground", 0]]}),
    ]


def triangles(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """A mesh's triangles as sorted rows of corner coordinates (order and numbering ignored)."""
    corners = np.round(np.asarray(vertices)[np.asarray(faces)], 6)
    rows = np.array([sorted(map(tuple, t)) for t in corners]).reshape(len(corners), 9)
    return rows[np.lexsort(rows.T[::-1])]


def test_compressed_assets_hold_the_same_triangles_as_plain_ones(tmp_path):
    plain, packed = tmp_path / "plain.glb", tmp_path / "packed.glb"
    plain.write_bytes(pack(meshes()))
    packed.write_bytes(pack(meshes(), compress=True, step=STEP, coarsest=0.0025))
    assert packed.stat().st_size < 0.6 * plain.stat().st_size
    a, b = named_meshes(*load(plain)), named_meshes(*load(packed))
    assert sorted(a) == sorted(b) == ["object2", "object3", "type1"]
    for name in a:
        ta, tb = triangles(*a[name]), triangles(*b[name])
        assert ta.shape == tb.shape
        # on the grid: exact; the large terrain's floats through the exponential filter: within
        # half a step
        assert np.abs(ta - tb).max() <= (STEP / 2 if name == "object3" else 1e-6), name
    head = json.loads(
        packed.read_bytes()[20 : 20 + struct.unpack("<I", packed.read_bytes()[12:16])[0]]
    )
    assert head["extensionsRequired"] == ["EXT_meshopt_compression", "KHR_mesh_quantization"]
    node = {n["name"]: n for n in head["nodes"]}
    assert node["type1"]["scale"] == [STEP] * 3  # 16-bit millimetres
    assert "scale" not in node["object3"]  # 500 m: float positions
    assert node["object3"]["extras"] == {"objects": [["ground", 0]]}
    filters = [
        v["extensions"]["EXT_meshopt_compression"].get("filter") for v in head["bufferViews"]
    ]
    assert "EXPONENTIAL" in filters


def test_compressed_assets_are_valid_and_an_independent_reader_agrees(validator, tmp_path):  # noqa: F811
    path = tmp_path / "meshes.glb"
    path.write_bytes(pack(meshes(), compress=True, step=STEP, coarsest=0.0025))
    report = validate(validator, [path])[str(path)]
    assert report["errors"] == 0 and report["warnings"] == 0, clean(report)
    node = shutil.which("node")
    run = subprocess.run(
        [node, str(VALIDATOR / "meshes.js"), str(path)], capture_output=True, text=True, timeout=120
    )
    assert run.returncode == 0, run.stderr
    theirs = {}
    for line in run.stdout.splitlines():
        found = json.loads(line)
        theirs[found["name"]] = (
            np.array(found["positions"]).reshape(-1, 3),
            np.array(found["indices"]).reshape(-1, 3),
        )
    ours = named_meshes(*load(path))
    assert sorted(theirs) == sorted(ours)
    for name, mesh in ours.items():
        # float32 arithmetic in the other reader: a micrometre
        assert np.abs(triangles(*theirs[name]) - triangles(*mesh)).max() < 2e-6, name


@pytest.mark.parametrize(
    "change",
    [
        ("mode", "FAST"),
        ("filter", "ZIP"),
        ("count", 10**12),
        ("count", 7),
        ("byteStride", 3),
        ("byteLength", 10**9),
        ("count", 3 * 10**7),
        ("buffer", 5),
    ],
)
def test_a_hostile_compressed_view_is_a_located_error(tmp_path, change):
    data = pack(meshes(), compress=True, step=STEP, coarsest=0.0025)
    length = struct.unpack("<I", data[12:16])[0]
    head = json.loads(data[20 : 20 + length])
    key, value = change
    head["bufferViews"][-1]["extensions"]["EXT_meshopt_compression"][key] = value
    text = json.dumps(head).encode()
    text += b" " * (-len(text) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text + data[20 + length :]
    path = tmp_path / "bad.glb"
    path.write_bytes(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
    with pytest.raises(BgrError, match="bufferView"):
        named_meshes(*load(path))


def test_corrupt_compressed_bytes_never_raise_anything_but_a_bgr_error(tmp_path):
    data = bytearray(pack(meshes(), compress=True, step=STEP, coarsest=0.0025))
    start = 20 + struct.unpack("<I", data[12:16])[0] + 8  # the BIN chunk's first byte
    rng = np.random.default_rng(7)
    refused = 0
    for trial in range(200):
        bad = bytearray(data)
        for at in rng.integers(start, len(bad), size=int(rng.integers(1, 12))):
            bad[at] = int(rng.integers(0, 256))
        path = tmp_path / f"bad{trial}.glb"
        path.write_bytes(bytes(bad))
        try:
            named_meshes(*load(path))
        except BgrError:
            refused += 1
    assert refused > 0  # some corruptions break the codes; none may crash the reader


# ---- whole buildings and carried kinds ---------------------------------------------------------


def tower_on_podium(shift: float) -> trimesh.Trimesh:
    """A podium and a narrower gabled tower on it (cut at the podium's roof and the eaves), each
    ``shift`` metres larger than the first's."""
    tower = gable_house(6 + shift / 3, 6, 14 + shift)
    tower.apply_translation([3, 5, 2])
    return trimesh.util.concatenate([box(0, 0, 0, 12 + shift, 5, 10), tower])


def scene(objects: list[trimesh.Trimesh], kinds: list[str] | None = None) -> CityScene:
    found, x = [], 0.0
    for k, m in enumerate(objects):
        m = m.copy()
        m.apply_translation([x, 0, 0])
        x += m.extents[0] + 5
        kind = kinds[k] if kinds else "object"
        found.append(CityObject(f"o{k}", kind, m.vertices, m.faces, proceduralize=kind == "object"))
    return CityScene(found, "city.obj", "y")


def test_a_building_whose_slabs_are_all_unique_is_kept_whole(tmp_path):
    city = scene([tower_on_podium(0), tower_on_podium(3)])
    grammar, _ = infer_scene(city, tmp_path)
    placed = grammar.placed
    assert placed.components == 2  # one a building, where cutting made three unique slabs each
    built_v, built_f = rebuilt(placed)
    assert len(built_f) == sum(len(o.faces) for o in city.objects)  # no triangle clipped
    assert trimesh.Trimesh(built_v, built_f).area == pytest.approx(
        sum(trimesh.Trimesh(o.vertices, o.faces).area for o in city.objects), rel=1e-9
    )


def test_repeated_slabs_keep_their_cuts(tmp_path):
    # two copies of a building: each slab has another instance, so the cuts pay
    city = scene([tower_on_podium(0), tower_on_podium(0)])
    grammar, _ = infer_scene(city, tmp_path)
    assert grammar.placed.components == 6
    assert len(grammar.placed.terminals) == 3


def test_objects_that_are_not_buildings_are_one_mesh_a_kind(tmp_path):
    roads = [box(0, 0, 0, 30, 0.2, 4), box(0, 0, 0, 4, 0.2, 40), box(0, 0, 0, 20, 0.2, 3)]
    water = [box(0, -1, 0, 25, 0, 25)]
    city = scene(
        [gable_house(8, 10, 6), *roads, *water], ["object", "Road", "Road", "Road", "WaterBody"]
    )
    grammar, text = infer_scene(city, tmp_path)
    assert [c.terminal.name for c in grammar.placed.carried] == ["Object1", "Object2"]
    assert "Road: 3 objects, carried as they are" in text
    nodes = named_meshes(*load(tmp_path / "city.assets" / "meshes.glb"))
    assert len(nodes["object1"][1]) == sum(len(m.faces) for m in roads)
    data = (tmp_path / "city.assets" / "meshes.glb").read_bytes()
    head = json.loads(data[20 : 20 + struct.unpack("<I", data[12:16])[0]])
    extras = {n["name"]: n.get("extras") for n in head["nodes"]}
    assert extras["object1"] == {"objects": [["o1", 0], ["o2", 12], ["o3", 24]]}
    # every carried triangle comes back where it was
    built_v, built_f = rebuilt(grammar.placed)
    assert len(built_f) == sum(len(o.faces) for o in city.objects)


def two_lods(path) -> None:
    """A CityJSON building with an LoD 1.2 block and an LoD 2.2 gabled house."""
    block, house = box(0, 0, 0, 8, 6, 10), gable_house(8, 10, 6)

    def solid(mesh: trimesh.Trimesh, base: int) -> list:
        return [[[[int(a) + base, int(b) + base, int(c) + base]] for a, b, c in mesh.faces]]

    # bgr's y up is CityJSON's z up: (x, y, z) -> (x, -z, y)
    def points(mesh: trimesh.Trimesh) -> list:
        return [[float(x), float(-z), float(y)] for x, y, z in mesh.vertices]

    doc = {
        "type": "CityJSON",
        "version": "2.0",
        "transform": {"scale": [0.001, 0.001, 0.001], "translate": [0, 0, 0]},
        "CityObjects": {
            "house": {
                "type": "Building",
                "geometry": [
                    {"type": "Solid", "lod": "1.2", "boundaries": solid(block, 0)},
                    {
                        "type": "Solid",
                        "lod": "2.2",
                        "boundaries": solid(house, len(block.vertices)),
                    },
                ],
            }
        },
        "vertices": [[round(c * 1000) for c in p] for p in points(block) + points(house)],
    }
    path.write_text(json.dumps(doc))


def test_lod_picks_the_level_of_detail_inferred(tmp_path, capsys):
    from bgr.cli import main

    city = tmp_path / "two.city.json"
    two_lods(city)
    assert main(["infer", str(city), "--lod", "1.2", "-o", str(tmp_path / "a.bgr")]) == 0
    assert "1 footprints extruded" in capsys.readouterr().err
    assert "polygon(" in (tmp_path / "a.bgr").read_text()
    assert main(["infer", str(city), "-o", str(tmp_path / "b.bgr")]) == 0
    assert "0 footprints extruded" in capsys.readouterr().err  # 2.2, the highest: a mesh
    assert main(["infer", str(city), "--lod", "3", "-o", str(tmp_path / "c.bgr")]) == 1
    assert "lod 3; the file has lods 1.2, 2.2" in capsys.readouterr().err
    assert not (tmp_path / "c.bgr").exists()
    obj = tmp_path / "one.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert main(["infer", str(obj), "--lod", "1.2", "-o", str(tmp_path / "d.bgr")]) == 1
    assert "level of detail" in capsys.readouterr().err


def test_position_bounds_are_the_decoded_values(tmp_path):
    """glTF wants an accessor's min and max to be its data's: for quantized and filtered views,
    the values a reader decodes, not the floats before the filter."""
    from bgr.formats.glb_read import accessor

    path = tmp_path / "meshes.glb"
    path.write_bytes(pack(meshes(), compress=True, step=STEP, coarsest=0.0025))
    gltf, blob = load(path)
    for mesh in gltf["meshes"]:
        index = mesh["primitives"][0]["attributes"]["POSITION"]
        values = accessor(gltf, blob, index).astype(np.float32)
        acc = gltf["accessors"][index]
        assert values.min(axis=0).tolist() == [np.float32(v) for v in acc["min"]]
        assert values.max(axis=0).tolist() == [np.float32(v) for v in acc["max"]]


@pytest.mark.parametrize(
    ("ctype", "normalized", "scale"), [(5122, True, 32767.0), (5121, False, 1.0)]
)
def test_quantized_positions_are_read_only_where_the_file_says_so(
    tmp_path, ctype, normalized, scale
):
    """KHR_mesh_quantization: integer positions (normalized ones mapped to [-1, 1] as glTF
    states, then the node's scale); without the extension in extensionsUsed, an error that says
    what is missing."""
    from test_gltf_hostile import INDICES, box, glb

    doc, _ = box()
    cells = np.array([[x, y, z] for x in (0, 10) for y in (0, 8) for z in (0, 12)])
    width = 2 if ctype == 5122 else 1
    rows = np.column_stack([cells, np.zeros(8, int)]).astype("<i2" if width == 2 else "u1")
    pos = rows.tobytes()
    doc["bufferViews"][0] |= {"byteLength": len(pos), "byteStride": 4 * width}
    doc["bufferViews"][1] |= {"byteOffset": len(pos)}
    doc["buffers"][0]["byteLength"] = len(pos) + INDICES.nbytes
    doc["accessors"][0] |= {"componentType": ctype, "normalized": normalized}
    doc["nodes"][0]["scale"] = [scale] * 3
    path = tmp_path / "q.glb"
    path.write_bytes(glb(doc, pos + INDICES.tobytes()))
    with pytest.raises(BgrError, match="KHR_mesh_quantization"):
        named_meshes(*load(path))
    doc["extensionsUsed"] = ["KHR_mesh_quantization"]
    path.write_bytes(glb(doc, pos + INDICES.tobytes()))
    vertices, faces = named_meshes(*load(path))["house"]
    assert len(faces) == 12
    np.testing.assert_allclose(vertices.min(axis=0), [0, 0, 0], atol=1e-9)
    np.testing.assert_allclose(vertices.max(axis=0), [10, 8, 12], atol=1e-9)


def test_a_tiny_file_cannot_claim_gigabytes_of_decoded_data(tmp_path):
    """A view whose count and byteLength agree but are far beyond what its codes can hold, and
    a fallback buffer that claims far more than its views: refused before any allocation."""
    data = pack(meshes(), compress=True, step=STEP, coarsest=0.0025)
    length = struct.unpack("<I", data[12:16])[0]

    def saved(head: dict) -> object:
        text = json.dumps(head).encode()
        text += b" " * (-len(text) % 4)
        body = struct.pack("<II", len(text), 0x4E4F534A) + text + data[20 + length :]
        path = tmp_path / "big.glb"
        path.write_bytes(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
        return path

    head = json.loads(data[20 : 20 + length])
    view = head["bufferViews"][-1]
    ext = view["extensions"]["EXT_meshopt_compression"]
    ext["count"] = 50_000_000
    view["byteLength"] = ext["count"] * ext["byteStride"]
    head["buffers"][1]["byteLength"] = view.get("byteOffset", 0) + view["byteLength"]
    with pytest.raises(BgrError, match="cannot hold"):
        named_meshes(*load(saved(head)))
    head = json.loads(data[20 : 20 + length])
    head["buffers"][1]["byteLength"] = 1 << 31
    with pytest.raises(BgrError, match="more than its compressed views fill"):
        named_meshes(*load(saved(head)))


# ---- surfaces of a format without types --------------------------------------------------------


def write_obj(path, named: list[tuple[str, trimesh.Trimesh]]) -> None:
    """An OBJ of named objects, z up as GIS exports are (bgr's y up turned: (x, y, z) ->
    (x, -z, y))."""
    lines, base = [], 1
    for name, mesh in named:
        lines.append(f"o {name}")
        lines += [f"v {x:.3f} {-z:.3f} {y:.3f}" for x, y, z in mesh.vertices]
        lines += [f"f {a + base} {b + base} {c + base}" for a, b, c in mesh.faces]
        base += len(mesh.vertices)
    path.write_text("\n".join(lines) + "\n")


def test_objects_without_walls_in_an_obj_are_carried_as_surfaces(tmp_path):
    """An OBJ says nothing of types: its roads and terrain (faces no steeper than 60 degrees on
    all but 5 % of their area) are carried like CityJSON's, one mesh for all, and its
    buildings are proceduralized."""
    from bgr.inverse.city.read import read_city

    ground = terrain(60.0, 6)
    ground.apply_translation([-10, -1, -10])
    road = box(0, 0, 20, 40, 0.0, 24)  # a flat slab: top and bottom, walls of no area
    road = trimesh.Trimesh(road.vertices, road.faces[road.area_faces > 0])
    named = [
        ("house", gable_house(8, 10, 6)),
        ("ground", ground),
        ("road", road),
        ("block", box(20, 0, 0, 30, 9, 12)),
    ]
    obj = tmp_path / "city.obj"
    write_obj(obj, named)
    city = read_city(obj)
    kinds = {o.name: (o.kind, o.proceduralize) for o in city.objects}
    assert kinds == {
        "house": ("object", True),
        "ground": ("surface", False),
        "road": ("surface", False),
        "block": ("object", True),
    }
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "bgr",
            "infer",
            str(obj),
            "--no-progress",
            "-o",
            str(tmp_path / "out.bgr"),
        ],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr
    assert "surface: 2 objects, carried as they are" in (tmp_path / "out.bgr").read_text()
    data = (tmp_path / "out.assets" / "meshes.glb").read_bytes()
    head = json.loads(data[20 : 20 + struct.unpack("<I", data[12:16])[0]])
    carried = [n["extras"]["objects"] for n in head["nodes"] if "extras" in n]
    assert [[name for name, _ in objects] for objects in carried] == [["ground", "road"]]
    # and level 0 still derives every triangle back where it was
    out = tmp_path / "out.obj"
    proc = subprocess.run(
        [sys.executable, "-m", "bgr", "derive", str(tmp_path / "out.bgr"), "-o", str(out)],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr
    built = trimesh.load(out, force="mesh", process=False)
    source = trimesh.load(obj, force="mesh", process=False)  # z up, as the file: no offset
    assert len(built.faces) == len(source.faces)
    _, gap, _ = trimesh.proximity.closest_point(source, built.vertices)
    assert gap.max() < 0.01


def test_a_file_of_nothing_but_surfaces_is_proceduralized(tmp_path):
    from bgr.inverse.city.read import read_city

    obj = tmp_path / "flat.obj"
    write_obj(obj, [("a", terrain(30.0, 3)), ("b", box(40, 0, 0, 50, 0, 10))])
    assert all(o.proceduralize and o.kind == "object" for o in read_city(obj).objects)
