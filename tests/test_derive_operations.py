"""Operations not covered elsewhere: i() with assets, taper, every roof kind, offset, appearance."""

import json

import numpy as np
import pytest
import trimesh

import bgr
from bgr.interpreter.terminals import world_vertices


def table(src, **kw):
    return bgr.derive(bgr.load(src), **kw).terminals


def bounds_of(t, row):
    mesh = t.library.meshes[t.mesh[row]]
    pts = world_vertices(t, np.array([row]), mesh)[0]
    return pts.min(axis=0), pts.max(axis=0)


@pytest.mark.parametrize("ext", ["obj", "glb", "ply"])
def test_assets_are_fitted_to_the_scope(tmp_path, ext):
    trimesh.creation.box(extents=(2, 4, 1)).export(tmp_path / f"pillar.{ext}")
    src = tmp_path / "a.bgr"
    src.write_text(f'asset pillar = "pillar.{ext}"\nLot --> s(3, 6, 1.5) i(pillar) P\nterminal P\n')
    t = table(src)
    lo, hi = bounds_of(t, 0)
    np.testing.assert_allclose(hi - lo, [3, 6, 1.5], atol=1e-9)
    assert t.geometry_names() == ["pillar"]


def test_asset_with_two_zero_sizes_scales_uniformly(tmp_path):
    trimesh.creation.box(extents=(2, 4, 1)).export(tmp_path / "p.obj")
    src = tmp_path / "a.bgr"
    src.write_text('asset p = "p.obj"\nLot --> s(0, 8, 0) i(p) P\nterminal P\n')
    np.testing.assert_allclose(table(src).size[0], [4, 8, 2], atol=1e-9)


def test_taper_narrows_the_top():
    t = table("Lot --> taper(10, 0.5) M\nterminal M\n", lot=(10, 10))
    mesh = t.library.meshes[t.mesh[0]]
    pts = world_vertices(t, np.array([0]), mesh)[0]
    top = pts[np.isclose(pts[:, 1], 10)]
    assert top[:, 0].min() == pytest.approx(2.5) and top[:, 0].max() == pytest.approx(7.5)
    assert trimesh.Trimesh(pts, mesh.faces).is_watertight


@pytest.mark.parametrize("kind", ["flat", "gable", "hip", "pyramid", "shed", "mansard", "gambrel"])
def test_every_roof_kind_on_a_lot(kind):
    t = table(
        f"Lot --> extrude(5) comp(f) {{ top: roof({kind}, 35, 0.3) R }}\nterminal R\n", lot=(12, 8)
    )
    lo, hi = bounds_of(t, 0)
    assert np.isfinite(lo).all() and np.isfinite(hi).all()
    assert lo[1] >= 5 - 0.3 * np.tan(np.radians(80)) - 1e-6  # eaves drop by the overhang at most
    assert 12 - 1e-6 <= hi[0] - lo[0] <= 12 + 4 * 0.3  # the overhang may widen the roof
    if kind != "flat":
        assert hi[1] > 6


def test_offset_inside_and_border_tile_the_face():
    t = table("Lot --> offset(1) { inside: I | border: B }\nterminal I, B\n", lot=(10, 6))
    assert t.label == ["I", "B"]
    np.testing.assert_allclose(t.size[0], [8, 0, 4])
    areas = [
        trimesh.Trimesh(
            world_vertices(t, np.array([i]), t.library.meshes[t.mesh[i]])[0],
            t.library.meshes[t.mesh[i]].faces,
        ).area
        for i in range(2)
    ]
    assert sum(areas) == pytest.approx(60) and areas[0] == pytest.approx(32)


def test_colour_material_and_label_reach_the_terminal_list(tmp_path):
    src = 'Lot --> color(0, 0.5, 1) material("glass") label("Window") W\nW --> NIL G\nterminal G\n'
    r = bgr.derive(
        bgr.load('Lot --> color(0, 0.5, 1) material("glass") label("Window") G\nterminal G\n')
    )
    r.save(tmp_path / "t.json")
    term = json.loads((tmp_path / "t.json").read_text())["terminals"][0]
    assert (term["color"], term["material"], term["label"], term["rule"]) == (
        "#0080ff",
        "glass",
        "Window",
        "G",
    )
    assert src  # the deleted variant derives to nothing
    assert len(bgr.derive(bgr.load(src))) == 0


