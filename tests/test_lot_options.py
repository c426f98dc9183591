"""How footprints become lots beyond their outline (issue 13): ``--map`` feeds attrs from feature
properties (OpenStreetMap's ``building:levels``), ``--front`` chooses the edge the scope's x runs
along, inner rings stay holes (courtyards), and a lot file that cannot be used is one line naming
it, status 1, with no output written.
"""

from __future__ import annotations

import json
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

import bgr
from bgr.grammar.errors import Warnings
from bgr.interpreter.lots import (
    LotOptions,
    PropertyMap,
    coerce,
    parse_front,
    parse_map,
    read_geojson,
)

# OpenStreetMap data (ODbL), committed with its attribution: examples/helsinki/README.md
HELSINKI = ROOT / "examples" / "helsinki" / "helsinki_osm_buildings.geojson"
FLOORS = 'attr floors = 2\nattr kind = "house"\nattr big = false\nterminal X\n'
FLOORS += "Lot --> extrude(floors * 3) X\n"


def feature(coords, properties=None, ident=None, kind="Polygon") -> dict:
    out = {"type": "Feature", "properties": properties or {}, "geometry": None}
    if coords is not None:
        out["geometry"] = {"type": kind, "coordinates": coords}
    if ident is not None:
        out["id"] = ident
    return out


def write(path: Path, *features, **members) -> Path:
    doc = {"type": "FeatureCollection", **members, "features": list(features)}
    path.write_text(json.dumps(doc))
    return path


def box(x0: float, y0: float, w: float = 10.0, d: float = 10.0) -> list:
    """A ring in GeoJSON (x, y) metres, counter-clockwise, first edge along +x."""
    return [[x0, y0], [x0 + w, y0], [x0 + w, y0 + d], [x0, y0 + d], [x0, y0]]


def heights(result: bgr.Result) -> list[float]:
    return [round(float(s[1]), 9) for s in result.terminals.size]


def bgr_cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "bgr", *map(str, args)], capture_output=True, text=True
    )


def options(*maps: str, front: str = "first", streets: str | None = None) -> LotOptions:
    return LotOptions(front=front, streets=streets, mapping=tuple(map(parse_map, maps)))


# ---------------------------------------------------------------------------------------------
# --map


@pytest.mark.parametrize(
    "text, parsed",
    [
        ("floors=building:levels:int", PropertyMap("floors", "building:levels", "int")),
        ("floors=building:levels", PropertyMap("floors", "building:levels", None)),
        ("h=height:float", PropertyMap("h", "height", "float")),
        ("name=addr:street:str", PropertyMap("name", "addr:street", "str")),
        ("flag=roof:bool", PropertyMap("flag", "roof", "bool")),
        ("x=int", PropertyMap("x", "int", None)),  # a property named int: no TYPE left of it
        ("x=a:integer", PropertyMap("x", "a:integer", None)),  # not a TYPE: part of the name
        (" floors = levels ", PropertyMap("floors", "levels", None)),
    ],
)
def test_parse_map(text, parsed):
    assert parse_map(text) == parsed


@pytest.mark.parametrize("text", ["floors", "=levels", "floors=", "floors=:int"])
def test_parse_map_refuses_what_is_no_mapping(text):
    with pytest.raises(bgr.BgrError, match=r"write NAME=PROPERTY\[:TYPE\]"):
        parse_map(text)


@pytest.mark.parametrize(
    "value, kind, expected",
    [
        ("6", "int", 6),
        ("3.5", "int", 4),  # halves away from zero, as round() in .bgr
        ("2.5", "int", 3),
        ("-2.5", "int", -3),
        (2.4, "int", 2),
        (" 7 ", "int", 7),
        ("6", "float", 6.0),
        (3, "float", 3.0),
        ("yes", "bool", True),
        ("No", "bool", False),
        ("1", "bool", True),
        (0, "bool", False),
        (False, "bool", False),
        (6, "str", "6"),
        (3.5, "str", "3.5"),
        (True, "str", "true"),
        ("flat", "str", "flat"),
        ("6", None, "6"),  # no TYPE: as it is, for the attr's type to judge
    ],
)
def test_coerce(value, kind, expected):
    got, why = coerce(value, kind)
    assert why is None and got == expected and type(got) is type(expected)


