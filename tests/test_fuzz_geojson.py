"""Mutation fuzzing of GeoJSON lot files (issue 10): whatever a file holds, ``bgr.derive(...,
lot=FILE)`` derives or raises ``bgr.BgrError``; no other exception, no traceback.

Valid footprint files (the examples, the test data and a longitude/latitude sample) are mutated
by hypothesis: values replaced by non-finite, huge, tiny or wrongly typed ones, keys deleted,
list items dropped or repeated, values wrapped in lists or nested deeply, and the text cut short.
Each mutant is derived with a grammar that reads a property as an attr, splits the walls and
puts a roof on, both leniently and with ``strict=True``.

The number of cases is ``pytest --fuzz-cases N`` or the environment variable ``BGR_FUZZ_CASES``
(tests/conftest.py; default 300, about 4 s on 2 cores); docs/fuzzing.md records a long run.
"""

from __future__ import annotations

import copy
import json
import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, event, given, note, settings
from hypothesis import strategies as st

import bgr

ROOT = Path(__file__).resolve().parent.parent
CASES = int(os.environ.get("BGR_FUZZ_CASES") or 300)  # pytest --fuzz-cases N sets it

GRAMMAR = bgr.load(
    'attr height = 9\nattr floors = 3\nattr style = "brick"\nattr flat = false\n'
    "terminal Wall, Roof, Top\n"
    "Lot --> extrude(height) comp(f) { top: Cap | side: Side }\n"
    "Cap --> case flat: Top | else: roof(hip, 30) Roof\n"
    "Side --> split(y) { ~height / floors: Wall }*\n"
)

LONLAT = {
    "type": "FeatureCollection",
    "features": [
        {
            "type": "Feature",
            "id": 4253124,
            "properties": {"height": "12.5", "floors": 4, "style": "plaster", "flat": True},
            "geometry": {
                "type": "MultiPolygon",
                "coordinates": [
                    [
                        [
                            [24.9410, 60.1690],
                            [24.9413, 60.1690],
                            [24.9413, 60.1692],
                            [24.9410, 60.1692],
                            [24.9410, 60.1690],
                        ],
                        [[24.9411, 60.1691], [24.9412, 60.1691], [24.9411, 60.1691]],
                    ],
                    [[[24.9420, 60.1690], [24.9422, 60.1690], [24.9421, 60.1692]]],
                ],
            },
        }
    ],
}


# legacy crs members (GeoJSON 2008), which name the CRS the coordinates are in
LEGACY_CRS = [
    dict(LONLAT, crs={"type": "name", "properties": {"name": "urn:ogc:def:crs:OGC:1.3:CRS84"}}),
    {
        "type": "FeatureCollection",
        "crs": {"type": "EPSG", "properties": {"code": 3067}},
        "features": [
            {
                "type": "Feature",
                "properties": {"height": 7},
                "geometry": {
                    "type": "Polygon",
                    "coordinates": [
                        [[385900, 6672300], [385920, 6672300], [385920, 6672315], [385900, 6672300]]
                    ],
                },
            }
        ],
    },
]


# a courtyard block (its inner ring a hole of the lot since issue 13) and a house beside it
COURTYARD = {
    "type": "FeatureCollection",
    "features": [
        {
            "type": "Feature",
            "properties": {"building:levels": "5", "height": 16},
            "geometry": {
                "type": "Polygon",
                "coordinates": [
                    [[0, 0], [40, 0], [40, 30], [0, 30], [0, 0]],
                    [[10, 8], [10, 22], [30, 22], [30, 8], [10, 8]],
                    [[33, 3], [33, 6], [36, 6], [36, 3], [33, 3]],
                ],
            },
        },
        {
            "type": "Feature",
            "properties": {"height": 7},
            "geometry": {
                "type": "Polygon",
                "coordinates": [[[50, 0], [60, 0], [60, 8], [50, 8], [50, 0]]],
            },
        },
    ],
}


def seeds() -> list:
    files = sorted(ROOT.glob("examples/*.geojson")) + sorted(ROOT.glob("tests/data/**/*.geojson"))
    docs = [json.loads(p.read_text(encoding="utf-8")) for p in files]
    return docs + [LONLAT, *LEGACY_CRS, COURTYARD]


SEEDS = seeds()