def test_offset_of_a_solid_offsets_each_face():
    # CGA offsets every face of a 3D shape: a box's six faces each get a frame and an inside
    import bgr

    grammar = bgr.load(
        "version 1\nterminal In, Frame\n"
        "Lot --> s(4, 2, 3) i(cube) offset(0.5) { inside: In | border: Frame }"
    )
    result = bgr.derive(grammar, lot=(10.0, 10.0))
    labels = list(result.terminals.label)
    assert labels.count("In") == 6 and labels.count("Frame") == 6
    inside = sorted(
        tuple(sorted(round(float(v), 6) for v in result.terminals.size[k][:2]))
        for k, label in enumerate(labels)
        if label == "In"
    )
    # faces 4 x 2, 4 x 3 and 2 x 3 (twice each), each 0.5 m in from every edge
    assert inside == [(1.0, 2.0)] * 2 + [(1.0, 3.0)] * 2 + [(2.0, 3.0)] * 2


def test_setback_sets_edges_in_as_cga_does():
    # the reference's example: setback(3) { front: Yard | remainder: Building }; each selected
    # edge's strip is a piece, corners going to the edge that comes first round the outline
    import bgr

    grammar = bgr.load(
        "version 1\nterminal Yard, Side, Rest\n"
        "Lot --> setback(3) { front: Yard | side: Side | remainder: Rest }"
    )
    result = bgr.derive(grammar, lot=(20.0, 15.0))
    pieces = [
        (label, [round(float(v), 6) for v in result.terminals.size[k]])
        for k, label in enumerate(result.terminals.label)
    ]
    assert pieces == [
        ("Yard", [20.0, 0.0, 3.0]),
        ("Side", [3.0, 0.0, 12.0]),
        ("Side", [17.0, 0.0, 3.0]),
        ("Side", [3.0, 0.0, 9.0]),
        ("Rest", [14.0, 0.0, 9.0]),
    ]
    assert result.mesh.area == pytest.approx(20 * 15)
    # an L: the strip follows the outline, the remainder is what is left
    l_shape = bgr.load(
        "version 1\nterminal Strip, Rest\n"
        "Lot --> footprint(L, 0.5, 0.5) setback(1) { all: Strip | remainder: Rest }"
    )
    done = bgr.derive(l_shape, lot=(10.0, 10.0))
    labels = list(done.terminals.label)
    assert labels.count("Strip") == 6 and labels.count("Rest") == 1
    assert done.mesh.area == pytest.approx(75.0)
    # a distance of 0 sets nothing back: the remainder is the whole shape
    zero = bgr.load("version 1\nterminal S, R\nLot --> setback(0) { all: S | remainder: R }")
    assert list(bgr.derive(zero, lot=(10.0, 10.0)).terminals.label) == ["R"]


def test_extrude_of_a_solid_extrudes_each_face_along_its_normal():
    # CGA extrudes every face of the geometry: a 10 x 20 x 4 box, each face 1 m out
    import bgr

    result = bgr.derive(
        bgr.load("version 1\nterminal B\nLot --> extrude(4) extrude(1) B"), lot=(10.0, 20.0)
    )
    assert np.allclose(result.mesh.bounds, [[-1, -1, -1], [11, 5, 21]])
    # six slabs, each the face's area thick 1 m: 2 x 40 + 2 x 80 + 2 x 200
    assert result.mesh.volume == pytest.approx(640.0)
    assert result.terminals.size[0] == pytest.approx([12.0, 6.0, 22.0])


def test_inner_rectangle_is_the_largest_rectangle_along_the_scope():
    # CGA's innerRectangle(scope) { shape: A | remainder: B }: an L's largest inner rectangle is
    # its longer bar; a rectangle is its own
    import bgr

    text = (
        "version 1\nterminal In, Out\n"
        "Lot --> FOOT innerRectangle(scope) { shape: In | remainder: Out }"
    )
    ell = bgr.derive(bgr.load(text.replace("FOOT", "footprint(L, 0.4, 0.5)")), lot=(20.0, 15.0))
    pieces = {
        label: [round(float(v), 6) for v in ell.terminals.size[k]]
        for k, label in enumerate(ell.terminals.label)
    }
    assert pieces == {"In": [20.0, 0.0, 7.5], "Out": [8.0, 0.0, 7.5]}
    assert ell.mesh.area == pytest.approx(20 * 7.5 + 8 * 7.5)
    box = bgr.derive(bgr.load(text.replace("FOOT ", "")), lot=(20.0, 15.0))
    assert list(box.terminals.label) == ["In"]