@pytest.mark.parametrize(
    "value, kind, why",
    [
        ("6 floors", "int", "not a number"),
        ("1_000", "int", "not a number"),
        (True, "int", "not a number"),
        ("1e300", "float", "out of range"),
        ("maybe", "bool", "not true/false, yes/no or 1/0"),
        (2, "bool", "not true/false"),
        ([6], "str", "not a single value"),
        ({"a": 1}, None, "not a single value"),
    ],
)
def test_coerce_refuses(value, kind, why):
    got, reason = coerce(value, kind)
    assert got is None and why in reason


def test_map_sets_attrs_from_properties(tmp_path):
    geo = write(
        tmp_path / "lots.geojson",
        feature([box(0, 0)], {"building:levels": "6"}, ident=1),
        feature([box(20, 0)], {"building:levels": "3.5"}, ident=2),  # rounds to 4
        feature([box(40, 0)], {}, ident=3),  # missing: the grammar's default, silently
        feature([box(60, 0)], {"building:levels": None}, ident=4),  # null: the same
        feature([box(80, 0)], {"building:levels": "six"}, ident=5),  # a warning, the default
        feature([box(100, 0)], {"building:levels": 2, "floors": 9}, ident=6),  # --map wins
        feature([box(120, 0)], {"floors": 9}, ident=7),  # the attr's own name, as before
    )
    result = bgr.derive(FLOORS, lot=str(geo), lot_options=options("floors=building:levels:int"))
    assert heights(result) == [18.0, 12.0, 6.0, 6.0, 6.0, 6.0, 27.0]
    assert [lot["attrs"]["floors"] for lot in result.terminals.lots] == [6, 4, 2, 2, 2, 2, 9]
    (warning,) = [w.render() for w in result.warnings]
    assert warning == (
        f"{geo}: warning: feature 4 (id 5): property 'building:levels' is \"six\", not a number "
        "(--map floors=building:levels:int); the attr 'floors' keeps its value"
    )
    with pytest.raises(bgr.BgrError, match=r"feature 4 \(id 5\): property 'building:levels'"):
        bgr.derive(
            FLOORS,
            lot=str(geo),
            strict=True,
            lot_options=options("floors=building:levels:int"),
        )


def test_map_types_meet_the_attrs_type(tmp_path):
    geo = write(
        tmp_path / "lots.geojson",
        feature([box(0, 0)], {"roof": "yes", "b": "office", "n": "7"}, ident=1),
        feature([box(20, 0)], {"roof": "no", "b": 7, "n": "x"}, ident=2),
    )
    lot_options = options("big=roof:bool", "kind=b:str", "floors=n")
    result = bgr.derive(FLOORS, lot=str(geo), lot_options=lot_options)
    attrs = [lot["attrs"] for lot in result.terminals.lots]
    assert [(a["big"], a["kind"], a["floors"]) for a in attrs] == [
        (True, "office", 7),  # no TYPE: "7" fits a number attr as a property would
        (False, "7", 2),
    ]
    (warning,) = result.warnings  # "x" is no number: the attr's type refuses it
    assert warning.message == (
        "feature 1 (id 2): --map gives 'floors' \"x\", not a number; the attr 'floors' keeps "
        "its value"
    )


def test_a_multipolygon_warns_once_for_its_property(tmp_path):
    multi = [[box(0, 0)], [box(20, 0)]]
    geo = write(tmp_path / "m.geojson", feature(multi, {"lv": "x"}, ident=1, kind="MultiPolygon"))
    result = bgr.derive(FLOORS, lot=str(geo), lot_options=options("floors=lv:int"))
    assert len(result.terminals.lots) == 2 and len(result.warnings) == 1
    assert result.warnings[0].message.startswith("feature 0 (id 1): property 'lv'")


