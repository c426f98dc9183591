"""Output writers: every format loads back, the terminal list is exact, GLB is well formed,
instancing round-trips, outputs are deterministic and atomic."""

from __future__ import annotations

import io
import json
import os
import struct
from pathlib import Path

import numpy as np
import pygltflib
import pytest
import trimesh

from bgr import BgrError
from bgr.formats import glb as glb_module
from bgr.formats import read_glb, to_trimesh, write, write_json
from bgr.formats.glb_read import parse, quat_matrix
from bgr.interpreter.terminals import TerminalTable, UnitMesh, color_hex

QUAD_V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
QUAD_F = [[0, 1, 2], [0, 2, 3]]
BOX_V = [[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)]
BOX_F = [
    [0, 1, 3],
    [0, 3, 2],
    [4, 6, 7],
    [4, 7, 5],
    [0, 4, 5],
    [0, 5, 1],
    [2, 3, 7],
    [2, 7, 6],
    [0, 2, 6],
    [0, 6, 4],
    [1, 5, 7],
    [1, 7, 3],
]
FORMATS = ["glb", "gltf", "obj", "ply", "stl"]


def rot_y(degrees: float) -> np.ndarray:
    """Axes (rows) of a frame turned about +y."""
    a = np.radians(degrees)
    return np.array([[np.cos(a), 0, -np.sin(a)], [0, 1, 0], [np.sin(a), 0, np.cos(a)]])


def add(t: TerminalTable, label, mesh, origin, axes, size, color, material=None, rule=None):
    t.label.append(label)
    t.rule.append(rule or label)
    t.path.append(f"Lot/{label}.{len(t.label) - 1}")
    t.origin.append(list(origin))
    t.axes.append(np.asarray(axes, dtype=float).tolist())
    t.size.append(list(size))
    t.color.append(list(color))
    t.material.append(material)
    t.mesh.append(mesh)


def small_table() -> TerminalTable:
    """A window quad, and one unit box used twice: coloured differently, one turned 30 degrees."""
    t = TerminalTable()
    quad = t.library.add(UnitMesh("quad", QUAD_V, QUAD_F))
    box = t.library.add(UnitMesh("cube", BOX_V, BOX_F))
    add(t, "Window", quad, (0.0, 3.2, 0.0), np.eye(3), (1.5, 2.0, 0.0), (0.23, 0.29, 0.35))
    add(t, "Wall", box, (1.0, 0.0, 1.0), np.eye(3), (2.0, 3.0, 4.0), (0.8, 0.2, 0.1), "brick")
    add(t, "Tower", box, (5.0, 0.0, -2.0), rot_y(30), (1.0, 6.0, 1.0), (0.1, 0.7, 0.2))
    return t.freeze()


def city_table(boxes: int = 40, quads: int = 30, seed: int = 1) -> TerminalTable:
    """Many copies of few meshes (instancing pays), plus a mirrored box and a one-off polygon."""
    rng = np.random.default_rng(seed)
    t = TerminalTable()
    quad = t.library.add(UnitMesh("quad", QUAD_V, QUAD_F))
    box = t.library.add(UnitMesh("cube", BOX_V, BOX_F))
    for _ in range(boxes):
        add(
            t,
            "Mass",
            box,
            rng.uniform(-50, 50, 3),
            rot_y(rng.uniform(0, 360)),
            rng.uniform(1, 10, 3),
            (0.6, 0.6, 0.55),
        )
    for i in range(quads):
        axes = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]]) if i % 2 else rot_y(90 * i)
        add(
            t,
            "Window",
            quad,
            rng.uniform(-50, 50, 3),
            axes,
            (1.2, 1.5, 0.0),
            (0.2, 0.3, 0.4),
            "glass",
        )
    mirror = np.diag([1.0, 1.0, -1.0])  # a left-handed frame: baked and re-wound
    add(t, "Mirror", box, (60, 0, 0), mirror, (2, 2, 2), (0.9, 0.9, 0.9))
    poly = t.library.add(UnitMesh("polygon", [[0, 0, 0], [1, 0, 0], [0.5, 0, 1]], [[0, 2, 1]]))
    add(t, "Roof", poly, (0, 10, 0), np.eye(3), (4, 0, 3), (0.5, 0.1, 0.1))
    return t.freeze()


