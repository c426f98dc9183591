"""OBJ and PLY as people expect (issue 11, part 4): normals that point out, an object per building
and a group per label, shared vertices, the same triangles as the GLB.

The OBJ and PLY files are read back by small parsers written here, independently of the writers,
and by trimesh; the GLB (with its instances expanded) is the reference.  The helpers they are
built on are tested in test_bulk_text.py."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pygltflib
import pytest
import trimesh
from conftest import ROOT
from test_writers import add, city_table, same_triangles, small_table

import bgr
from bgr.formats import obj as obj_module
from bgr.formats import read_glb, to_trimesh, write
from bgr.formats.materials import materials_of
from bgr.formats.obj import obj_name, obj_names
from bgr.interpreter.terminals import TerminalTable, UnitMesh

EXAMPLES = [
    ("house.bgr", {}),
    ("stdlib_street.bgr", {"lot": str(ROOT / "examples" / "block.geojson"), "seed": 5}),
    ("city_block.bgr", {}),
]


# --- independent readers --------------------------------------------------------------------------


def parse_obj(text: str) -> dict:
    """v, vn, o, g, usemtl, mtllib and ``f a//n b//n c//n`` lines; anything else fails."""
    v, vn, v_object, objects, faces = [], [], [], [], []
    obj = group = mtl = None
    for line in text.splitlines():
        if not line or line.startswith("#"):
            continue
        head, *rest = line.split()
        assert line == " ".join([head, *rest]), f"odd spacing: {line!r}"
        if head in ("v", "vn"):
            assert len(rest) == 3
            (v if head == "v" else vn).append([float(x) for x in rest])
            if head == "v":
                v_object.append(obj)
        elif head in ("o", "g", "usemtl", "mtllib"):
            assert len(rest) == 1, line
            if head == "o":
                obj, group, mtl = rest[0], None, None
                objects.append(obj)
            elif head == "g":
                group = rest[0]
            elif head == "usemtl":
                mtl = rest[0]
        elif head == "f":
            corners = [c.split("/") for c in rest]
            assert len(corners) == 3 and all(len(c) == 3 and c[1] == "" for c in corners), line
            faces.append(
                (obj, group, mtl, [int(c[0]) for c in corners], [int(c[2]) for c in corners])
            )
        else:
            raise AssertionError(f"unexpected line {line!r}")
    return {
        "v": np.array(v, dtype=float).reshape(-1, 3),
        "vn": np.array(vn, dtype=float).reshape(-1, 3),
        "v_object": v_object,
        "objects": objects,
        "keys": [f[:3] for f in faces],
        "fv": np.array([f[3] for f in faces], dtype=np.int64).reshape(-1, 3) - 1,
        "fn": np.array([f[4] for f in faces], dtype=np.int64).reshape(-1, 3) - 1,
    }


PLY_TYPES = {"double": "<f8", "float": "<f4", "uchar": "u1", "int": "<i4"}


def parse_ply(data: bytes) -> tuple[np.ndarray, np.ndarray]:
    """The vertex records and (F, 3) faces of a binary little-endian PLY of triangles."""
    end = data.index(b"end_header\n") + len(b"end_header\n")
    lines = data[:end].decode("ascii").splitlines()
    assert lines[:2] == ["ply", "format binary_little_endian 1.0"]
    elements: list[list] = []
    for line in lines[2:-1]:
        words = line.split()
        if words[0] == "element":
            elements.append([words[1], int(words[2]), []])
        elif words[0] == "property":
            elements[-1][2].append(words[1:])
    (vname, nv, vprops), (fname, nf, fprops) = elements
    assert (vname, fname) == ("vertex", "face")
    assert fprops == [["list", "uchar", "int", "vertex_indices"]]
    vertex = np.dtype([(name, PLY_TYPES[kind]) for kind, name in vprops])
    vertices = np.frombuffer(data, dtype=vertex, count=nv, offset=end)
    face = np.dtype([("n", "u1"), ("i", "<i4", (3,))])
    faces = np.frombuffer(data, dtype=face, count=nf, offset=end + nv * vertex.itemsize)
    assert (faces["n"] == 3).all()
    assert end + nv * vertex.itemsize + nf * face.itemsize == len(data)
    return vertices, faces["i"].astype(np.int64)