def test_cli_map(tmp_path):
    src = tmp_path / "floors.bgr"
    src.write_text(FLOORS)
    geo = write(
        tmp_path / "lots.geojson",
        feature([box(0, 0)], {"building:levels": "5"}, ident=1),
        feature([box(20, 0)], {"building:levels": "five"}, ident=2),
    )
    out = tmp_path / "out.json"
    args = ("derive", src, "--lot", geo, "-o", out, "--map", "floors=building:levels:int")
    proc = bgr_cli(*args)
    assert proc.returncode == 0, proc.stderr
    assert "feature 1 (id 2): property 'building:levels' is \"five\", not a number" in proc.stderr
    data = json.loads(out.read_text())
    assert [t["size"][1] for t in data["terminals"]] == [15.0, 6.0]
    out.unlink()
    proc = bgr_cli(*args, "--strict")
    assert proc.returncode == 1 and not out.exists() and "Traceback" not in proc.stderr
    # an attr the grammar does not have: as --set, status 1 and the closest name
    proc = bgr_cli("derive", src, "--lot", geo, "-o", out, "--map", "flors=building:levels:int")
    assert proc.returncode == 1 and not out.exists()
    assert proc.stderr.splitlines() == [
        f"{src}: error: --map flors=building:levels:int: the grammar has no attr 'flors' to set",
        "hint: did you mean 'floors'?",
    ]
    # malformed options are usage errors (status 2)
    for bad in (("--map", "floors"), ("--front", "middle"), ("--front", "street:")):
        proc = bgr_cli("derive", src, "--lot", geo, "-o", out, *bad)
        assert proc.returncode == 2 and not out.exists(), bad
    proc = bgr_cli("derive", src, "--lot", "20,30", "-o", out, "--map", "floors=x")
    assert proc.returncode == 2 and "apply to a GeoJSON lot file" in proc.stderr


@pytest.mark.parametrize("text", ["20x30", "20X30", " 20 x 30 ", "20.0x3e1"])
def test_lot_takes_w_by_d_as_size_does(tmp_path, monkeypatch, text):
    """`bgr derive house.bgr --lot 20x20` said "no such lot file" (issue 24): WxD is W,D."""
    src = tmp_path / "floors.bgr"
    src.write_text(FLOORS)
    out = tmp_path / "out.json"
    proc = bgr_cli("derive", src, "--lot", text, "-o", out)
    assert proc.returncode == 0, proc.stderr
    lot = json.loads(out.read_text())["lots"][0]
    assert lot["size"] == [20.0, 0.0, 30.0]
    assert bgr.derive(bgr.load(src), lot=text).terminals.size.tolist() == [[20.0, 6.0, 30.0]]
    # two numbers are a rectangle even beside a file of that name; ./NAME is the file
    monkeypatch.chdir(tmp_path)
    write(tmp_path / "20x30", feature([box(0, 0)]))
    assert bgr.derive(bgr.load(src), lot="20x30").terminals.size.tolist() == [[20.0, 6.0, 30.0]]
    assert bgr.derive(bgr.load(src), lot="./20x30").terminals.size[0, 0] != 20.0


def test_a_lot_that_is_neither_says_what_lot_takes(tmp_path):
    src = tmp_path / "floors.bgr"
    src.write_text(FLOORS)
    proc = bgr_cli("derive", src, "--lot", "20*20", "-o", tmp_path / "out.json")
    assert proc.returncode == 1 and proc.stderr.splitlines() == [
        "20*20: error: no such lot file",
        "hint: --lot takes W,D (or WxD) in metres, or a GeoJSON file",
    ]
    proc = bgr_cli("derive", src, "--lot", "1e400x3", "-o", tmp_path / "out.json")
    assert proc.returncode == 1 and "write the lot as WIDTH,DEPTH (or WIDTHxDEPTH)" in proc.stderr