def expected_world(t: TerminalTable) -> np.ndarray:
    """Every terminal's placed vertices, computed one by one (independently of the writers)."""
    points = []
    for i in range(len(t)):
        unit = t.library.meshes[t.mesh[i]].vertices
        for v in unit:
            points.append(t.origin[i] + sum(v[k] * t.size[i][k] * t.axes[i][k] for k in range(3)))
    return np.array(points)


def expected_bounds(t: TerminalTable) -> np.ndarray:
    p = expected_world(t)
    return np.array([p.min(axis=0), p.max(axis=0)])


# --- GLB structural validation ---------------------------------------------------------------

COMPONENT_SIZE = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def validate_glb(path: Path) -> dict:
    """Check the container and the JSON's references, alignment and bounds; return the JSON."""
    data = path.read_bytes()
    magic, version, length = struct.unpack_from("<4sII", data)
    assert (magic, version, length) == (b"glTF", 2, len(data))
    json_len, json_type = struct.unpack_from("<II", data, 12)
    assert json_type == 0x4E4F534A and json_len % 4 == 0
    gltf, blob = parse(data)
    assert gltf["asset"]["version"] == "2.0"
    buffers = gltf.get("buffers", [])
    if buffers:
        bin_len, bin_type = struct.unpack_from("<II", data, 20 + json_len)
        assert bin_type == 0x004E4942 and bin_len % 4 == 0
        assert 20 + json_len + 8 + bin_len == len(data)
        assert buffers[0]["byteLength"] <= bin_len < buffers[0]["byteLength"] + 4
        assert len(blob) == bin_len
    for view in gltf.get("bufferViews", []):
        assert view["buffer"] < len(buffers)
        assert view.get("byteOffset", 0) % 4 == 0
        assert (
            view.get("byteOffset", 0) + view["byteLength"] <= buffers[view["buffer"]]["byteLength"]
        )

    accessors = gltf.get("accessors", [])
    for acc in accessors:
        view = gltf["bufferViews"][acc["bufferView"]]
        size = COMPONENT_SIZE[acc["componentType"]] * WIDTH[acc["type"]]
        assert acc["count"] >= 1
        assert acc.get("byteOffset", 0) % COMPONENT_SIZE[acc["componentType"]] == 0
        assert acc.get("byteOffset", 0) + acc["count"] * size <= view["byteLength"]

    def read(index: int) -> np.ndarray:
        from bgr.formats.glb_read import accessor

        return accessor(gltf, blob, index)

    materials = gltf.get("materials", [])
    for material in materials:
        factor = material["pbrMetallicRoughness"]["baseColorFactor"]
        assert len(factor) == 4 and all(0.0 <= c <= 1.0 for c in factor)
    for mesh in gltf.get("meshes", []):
        for prim in mesh["primitives"]:
            assert prim.get("mode", 4) == 4
            assert 0 <= prim["material"] < len(materials)
            attrs = prim["attributes"]
            pos_acc = accessors[attrs["POSITION"]]
            assert pos_acc["type"] == "VEC3" and pos_acc["componentType"] == 5126
            pos = read(attrs["POSITION"])
            # the validator's rule: min/max are exactly the data's bounds
            assert pos_acc["min"] == pos.min(axis=0).tolist()
            assert pos_acc["max"] == pos.max(axis=0).tolist()
            assert accessors[attrs["NORMAL"]]["count"] == pos_acc["count"]
            assert np.allclose(np.linalg.norm(read(attrs["NORMAL"]), axis=1), 1.0, atol=1e-5)
            assert "indices" in prim or pos_acc["count"] % 3 == 0

    used = set()
    for node in gltf["nodes"]:
        assert 0 <= node.get("mesh", 0) < len(gltf.get("meshes", [None]))
        for name, ext in node.get("extensions", {}).items():
            used.add(name)
            if name == "EXT_mesh_gpu_instancing":
                counts = {accessors[i]["count"] for i in ext["attributes"].values()}
                assert len(counts) == 1
                assert np.allclose(
                    np.linalg.norm(read(ext["attributes"]["ROTATION"]), axis=1), 1.0, atol=1e-6
                )
                for i in ext["attributes"].values():
                    assert "target" not in gltf["bufferViews"][accessors[i]["bufferView"]]
    assert used == set(gltf.get("extensionsUsed", []))
    for scene in gltf["scenes"]:
        assert all(0 <= n < len(gltf["nodes"]) for n in scene["nodes"])
    return gltf