def pygltflib_triangles(path: Path) -> int:
    """Triangles of a GLB counted with pygltflib, each instanced node counted once per instance."""
    doc = pygltflib.GLTF2().load(str(path))
    total = 0
    for node in doc.nodes:
        if node.mesh is None:
            continue
        per_copy = 0
        for prim in doc.meshes[node.mesh].primitives:
            counted = prim.indices if prim.indices is not None else prim.attributes.POSITION
            per_copy += doc.accessors[counted].count // 3
        copies = 1
        ext = (node.extensions or {}).get("EXT_mesh_gpu_instancing")
        if ext:
            copies = doc.accessors[ext["attributes"]["TRANSLATION"]].count
        total += per_copy * copies
    return total


def geometric_normals(tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals of (F, 3, 3) triangles by their winding, and twice their areas."""
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(n, axis=1)
    return n / np.where(length > 0, length, 1)[:, None], length


def terminal_counts(t: TerminalTable) -> dict[tuple[str, str, str], int]:
    """Triangles per (object name, label, material name), from the table alone."""
    names = obj_names(materials_of(t))
    index = materials_of(t).index
    per_mesh = [len(m.faces) for m in t.library.meshes]
    counts: dict[tuple[str, str, str], int] = {}
    for lot in t.lots or [{"name": "lot-0", "rows": [0, len(t)]}]:
        for row in range(*lot["rows"]):
            key = (obj_name(lot["name"]), obj_name(t.label[row]), names[index[row]])
            if per_mesh[t.mesh[row]]:
                counts[key] = counts.get(key, 0) + per_mesh[t.mesh[row]]
    return counts


# --- the examples ------------------------------------------------------------------------------


@pytest.fixture(scope="module", params=EXAMPLES, ids=[name for name, _ in EXAMPLES])
def example(request, tmp_path_factory):
    name, options = request.param
    result = bgr.derive(bgr.load(ROOT / "examples" / name), **options)
    folder = tmp_path_factory.mktemp(name.split(".")[0])
    for ext in ("glb", "obj", "ply"):
        result.save(folder / f"out.{ext}")
    return result.terminals, folder


def test_every_reader_counts_the_same_triangles(example):
    t, folder = example
    triangles = t.triangle_count()
    assert len(read_glb(folder / "out.glb").faces) == triangles
    assert pygltflib_triangles(folder / "out.glb") == triangles
    assert len(trimesh.load(folder / "out.obj", force="mesh").faces) == triangles
    assert len(parse_obj((folder / "out.obj").read_text())["fv"]) == triangles
    assert len(trimesh.load(folder / "out.ply", process=False).faces) == triangles
    assert len(parse_ply((folder / "out.ply").read_bytes())[1]) == triangles


def test_obj_objects_are_lots_and_groups_are_labels(example):
    t, folder = example
    doc = parse_obj((folder / "out.obj").read_text())
    assert doc["objects"] == [lot["name"] for lot in t.lots]
    counts: dict = {}
    for key in doc["keys"]:
        counts[key] = counts.get(key, 0) + 1
    assert counts == terminal_counts(t)
    # each object's group runs once: a label's faces are together
    runs = [k[:2] for i, k in enumerate(doc["keys"]) if i == 0 or doc["keys"][i - 1][:2] != k[:2]]
    assert len(runs) == len(set(runs))


def test_obj_normals_point_out_and_vertices_are_shared(example):
    t, folder = example
    doc = parse_obj((folder / "out.obj").read_text())
    v, vn, fv, fn = doc["v"], doc["vn"], doc["fv"], doc["fn"]
    assert np.allclose(np.linalg.norm(vn, axis=1), 1.0, atol=2e-6)
    assert (fn == fn[:, :1]).all()  # flat shaded: one normal per triangle
    geometric, twice_area = geometric_normals(v[fv])
    real = twice_area > 1e-9
    assert real.mean() > 0.99
    assert (np.einsum("ij,ij->i", geometric[real], vn[fn[real, 0]]) > 0.99).all()
    # shared: far fewer vertices than corners, each written once per object, used in its object
    assert len(v) < 3 * len(fv)
    assert len(v) <= sum(len(t.library.meshes[m].vertices) for m in t.mesh)
    objects = np.array(doc["v_object"])
    for name in doc["objects"]:
        mine = v[objects == name]
        assert len(np.unique(np.round(mine * 1e6), axis=0)) == len(mine)
    face_object = np.array([k[0] for k in doc["keys"]])
    assert (objects[fv] == face_object[:, None]).all()
    assert len(np.unique(np.round(vn * 1e6), axis=0)) == len(vn)


def test_obj_and_ply_have_the_glb_surface(example):
    t, folder = example
    glb_area = read_glb(folder / "out.glb").area
    doc = parse_obj((folder / "out.obj").read_text())
    obj_area = geometric_normals(doc["v"][doc["fv"]])[1].sum() / 2
    assert obj_area == pytest.approx(glb_area, rel=1e-6)
    vertices, faces = parse_ply((folder / "out.ply").read_bytes())
    xyz = np.stack([vertices[c] for c in "xyz"], axis=1)
    assert geometric_normals(xyz[faces])[1].sum() / 2 == pytest.approx(glb_area, rel=1e-6)
    assert np.allclose(
        np.sort(trimesh.load(folder / "out.obj", force="mesh").bounds.ravel()),
        np.sort(read_glb(folder / "out.glb").bounds.ravel()),
        atol=1e-4,
    )


def test_ply_vertices_carry_normal_and_colour(example):
    t, folder = example
    vertices, faces = parse_ply((folder / "out.ply").read_bytes())
    assert vertices.dtype.names == ("x", "y", "z", "nx", "ny", "nz", "red", "green", "blue")
    assert vertices.dtype["x"] == np.dtype("<f8") and vertices.dtype["nx"] == np.dtype("<f4")
    xyz = np.stack([vertices[c] for c in "xyz"], axis=1)
    normal = np.stack([vertices[c] for c in ("nx", "ny", "nz")], axis=1).astype(float)
    rgb = np.stack([vertices[c] for c in ("red", "green", "blue")], axis=1)
    assert np.allclose(np.linalg.norm(normal, axis=1), 1.0, atol=1e-6)
    geometric, twice_area = geometric_normals(xyz[faces])
    real = twice_area > 1e-9
    for k in range(3):
        assert (np.einsum("ij,ij->i", geometric[real], normal[faces[real, k]]) > 0.99).all()
        assert (rgb[faces[:, k]] == rgb[faces[:, 0]]).all()  # one colour per triangle
    # the triangles of each colour are the terminals' of that colour
    expected = to_trimesh(t).visual.face_colors[:, :3]
    got = rgb[faces[:, 0]]
    for colour in np.unique(expected, axis=0):
        assert (got == colour).all(axis=1).sum() == (expected == colour).all(axis=1).sum()
    assert len(vertices) < 3 * len(faces)
    key = np.column_stack([np.round(xyz * 1e6), np.round(normal * 1e6), rgb])
    assert len(np.unique(key, axis=0)) == len(key)  # each (position, normal, colour) once
    loaded = trimesh.load(folder / "out.ply", process=False)
    assert np.allclose(loaded.vertex_normals, normal, atol=1e-6)


# --- hand-made tables -------------------------------------------------------------------------


def test_obj_triangles_are_the_terminals_and_mirrors_stay_closed(tmp_path):
    t = city_table()
    write(t, tmp_path / "c.obj", seed=0, attrs={})
    doc = parse_obj((tmp_path / "c.obj").read_text())
    back = trimesh.Trimesh(doc["v"], doc["fv"], process=False)
    assert same_triangles(back, to_trimesh(t), atol=1e-5)
    # the mirrored box (left-handed frame) is re-wound: closed, outward, volume +8
    mirror = np.array([k[1] == "Mirror" for k in doc["keys"]])
    tri = doc["v"][doc["fv"][mirror]]
    assert len(tri) == 12
    assert np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6 == (
        pytest.approx(8.0)
    )
    normals = doc["vn"][doc["fn"][mirror, 0]]
    centre = tri.reshape(-1, 3).mean(axis=0)
    assert (np.einsum("ij,ij->i", normals, tri.mean(axis=1) - centre) > 0).all()


def test_degenerate_terminals_are_written_with_a_unit_normal(tmp_path):
    t = TerminalTable()
    box = t.library.add(UnitMesh("cube", np.eye(3).tolist() + [[0, 0, 0]], [[0, 1, 2], [3, 2, 1]]))
    add(t, "Flat", box, (1, 2, 3), np.eye(3), (2, 0, 0), (0.5, 0.5, 0.5))
    t.freeze()
    for ext in ("obj", "ply"):
        write(t, tmp_path / f"d.{ext}", seed=0, attrs={})
    doc = parse_obj((tmp_path / "d.obj").read_text())
    assert len(doc["fv"]) == 2 and np.allclose(np.linalg.norm(doc["vn"], axis=1), 1.0)
    vertices, faces = parse_ply((tmp_path / "d.ply").read_bytes())
    assert len(faces) == 2 and len(vertices) <= 4


def test_object_and_group_names_are_one_word_and_distinct(tmp_path):
    t = TerminalTable()
    quad = t.library.add(
        UnitMesh("quad", [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]])
    )
    for i, label in enumerate(["Wall panel", "Wall\tpanel", "Door#1", "Door#1"]):
        add(t, label, quad, (i, 0, 0), np.eye(3), (1, 1, 0), (0.2, 0.2, 0.2))
    t.lots = [
        {"name": "way/12 main street", "rows": [0, 1]},
        {"name": "way/12 main street", "rows": [1, 2]},
        {"name": "x\ny", "rows": [2, 3]},
    ]  # the last terminal is in no lot
    t.freeze()
    write(t, tmp_path / "n.obj", seed=0, attrs={})
    text = (tmp_path / "n.obj").read_text()
    doc = parse_obj(text)
    assert doc["objects"] == ["way_12_main_street", "way_12_main_street_", "x_y", "lot-3"]
    groups = [line.split(" ", 1)[1] for line in text.splitlines() if line.startswith("g ")]
    assert groups == ["Wall_panel", "Wall_panel_", "Door_1", "Door_1"]
    assert len(doc["fv"]) == 8


def test_a_table_without_lots_is_one_object(tmp_path):
    write(small_table(), tmp_path / "s.obj", seed=0, attrs={})
    doc = parse_obj((tmp_path / "s.obj").read_text())
    assert doc["objects"] == ["lot-0"]
    assert [k[1:] for k in dict.fromkeys(doc["keys"])] == [
        ("Window", "c_3b4a59"),
        ("Wall", "brick"),
        ("Tower", "c_1ab233"),
    ]
    assert len(doc["v"]) == 4 + 8 + 8  # a quad and two boxes: every corner once


def test_obj_is_the_same_whatever_the_block_size(tmp_path, monkeypatch):
    t = city_table()
    write(t, tmp_path / "a.obj", seed=0, attrs={})
    monkeypatch.setattr(obj_module, "LINES_PER_BLOCK", 7)
    write(t, tmp_path / "b.obj", seed=0, attrs={})
    a = (tmp_path / "a.obj").read_bytes().replace(b"a.mtl", b"x")
    assert a == (tmp_path / "b.obj").read_bytes().replace(b"b.mtl", b"x")


@pytest.mark.parametrize("ext", ["obj", "ply"])
def test_derived_twice_written_twice_identical(tmp_path, ext):
    grammar = bgr.load(ROOT / "examples" / "stdlib_street.bgr")
    lot = str(ROOT / "examples" / "block.geojson")
    for name in ("a", "b"):
        bgr.derive(grammar, seed=5, lot=lot).save(tmp_path / f"{name}.{ext}")
    a, b = (tmp_path / f"a.{ext}").read_bytes(), (tmp_path / f"b.{ext}").read_bytes()
    assert a.replace(b"a.mtl", b"") == b.replace(b"b.mtl", b"")


def test_the_obj_example_in_the_docs_is_what_bgr_writes(tmp_path):
    text = (ROOT / "docs" / "cli.md").read_text()
    start = text.index("$ cat box.obj\n") + len("$ cat box.obj\n")
    shown = text[start : text.index("```", start)]
    grammar = (
        "attr height = 6\n\n"
        "Lot --> extrude(height) comp(f) { top: Roof | front: Door | bottom: NIL }\n"
        'Roof --> roof(flat) color("#7a3b2e")\n'
        'Door --> s(1.2, 2.2, 0) center(x) color("#3b4a5a") label("Entrance")\n'
    )
    assert grammar in text  # the box.bgr the docs show
    bgr.derive(grammar, lot=(8, 6), attrs={"height": 3}).save(tmp_path / "box.obj")
    assert (tmp_path / "box.obj").read_text() == shown
    assert len(trimesh.load(tmp_path / "box.obj", force="mesh").faces) == 4