def test_render_takes_map_and_front(tmp_path):
    src = tmp_path / "floors.bgr"
    src.write_text(FLOORS)
    geo = write(tmp_path / "lots.geojson", feature([box(0, 0)], {"lv": "x"}, ident=1))
    out = tmp_path / "x.png"
    args = ("render", src, "--lot", geo, "-o", out, "--backend", "numpy", "--size", "64x48")
    proc = bgr_cli(*args, "--map", "floors=lv:int", "--front", "longest")
    assert proc.returncode == 0, proc.stderr
    assert "property 'lv' is \"x\", not a number" in proc.stderr
    proc = bgr_cli(*args, "--map", "nope=lv")
    assert proc.returncode == 1 and "the grammar has no attr 'nope'" in proc.stderr


def test_lots_pickle_with_their_mapped_values(tmp_path):
    # the per-lot pipeline sends lots to worker processes
    outer, hole = box(0, 0, 20, 20), box(5, 5)[::-1]
    geo = write(tmp_path / "l.geojson", feature([outer, hole], {"lv": "4"}, ident=1))
    (lot,) = read_geojson(geo, Warnings(), options("floors=lv:int", front="longest"))
    again = pickle.loads(pickle.dumps(lot))
    assert again.mapped == {"floors": 4} and again.shape.geom == lot.shape.geom
    assert again.shape.axes == lot.shape.axes and again.name == lot.name


# ---------------------------------------------------------------------------------------------
# --front


def frame(lot):
    return np.array(lot.shape.origin), [np.array(a) for a in lot.shape.axes]


def inside_is_plus_z(lot) -> bool:
    """The lot's front (the first edge of its outline) runs along its scope's x, and the lot
    lies on the +z side of it (z points into the lot)."""
    from shapely.geometry import Point, Polygon

    polys = lot.shape.geom.polys
    ring = [(0, 0), (1, 0), (1, 1), (0, 1)] if polys == "rect" else polys[0][0]
    sx, _, sz = lot.shape.size
    pts = np.array([(u * sx, v * sz) for u, v in ring])
    a, b = pts[0], pts[1]
    along_x = abs(a[1] - b[1]) < 1e-9 and b[0] > a[0]
    return along_x and Polygon(pts).contains(Point((a + b) / 2 + [0.0, 0.01]))


def test_front_longest_takes_the_longest_edge(tmp_path):
    # 10 m along x, 30 m along y (north, world -z): the first edge is a short one
    geo = write(tmp_path / "l.geojson", feature([box(0, 0, 10, 30)], ident=1))
    (first,) = read_geojson(geo)
    (longest,) = read_geojson(geo, Warnings(), options(front="longest"))
    assert first.shape.size == pytest.approx((10.0, 0.0, 30.0))
    _, (x, _, _) = frame(first)
    assert abs(x[0]) == pytest.approx(1.0)
    assert longest.shape.size == pytest.approx((30.0, 0.0, 10.0))
    origin, (x, y, z) = frame(longest)
    assert abs(x[2]) == pytest.approx(1.0)  # x runs north-south, along the long side
    assert y == pytest.approx([0.0, 1.0, 0.0]) and np.cross(x, y) @ z > 0  # right-handed, y up
    assert inside_is_plus_z(longest)
    # the lot lies between x = 0 and x = 10: z points into it from whichever long side
    assert (origin + 5.0 * z)[0] == pytest.approx(5.0)


def test_front_street_takes_the_edge_nearest_a_street(tmp_path):
    # two lots 10 x 30 m; a street runs east-west 5 m north of them, another north-south along
    # the east side of the second one
    geo = write(
        tmp_path / "l.geojson",
        feature([box(0, 0, 10, 30)], ident="a"),
        feature([box(40, -20, 10, 30)], ident="b"),
    )
    streets = write(
        tmp_path / "streets.geojson",
        feature([[-50, 35], [30, 35]], kind="LineString"),
        feature([[[55, -40], [55, 0]], [[55, 0], [55, 5]]], kind="MultiLineString"),
        feature([0, 0], kind="Point"),  # not a street: left out
    )
    a, b = read_geojson(geo, Warnings(), options(front="street", streets=str(streets)))
    origin, (x, _, z) = frame(a)
    assert a.shape.size == pytest.approx((10.0, 0.0, 30.0))
    assert abs(x[0]) == pytest.approx(1.0) and origin[2] == pytest.approx(-30.0)  # north edge
    assert z[2] == pytest.approx(1.0)  # into the lot: south, away from the street
    origin, (x, _, z) = frame(b)
    assert b.shape.size == pytest.approx((30.0, 0.0, 10.0))
    assert abs(x[2]) == pytest.approx(1.0) and origin[0] == pytest.approx(50.0)  # east edge
    assert z[0] == pytest.approx(-1.0)