def canonical_triangles(mesh: trimesh.Trimesh) -> np.ndarray:
    """(F, 9) triangles, each rotated (keeping its winding) to start at its smallest corner."""
    tri = mesh.vertices[mesh.faces]
    first = np.lexsort(
        np.round(tri, 4).transpose(2, 0, 1)[::-1].reshape(3, -1)
    )  # corners by position
    rank = np.empty(tri.shape[0] * 3, dtype=int)
    rank[first] = np.arange(len(first))
    start = rank.reshape(-1, 3).argmin(axis=1)
    roll = (start[:, None] + np.arange(3)) % 3
    return np.take_along_axis(tri, roll[:, :, None], axis=1).reshape(-1, 9)


def same_triangles(a: trimesh.Trimesh, b: trimesh.Trimesh, atol: float) -> bool:
    """Every triangle of a has a triangle of b within atol, corner by corner, winding included."""
    ta, tb = canonical_triangles(a), canonical_triangles(b)
    if len(ta) != len(tb):
        return False
    near_a, near_b = np.full(len(ta), np.inf), np.full(len(tb), np.inf)
    for lo in range(0, len(ta), 256):
        gap = np.abs(ta[lo : lo + 256, None, :] - tb[None, :, :]).max(axis=2)
        near_a[lo : lo + 256] = gap.min(axis=1)
        near_b = np.minimum(near_b, gap.min(axis=0))
    return bool((near_a < atol).all() and (near_b < atol).all())


# --- every format -------------------------------------------------------------------------------


@pytest.mark.parametrize("fmt", FORMATS)
def test_every_format_loads_back(tmp_path, fmt):
    t = small_table()
    path = tmp_path / f"out.{fmt}"
    write(t, path, seed=3, attrs={"height": 18})
    loaded = trimesh.load(path)  # the plain call must work too
    assert loaded is not None
    mesh = trimesh.load(path, force="mesh", process=False)
    assert len(mesh.faces) == 2 + 12 + 12 == t.triangle_count()
    assert np.allclose(mesh.bounds, expected_bounds(t), atol=1e-5)
    if fmt == "obj":
        assert (tmp_path / "out.mtl").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [path.name] + (["out.mtl"] if fmt == "obj" else [])
    )


@pytest.mark.parametrize("fmt", ["glb", "gltf"])
def test_gltf_loads_with_pygltflib(tmp_path, fmt):
    path = tmp_path / f"out.{fmt}"
    write(city_table(), path, seed=0, attrs={})
    doc = pygltflib.GLTF2().load(str(path))
    assert doc.asset.version == "2.0"
    assert not doc.extensionsUsed and not doc.extensionsRequired  # baked by default
    assert len(doc.materials) == 4
    assert doc.nodes[doc.scenes[0].nodes[0]].name == "bgr"
    # opted in, the extension is required: a reader without it refuses the file
    write(city_table(), path, seed=0, attrs={}, gltf={"instancing": "auto"})
    doc = pygltflib.GLTF2().load(str(path))
    assert doc.extensionsUsed == doc.extensionsRequired == ["EXT_mesh_gpu_instancing"]


def test_to_trimesh():
    t = small_table()
    mesh = to_trimesh(t)
    assert len(mesh.faces) == 26
    assert np.allclose(mesh.bounds, expected_bounds(t))
    assert mesh.metadata["terminal"].tolist() == [0] * 2 + [1] * 12 + [2] * 12
    assert mesh.visual.face_colors[5, :3].tolist() == [204, 51, 26]  # (0.8, 0.2, 0.1)
    assert np.allclose(np.sort(mesh.vertices, axis=0), np.sort(expected_world(t), axis=0))