@pytest.mark.parametrize(
    "call, shape_area, pieces",
    [
        # CGA's shapeL(frontWidth, leftWidth): the front strip and the left one, as an L
        ("shapeL(4, 5)", 20 * 4 + 5 * (15 - 4), 1),
        # shapeU(front, right, left): three strips
        ("shapeU(4, 3, 5)", 20 * 4 + (3 + 5) * (15 - 4), 1),
        # shapeO(front, right, back, left): a ring round a courtyard of 12 x 8
        ("shapeO(4, 3, 3, 5)", 20 * 15 - 12 * 8, 1),
    ],
)
def test_shape_l_u_o_cut_strips_along_the_scope(call, shape_area, pieces):
    src = f"version 1\nterminal In, Out\nLot --> {call} {{ shape: In | remainder: Out }}\n"
    result = bgr.derive(bgr.load(src), lot=(20.0, 15.0))
    labels = list(result.terminals.label)
    assert labels.count("In") == pieces and labels.count("Out") == 1
    areas = {"In": 0.0, "Out": 0.0}
    for row, label in enumerate(labels):
        mesh = result.terminals.library.meshes[result.terminals.mesh[row]]
        pts = world_vertices(result.terminals, np.array([row]), mesh)[0]
        areas[label] += float(trimesh.Trimesh(pts, mesh.faces, process=False).area)
    assert areas["In"] == pytest.approx(shape_area)
    assert areas["In"] + areas["Out"] == pytest.approx(20 * 15)
    # the L's front strip lies along the street edge (z = 0) and its left strip at x = 0
    if call.startswith("shapeL"):
        row = labels.index("In")
        low, high = bounds_of(result.terminals, row)
        assert low[0] == pytest.approx(0) and low[2] == pytest.approx(0)


def test_reverse_normals_of_a_solid_turns_its_triangles_over():
    solid = bgr.derive(bgr.load("Lot --> extrude(3) reverseNormals() A\nterminal A\n"), lot=(4, 4))
    plain = bgr.derive(bgr.load("Lot --> extrude(3) A\nterminal A\n"), lot=(4, 4))
    # the same box, every face looking inward: its signed volume changes sign
    assert solid.mesh.volume == pytest.approx(-plain.mesh.volume)
    assert plain.mesh.volume == pytest.approx(48)


def test_a_face_turned_into_a_mesh_still_comes_apart():
    # alignScopeToAxes of a face on a turned mass leaves it a mesh in the new scope; extrude
    # and comp(f) take it apart as a prism's faces
    src = (
        "Lot --> r(0, 30, 0) extrude(6) comp(f) { front: Front }\n"
        "Front --> alignScopeToAxes(y) extrude(0.5) comp(f) { all: P }\nterminal P\n"
    )
    result = bgr.derive(bgr.load(src), lot=(10, 8))
    assert len(result.terminals.label) == 6


def test_inner_rectangle_along_an_edge_finds_a_turned_rectangle():
    # CGA's innerRectangle(edge): a 10 x 6 rectangle turned 30 degrees in its scope is its own
    # largest inner rectangle along its edges; along the scope's axes it is much less
    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    pts = [(0, 0), (10 * c, 10 * s), (10 * c - 6 * s, 10 * s + 6 * c), (-6 * s, 6 * c)]
    corners = ", ".join(f"{x + 3:.9f}, {z:.9f}" for x, z in pts)
    text = (
        f"terminal In, Out\nLot --> polygon({corners}) innerRectangle(ALIGN) "
        "{ shape: In | remainder: Out }\n"
    )
    edge = bgr.derive(bgr.load(text.replace("ALIGN", "edge")), lot=(20.0, 20.0))
    scope = bgr.derive(bgr.load(text.replace("ALIGN", "scope")), lot=(20.0, 20.0))

    def area(result, label):
        total = 0.0
        for row, name in enumerate(result.terminals.label):
            if name == label:
                mesh = result.terminals.library.meshes[result.terminals.mesh[row]]
                pts = world_vertices(result.terminals, np.array([row]), mesh)[0]
                total += trimesh.Trimesh(pts, mesh.faces, process=False).area
        return total

    assert area(edge, "In") == pytest.approx(60, rel=1e-6)
    assert area(edge, "Out") == pytest.approx(0, abs=1e-6)
    assert 20 < area(scope, "In") < 50
    # the scope keeps its axes, as CGA's: the piece is a turned rectangle in it
    assert np.allclose(edge.terminals.axes[0], np.eye(3))
