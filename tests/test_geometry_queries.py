"""CGA's geometry functions (interpreter/geometry/queries.py): geometry.area, volume,
nVertices, nFaces and height measure the shape's own geometry in metres, as CityEngine's do."""

import math

import pytest

import bgr


def measured(source: str, lot=(10, 20)) -> dict[str, list[float]]:
    """Each terminal's label -> its size, where the grammar writes the measures into s()."""
    table = bgr.derive(bgr.load(source), lot=lot).terminals.freeze()
    return {table.label[i]: [float(v) for v in table.size[i]] for i in range(len(table))}


def test_a_lot_and_its_extrusion():
    sizes = measured(
        "Lot --> [ Flat ] [ extrude(5) Box ]\n"
        "Flat --> s(geometry.area(), geometry.volume() + 1, geometry.nVertices()) F\n"
        "Box --> [ s(geometry.area(), geometry.volume(), geometry.height()) B ]\n"
        "    [ s(geometry.nVertices(), geometry.nFaces(), 1) C ]\n"
        "terminal F, B, C\n"
    )
    assert sizes["F"] == [200.0, 1.0, 4.0]  # a 2D shape has no volume
    assert sizes["B"] == pytest.approx([2 * 200 + 2 * (10 + 20) * 5, 1000.0, 5.0])
    assert sizes["C"] == [8.0, 6.0, 1.0]  # a box's corners and faces, not its triangles'


def test_a_pyramid_roof_and_an_inserted_cube():
    sizes = measured(
        "Lot --> [ roof(pyramid, 45) Roof ] [ s(2, 3, 4) i(cube) Cube ]\n"
        "Roof --> [ s(geometry.volume(), geometry.height(), geometry.nFaces()) R ]\n"
        "    [ s(geometry.nVertices(), geometry.area(), 1) Q ]\n"
        "Cube --> s(geometry.volume(), geometry.area(), geometry.nFaces()) K\n"
        "terminal R, Q, K\n",
        lot=(10, 10),
    )
    assert sizes["R"] == pytest.approx([100 * 5 / 3, 5.0, 4.0])  # four slopes, 5 m high
    assert sizes["Q"] == pytest.approx([5.0, 4 * 0.5 * 10 * math.hypot(5, 5), 1.0])
    assert sizes["K"] == pytest.approx([24.0, 52.0, 6.0])


def test_height_is_along_the_world_vertical_whatever_the_scope():
    # a façade's scope is turned: its y is the world's, its z points out of the wall
    sizes = measured(
        "Lot --> extrude(12) comp(f) { front: Wall | top: Top }\n"
        "Wall --> s(geometry.height(), geometry.area(), 1) W\n"
        "Top --> s(geometry.height() + 1, geometry.area(), 1) T\n"
        "terminal W, T\n"
    )
    assert sizes["W"] == pytest.approx([12.0, 10 * 12, 1.0])
    assert sizes["T"] == pytest.approx([1.0, 200.0, 1.0])


def test_a_rule_that_asks_is_still_derived_once_and_replayed(monkeypatch):
    source = (
        "Lot --> extrude(30) comp(f) { side: Facade }\n"
        "Facade --> split(y) { 3: Floor }*\n"
        "Floor --> split(x) { ~2: Tile }*\n"
        "Tile --> s(geometry.area(), 1, 1) T\n"
        "terminal T\n"
    )
    with_reuse = bgr.derive(source, lot=(20, 10)).terminals.freeze()
    monkeypatch.setattr("bgr.interpreter.engine.REUSE", False)
    without = bgr.derive(source, lot=(20, 10)).terminals.freeze()
    assert (with_reuse.size == without.size).all() and (with_reuse.origin == without.origin).all()
    assert with_reuse.size[:, 0].tolist() == pytest.approx([6.0] * len(with_reuse))  # 2 x 3 m


def test_the_functions_take_no_arguments():
    with pytest.raises(bgr.BgrCheckError, match="geometry.area"):
        bgr.load("Lot --> s(geometry.area(2), 1, 1) A\nterminal A\n")


