"""Warnings of a GeoJSON lot file come in feature order, the same from the API, a serial run and
a pool of workers (issue 24).

A lot file is read in two passes (features parsed, then projected and cleaned together) and then
derived lot by lot: a skipped Point, a repaired self-crossing outline and a property that does
not fit its attr are found at three different times, and used to be reported in that order.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

import bgr

GRAMMAR = "attr floors = 3\nterminal T\nLot --> extrude(floors * 3) T\n"


def _square(x: float) -> list:
    return [[x, 1000], [x + 10, 1000], [x + 10, 1010], [x, 1010], [x, 1000]]


def _bow_tie(x: float) -> list:  # crosses itself: repaired, the larger half kept
    return [[x, 1000], [x + 10, 1010], [x + 10, 1000], [x, 1010], [x, 1000]]


def _feature(ident: str, geometry: dict, **properties) -> dict:
    return {"type": "Feature", "id": ident, "properties": properties, "geometry": geometry}


FEATURES = [
    _feature("ok0", {"type": "Polygon", "coordinates": [_square(1000)]}),
    _feature("cross1", {"type": "Polygon", "coordinates": [_bow_tie(1020)]}),
    _feature("point2", {"type": "Point", "coordinates": [1040, 1000]}),
    _feature(
        "flat3", {"type": "Polygon", "coordinates": [[[1060, 1000], [1065, 1000], [1070, 1000]]]}
    ),
    _feature("misfit4", {"type": "Polygon", "coordinates": [_square(1080)]}, floors="lots"),
    _feature("line5", {"type": "LineString", "coordinates": [[1100, 1000], [1110, 1000]]}),
    _feature("cross6", {"type": "Polygon", "coordinates": [_bow_tie(1120)]}),
    _feature("ok7", {"type": "Polygon", "coordinates": [_square(1140)]}),
    _feature("empty8", {"type": "Polygon", "coordinates": [[]]}),
]
EXPECTED = [
    "feature 1 (id cross1): its outline crosses itself",
    "feature 2 (id point2) skipped: a Point is not a footprint",
    "feature 3 (id flat3) skipped:",
    "feature 4 (id misfit4): property 'floors' is \"lots\"",
    "feature 5 (id line5) skipped: a LineString is not a footprint",
    "feature 6 (id cross6): its outline crosses itself",
    "feature 8 (id empty8) skipped:",
]


@pytest.fixture
def files(tmp_path):
    (tmp_path / "g.bgr").write_text(GRAMMAR)
    (tmp_path / "bad.geojson").write_text(
        json.dumps({"type": "FeatureCollection", "features": FEATURES})
    )
    return tmp_path


def _in_order(messages: list[str]) -> None:
    assert len(messages) == len(EXPECTED), messages
    for message, start in zip(messages, EXPECTED, strict=True):
        assert message.startswith(start), (message, start)


def test_api_warnings_come_in_feature_order(files):
    result = bgr.derive(files / "g.bgr", lot=str(files / "bad.geojson"))
    _in_order([w.message for w in result.warnings])
    assert len(result.terminals.lots) == 5


def test_strict_stops_at_the_first_feature_in_the_file(files):
    with pytest.raises(bgr.BgrError, match="feature 1 "):
        bgr.derive(files / "g.bgr", lot=str(files / "bad.geojson"), strict=True)


def test_serial_and_workers_print_the_api_order(files):
    api = bgr.derive(files / "g.bgr", lot=str(files / "bad.geojson")).warnings
    expected = [w.render() for w in api]
    env = {k: v for k, v in os.environ.items() if k != "BGR_DEBUG"}
    for workers in ("1", "2"):
        proc = subprocess.run(
            [sys.executable, "-m", "bgr", "derive", "g.bgr", "--lot", "bad.geojson"]
            + ["-o", "out.glb", "--workers", workers],
            cwd=files,
            capture_output=True,
            text=True,
            env=env,
            timeout=120,
        )
        assert proc.returncode == 0, proc.stderr
        lines = [line for line in proc.stderr.splitlines() if ": warning: " in line]
        assert lines == [e.replace(str(files / "bad.geojson"), "bad.geojson") for e in expected]
        _in_order([line.split(": warning: ", 1)[1] for line in lines])