def test_front_street_ties_go_to_the_longer_edge(tmp_path):
    # the street's nearest point (25, 27.5) is as far from the middle of the east edge (20, 5)
    # as from the middle of the north edge (10, 10): the north edge is the longer one
    geo = write(tmp_path / "l.geojson", feature([box(0, 0, 20, 10)], ident=1))
    streets = write(tmp_path / "s.geojson", feature([[25, 27.5], [26, 29.5]], kind="LineString"))
    (lot,) = read_geojson(geo, Warnings(), options(front="street", streets=str(streets)))
    origin, (x, _, _) = frame(lot)
    assert lot.shape.size[0] == pytest.approx(20.0) and origin[2] == pytest.approx(-10.0)


def test_front_street_projects_streets_as_the_lots(tmp_path):
    # longitude/latitude: the streets go through the same UTM projection and origin
    lon, lat, dlon, dlat = 24.94, 60.17, 0.0002, 0.0001
    ring = [[lon, lat], [lon + dlon, lat], [lon + dlon, lat + dlat], [lon, lat + dlat], [lon, lat]]
    geo = write(tmp_path / "l.geojson", feature([ring], ident=1))
    east = [[lon + 2 * dlon, lat - dlat], [lon + 2 * dlon, lat + 2 * dlat]]
    streets = write(tmp_path / "s.geojson", feature(east, kind="LineString"))
    (lot,) = read_geojson(geo, Warnings(), options(front="street", streets=str(streets)))
    _, (x, _, z) = frame(lot)
    assert abs(x[2]) > 0.99 and z[0] < -0.99  # the east edge, z pointing west into the lot


@pytest.mark.parametrize(
    "text, message",
    [
        (None, "no such street file"),
        ("{", "not valid JSON"),
        ('{"type": "LineString", "coordinates": [[0, 0], [1, 1]]}', "this one is a bare LineS"),
        ('{"type": "FeatureCollection", "features": []}', "has no LineString or MultiLineString"),
        (
            '{"type": "FeatureCollection", "crs": {"type": "name", "properties": {"name": '
            '"EPSG:4326"}}, "features": []}',
            "the street file is in EPSG:4326, not in the lot file's CRS",
        ),
        (
            '{"type": "FeatureCollection", "crs": {"type": "name", "properties": {"name": '
            '"EPSG:1"}}, "features": []}',
            "the street file's crs member names no CRS bgr knows ('EPSG:1')",
        ),
    ],
)
def test_a_bad_street_file_is_an_error_naming_it(tmp_path, text, message):
    geo = write(tmp_path / "l.geojson", feature([box(0, 0)], ident=1))
    streets = tmp_path / "streets.geojson"
    if text is not None:
        streets.write_text(text)
    with pytest.raises(bgr.BgrError) as caught:
        read_geojson(geo, Warnings(), options(front="street", streets=str(streets)))
    assert caught.value.path == str(streets) and message in caught.value.message


def test_a_bad_street_line_is_skipped_with_a_warning(tmp_path):
    geo = write(tmp_path / "l.geojson", feature([box(0, 0)], ident=1))
    streets = write(
        tmp_path / "s.geojson",
        feature([[0, 20], [10, 20]], kind="LineString", ident="good"),
        feature([[0, "x"], [10, 20]], kind="LineString", ident="bad"),
    )
    warnings = Warnings()
    (lot,) = read_geojson(geo, warnings, options(front="street", streets=str(streets)))
    assert [w.message for w in warnings.items] == [
        "street feature 1 (id bad) skipped: its coordinates are not [x, y] numbers"
    ]
    assert lot.shape.origin[2] == pytest.approx(-10.0)  # the north edge faces the good street


