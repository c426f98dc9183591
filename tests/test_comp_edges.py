"""comp(e) and comp(v): edges and vertices as shapes, CGA's edge and vertex component splits
(the reference's examples: ``comp(e) { all : B }``, ``comp(v) { all : B }``, roof edges)."""

import io
import json
from collections import Counter

import numpy as np
import pytest

import bgr
from bgr.formats import write_json
from bgr.grammar.errors import BgrError

BAR = "Bar --> s('1, 0.2, 0.2) center(yz) i(cube)\n"


def rows(src: str, lot=(10, 6)) -> list[dict]:
    result = bgr.derive(bgr.load(src), lot=lot)
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=result.seed, attrs=result.attrs)
    return json.loads(buffer.getvalue())["terminals"]


def labels(src: str, lot=(10, 6)) -> Counter:
    return Counter(t["label"] for t in rows(src, lot))


def test_a_box_has_twelve_edges_and_eight_vertices():
    src = "Lot --> extrude(4) [ comp(e) { all: s('1, 0.1, 0.1) i(cube) E } ] comp(v) { all: V }\n"
    src += "V --> s(0.1, 0.1, 0.1) i(cube)\nterminal E\n"
    assert labels(src) == {"E": 12, "V": 8}


def test_edge_scope_runs_along_the_edge_with_y_the_mean_normal():
    src = "Lot --> extrude(4) comp(e) { vertical: s('1, 0.2, 0.2) i(cube) Post }\nterminal Post\n"
    posts = rows(src)
    assert len(posts) == 4
    corners = {(0, 0), (10, 0), (10, 6), (0, 6)}
    for t in posts:
        x, y, z = np.array(t["axes"])
        assert abs(abs(x[1]) - 1) < 1e-9  # along the vertical edge
        assert t["size"] == pytest.approx([4, 0.2, 0.2])
        assert abs(y[1]) < 1e-9 and abs(abs(y[0]) - abs(y[2])) < 1e-9  # 45 degrees outward
        assert np.allclose(np.cross(x, y), z)
        # the bar's ends lie on the box's corner posts
        start = np.array(t["origin"])
        bottom = start if x[1] > 0 else start + 4 * x
        assert (round(bottom[0]), round(bottom[2])) in corners and abs(bottom[1]) < 1e-9
    # the mean normal points away from the box
    for t in posts:
        o, y = np.array(t["origin"]), np.array(t["axes"][1])
        assert np.dot(y[[0, 2]], o[[0, 2]] - np.array([5, 3])) > 0


def test_a_lots_edges_are_its_outline_and_report_its_perimeter():
    # the corpus's "Parcel Edges Length": comp(e) { all : report(..., scope.sx) NIL }
    src = 'Lot --> comp(e) { border: report("edge", scope.sx) NIL }\n'
    result = bgr.derive(bgr.load(src), lot=(10, 6))
    (lot,) = result.reports
    assert lot["reports"]["edge"]["count"] == 4
    assert lot["reports"]["edge"]["sum"] == pytest.approx(32.0)


def test_bare_edges_and_vertices_make_no_terminals():
    src = "Lot --> extrude(4) [ comp(e) { all: Edge } ] comp(v) { all: Corner }\n"
    src += "terminal Edge, Corner\n"
    assert rows(src) == []


def test_vertical_horizontal_aslant_nutant_on_a_box():
    src = (
        "Lot --> extrude(4) comp(e) { vertical: Bar V | aslant: Bar A | nutant: Bar N "
        "| all: Bar O }\n" + BAR + "terminal V, A, N, O\n"
    )
    # a box's edges: 4 upright (normal level), 4 at the top (normal up at 45 degrees),
    # 4 at the bottom (down at 45 degrees)
    got = Counter(
        t["label"]
        for t in rows(
            src.replace("Bar V", 'label("V") Bar')
            .replace("Bar A", 'label("A") Bar')
            .replace("Bar N", 'label("N") Bar')
            .replace("Bar O", 'label("O") Bar')
        )
    )
    assert got == {"V": 4, "A": 4, "N": 4}