def test_colours_survive(tmp_path):
    t = small_table()
    write(t, tmp_path / "a.glb", seed=0, attrs={})
    write(t, tmp_path / "a.ply", seed=0, attrs={})
    back = read_glb(tmp_path / "a.glb")
    assert {color_hex(c[:3] / 255) for c in back.visual.face_colors} == {
        color_hex(c) for c in t.color
    }
    ply = trimesh.load(tmp_path / "a.ply", process=False)
    assert {color_hex(c[:3] / 255) for c in ply.visual.vertex_colors} == {
        color_hex(c) for c in t.color
    }
    mtl = tmp_path / "b.mtl"
    write(t, tmp_path / "b.obj", seed=0, attrs={})
    text = mtl.read_text()
    assert "newmtl brick" in text and "newmtl c_3b4a59" in text and "Kd 0.8 0.2 0.101961" in text
    obj = (tmp_path / "b.obj").read_text()
    assert obj.count("usemtl ") == 3 and "mtllib b.mtl" in obj


# --- the terminal list ----------------------------------------------------------------------------


def test_json_is_exactly_the_terminal_list(tmp_path):
    t = small_table()
    path = tmp_path / "out.json"
    write(t, path, seed=3, attrs={"height": 18, "style": "brick"})
    doc = json.loads(path.read_text())
    assert list(doc) == ["bgr", "seed", "attrs", "terminals"]
    assert doc["bgr"] == 1 and doc["seed"] == 3 and doc["attrs"] == {"height": 18, "style": "brick"}
    assert len(doc["terminals"]) == 3
    keys = ["label", "rule", "path", "origin", "axes", "size", "color", "material", "geometry"]
    for i, term in enumerate(doc["terminals"]):
        assert list(term) == keys
        assert (
            term["label"] == t.label[i] and term["rule"] == t.rule[i] and term["path"] == t.path[i]
        )
        assert term["origin"] == t.origin[i].tolist()  # exact: floats round-trip
        assert term["axes"] == t.axes[i].tolist()
        assert term["size"] == t.size[i].tolist()
        assert term["color"] == color_hex(t.color[i])
    assert doc["terminals"][0] == {
        "label": "Window",
        "rule": "Window",
        "path": "Lot/Window.0",
        "origin": [0.0, 3.2, 0.0],
        "axes": [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        "size": [1.5, 2.0, 0.0],
        "color": "#3b4a59",
        "material": None,
        "geometry": "quad",
    }
    assert doc["terminals"][1]["material"] == "brick" and doc["terminals"][2]["geometry"] == "cube"
    assert doc["terminals"][2]["axes"][0] == rot_y(30)[0].tolist()
    assert "-0.0" not in path.read_text()


def test_json_to_a_stream_and_stdout(tmp_path, capsys):
    t = small_table()
    write(t, tmp_path / "out.json", seed=3, attrs={"n": np.int64(2), "c": (0.5, 0.5, 0.5)})
    stream = io.StringIO()
    write_json(t, stream, seed=3, attrs={"n": 2, "c": [0.5, 0.5, 0.5]})
    assert stream.getvalue() == (tmp_path / "out.json").read_text()
    write(t, Path("-"), seed=3, attrs={"n": 2, "c": [0.5, 0.5, 0.5]}, fmt="json")
    assert capsys.readouterr().out == stream.getvalue()
    with pytest.raises(BgrError, match="needs a format"):
        write(t, Path("-"), seed=3, attrs={})


@pytest.mark.parametrize("fmt", FORMATS + ["json"])
def test_empty_table(tmp_path, fmt):
    write(TerminalTable(), tmp_path / f"e.{fmt}", seed=0, attrs={})
    if fmt == "json":
        assert json.loads((tmp_path / "e.json").read_text()) == {
            "bgr": 1,
            "seed": 0,
            "attrs": {},
            "terminals": [],
        }
    else:
        assert (tmp_path / f"e.{fmt}").stat().st_size > 0


# --- GLB ----------------------------------------------------------------------------------------


def test_glb_structure(tmp_path):
    path = tmp_path / "out.glb"
    write(small_table(), path, seed=3, attrs={"height": 18})
    gltf = validate_glb(path)
    assert "extensionsUsed" not in gltf  # nothing repeats enough to pay for instancing
    assert [m["name"] for m in gltf["materials"]] == ["#3b4a59", "brick", "#1ab233"]
    assert gltf["materials"][1]["extras"] == {"color": "#cc331a", "material": "brick"}
    assert gltf["asset"]["extras"] == {"bgr": 1, "seed": 3, "attrs": {"height": 18}}
    # sRGB 0.8 -> linear 0.603827
    assert gltf["materials"][1]["pbrMetallicRoughness"]["baseColorFactor"][0] == pytest.approx(
        0.603827
    )


def test_glb_normals_point_out(tmp_path):
    """Baked normals agree with the winding, for a rotated and a mirrored (re-wound) box."""
    t = city_table()
    path = tmp_path / "n.glb"
    write(t, path, seed=0, attrs={})
    gltf, blob = parse(path.read_bytes())
    from bgr.formats.glb_read import accessor

    prim = gltf["meshes"][0]["primitives"]
    for p in prim:
        pos = accessor(gltf, blob, p["attributes"]["POSITION"]).reshape(-1, 3, 3)
        nrm = accessor(gltf, blob, p["attributes"]["NORMAL"]).reshape(-1, 3, 3)[:, 0]
        geometric = np.cross(pos[:, 1] - pos[:, 0], pos[:, 2] - pos[:, 0])
        geometric /= np.linalg.norm(geometric, axis=1, keepdims=True)
        assert np.allclose(geometric, nrm, atol=1e-4)
    # the mirrored box is a closed mesh with outward faces: positive volume
    mirror = [i for i in range(len(t)) if t.label[i] == "Mirror"]
    one = TerminalTable(library=t.library)
    i = mirror[0]
    add(one, "Mirror", t.mesh[i], t.origin[i], t.axes[i], t.size[i], t.color[i])
    one.freeze()
    write(one, tmp_path / "m.glb", seed=0, attrs={})
    back = read_glb(tmp_path / "m.glb")
    assert back.volume == pytest.approx(8.0, rel=1e-5)
    assert to_trimesh(one).volume == pytest.approx(8.0)


def test_instancing_round_trips(tmp_path):
    t = city_table()
    inst, flat = tmp_path / "inst.glb", tmp_path / "flat.glb"
    write(t, inst, seed=0, attrs={}, gltf={"instancing": "auto"})
    write(t, flat, seed=0, attrs={})  # the default: every terminal baked
    g_inst, g_flat = validate_glb(inst), validate_glb(flat)
    assert g_inst["extensionsUsed"] == g_inst["extensionsRequired"] == ["EXT_mesh_gpu_instancing"]
    assert "extensionsUsed" not in g_flat and "extensionsRequired" not in g_flat
    instanced = [n for n in g_inst["nodes"] if "extensions" in n]
    # boxes (40 of one colour) and windows (30, zero depth: scale 1 on z) are instanced
    assert sorted(n["name"] for n in instanced) == ["cube #99998c", "quad glass"]
    assert inst.stat().st_size < flat.stat().st_size

    expected = to_trimesh(t)
    for path in (inst, flat):
        back = read_glb(path)
        assert len(back.faces) == t.triangle_count()
        assert np.allclose(back.bounds, expected_bounds(t), atol=1e-4)
        assert same_triangles(back, expected, atol=1e-4)
    # trimesh itself ignores the extension: it sees one copy of each instanced group
    assert len(trimesh.load(inst, force="mesh").faces) < t.triangle_count()
    assert len(trimesh.load(flat, force="mesh", process=False).faces) == t.triangle_count()


def test_bulk_paths_agree_with_one_by_one(tmp_path):
    """Baked terminals in every layout the bulk code handles: many unique meshes of one shape,
    one colour per terminal (scattered writes), zero sizes (degenerate triangles), shuffled."""
    rng = np.random.default_rng(9)
    t = TerminalTable()
    box = t.library.add(UnitMesh("cube", BOX_V, BOX_F))
    polys = [
        t.library.add(
            UnitMesh("polygon", np.array(QUAD_V) * [rng.uniform(0.5, 1), 1, 0], QUAD_F),
            key=("p", i),
        )
        for i in range(60)
    ]
    palette = rng.uniform(0, 1, (40, 3))  # materials shared by boxes and polygons: scattered runs
    rows = [("Poly", p, palette[i % 40]) for i, p in enumerate(polys)]
    rows += [("Box", box, palette[i % 40]) for i in range(100)]
    rows += [
        ("Flat", box, (0.4, 0.4, 0.4)),
        ("Empty", t.library.add(UnitMesh("empty", [], [])), (0, 0, 0)),
    ]
    for j in rng.permutation(len(rows)):
        label, mesh, colour = rows[j]
        size = (3, 0, 2) if label == "Flat" else rng.uniform(0.5, 5, 3)
        add(t, label, mesh, rng.uniform(-20, 20, 3), rot_y(rng.uniform(0, 360)), size, colour)
    t.freeze()
    path = tmp_path / "bulk.glb"
    with open(path, "wb") as f:
        glb_module.write_glb(t, f, seed=0, attrs={}, instancing=False)
    validate_glb(path)
    back, expected = read_glb(path), to_trimesh(t)
    assert len(back.faces) == t.triangle_count() == 60 * 2 + 101 * 12
    assert same_triangles(back, expected, atol=1e-4)
    assert np.allclose(np.sort(expected.vertices, axis=0), np.sort(expected_world(t), axis=0))
    write(t, tmp_path / "auto.glb", seed=0, attrs={})  # auto: the 60 polygons' meshes all differ
    assert same_triangles(read_glb(tmp_path / "auto.glb"), expected, atol=1e-4)


def test_quaternions_match_the_axes():
    rng = np.random.default_rng(5)
    q, _ = np.linalg.qr(rng.normal(size=(200, 3, 3)))
    q[np.linalg.det(q) < 0, 2] *= -1  # right-handed
    special = np.array(
        [
            np.eye(3),
            np.diag([-1.0, -1.0, 1.0]),
            np.diag([1.0, -1.0, -1.0]),
            np.diag([-1.0, 1.0, -1.0]),
            rot_y(180),
        ]
    )
    axes = np.concatenate([q, special])
    quat = glb_module.quaternions(axes)
    assert np.allclose(np.linalg.norm(quat, axis=1), 1.0)
    assert (quat[:, 3] >= 0).all()
    assert np.allclose(quat_matrix(quat), axes.transpose(0, 2, 1), atol=1e-9)


def test_far_from_the_origin_keeps_precision(tmp_path):
    t = TerminalTable()
    box = t.library.add(UnitMesh("cube", BOX_V, BOX_F))
    for i in range(3):
        add(
            t,
            "Box",
            box,
            (500000.0 + 0.001 * i, 20.0, 4000000.0),
            np.eye(3),
            (0.01, 0.01, 0.01),
            (1, 1, 1),
        )
    t.freeze()
    path = tmp_path / "far.glb"
    write(t, path, seed=0, attrs={})
    gltf = validate_glb(path)
    assert gltf["nodes"][0]["translation"] == [500000.0, 20.0, 4000000.0]
    back = read_glb(path)
    assert np.allclose(back.bounds, expected_bounds(t), atol=1e-6, rtol=0)


def test_empty_table_glb(tmp_path):
    path = tmp_path / "e.glb"
    write(TerminalTable().freeze(), path, seed=0, attrs={})
    gltf = validate_glb(path)
    assert [node["name"] for node in gltf["nodes"]] == ["bgr"] and "buffers" not in gltf
    pygltflib.GLTF2().load(str(path))


# --- determinism, atomicity, errors ---------------------------------------------------------------


@pytest.mark.parametrize("fmt", FORMATS + ["json"])
def test_writing_twice_gives_identical_bytes(tmp_path, fmt):
    t = city_table()
    a, b = tmp_path / f"a.{fmt}", tmp_path / f"b.{fmt}"
    write(t, a, seed=7, attrs={"h": 1.5})
    write(city_table(), b, seed=7, attrs={"h": 1.5})  # a fresh, equal table
    data_a, data_b = a.read_bytes(), b.read_bytes()
    if fmt == "obj":
        data_a, data_b = data_a.replace(b"a.mtl", b""), data_b.replace(b"b.mtl", b"")
        assert a.with_suffix(".mtl").read_bytes() == b.with_suffix(".mtl").read_bytes()
    assert data_a == data_b


def test_unknown_extension_is_a_bgr_error(tmp_path):
    t = small_table()
    with pytest.raises(BgrError) as err:
        write(t, tmp_path / "out.fbx", seed=0, attrs={})
    for ext in (".glb", ".gltf", ".obj", ".ply", ".stl", ".json", ".city.json", ".city.jsonl"):
        assert ext in str(err.value)
    with pytest.raises(BgrError, match="unknown output format"):
        write(t, tmp_path / "out.glb", seed=0, attrs={}, fmt="fbx")
    with pytest.raises(BgrError, match="has no extension"):
        write(t, tmp_path / "out", seed=0, attrs={})
    assert list(tmp_path.iterdir()) == []


def test_format_option_overrides_the_extension(tmp_path):
    path = tmp_path / "model.bin"
    write(small_table(), path, seed=0, attrs={}, fmt="glb")
    assert path.read_bytes()[:4] == b"glTF"


def test_unwritable_target_leaves_nothing(tmp_path):
    t = small_table()
    with pytest.raises(BgrError, match="cannot write the output file"):
        write(t, tmp_path / "missing" / "out.glb", seed=0, attrs={})
    (tmp_path / "dir.glb").mkdir()
    with pytest.raises(BgrError, match="cannot write the output file"):
        write(t, tmp_path / "dir.glb", seed=0, attrs={})
    assert [p.name for p in tmp_path.iterdir()] == ["dir.glb"]
    assert list((tmp_path / "dir.glb").iterdir()) == []


@pytest.mark.parametrize("fmt", FORMATS + ["json"])
def test_failure_mid_write_leaves_nothing(tmp_path, monkeypatch, fmt):
    import bgr.formats as writers

    def explode(*args, **kwargs):
        for stream in args[1:]:
            if hasattr(stream, "write"):
                stream.write(b"partial" if not isinstance(stream, io.TextIOBase) else "partial")
        raise RuntimeError("disk on fire")

    monkeypatch.setitem(writers.FORMATS, fmt, explode)
    monkeypatch.setattr(writers, "write_obj", explode)
    (tmp_path / "keep.txt").write_text("untouched")
    with pytest.raises(RuntimeError, match="disk on fire"):
        write(small_table(), tmp_path / f"out.{fmt}", seed=0, attrs={})
    assert [p.name for p in tmp_path.iterdir()] == ["keep.txt"]


def test_failure_keeps_the_previous_file(tmp_path, monkeypatch):
    import bgr.formats as writers

    path = tmp_path / "out.glb"
    write(small_table(), path, seed=0, attrs={})
    before = path.read_bytes()

    def explode(table, stream, **kwargs):
        stream.write(b"half")
        raise MemoryError

    monkeypatch.setitem(writers.FORMATS, "glb", explode)
    with pytest.raises(MemoryError):
        write(small_table(), path, seed=0, attrs={})
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["out.glb"]


def test_new_files_get_ordinary_permissions(tmp_path):
    path = tmp_path / "out.stl"
    write(small_table(), path, seed=0, attrs={})
    umask = os.umask(0)
    os.umask(umask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask


def test_bad_attrs_are_a_bgr_error(tmp_path):
    with pytest.raises(BgrError, match="JSON"):
        write(small_table(), tmp_path / "out.json", seed=0, attrs={"x": object()})
    with pytest.raises(BgrError, match="attr 'x' = nan: numbers must be finite"):
        write(small_table(), tmp_path / "out.glb", seed=0, attrs={"x": float("nan")})
    assert list(tmp_path.iterdir()) == []