def test_parse_front():
    assert parse_front("longest") == ("longest", None)
    assert parse_front("street:a:b.geojson") == ("street", "a:b.geojson")
    for bad in ("street", "street:", "shortest", "Longest"):
        with pytest.raises(bgr.BgrError, match="write first, longest or street:LINES.geojson"):
            parse_front(bad)
    with pytest.raises(bgr.BgrError):
        LotOptions(front="street")
    with pytest.raises(bgr.BgrError):
        LotOptions(front="sideways")


# ---------------------------------------------------------------------------------------------
# holes (courtyards)

HOLED = [box(0, 0, 30, 30), box(10, 10)[::-1]]  # a 30 m block round a 10 m courtyard


def covers(result: bgr.Result, x: float, z: float) -> list[str]:
    """Labels of the terminals with a triangle over the point (x, z) seen from above."""
    from bgr.interpreter.terminals import world_vertices

    table = result.terminals
    labels = []
    for row in range(len(table)):
        mesh = table.library.meshes[table.mesh[row]]
        pts = world_vertices(table, np.array([row]), mesh)[0][:, [0, 2]]
        a, b, c = (pts[mesh.faces[:, i]] for i in range(3))

        def side(p, q):
            return (q[:, 0] - p[:, 0]) * (z - p[:, 1]) - (q[:, 1] - p[:, 1]) * (x - p[:, 0])

        s1, s2, s3 = side(a, b), side(b, c), side(c, a)
        inside = ((s1 > 0) & (s2 > 0) & (s3 > 0)) | ((s1 < 0) & (s2 < 0) & (s3 < 0))
        if inside.any():
            labels.append(table.label[row])
    return labels


def test_a_courtyard_stays_open(tmp_path):
    geo = write(tmp_path / "c.geojson", feature(HOLED, ident=1))
    src = "terminal Wall, Top\nLot --> extrude(9) comp(f) { side: Wall | top: Top }\n"
    result = bgr.derive(src, lot=str(geo))
    assert result.terminals.label.count("Wall") == 8  # four walls outside, four round the courtyard
    assert covers(result, 15.0, -15.0) == []  # the courtyard's centre (north is -z)
    assert covers(result, 4.0, -7.0) == ["Top"]  # the block
    # flat roofs leave it open too, the eaves reaching into it by the overhang
    for roof in ("roof(flat)", "roof(flat, 0, 1)"):
        src = f"terminal R\nLot --> extrude(9) comp(f) {{ top: {roof} R }}\n"
        result = bgr.derive(src, lot=str(geo))
        assert covers(result, 15.0, -15.0) == [] and covers(result, 4.0, -7.0) == ["R"]
    result = bgr.derive("terminal R\nLot --> roof(flat, 0, 1) R\n", lot=str(geo))
    assert covers(result, 10.5, -15.0) == ["R"] and covers(result, 11.5, -15.0) == []


def test_the_stdlib_builds_on_a_courtyard(tmp_path):
    geo = write(tmp_path / "c.geojson", feature(HOLED, ident=1))
    for rule in ("mass.Block", "mass.Block(roof = rf.Hip)", "mass.UMansard", "mass.PodiumSlab"):
        src = f"import stdlib.mass as mass\nimport stdlib.roof as rf\nLot --> {rule}\n"
        result = bgr.derive(src, lot=str(geo))
        assert len(result.terminals) > 100 and not result.warnings, rule
    # the parapet roof of a Block leaves the courtyard open; a hip roof covers it (the skeleton
    # roofs are built on the outline: see interpreter/geometry/roofs.py, "Holes")
    src = "import stdlib.mass as mass\nLot --> mass.Block(h = 9)\n"
    assert covers(bgr.derive(src, lot=str(geo)), 15.0, -15.0) == []