# values a careless or hostile file may hold anywhere
HOSTILE = [
    float("nan"),
    float("inf"),
    float("-inf"),
    1e300,
    -1e300,
    1e-300,
    10**400,
    2**63,
    0,
    -1,
    0.5,
    True,
    False,
    None,
    "",
    "x",
    "1e400",
    "nan",
    "12",
    "Polygon",
    "MultiPolygon",
    "FeatureCollection",
    [],
    {},
    [[]],
    [[[]]],
    [0, 0],
    [[0, 0]],
    {"type": "Polygon"},
    {"type": "Polygon", "coordinates": None},
    "\u0661\u0660",
    "a" * 10_000,
]


def paths(value, prefix=()) -> list[tuple]:
    """Every place in a JSON document (to depth 20), as the keys and indices that lead there."""
    out = [prefix]
    if len(prefix) >= 20:
        return out
    if isinstance(value, dict):
        for key, item in value.items():
            out += paths(item, (*prefix, key))
    elif isinstance(value, list):
        for i, item in enumerate(value):
            out += paths(item, (*prefix, i))
    return out


def replace_at(doc, path: tuple, new):
    if not path:
        return new
    parent = doc
    for key in path[:-1]:
        parent = parent[key]
    parent[path[-1]] = new
    return doc


def get_at(doc, path: tuple):
    for key in path:
        doc = doc[key]
    return doc


MUTATIONS = ["value", "value", "number", "delete", "drop", "repeat", "wrap", "deep"]


@st.composite
def mutants(draw) -> str:
    """The text of a mutated lot file."""
    doc = copy.deepcopy(draw(st.sampled_from(SEEDS)))
    for _ in range(draw(st.integers(1, 4))):
        places = paths(doc)
        path = places[draw(st.integers(0, len(places) - 1))]
        old = get_at(doc, path)
        kind = draw(st.sampled_from(MUTATIONS))
        if kind == "value":
            doc = replace_at(doc, path, copy.deepcopy(draw(st.sampled_from(HOSTILE))))
        elif kind == "number":
            number = draw(st.floats(allow_nan=True, allow_infinity=True) | st.integers())
            doc = replace_at(doc, path, number)
        elif kind == "delete" and path:
            parent = get_at(doc, path[:-1])
            del parent[path[-1]]
        elif kind == "drop" and isinstance(old, list) and old:
            del old[draw(st.integers(0, len(old) - 1))]
        elif kind == "repeat" and isinstance(old, list) and old:
            i = draw(st.integers(0, len(old) - 1))
            old[i:i] = [copy.deepcopy(old[i])] * draw(st.integers(1, 300))
        elif kind == "wrap":
            doc = replace_at(doc, path, [old])
        elif kind == "deep":
            deep: object = old
            for _ in range(draw(st.sampled_from([2, 10, 900, 5000]))):
                deep = [deep]
            doc = replace_at(doc, path, deep)
            break  # the last mutation: the others would walk the deep list
    try:
        text = json.dumps(doc, allow_nan=True)
    except RecursionError:  # json.dumps itself recurses: a document this deep is written by hand
        text = "[" * 100_000 + "]" * 100_000
    if draw(st.integers(0, 19)) == 7:  # cut short (1 in 20), as a download that stopped
        text = text[: draw(st.integers(0, len(text)))]
    return text


@settings(
    max_examples=CASES,
    deadline=None,
    database=None,
    suppress_health_check=[
        HealthCheck.too_slow,
        HealthCheck.data_too_large,
        HealthCheck.large_base_example,
        HealthCheck.function_scoped_fixture,
    ],
)
@given(text=mutants(), strict=st.booleans())
def test_a_mutated_lot_file_derives_or_is_a_bgr_error(tmp_path_factory, text, strict):
    path = tmp_path_factory.mktemp("lots") / "lots.geojson"
    path.write_text(text, encoding="utf-8")
    note(text[:2000])
    try:
        result = bgr.derive(GRAMMAR, lot=str(path), strict=strict, max_shapes=200_000)
    except bgr.BgrError as e:
        assert e.diagnostics and "Traceback" not in e.render()
        event("BgrError: " + e.diagnostics[0].message.split(":")[0][:40])
        return
    event("derived, with warnings" if result.warnings else "derived")
    assert len(result.terminals) > 0
    if strict:
        assert not result.warnings


@pytest.mark.parametrize("seed", range(len(SEEDS)))
def test_the_seed_files_derive(tmp_path, seed):
    path = tmp_path / "lots.geojson"
    path.write_text(json.dumps(SEEDS[seed]))
    assert len(bgr.derive(GRAMMAR, lot=str(path))) > 0
