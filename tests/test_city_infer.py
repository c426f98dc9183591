"""bgr infer --kind city: cut planes, types, Girvan-Newman groups, the written grammar, and that
deriving it gives the city back (issue 12)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import trimesh

import bgr
from bgr.cli import main
from bgr.formats.assets_folder import MANIFEST
from bgr.formats.meshes import bake
from bgr.inverse.city.cuts import cut_heights, slabs
from bgr.inverse.city.model import CityObject, CityScene
from bgr.inverse.city.pipeline import Options, build, decompose, place, to_text, write
from bgr.inverse.city.types import cluster, level_for

CITIES = Path(__file__).resolve().parent.parent.parent / "shared" / "data" / "cities"


def box(x0, y0, z0, x1, y1, z1) -> trimesh.Trimesh:
    return trimesh.creation.box(bounds=[[x0, y0, z0], [x1, y1, z1]])


def gable_house(w: float, d: float, h: float, ridge: float = 3.0) -> trimesh.Trimesh:
    body = box(0, 0, 0, w, h, d)
    v = np.array(
        [[0, h, 0], [w, h, 0], [w, h, d], [0, h, d], [0, h + ridge, d / 2], [w, h + ridge, d / 2]],
        float,
    )
    f = np.array([[0, 4, 1], [1, 4, 5], [2, 5, 4], [2, 4, 3], [0, 3, 4], [1, 5, 2]])
    return trimesh.util.concatenate([body, trimesh.Trimesh(v, f)])


# ---- cut planes -------------------------------------------------------------------------------


def test_stacked_boxes_are_cut_where_one_box_sits_on_the_next():
    m = trimesh.util.concatenate([box(0, 0, 0, 10, 5, 10), box(2, 5, 2, 8, 12, 8)])
    assert cut_heights(m.vertices, m.faces) == pytest.approx([5.0])


def test_a_tower_with_setbacks_is_cut_at_every_setback_and_nowhere_else():
    tiers = [(0, 0, 30, 20), (2, 20, 26, 35), (4, 35, 22, 47), (6, 47, 20, 60)]
    m = trimesh.util.concatenate([box(a, lo, a, b, hi, b) for a, lo, b, hi in tiers])
    # the walls are split into many triangles at other heights: they must not make cuts
    m = m.subdivide().subdivide()
    assert cut_heights(m.vertices, m.faces) == pytest.approx([20.0, 35.0, 47.0])


def test_a_gable_house_is_cut_at_the_eaves_and_its_roof_is_one_component():
    m = gable_house(8, 10, 6)
    cuts = cut_heights(m.vertices, m.faces)
    assert cuts == pytest.approx([6.0])
    parts = slabs(m.vertices, m.faces, cuts)
    assert [len(p.faces) for p in parts] == [12, 6]  # the box (its top faces up: below); the roof


def test_slabs_cover_the_building_exactly_when_walls_cross_a_cut():
    # a tall box beside a low one: the tall walls cross the cut at the low one's roof
    m = trimesh.util.concatenate([box(0, 0, 0, 4, 10, 4), box(4, 0, 0, 8, 6, 4)])
    cuts = cut_heights(m.vertices, m.faces)
    assert cuts == pytest.approx([6.0])
    parts = slabs(m.vertices, m.faces, cuts)
    area = sum(trimesh.Trimesh(p.vertices, p.faces).area for p in parts)
    assert area == pytest.approx(m.area)
    assert parts[0].vertices[:, 1].max() == pytest.approx(6.0)
    assert parts[1].vertices[:, 1].min() == pytest.approx(6.0)
    # each tall wall's two strips are two triangles each, not the six pieces clipping leaves
    # (issue 29): below, the tall box's bottom and lower strips and the whole low box; above,
    # the upper strips and the top
    assert [len(p.faces) for p in parts] == [22, 10]


def test_clipped_pieces_of_two_colours_are_not_merged():
    """A wall rectangle crossing a cut: its strips are merged into two triangles each when
    both halves have one colour, and left as clipped (three pieces a half) when they differ."""
    v = np.array([[0, 0, 0], [4, 0, 0], [4, 10, 0], [0, 10, 0]], float)
    f = np.array([[0, 1, 2], [0, 2, 3]])
    one = np.array([[200, 0, 0, 255], [200, 0, 0, 255]], np.uint8)
    two = np.array([[200, 0, 0, 255], [0, 0, 200, 255]], np.uint8)
    merged = slabs(v, f, [6.0], one)
    assert [len(p.faces) for p in merged] == [2, 2]
    for p in merged:  # facing as the wall did (+z)
        assert np.allclose(trimesh.Trimesh(p.vertices, p.faces).face_normals, [0, 0, 1])
    kept = slabs(v, f, [6.0], two)
    assert sum(len(p.faces) for p in kept) == 6
    for parts in (merged, kept):
        area = sum(trimesh.Trimesh(p.vertices, p.faces).area for p in parts)
        assert area == pytest.approx(40.0)


# ---- the street of repeated patterns ----------------------------------------------------------


def street(repeats: int = 10) -> CityScene:
    """A street of triplets: two gable houses and a flat-roofed block, then a wide gap."""
    objects, x = [], 0.0
    for _ in range(repeats):
        for kind in "AAB":
            m = gable_house(8, 10, 6) if kind == "A" else box(0, 0, 0, 12, 9, 10)
            m.apply_translation([x, 0, 0])
            x += (8 if kind == "A" else 12) + 2
            objects.append(CityObject(f"b{len(objects)}", "object", m.vertices, m.faces))
        x += 25
    return CityScene(objects, "street.obj", "y")


def infer_scene(scene: CityScene, tmp_path: Path, level: int | None = None):
    options = Options(progress=False, level=level)
    comps = decompose(scene, options)
    types = cluster(comps)
    placed = place(scene, comps, types, level_for(types, level=level), options)
    grammar = build(scene, comps, types, placed, options)
    text = to_text(grammar)
    write(grammar, text, tmp_path / "city.bgr", tmp_path / "city.assets")
    return grammar, text


def test_girvan_newman_groups_a_street_of_triplets_into_one_rule(tmp_path):
    grammar, text = infer_scene(street(), tmp_path)
    groups = re.findall(r"^(Group\d+) -->", text, re.M)
    assert groups == ["Group1"]
    body = text.split("Group1 -->", 1)[1].split("\n#", 1)[0]
    assert re.findall(r"\b(Building\d+) \]", body) == ["Building1", "Building1", "Building2"]
    city = text.split("City -->", 1)[1].split("\n\n", 1)[0]
    assert city.count("Group1") == 10 and "Building" not in city
    # three component types: the house body, its roof, the block
    assert len(grammar.placed.terminals) == 3


def test_deriving_the_street_grammar_gives_every_triangle_back(tmp_path):
    scene = street(4)
    infer_scene(scene, tmp_path)
    result = bgr.derive(
        bgr.load((tmp_path / "city.bgr").read_text(), path=str(tmp_path / "city.bgr"))
    )
    baked = bake(result.terminals)
    derived = trimesh.Trimesh(baked.vertices, baked.faces, process=False)
    source = trimesh.util.concatenate([trimesh.Trimesh(o.vertices, o.faces) for o in scene.objects])
    assert derived.area == pytest.approx(source.area)
    assert np.allclose(derived.bounds, source.bounds, atol=1e-6)
    from bgr.inverse.city.distance import surface_distances

    d = surface_distances(source.vertices, source.faces, derived.vertices, derived.faces)
    assert d.hausdorff < 1e-6


def test_a_coarser_level_has_fewer_types(tmp_path):
    scene = street(3)
    # make every building a little different: level 0 has a type for each
    for i, obj in enumerate(scene.objects):
        obj.vertices = obj.vertices * np.array([1 + 0.01 * i, 1, 1])
    fine, _ = infer_scene(scene, tmp_path)
    coarse, _ = infer_scene(scene, tmp_path, level=3)
    assert len(coarse.placed.terminals) < len(fine.placed.terminals)


def test_a_lossy_level_writes_lengths_no_finer_than_it_moves_things(tmp_path):
    """Level 0 writes millimetres (a tenth of the 1 cm tolerance); level 3, whose building kinds
    merge on a 1 m grid, centimetres: the digits it would spend are noise."""
    scene = street(3)
    for i, obj in enumerate(scene.objects):
        obj.vertices = obj.vertices * np.array([1 + 0.01 * i, 1, 1]) + 0.0123

    def decimals(text: str) -> int:
        lengths = re.findall(r"\b(?:t|s|polygon|extrude)\(([^)]*)\)", text)
        return max(len(d) for args in lengths for d in re.findall(r"\d\.(\d+)", args))

    _, fine = infer_scene(scene, tmp_path)
    _, coarse = infer_scene(scene, tmp_path, level=3)
    assert decimals(fine) == 3 and decimals(coarse) == 1
    turns = re.findall(r"\br\(0, -?\d+\.(\d+), 0\)", coarse)
    assert all(len(d) == 1 for d in turns)  # degrees to a tenth, as the lengths' decimetres
    from bgr.inverse.city.tree import level_digits

    assert [level_digits(level) for level in range(1, 9)] == [2, 2, 1, 1, 1, 1, 1, 1]


# ---- editing ----------------------------------------------------------------------------------


def test_editing_one_type_changes_every_instance_of_it_and_nothing_else(tmp_path):
    infer_scene(street(5), tmp_path)
    path = tmp_path / "city.bgr"
    text = path.read_text()
    before = bgr.derive(bgr.load(text, path=str(path))).terminals
    edited = re.sub(r"^Type2 --> .*$", 'Type2 --> color("#ff0000") i(cube)', text, flags=re.M)
    assert edited != text
    after = bgr.derive(bgr.load(edited, path=str(path))).terminals
    assert len(before) == len(after)
    rule = np.array([before.rule[i] for i in range(len(before))])

    def differs(i: int) -> bool:
        a, b = bake(before, [i]).vertices, bake(after, [i]).vertices
        geometry = a.shape != b.shape or not np.allclose(a, b)
        return geometry or bool(np.any(before.color[i] != after.color[i]))

    changed = np.array([differs(i) for i in range(len(before))])
    assert changed.any()
    assert np.array_equal(changed, rule == "Type2"), "only Type2's instances change"


# ---- real cities: level 0 is lossless ---------------------------------------------------------


# delft.obj (2,000+ buildings) is the long one: `pytest -m slow`
@pytest.mark.parametrize(
    "name, tolerance",
    [
        pytest.param("delft.obj", 0.01, marks=pytest.mark.slow),
        ("zurich_lod2.obj", 0.01),  # the default
        ("zurich_lod2.obj", 0.001),
        ("zurich_lod2.city.json", 0.0001),
    ],
)
def test_level_0_of_a_real_city_derives_back_within_its_tolerance(tmp_path, name, tolerance):
    source = CITIES / name
    if not source.is_file():
        pytest.skip("../shared/data is not here")
    out = tmp_path / "city.bgr"
    args = ["infer", str(source), "-o", str(out), "--no-progress"]
    assert main([*args, "--tolerance", str(tolerance)]) == 0
    result = bgr.derive(bgr.load(out.read_text(), path=str(out)))
    baked = bake(result.terminals)
    from bgr.inverse.city.distance import surface_distances
    from bgr.inverse.city.read import read_city

    scene = read_city(source)
    verts = np.concatenate([o.vertices for o in scene.objects])
    starts = np.cumsum([0] + [len(o.vertices) for o in scene.objects])
    faces = np.concatenate([o.faces + s for o, s in zip(scene.objects, starts, strict=False)])
    d = surface_distances(verts, faces, baked.vertices, baked.faces)
    assert d.hausdorff < tolerance


def test_components_within_the_tolerance_are_one_type(tmp_path):
    """Two boxes 1 mm apart in width: one type at the default 1 cm, two at 0.5 mm.  (Meshes
    are compared on a grid of tolerance / sqrt(3): equal there, they agree within the
    tolerance; nearer than that, they may still straddle a cell's edge.)"""
    first, second = box(0, 0, 0, 10, 6, 8), box(20, 0, 0, 30.001, 6, 8)
    lines, base = [], 1
    for k, m in enumerate((first, second)):
        lines.append(f"o b{k}")
        lines += [f"v {x:.4f} {y:.4f} {z:.4f}" for x, y, z in m.vertices]
        lines += [f"f {a + base} {b + base} {c + base}" for a, b, c in m.faces]
        base += len(m.vertices)
    source = tmp_path / "two.obj"
    source.write_text("\n".join(lines) + "\n")
    for tolerance, types in (("0.01", 1), ("0.0005", 2)):
        out = tmp_path / f"t{types}.bgr"
        assert (
            main(["infer", str(source), "--up", "y", "--tolerance", tolerance, "-o", str(out)]) == 0
        )
        grammar = bgr.load(out)
        assert {r for r in grammar.rules if r.startswith("Type")} == {
            f"Type{k + 1}" for k in range(types)
        }


def test_a_tolerance_out_of_range_is_refused(tmp_path, capsys):
    source = tmp_path / "one.obj"
    source.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    for bad in ("0", "-1", "nan", "2"):
        assert main(["infer", str(source), "--tolerance", bad, "-o", str(tmp_path / "x.bgr")]) == 2
        assert "--tolerance must be a distance over 0" in capsys.readouterr().err


# ---- the command line -------------------------------------------------------------------------


def test_infer_prints_the_grammar_and_puts_the_assets_in_the_working_folder(
    tmp_path, monkeypatch, capsys
):
    scene = street(2)
    m = trimesh.util.concatenate([trimesh.Trimesh(o.vertices, o.faces) for o in scene.objects])
    src = tmp_path / "in" / "street.obj"
    src.parent.mkdir()
    m.export(src)
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    assert main(["infer", str(src), "--no-progress"]) == 0
    out = capsys.readouterr().out
    # the roofed houses are meshes, the boxes footprints extruded
    assert re.search(r'asset type(\d+) = "city\.assets/meshes\.glb#type\1"', out)
    assert re.search(r"Type\d+ --> polygon\([-0-9., ]+\) extrude\([0-9.]+\)", out)
    # every type's mesh in one file (issue 29), a node each
    assert sorted(p.name for p in (work / "city.assets").iterdir()) == [MANIFEST, "meshes.glb"]
    (work / "city.bgr").write_text(out)
    assert main(["check", "city.bgr"]) == 0


@pytest.mark.parametrize(
    ("name", "content", "message"),
    [
        ("cut.obj", "v 0 0 0\nv 1 0 0\nv 1 1", "cut short"),
        ("nan.obj", "v 0 0 nan\nv 1 0 0\nv 1 1 0\nf 1 2 3\n", "NaN"),
        ("empty.obj", "", "no triangles"),
        ("points.obj", "v 0 0 0\nv 1 0 0\n", "no triangles"),
        (
            "novertices.city.json",
            '{"type": "CityJSON", "version": "2.0", "CityObjects": {}}',
            "vertices",
        ),
    ],
)
def test_malformed_cities_end_with_a_clear_error_and_exit_1(
    tmp_path, capsys, name, content, message
):
    src = tmp_path / name
    src.write_text(content)
    out = tmp_path / "city.bgr"
    assert main(["infer", str(src), "-o", str(out), "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert message.lower() in err.lower()
    assert "Traceback" not in err and "internal error" not in err
    assert not out.exists() and not (tmp_path / "city.assets").exists()


def test_the_grammar_synthesises_new_buildings_on_other_lots(tmp_path, root):
    infer_scene(street(3), tmp_path)
    path = tmp_path / "city.bgr"
    grammar = bgr.load(path.read_text(), path=str(path))
    lots = root / "examples" / "block.geojson"
    result = bgr.derive(grammar, lot=str(lots))
    rules = {result.terminals.rule[i] for i in range(len(result.terminals))}
    assert rules <= {"Type1", "Type2", "Type3"} and rules
    # on the default lot it is the city again: 3 x (2 houses of 2 parts + 1 block)
    city = bgr.derive(grammar)
    assert len(city.terminals) == 15