@pytest.mark.parametrize(
    "hole, why",
    [
        (box(25, 10, 10, 10), "it is not inside the outline, clear of its edges"),  # crosses it
        (box(40, 10), "it is not inside the outline"),  # outside
        (box(0, 10), "clear of its edges"),  # touches the outline
        ([[5, 5], [6, 5], [7, 5], [5, 5]], "its outline has no area"),
        ([[5, 5], [6, "x"], [7, 5], [5, 5]], "its coordinates are not [x, y] numbers"),
    ],
)
def test_an_unusable_hole_is_dropped_with_a_warning(tmp_path, hole, why):
    geo = write(tmp_path / "c.geojson", feature([box(0, 0, 30, 30), hole], ident=7))
    warnings = Warnings()
    (lot,) = read_geojson(geo, warnings)
    assert lot.shape.geom.polys == "rect"  # the block, built over
    (warning,) = warnings.items
    assert warning.message == f"feature 0 (id 7): hole 1 dropped: {why}" or (
        warning.message.startswith("feature 0 (id 7): hole 1 dropped: ") and why in warning.message
    )
    with pytest.raises(bgr.BgrError, match=r"hole 1 dropped"):
        bgr.derive(FLOORS, lot=str(geo), strict=True)


def test_overlapping_holes_keep_the_first(tmp_path):
    rings = [box(0, 0, 30, 30), box(5, 5), box(10, 10)]
    warnings = Warnings()
    (lot,) = read_geojson(write(tmp_path / "c.geojson", feature(rings, ident=7)), warnings)
    assert len(lot.shape.geom.polys[0][1]) == 1
    assert [w.message for w in warnings.items] == [
        "feature 0 (id 7): hole 2 dropped: it touches or overlaps another hole"
    ]


def test_a_concave_outline_faces_into_the_lot(tmp_path):
    # a bar above its first edge and a leg below its start: the corners' mean (used to tell the
    # inside until issue 13) lies below the first edge, the lot above it
    local = [(0, 0), (10, 0), (10, 2), (-2, 2), (-2, -10), (-1, -10), (-1, -9.5), (-0.5, -9.5)]
    local += [(-0.5, -10), (0, -10), (0, 0)]
    ring = [[u, -w] for u, w in local]  # world z is -y: the first edge runs along +x
    (lot,) = read_geojson(write(tmp_path / "l.geojson", feature([ring], ident=1)))
    assert inside_is_plus_z(lot)
    assert lot.shape.axes[0] == pytest.approx((1.0, 0.0, 0.0))


# ---------------------------------------------------------------------------------------------
# lot files that cannot be used: status 1, one message naming the file, no output


@pytest.mark.parametrize(
    "doc, first, hint",
    [
        (
            {"type": "Polygon", "coordinates": [box(0, 0)]},
            "a lot file must be a GeoJSON FeatureCollection or Feature; this one is a bare "
            "Polygon geometry",
            'wrap it in a Feature: {"type": "Feature"',
        ),
        (
            {"type": "CityJSON", "version": "2.0"},
            'this one is a JSON object of type "CityJSON"',
            "ogr2ogr -f GeoJSON",
        ),
        ([1, 2], "this one is a JSON array", "ogr2ogr"),
        (
            {"type": "FeatureCollection", "features": [feature(None), feature(None)]},
            "none of the lot file's 2 features has a geometry",
            "a footprint is a feature with a Polygon or MultiPolygon geometry",
        ),
        (
            {"type": "FeatureCollection", "features": []},
            "the lot file has no features",
            "features with a Polygon or MultiPolygon geometry",
        ),
        (
            {
                "type": "FeatureCollection",
                "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::999999"}},
                "features": [feature([box(0, 0)])],
            },
            "the lot file's crs member names no CRS bgr knows ('urn:ogc:def:crs:EPSG::999999')",
            "reproject the file to longitude/latitude (EPSG:4326, e.g. ogr2ogr -t_srs EPSG:4326 "
            "out.geojson in.geojson) or to a projected CRS in metres",
        ),
    ],
)
def test_a_lot_file_that_cannot_be_used_is_status_1_and_no_output(tmp_path, doc, first, hint):
    src = tmp_path / "box.bgr"
    src.write_text(FLOORS)
    geo = tmp_path / "lots.geojson"
    geo.write_text(json.dumps(doc))
    out = tmp_path / "out.glb"
    proc = bgr_cli("derive", src, "--lot", geo, "-o", out)
    assert proc.returncode == 1 and not out.exists()
    lines = proc.stderr.splitlines()
    assert lines[0].startswith(f"{geo}: error: ") and first in lines[0]
    assert lines[1].startswith("hint: ") and hint in lines[1]
    assert len(lines) == 2 and "Traceback" not in proc.stderr


