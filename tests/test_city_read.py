"""bgr.inverse.city.read: every input format of ``bgr infer --kind city`` read into objects of
triangles in bgr's frame (issue 12, point 1).

Small files are written by the tests themselves; the real cities of ../shared/data/cities are
read when they are there (they are not the repository's to ship) and skipped otherwise."""

from __future__ import annotations

import base64
import json
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, SHARED
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import bgr
from bgr.formats import write
from bgr.grammar.errors import BgrError
from bgr.inverse.city import read as city_read
from bgr.inverse.city.read import read_city

CITIES = SHARED / "data" / "cities"
BLOCK = ROOT / "examples" / "block.geojson"


def shared(name: str) -> Path:
    path = CITIES / name
    if not path.exists():
        pytest.skip(f"{path} is absent (the shared city data)")
    return path


# --- small meshes -------------------------------------------------------------------------------


def box_obj(x0: float, y0: float, z0: float, x1: float, y1: float, z1: float, base: int) -> str:
    """``v`` and ``f`` lines of an axis-aligned box as 6 quads (outward, counter-clockwise),
    its first vertex numbered ``base`` + 1."""
    corners = [(x, y, z) for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    lines = [f"v {x} {y} {z}" for x, y, z in corners]
    lines += ["f " + " ".join(str(base + i + 1) for i in q) for q in quads]
    return "\n".join(lines) + "\n"


def write_text(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def triangle_area(obj) -> float:
    corners = obj.vertices[obj.faces]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    return float(np.linalg.norm(cross, axis=1).sum() / 2)


# --- OBJ: objects, groups, components --------------------------------------------------------


def test_obj_objects_are_its_o_names_with_their_faces(tmp_path):
    text = "o first\n" + box_obj(0, 0, 0, 1, 1, 1, 0)
    text += "o second\nv 5 0 0\nv 6 0 0\nv 6 1 0\nf 9 10 11\n"
    scene = read_city(write_text(tmp_path / "two.obj", text))
    assert [o.name for o in scene.objects] == ["first", "second"]
    assert [len(o.faces) for o in scene.objects] == [12, 1]
    assert [len(o.vertices) for o in scene.objects] == [8, 3]  # only the vertices it uses
    assert all(o.kind == "object" and o.proceduralize for o in scene.objects)


def test_obj_a_name_used_twice_is_one_object_in_order_of_first_face(tmp_path):
    text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
    text += "o b\nf 1 2 3\no a\nf 1 3 4\no b\nf 2 3 4\n"
    scene = read_city(write_text(tmp_path / "again.obj", text), up="y")
    assert [(o.name, len(o.faces)) for o in scene.objects] == [("b", 2), ("a", 1)]


def test_obj_without_objects_has_its_groups_as_objects(tmp_path):
    text = "g roof\n" + box_obj(0, 0, 0, 1, 1, 1, 0) + "g wall\n" + box_obj(3, 0, 0, 4, 1, 1, 8)
    text += "g roof\nv 0 0 5\nv 1 0 5\nv 1 1 5\nf 17 18 19\n"
    scene = read_city(write_text(tmp_path / "groups.obj", text))
    # the group's triangle lies apart from its box on the ground (y is up): a building of its own
    groups = [(o.name, len(o.faces)) for o in scene.objects]
    assert groups == [("roof/1", 12), ("roof/2", 1), ("wall", 12)]


def test_obj_without_names_is_cut_into_connected_components(tmp_path):
    text = box_obj(0, 0, 0, 10, 10, 8, 0) + box_obj(20, 0, 0, 30, 10, 12, 8)
    scene = read_city(write_text(tmp_path / "boxes.obj", text), up="z")
    assert [o.name for o in scene.objects] == ["object-1", "object-2"]
    assert [len(o.faces) for o in scene.objects] == [12, 12]
    heights = [o.vertices[:, 1].max() for o in scene.objects]
    assert heights == [8.0, 12.0]  # numbered by their first face: the file's order


def test_an_object_of_several_buildings_is_split_into_them(tmp_path):
    """Issue 29: a file that puts two buildings apart on the ground into one object gives two
    objects, NAME/1 and NAME/2, in the order of their first faces; others keep their place."""
    text = "o pair\n" + box_obj(0, 0, 0, 10, 10, 8, 0) + box_obj(30, 0, 0, 40, 10, 12, 8)
    text += "o single\n" + box_obj(60, 0, 0, 70, 10, 8, 16)
    text += "o terrace\n" + box_obj(80, 0, 0, 90, 10, 8, 24) + box_obj(90, 0, 0, 95, 10, 4, 32)
    scene = read_city(write_text(tmp_path / "pair.obj", text), up="z")
    names = [(o.name, len(o.faces), o.vertices[:, 1].max()) for o in scene.objects]
    assert names == [
        ("pair/1", 12, 8.0),
        ("pair/2", 12, 12.0),
        ("single", 12, 8.0),
        ("terrace", 24, 8.0),  # two boxes that touch: one building
    ]


def test_carried_objects_are_not_split(tmp_path):
    """A CityJSON Road in two pieces stays one object (carried through as it is)."""
    road = [[[0, 1, 2, 3]], [[4, 5, 6, 7]]]
    doc = {
        "type": "CityJSON",
        "version": "2.0",
        "transform": {"scale": [1, 1, 1], "translate": [0, 0, 0]},
        "CityObjects": {
            "r": {
                "type": "Road",
                "geometry": [{"type": "MultiSurface", "lod": "1", "boundaries": road}],
            },
        },
        "vertices": [[0, 0, 0], [5, 0, 0], [5, 5, 0], [0, 5, 0]]
        + [[50, 0, 0], [55, 0, 0], [55, 5, 0], [50, 5, 0]],
    }
    scene = read_city(write_text(tmp_path / "road.city.json", json.dumps(doc)))
    assert [(o.name, o.proceduralize, len(o.faces)) for o in scene.objects] == [("r", False, 4)]


def test_a_window_floating_in_front_of_a_facade_joins_its_building(tmp_path):
    # z up: the façade at y = 0 faces -y; the window quad 5 cm in front of it, not touching
    text = box_obj(0, 0, 0, 10, 8, 6, 0)
    text += "v 2 -0.05 2\nv 4 -0.05 2\nv 4 -0.05 4\nv 2 -0.05 4\nf 9 10 11 12\n"
    text += box_obj(30, 0, 0, 40, 8, 6, 12)  # another building, far away
    scene = read_city(write_text(tmp_path / "window.obj", text), up="z")
    assert [len(o.faces) for o in scene.objects] == [14, 12]


def test_obj_vertices_are_welded_by_position_for_components(tmp_path):
    # two triangles of one quad that repeat its corners instead of sharing v lines: one object
    text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 4 5 6\n"
    text += "v 5 0 0\nv 6 0 0\nv 6 1 0\nf 7 8 9\n"
    scene = read_city(write_text(tmp_path / "weld.obj", text), up="y")
    assert [len(o.faces) for o in scene.objects] == [2, 1]


def test_obj_negative_indices_count_back_from_the_vertices_above(tmp_path):
    absolute = "o a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\no b\nv 0 0 1\nv 1 0 1\nv 1 1 1\nf 4 5 6\n"
    relative = absolute.replace("f 1 2 3", "f -3 -2 -1").replace("f 4 5 6", "f -3/1 -2/1 -1/1")
    a = read_city(write_text(tmp_path / "abs.obj", absolute), up="y")
    b = read_city(write_text(tmp_path / "rel.obj", relative), up="y")
    for x, y in zip(a.objects, b.objects, strict=True):
        assert x.name == y.name
        np.testing.assert_array_equal(x.vertices[x.faces], y.vertices[y.faces])
    assert b.objects[1].vertices[:, 2].tolist() == [1.0, 1.0, 1.0]  # y up: input z is bgr z


def test_obj_polygons_are_triangulated_convex_and_concave(tmp_path):
    # a quad (v//n and v/t/n corners), and an L-shaped hexagon whose fan would cover the notch
    text = "vn 0 0 1\nv 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nf 1//1 2//1 3//1 4//1\n"
    text += "v 10 0 0\nv 14 0 0\nv 14 1 0\nv 11 1 0\nv 11 4 0\nv 10 4 0\n"
    text += "f 8/1/1 9/1/1 10/1/1 5/1/1 6/1/1 7/1/1\n"  # starts at the reflex corner (11, 1)
    scene = read_city(write_text(tmp_path / "polygons.obj", text), up="y")
    quad, ell = scene.objects
    assert len(quad.faces) == 2 and triangle_area(quad) == pytest.approx(2.0)
    assert len(ell.faces) == 4 and triangle_area(ell) == pytest.approx(4 + 3)
    # every triangle faces +z like the polygon (bgr's frame: y up, so input z is bgr z)
    for obj in (quad, ell):
        c = obj.vertices[obj.faces]
        normal = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
        assert (normal[:, 2] > 0).all()


def test_obj_faces_that_repeat_a_vertex_are_dropped(tmp_path):
    text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 1 2\nf 2 3 3 3\n"
    scene = read_city(write_text(tmp_path / "degenerate.obj", text), up="y")
    assert scene.triangles == 1


def test_a_face_repeated_in_its_object_is_read_once_and_its_reverse_stays(tmp_path):
    # a repeated face adds no surface but all the work of one: 3,000 copies took 10 s to infer
    text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 0 1\no a\n" + "f 1 2 3\nf 2 3 1\n" * 3000
    text += "f 3 2 1\nf 1 2 4\no b\nf 1 2 3\n"
    scene = read_city(write_text(tmp_path / "repeated.obj", text), up="y")
    by_name = {obj.name: obj for obj in scene.objects}
    assert len(by_name["a"].faces) == 3  # 1 2 3 (and its rotation 2 3 1), 3 2 1, 1 2 4
    assert len(by_name["b"].faces) == 1  # the same triangle in another object stays there


def test_obj_vertex_colours_are_averaged_per_face(tmp_path):
    text = "v 0 0 0 1 0 0\nv 1 0 0 1 0 0\nv 1 1 0 0 0 1\nf 1 2 3\n"
    (obj,) = read_city(write_text(tmp_path / "rgb.obj", text), up="y").objects
    assert obj.colors.tolist() == [[170, 0, 85, 255]]


def test_obj_of_crlf_tabs_comments_and_indentation(tmp_path):
    text = "# a comment\r\n  v 0 0 0 # origin\r\n\tv\t1 0 0\r\nv 1 1 0\r\n o   the one \r\n"
    text += "f 1 2 3 # one\r\n"
    (obj,) = read_city(write_text(tmp_path / "odd.obj", text), up="y").objects
    assert obj.name == "the one" and len(obj.faces) == 1


# --- up axis and re-centring -----------------------------------------------------------------


def city_obj(east: float, north: float, ground: float) -> str:
    """Two buildings 60 m apart, 10 and 20 m tall, at projected coordinates (z up)."""
    return (
        "o a\n"
        + box_obj(east, north, ground, east + 20, north + 15, ground + 10, 0)
        + "o b\n"
        + box_obj(east + 60, north + 30, ground, east + 80, north + 45, ground + 20, 8)
    )


def test_a_z_up_city_at_projected_coordinates_is_turned_and_recentred(tmp_path):
    path = write_text(tmp_path / "delftish.obj", city_obj(85000.25, 447000.5, 0.0))
    scene = read_city(path)
    assert scene.up == "z"
    # the centre of the box (85000.25..85080.25, 447000.5..447045.5), in whole metres
    assert scene.offset.tolist() == [85040.0, 447023.0, 0.0]
    a, b = scene.objects
    assert a.vertices[:, 1].min() == 0.0 and a.vertices[:, 1].max() == 10.0  # heights on y
    assert b.vertices[:, 1].max() == 20.0
    # bgr z is -north: b lies north of a, so at smaller z
    assert b.vertices[:, 2].max() < a.vertices[:, 2].min()
    points = np.array([[85000.25, 447000.5, 0.0], [85080.25, 447045.5, 20.0], [1.0, 2.0, 3.0]])
    assert np.array_equal(scene.to_input(scene.from_input(points)), points)
    # every vertex of the file comes back exactly where the file has it
    written = {
        tuple(float(t) for t in line.split()[1:])
        for line in path.read_text().splitlines()
        if line.startswith("v ")
    }
    back = np.concatenate([scene.to_input(o.vertices) for o in scene.objects])
    assert {tuple(p) for p in back.tolist()} == written


def test_a_city_at_altitude_is_brought_down_in_whole_metres(tmp_path):
    scene = read_city(write_text(tmp_path / "zurichish.obj", city_obj(2682700.0, 1248400.0, 403.7)))
    assert scene.up == "z"
    assert scene.offset[2] == 403.0
    assert min(o.vertices[:, 1].min() for o in scene.objects) == pytest.approx(0.7)


def test_small_coordinates_are_not_moved_and_a_tall_model_is_y_up(tmp_path):
    scene = read_city(write_text(tmp_path / "near.obj", city_obj(10.0, 20.0, 0.0)))
    assert scene.up == "z" and scene.offset.tolist() == [0.0, 0.0, 0.0]
    tower = read_city(write_text(tmp_path / "tower.obj", box_obj(0, 0, 0, 10, 50, 10, 0)))
    assert tower.up == "y" and tower.objects[0].vertices[:, 1].max() == 50.0


def test_the_up_axis_can_be_given(tmp_path):
    path = write_text(tmp_path / "given.obj", box_obj(0, 0, 0, 10, 50, 10, 0))
    scene = read_city(path, up="z")
    assert scene.up == "z" and scene.objects[0].vertices[:, 1].max() == 10.0
    with pytest.raises(BgrError, match="unknown up axis"):
        read_city(path, up="x")
    with pytest.raises(BgrError, match="CityJSON"):
        read_city(path, lod="2")


# --- errors ----------------------------------------------------------------------------------

TRIANGLE = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"

MALFORMED = [
    # (file text, line, column, words of the message)
    (TRIANGLE + "f 1 2 3\nv 1 2", 5, 6, "three coordinates, this one has 2 (the file may be cut"),
    (TRIANGLE + "f 1 2 4\n", 4, 7, "vertex index 4 is out of range"),
    (TRIANGLE + "f 1 0 3\n", 4, 5, "vertex index is 0"),
    (TRIANGLE + "f -1 -2 -4\n", 4, 9, "reaches before the first vertex"),
    (TRIANGLE + "f 1 2\n", 4, 6, "at least three vertices, this one has 2"),
    ("v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n", 2, 5, "not a finite number"),
    ("v 0 0 0\nv 1 0 -inf\nv 0 1 0\nf 1 2 3\n", 2, 7, "not a finite number"),
    ("v 0 0 0\nv 1 0 1e999\nv 0 1 0\nf 1 2 3\n", 2, 7, "not a finite number"),
    ("v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n", 2, 5, "not a number"),
    ("v 0 0 0\nv 1 1,5 0\nv 0 1 0\nf 1 2 3\n", 2, 5, "not a number"),
    ("v 0 0 0\nv 1 0 0 1 1\nv 0 1 0\nf 1 2 3\n", 2, 11, "a vertex of 5 numbers"),
    (TRIANGLE + "f 1 2 3.0\n", 4, 7, "not a vertex index"),
    (TRIANGLE + "f 1 /2 3\n", 4, 5, "not a vertex index"),
    ("v 0 0 0\r\nv 1 0 0\r\n\r\nf 1 2 3\r\n", 4, 7, "vertex index 3 is out of range"),
]


@pytest.mark.parametrize(("text", "line", "column", "words"), MALFORMED)
def test_malformed_obj_is_an_error_at_its_line_and_column(tmp_path, text, line, column, words):
    with pytest.raises(BgrError) as caught:
        read_city(write_text(tmp_path / "bad.obj", text))
    error = caught.value
    assert (error.line, error.column) == (line, column), error.render()
    assert words in error.message
    assert error.path.endswith("bad.obj") and error.hint


@pytest.mark.parametrize(
    ("text", "hint"),
    [
        ("", "the file is empty"),
        ("v 0 0 0\nv 1 0 0\nv 1 1 0\n", "3 vertices and no `f` lines"),
        ("# nothing\nvn 0 0 1\n", "no `v` or `f` lines"),
        ("v 0 0 0\nv 1 0 0\nf 1 2 2\n", "repeats a vertex"),
    ],
)
def test_an_obj_without_triangles_is_an_error(tmp_path, text, hint):
    path = write_text(tmp_path / "empty.obj", text)
    with pytest.raises(BgrError, match="no triangles in .*empty.obj") as caught:
        read_city(path)
    assert hint in caught.value.hint


def test_unknown_extensions_and_missing_files_are_errors(tmp_path):
    with pytest.raises(BgrError, match="extension") as caught:
        read_city(write_text(tmp_path / "city.stl", "solid x\n"))
    assert ".obj" in caught.value.hint and ".city.json" in caught.value.hint
    with pytest.raises(BgrError, match="no such city file"):
        read_city(tmp_path / "missing.obj")


# --- hostile OBJ text --------------------------------------------------------------------------

SEED_OBJ = (
    "# seed\no a\nv 0 0 0\nv 1 0 0\nv 1 1 0 \nv 0 1 0\nf 1 2 3 4\ng w\nf -4//1 -2//1 -1//1\n"
    "o b\nv 0 0 1 0.5 0.5 0.5\nv 1 0 1 0.5 0.5 0.5\nv 1 1 1 1 1 1\nf 5/1 6/1 7/1\n"
)
PIECES = [" ", "\n", "/", "-", ".", "0", "1", "9", "e", "#", "f", "v", "o", "nan", "\t", "\r", "é"]


@st.composite
def mutated_obj(draw) -> str:
    text = SEED_OBJ
    for _ in range(draw(st.integers(1, 6))):
        at = draw(st.integers(0, len(text)))
        how = draw(st.sampled_from(["delete", "insert", "replace", "duplicate", "truncate"]))
        if how == "truncate":
            text = text[:at]
        elif how == "delete":
            text = text[:at] + text[at + draw(st.integers(1, 8)) :]
        elif how == "duplicate":
            end = at + draw(st.integers(1, 30))
            text = text[:end] + text[at:end] + text[end:]
        else:
            piece = draw(st.sampled_from(PIECES + [str(draw(st.integers(-20, 20)))]))
            skip = 1 if how == "replace" else 0
            text = text[:at] + piece + text[at + skip :]
    return text


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated_obj())
def test_mutated_obj_reads_or_is_a_bgr_error(tmp_path_factory, text):
    path = tmp_path_factory.mktemp("fuzz") / "m.obj"
    path.write_bytes(text.encode("utf-8"))
    try:
        scene = read_city(path)
    except BgrError as error:
        assert error.path == str(path)
        return
    assert scene.triangles > 0 and all(np.isfinite(o.vertices).all() for o in scene.objects)
    for obj in scene.objects:
        assert obj.faces.min() >= 0 and obj.faces.max() < len(obj.vertices)


@settings(max_examples=200, deadline=None)
@given(mutated_obj())
def test_the_bulk_obj_parser_agrees_with_the_line_by_line_one(text):
    """Where numpy reads the numbers in bulk, the careful parser must read the same numbers
    (and must not find an error): bulk is only ever a faster way to the same result."""
    obj = city_read.ObjText("m.obj", text.encode("utf-8"))
    v_lines, f_lines = obj.lines_of("v"), obj.lines_of("f")
    numbers, widths = city_read._bulk(obj.rests(v_lines), len(v_lines), float)
    usable = numbers is not None and np.isfinite(numbers).all()
    if usable and np.isin(widths, city_read.VERTEX_WIDTHS).all():
        slow, slow_widths = city_read._vertex_lines(obj, v_lines)
        np.testing.assert_array_equal(numbers, slow)
        np.testing.assert_array_equal(widths, slow_widths)
    indices, sizes = city_read._bulk(obj.rests(f_lines), len(f_lines), int)
    if indices is not None and (sizes >= 3).all():
        slow, slow_sizes = city_read._face_lines(obj, f_lines)
        np.testing.assert_array_equal(indices, slow)
        np.testing.assert_array_equal(sizes, slow_sizes)


# --- real OBJ cities -------------------------------------------------------------------------


def test_delft_obj_is_570_objects_z_up():
    scene = read_city(shared("delft.obj"))
    assert len(scene.objects) == 570 and scene.triangles == 36271
    assert scene.up == "z" and abs(scene.offset[0] - 85000) < 1000
    assert scene.offset[1] == pytest.approx(447000, abs=1000)
    # its roads, land use and water have no walls: 218 surfaces, carried (no building among
    # them: the CityJSON of the same tile types them)
    surfaces = [o for o in scene.objects if o.kind == "surface"]
    assert len(surfaces) == 218 and not any(o.proceduralize for o in surfaces)
    typed = {o.name: o.kind for o in read_city(shared("delft.city.json")).objects}
    assert not any(typed.get(o.name) == "Building" for o in surfaces)
    assert sum(typed.get(o.name) == "Building" for o in scene.objects) == 160


# --- CityJSON ------------------------------------------------------------------------------------


def cube(x: int, y: int, z: int, size: int, base: int) -> tuple[list, list]:
    """Vertices (integers) and a Solid shell of a cube, its vertices numbered from ``base``."""
    v = [[x + dx, y + dy, z + dz] for dz in (0, size) for dy in (0, size) for dx in (0, size)]
    faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    return v, [[[base + i for i in f]] for f in faces]


def small_cityjson() -> dict:
    """A Building (a cube), a Building made of one BuildingPart, and a Road, on a millimetre
    grid translated to Dutch national coordinates."""
    v1, shell1 = cube(0, 0, 0, 10000, 0)
    v2, shell2 = cube(30000, 0, 0, 5000, 8)
    road = [[0, -5000, 0], [40000, -5000, 0], [40000, -2000, 0], [0, -2000, 0]]
    solid = {"type": "Solid", "lod": "2", "boundaries": [shell1]}
    return {
        "type": "CityJSON",
        "version": "2.0",
        "transform": {"scale": [0.001, 0.001, 0.001], "translate": [85000.0, 447000.0, -1.5]},
        "metadata": {"referenceSystem": "https://www.opengis.net/def/crs/EPSG/0/7415"},
        "CityObjects": {
            "house": {"type": "Building", "attributes": {"roofType": "flat"}, "geometry": [solid]},
            "hall": {"type": "Building", "children": ["hall-1"]},
            "hall-1": {
                "type": "BuildingPart",
                "parents": ["hall"],
                "geometry": [{"type": "Solid", "lod": "2", "boundaries": [shell2]}],
            },
            "street": {
                "type": "Road",
                "geometry": [
                    {"type": "MultiSurface", "lod": "1", "boundaries": [[[16, 17, 18, 19]]]}
                ],
            },
        },
        "vertices": v1 + v2 + road,
    }


def test_a_small_cityjson_with_a_transform(tmp_path):
    path = tmp_path / "small.city.json"
    path.write_text(json.dumps(small_cityjson()))
    scene = read_city(path)
    assert scene.up == "z" and scene.crs.endswith("EPSG/0/7415")
    assert [(o.name, o.kind, o.proceduralize) for o in scene.objects] == [
        ("house", "Building", True),
        ("hall-1", "BuildingPart", True),
        ("street", "Road", False),
    ]
    house, hall, street = scene.objects
    assert house.attributes == {"roofType": "flat"}
    assert len(house.faces) == 12 and triangle_area(house) == pytest.approx(600.0)
    assert len(street.faces) == 2
    # the transform applied, then re-centred on whole metres (offset in the file's frame)
    assert scene.offset.tolist() == [85020.0, 447002.0, 0.0]  # 447002.5 rounds to even
    back = scene.to_input(house.vertices)
    assert back.min(axis=0) == pytest.approx([85000.0, 447000.0, -1.5])
    assert back.max(axis=0) == pytest.approx([85010.0, 447010.0, 8.5])
    assert house.vertices[:, 1].max() - house.vertices[:, 1].min() == pytest.approx(10.0)


def test_cityjson_lod_and_up_are_checked(tmp_path):
    path = tmp_path / "small.json"
    path.write_text(json.dumps(small_cityjson()))
    scene = read_city(path, lod="1")
    assert [o.name for o in scene.objects] == ["street"]
    with pytest.raises(BgrError, match="no triangles") as caught:
        read_city(path, lod="3")
    assert "lod 3" in caught.value.hint
    with pytest.raises(BgrError, match="z up"):
        read_city(path, up="y")


def test_cityjson_seq_reads_like_cityjson(tmp_path):
    doc = small_cityjson()
    head = {key: doc[key] for key in ("type", "version", "transform", "metadata")}
    feature = {"type": "CityJSONFeature", "id": "all", "CityObjects": doc["CityObjects"]}
    feature["vertices"] = doc["vertices"]
    path = tmp_path / "small.city.jsonl"
    path.write_text(json.dumps({**head, "CityObjects": {}, "vertices": []}) + "\n")
    with path.open("a") as f:
        f.write(json.dumps(feature) + "\n")
    assert [o.name for o in read_city(path).objects] == ["house", "hall-1", "street"]


def test_cityjson_without_vertices_is_an_error(tmp_path):
    doc = small_cityjson()
    del doc["vertices"]
    path = tmp_path / "novertices.city.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(BgrError, match="vertices") as caught:
        read_city(path)
    assert caught.value.path == str(path)


def test_delft_cityjson_proceduralizes_buildings_and_carries_the_rest():
    scene = read_city(shared("delft.city.json"))
    kinds = {o.kind for o in scene.objects}
    assert {"Building", "Road", "LandUse"} <= kinds
    for obj in scene.objects:
        assert obj.proceduralize == (obj.kind in ("Building", "BuildingPart")), obj.kind
    assert sum(o.kind == "Building" for o in scene.objects) == 160
    assert scene.crs.endswith("7415") and scene.up == "z"


def test_zurich_cityjson_objects_are_the_building_parts():
    scene = read_city(shared("zurich_lod2.city.json"))
    assert len(scene.objects) == 161
    assert {o.kind for o in scene.objects} == {"BuildingPart"}
    assert all(o.proceduralize for o in scene.objects)
    assert scene.offset[2] > 300  # 400 m above sea level, brought down
    assert min(o.vertices[:, 1].min() for o in scene.objects) == pytest.approx(0.0, abs=1.0)


def test_3dbag_lods_are_chosen(tmp_path):
    path = shared("3dbag_multi_lod.city.json")
    high, low = read_city(path), read_city(path, lod="1.2")
    assert len(high.objects) == len(low.objects) == 10
    assert low.triangles < high.triangles


# --- glTF and PLY ---------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def block():
    return bgr.derive(ROOT / "examples" / "house.bgr", seed=1, lot=str(BLOCK))


@pytest.mark.parametrize("ext", ["glb", "gltf"])
def test_gltf_written_by_bgr_has_an_object_per_lot(tmp_path, block, ext):
    path = tmp_path / f"block.{ext}"
    write(block.terminals, path, seed=1, attrs=block.attrs)
    scene = read_city(path)
    lots = len(json.loads(BLOCK.read_text())["features"])
    assert scene.up == "y"
    assert [o.name for o in scene.objects] == [f"lot-{i}" for i in range(lots)]
    assert scene.triangles == block.terminals.triangle_count()
    assert all(o.colors is not None and len(o.colors) == len(o.faces) for o in scene.objects)
    # the same objects as bgr's own OBJ of the run
    write(block.terminals, tmp_path / "block.obj", seed=1, attrs=block.attrs)
    from_obj = read_city(tmp_path / "block.obj", up="y")
    for a, b in zip(scene.objects, from_obj.objects, strict=True):
        assert a.name == b.name and len(a.faces) == len(b.faces)
        assert triangle_area(a) == pytest.approx(triangle_area(b), rel=1e-5)


def test_gltf_root_nodes_are_objects_and_buffers_may_be_files(tmp_path, block):
    # no single root: the lots are the scene's roots; the buffer in a .bin beside the .gltf
    write(block.terminals, tmp_path / "embedded.gltf", seed=1, attrs=block.attrs)
    doc = json.loads((tmp_path / "embedded.gltf").read_text())
    root = doc["nodes"][0]
    assert "translation" not in root  # small coordinates: no shift to carry over
    doc["scenes"][0]["nodes"] = root.pop("children")
    uri = doc["buffers"][0]["uri"]
    (tmp_path / "data.bin").write_bytes(base64.b64decode(uri.split(",", 1)[1]))
    doc["buffers"][0]["uri"] = "data.bin"
    path = tmp_path / "roots.gltf"
    path.write_text(json.dumps(doc))
    scene = read_city(path)
    assert [o.name for o in scene.objects] == ["lot-0", "lot-1", "lot-2"]
    assert scene.triangles == block.terminals.triangle_count()
    (tmp_path / "data.bin").unlink()
    with pytest.raises(BgrError, match="not a glTF file .*data.bin"):
        read_city(path)


def test_a_gltf_of_one_node_is_cut_into_components(tmp_path, block):
    path = tmp_path / "flat.glb"
    write(block.terminals, path, seed=1, attrs=block.attrs, gltf={"group_by": "none"})
    scene = read_city(path)
    assert [o.name for o in scene.objects] == ["object-1", "object-2", "object-3"]
    assert scene.triangles == block.terminals.triangle_count()


def test_a_broken_glb_is_an_error(tmp_path):
    path = tmp_path / "broken.glb"
    path.write_bytes(b"glTF\x02\x00\x00\x00")
    with pytest.raises(BgrError, match="not a glTF file"):
        read_city(path)


def ply_of(*boxes: tuple[float, ...]) -> str:
    """An ASCII PLY of boxes (x0, y0, z0, x1, y1, z1), as triangles."""
    vertices, faces = [], []
    for x0, y0, z0, x1, y1, z1 in boxes:
        base = len(vertices)
        vertices += [(x, y, z) for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)]
        for a, b, c, d in [
            (0, 2, 3, 1),
            (4, 5, 7, 6),
            (0, 1, 5, 4),
            (2, 6, 7, 3),
            (0, 4, 6, 2),
            (1, 3, 7, 5),
        ]:
            faces += [(base + a, base + b, base + c), (base + a, base + c, base + d)]
    head = [
        "ply",
        "format ascii 1.0",
        f"element vertex {len(vertices)}",
        "property float x",
        "property float y",
        "property float z",
        f"element face {len(faces)}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    body = [f"{x} {y} {z}" for x, y, z in vertices] + [f"3 {a} {b} {c}" for a, b, c in faces]
    return "\n".join(head + body) + "\n"


def test_ply_of_two_boxes_is_two_objects(tmp_path):
    path = write_text(tmp_path / "boxes.ply", ply_of((0, 0, 0, 10, 10, 6), (40, 20, 0, 50, 30, 9)))
    scene = read_city(path)
    assert scene.up == "z"
    assert [(o.name, len(o.faces)) for o in scene.objects] == [("object-1", 12), ("object-2", 12)]
    assert [o.vertices[:, 1].max() for o in scene.objects] == pytest.approx([6.0, 9.0])


def test_a_broken_ply_is_an_error(tmp_path):
    path = write_text(tmp_path / "broken.ply", "ply\nformat ascii 1.0\nelement vertex 3\n")
    with pytest.raises(BgrError, match="PLY|no triangles") as caught:
        read_city(path)
    assert caught.value.path == str(path)
