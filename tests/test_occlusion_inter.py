"""CGA's ``inter`` occlusion: a query tests the closed shapes of the lots around its own
(within 1 m, CityEngine's neighbourhood), those lots' first passes; the reference's example of
two neighbouring houses whose windows turn to wall where they touch the other's mass."""

import io
import json
import subprocess
import sys
from collections import Counter

import numpy as np
import pytest

import bgr
from bgr.formats import write_json
from bgr.interpreter.lots import footprint
from bgr.interpreter.occlusion import neighbourhoods

HOUSES = """terminal Wall, Window, Roof
attr tall = 0
Lot --> case tall > 0: extrude(20) Mass | else: extrude(10) Mass
Mass --> comp(f) { side: Facade | top: Roof }
Facade --> split(y) { ~3: split(x) { ~3: Tile }* }*
Tile --> case touches(TARGET): Wall | else: Window
"""


def square(x0: float, tall: bool = False):
    return footprint([(x0, 0), (x0 + 10, 0), (x0 + 10, 10), (x0, 10)], {"tall": int(tall)})


# a 20 m house, a 10 m one against its east wall, and one 30 m off
STREET = [square(0, tall=True), square(10), square(40)]


def terminals(target: str, lots=STREET) -> list[dict]:
    result = bgr.derive(bgr.load(HOUSES.replace("TARGET", target)), lot=lots)
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=result.seed, attrs=result.attrs)
    return json.loads(buffer.getvalue())["terminals"]


def walls(tiles: list[dict]) -> Counter:
    return Counter(t["path"].split("/")[0] for t in tiles if t["label"] == "Wall")


def test_windows_against_the_neighbours_mass_turn_to_wall():
    tiles = terminals("inter")
    # the low house's whole west face (3 x 3 tiles); the tall house's east face up to the
    # row that reaches past the neighbour's 10 m (4 rows of 20/7 m x 3)
    assert walls(tiles) == {"Lot.1": 9, "Lot.0": 12}
    for t in tiles:
        if t["label"] == "Wall":
            assert round(t["origin"][0], 6) == 10.0  # only on the shared wall
            if t["path"].startswith("Lot.0"):
                assert t["origin"][1] < 10  # none above the neighbour's roof


def test_intra_does_not_see_other_lots_and_all_sees_both():
    assert walls(terminals("intra")) == {}
    assert walls(terminals("all")) == walls(terminals("inter"))


def test_a_lot_alone_or_far_away_has_no_neighbours():
    assert walls(terminals("inter", [STREET[0], STREET[2]])) == {}


def test_the_same_bytes_on_workers_and_in_any_lot_order(tmp_path):
    # the lots' second passes need every first pass: the workers' run must agree with the
    # serial one (bgr derive --workers 2)
    lots = tmp_path / "lots.geojson"
    features = [
        {
            "type": "Feature",
            "properties": {"tall": tall},
            "geometry": {
                "type": "Polygon",
                "coordinates": [[[x, 0], [x + 10, 0], [x + 10, 10], [x, 10], [x, 0]]],
            },
        }
        for x, tall in ((0, 1), (10, 0), (40, 0), (50, 1))
    ]
    lots.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    grammar = tmp_path / "houses.bgr"
    grammar.write_text(HOUSES.replace("TARGET", "inter"))
    outputs = []
    for workers in ("1", "2"):
        out = tmp_path / f"w{workers}.json"
        run = [sys.executable, "-m", "bgr", "derive", str(grammar), "--lot", str(lots)]
        subprocess.run([*run, "--workers", workers, "-o", str(out)], check=True)
        outputs.append(out.read_bytes())
    assert outputs[0] == outputs[1]
    tiles = json.loads(outputs[0])["terminals"]
    assert Counter(t["label"] for t in tiles)["Wall"] == 9 + 12 + 9 + 12


@pytest.mark.parametrize("gap, near", [(0.0, True), (0.99, True), (1.01, False), (30.0, False)])
def test_neighbourhood_is_one_metre_between_bounding_boxes(gap, near):
    boxes = np.array([[[0, 0, 0], [10, 5, 10]], [[10 + gap, 0, 0], [20 + gap, 5, 10]]], dtype=float)
    assert neighbourhoods(boxes) == ([[1], [0]] if near else [[], []])