def test_written_without_brackets_as_cga_allows():
    source = (
        "Lot --> case geometry.area < 100: s(geometry.area, geometry.nVertices, 1) Small\n"
        "    | else: s(geometry.area, 1, 1) Large\n"
        "terminal Small, Large\n"
    )
    assert measured(source, lot=(5, 5)) == {"Small": [25.0, 4.0, 1.0]}
    assert measured(source, lot=(10, 20)) == {"Large": [200.0, 1.0, 1.0]}
    with pytest.raises(bgr.BgrCheckError, match="only known while deriving a shape"):
        bgr.load("attr a = geometry.area\nLot --> NIL\n")


def test_edges_holes_boundary_concavity_and_planarity():
    # a 10 x 20 lot and its box, and an L: CGA's nEdges, nHoles, boundaryLength, isConcave and
    # isPlanar of each
    sizes = measured(
        "Lot --> [ Flat ] [ extrude(5) Box ] [ footprint(L, 0.4, 0.5) Ell ]\n"
        "Flat --> s(geometry.nEdges(), geometry.boundaryLength(), geometry.nHoles()) "
        "label(str(geometry.isPlanar()) + str(geometry.isConcave())) F\n"
        "Box --> s(geometry.nEdges, geometry.boundaryLength + 1, geometry.nHoles + 1) "
        "label(str(geometry.isPlanar(1)) + str(geometry.isConcave)) B\n"
        "Ell --> s(geometry.nEdges(), 1, 1) label(str(geometry.isConcave())) L\n"
        "terminal F, B, L\n"
    )
    assert sizes["truefalse"] == [4.0, 60.0, 0.0]  # the lot: 4 edges, 60 m round, planar
    assert sizes["falsefalse"] == [12.0, 1.0, 1.0]  # the box: 12 edges, closed, no holes
    assert sizes["true"] == [6.0, 1.0, 1.0]  # the L: 6 edges, concave


def test_area_of_the_faces_a_selector_takes():
    # CGA's geometry.area(selector): the faces a comp(f) selector would take
    sizes = measured(
        "Lot --> extrude(5) s(geometry.area(top), geometry.area(side), geometry.area(front)) B\n"
        "terminal B\n"
    )
    assert sizes["B"] == pytest.approx([200.0, 300.0, 50.0])
    with pytest.raises(bgr.BgrError, match="takes a face selector"):
        bgr.load("version 1\nterminal B\nLot --> s(geometry.area(3), 1, 1) B")


def test_geometry_angle_of_a_gable_roofs_faces():
    # the reference's example colours a cone's faces by geometry.angle(maxSlope) / 90 and by
    # geometry.angle(azimuth) / 360; here a gable roof's slopes and gable ends are measured
    sizes = measured(
        "Lot --> extrude(4) comp(f) { top: Roof }\n"
        "Roof --> roof(gable, 30) comp(f) { all: s(geometry.angle(maxSlope) + 1, "
        'geometry.angle(azimuth) + 1, geometry.angle(zenith) + 1) label("f" + comp.index) F }\n'
        "terminal F\n",
        lot=(10, 8),
    )
    got = sorted(
        (round(s[0] - 1, 6), round(s[1] - 1, 6), round(s[2] - 1, 6)) for s in sizes.values()
    )
    # two 30-degree slopes facing north (0) and south (180), two gable ends facing east and west
    assert got == [(30.0, 0.0, 60.0), (30.0, 180.0, 60.0), (90.0, 90.0, 0.0), (90.0, 270.0, 0.0)]


def test_geometry_angle_of_a_lot_and_a_turned_box():
    sizes = measured(
        "Lot --> [ s(geometry.angle(maxSlope) + 1, geometry.angle(zenith), 1) Flat ]\n"
        "    [ extrude(3) r(0, 45, 0) s(geometry.angle(maxSlope), 1, 1) Box ]\n"
        "terminal Flat, Box\n"
    )
    assert sizes["Flat"] == pytest.approx([1.0, 90.0, 1.0])  # a level lot: no slope
    assert sizes["Box"] == pytest.approx([90.0, 1.0, 1.0])  # its walls


@pytest.mark.parametrize("call", ["geometry.angle(steep)", "geometry.angle(1)", "geometry.angle()"])
def test_geometry_angle_takes_one_of_its_words(call):
    with pytest.raises(bgr.BgrError):
        bgr.load(f"Lot --> s({call}, 1, 1) A\nterminal A\n")