ROOF = (
    "Lot --> footprint({fp}) extrude(4) comp(f) {{ top: Roof }}\n"
    'Roof --> roof({kind}, 30) comp(e) {{ ridge: label("ridge") Bar | hip: label("hip") Bar '
    '| valley: label("valley") Bar | eave: label("eave") Bar | all: label("other") Bar }}\n' + BAR
)


@pytest.mark.parametrize(
    "fp, kind, want",
    [
        ("rect", "hip", {"ridge": 1, "hip": 4, "eave": 4}),
        ("rect", "pyramid", {"hip": 4, "eave": 4}),
        # the L's arms differ in width: a short hip joins their ridges' ends
        ("L", "hip", {"ridge": 2, "hip": 6, "valley": 1, "eave": 6}),
        # the gable ends' rakes and feet are none of the four
        ("rect", "gable", {"ridge": 1, "eave": 2, "other": 6}),
        ("rect", "shed", {"eave": 1, "other": 8}),
    ],
)
def test_roof_edges(fp, kind, want):
    got = labels(ROOF.format(fp=fp, kind=kind), lot=(16, 12))
    assert got == want


def test_index_selectors_and_comp_index():
    src = (
        'Lot --> comp(e) { edge(2): label("third") Bar | all: set(n, comp.total) '
        'label("rest") Bar }\nattr n = 0\n' + BAR
    )
    got = labels(src)
    assert got == {"third": 1, "rest": 3}
    src = "Lot --> comp(v) { vertex(0): s(1, 1, 1) i(cube) First }\nterminal First\n"
    (first,) = rows(src)
    assert np.allclose(first["origin"], [0, 0, 0]) or np.allclose(first["origin"], [10, 0, 0])


def test_vertex_scope_sits_on_the_corner_with_y_the_mean_normal():
    src = "Lot --> extrude(4) comp(v) { all: s(0.5, 0.5, 0.5) i(cube) C }\nterminal C\n"
    found = rows(src)
    assert len(found) == 8
    for t in found:
        x, y, z = np.array(t["axes"])
        origin = np.array(t["origin"])
        # a box corner's three faces: the normal leans out along all three axes
        assert abs(abs(y[1]) - 1 / np.sqrt(3)) < 1e-9
        centre = np.array([5, 2, 3])
        assert np.dot(y, origin - centre) > 0
        assert np.allclose(np.cross(x, y), z)


@pytest.mark.parametrize(
    "src, message",
    [
        ("Lot --> comp(f) { eave: A }\nterminal A\n", "unknown comp selector 'eave'"),
        ("Lot --> comp(e) { face(0): A }\nterminal A\n", "edge(i)"),
        ("Lot --> comp(v) { ridge: A }\nterminal A\n", "unknown comp selector 'ridge'"),
        ("Lot --> comp(q) { all: A }\nterminal A\n", "comp"),
    ],
)
def test_checker_knows_each_kinds_selectors(src, message):
    with pytest.raises(BgrError) as e:
        bgr.load(src)
    assert message in str(e.value)


def test_selectors_of_each_kind_check():
    bgr.load(
        "Lot --> comp(e) { eave: A | ridge: A | hip: A | valley: A | border: A | inside: A "
        "| edge(0): A }\nB --> comp(v) { border: A | vertex(1): A | nutant: A }\n"
        "C --> comp(f) { nutant: A | face(0): A }\nterminal A\n"
    )


def test_an_edge_extrudes_into_a_wall_along_it():
    # a fence along a lot's outline: each edge's y is the lot's normal, so the walls stand up
    src = "Lot --> comp(e) { all: extrude(1.5) Fence }\nterminal Fence\n"
    fences = rows(src)
    assert len(fences) == 4
    assert sorted(round(t["size"][0], 6) for t in fences) == [6, 6, 10, 10]
    for t in fences:
        assert t["size"][1] == pytest.approx(1.5) and t["geometry"] == "polygon"
        assert abs(t["axes"][1][1] - 1) < 1e-9  # up
    result = bgr.derive(bgr.load(src), lot=(10, 6))
    assert result.mesh.area == pytest.approx(2 * (10 + 6) * 1.5)