def test_a_self_crossing_outline_is_repaired_with_a_warning(tmp_path):
    src = tmp_path / "box.bgr"
    src.write_text(FLOORS)
    bow = [[0, 0], [30, 20], [30, 0], [0, 10], [0, 0]]
    geo = write(tmp_path / "lots.geojson", feature([bow], ident=33))
    out = tmp_path / "out.glb"
    proc = bgr_cli("derive", src, "--lot", geo, "-o", out)
    assert proc.returncode == 0 and out.exists()
    assert proc.stderr.splitlines()[0] == (
        f"{geo}: warning: feature 0 (id 33): its outline crosses itself; repaired, keeping the "
        "largest of its 2 parts (200 of 250 m²)"
    )
    out.unlink()
    proc = bgr_cli("derive", src, "--lot", geo, "-o", out, "--strict")
    assert proc.returncode == 1 and not out.exists()
    assert proc.stderr.startswith(f"{geo}: error: feature 0 (id 33): its outline crosses itself")


# ---------------------------------------------------------------------------------------------
# Helsinki: examples/helsinki


def test_helsinki_levels_and_courtyards():
    warnings = Warnings()
    lots = read_geojson(HELSINKI, warnings, options("floors=building:levels:int"))
    assert len(lots) == 481 and len(warnings.items) == 6 + 8  # skipped, repaired: no map warning
    data = json.loads(HELSINKI.read_text())
    levels = {
        str(f["properties"]["id"]): f["properties"].get("building:levels") for f in data["features"]
    }
    for lot in lots:
        tag = levels[lot.feature_id.split("-")[0]]
        expected = {} if tag is None else {"floors": int(float(tag) + 0.5)}
        assert lot.mapped == expected, lot.name
    holed = [lot for lot in lots if lot.shape.geom.polys != "rect" and lot.shape.geom.polys[0][1]]
    assert len(holed) == 61  # every inner ring of the file is a courtyard
    # every front faces into its lot (25 of these did not before issue 13), and every longest
    lots += read_geojson(HELSINKI, Warnings(), options(front="longest"))
    assert all(inside_is_plus_z(lot) for lot in lots)


EXAMPLE = HELSINKI.parent


def test_the_helsinki_example_derives_with_its_levels(tmp_path):
    """examples/helsinki on 60 of its footprints (the whole file takes about 40 s): every one is
    derived, its storeys from building:levels where it has the tag, 4 elsewhere."""
    data = json.loads((EXAMPLE / "helsinki_osm_buildings.geojson").read_text())
    data["features"] = [f for f in data["features"] if f["geometry"]["type"] == "Polygon"][:60]
    geo = tmp_path / "part.geojson"
    geo.write_text(json.dumps(data))
    result = bgr.derive(
        EXAMPLE / "helsinki.bgr", lot=str(geo), lot_options=options("floors=building:levels:int")
    )
    lots = result.terminals.lots
    skipped = [w for w in result.warnings if "skipped" in w.message]
    assert len(lots) == 60 - len(skipped) and len(result.terminals) > 10_000
    for lot in lots:
        tag = lot["properties"].get("building:levels")
        assert lot["attrs"]["floors"] == (4 if tag is None else int(float(tag) + 0.5))
    assert len({lot["attrs"]["floors"] for lot in lots}) >= 5  # tagged 2, 3, 5, 7, 9 here
