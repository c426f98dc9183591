"""report(key, value) (CGA's reports): each lot's values counted, summed and averaged per key,
in the derive result and in ``bgr derive --reports FILE.json``, the same however the lots
are derived, and without changing what is built."""

import json
import subprocess
import sys

import pytest

import bgr

GRAMMAR = """\
Lot --> report("lot area", geometry.area()) extrude(10) comp(f) { side: Facade | top: Roof }
Facade --> split(y) { 3: Floor }*
Floor --> report("floor", "level") split(x) { ~2: Tile }*
Tile --> report("window area", 1.5) report("lit", split.index % 2 == 0) Win
terminal Win, Roof
"""


def test_each_key_is_counted_summed_and_averaged():
    result = bgr.derive(GRAMMAR, lot=(10, 8))
    (lot,) = result.reports
    reports = lot["reports"]
    assert list(reports) == ["lot area", "floor", "window area", "lit"]
    assert reports["lot area"] == {"count": 1, "sum": 80.0, "mean": 80.0, "min": 80.0, "max": 80.0}
    windows = sum(label == "Win" for label in result.terminals.label)
    assert (
        reports["window area"]["count"] == windows
        and reports["window area"]["sum"] == 1.5 * windows
    )
    assert reports["floor"] == {
        "count": reports["floor"]["count"],
        "values": {"level": reports["floor"]["count"]},
    }
    lit = reports["lit"]["values"]
    assert lit["true"] + lit["false"] == windows and lit["true"] >= lit["false"]


def test_reporting_changes_nothing_that_is_built(tmp_path):
    """A subtree that reports is derived each time rather than replayed, so every call counts;
    the terminals are the bytes the same grammar without reports makes."""
    plain = (
        GRAMMAR.replace('report("lot area", geometry.area()) ', "")
        .replace('report("floor", "level") ', "")
        .replace('report("window area", 1.5) report("lit", split.index % 2 == 0) ', "")
    )
    assert "report" not in plain
    one, two = tmp_path / "one.glb", tmp_path / "two.glb"
    bgr.derive(GRAMMAR, lot=(30, 12)).save(one)
    bgr.derive(plain, lot=(30, 12)).save(two)
    assert one.read_bytes() == two.read_bytes()


def test_a_bad_value_is_an_error_at_its_place():
    with pytest.raises(bgr.BgrCheckError) as info:
        bgr.load("Lot --> report(1, 2) A\nterminal A\n")
    assert info.value.diagnostics[0].line == 1
    with pytest.raises(bgr.BgrCheckError, match="is a rule, not a value"):
        bgr.load('Lot --> report("rule", A) A\nterminal A\n')
    # a rule handed over in a parameter is known only while deriving
    handed = 'Lot --> Part(x = A)\nPart(x) --> report("rule", x) A\nterminal A\n'
    with pytest.raises(bgr.BgrError, match="takes a number, a string or true/false") as info:
        bgr.derive(handed)
    assert info.value.line == 2


def lots_file(path, n=5):
    square = [[0, 0], [12, 0], [12, 9], [0, 9], [0, 0]]
    features = [
        {
            "type": "Feature",
            "id": f"b{i}",
            "properties": {},
            "geometry": {"type": "Polygon", "coordinates": [[[x + 30 * i, y] for x, y in square]]},
        }
        for i in range(n)
    ]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


def cli(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "bgr", *args], capture_output=True, text=True, cwd=cwd
    )


def test_the_cli_writes_every_lots_reports_and_the_total(tmp_path):
    (tmp_path / "g.bgr").write_text(GRAMMAR)
    lots_file(tmp_path / "lots.geojson")
    docs = []
    for workers in ("1", "2"):
        out = f"r{workers}.json"
        proc = cli("derive", "g.bgr", "--lot", "lots.geojson", "-o", f"o{workers}.glb",
                   "--reports", out, "--workers", workers, cwd=tmp_path)  # fmt: skip
        assert proc.returncode == 0, proc.stderr
        docs.append(json.loads((tmp_path / out).read_text()))
    assert docs[0] == docs[1]  # however the lots were derived
    doc = docs[0]
    assert [lot["id"] for lot in doc["lots"]] == [f"b{i}" for i in range(5)]
    assert doc["total"]["lot area"] == {
        "count": 5,
        "sum": 540.0,
        "mean": 108.0,
        "min": 108.0,
        "max": 108.0,
    }
    per_lot = doc["lots"][0]["reports"]["window area"]["count"]
    assert doc["total"]["window area"]["count"] == 5 * per_lot


def test_a_reports_file_that_cannot_be_written_stops_the_run_before_it_starts(tmp_path):
    (tmp_path / "g.bgr").write_text(GRAMMAR)
    proc = cli("derive", "g.bgr", "-o", "out.glb", "--reports", "/proc/reports.json", cwd=tmp_path)
    assert proc.returncode == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert not (tmp_path / "out.glb").exists()


def test_print_writes_each_call_in_order_derived_or_not(tmp_path):
    source = (
        "attr floors = 3\n"
        'Lot --> print("floors: " + floors) extrude(9) comp(f) { side: Facade | top: Roof }\n'
        "Facade --> split(y) { 3: Floor }*\n"
        'Floor --> print("floor " + split.index) Wall\n'
        "terminal Wall, Roof\n"
    )
    prints = bgr.derive(source, lot=(10, 8)).prints
    # four sides of three floors each: a floor that prints is derived, not replayed
    assert prints == ["floors: 3"] + [f"floor {i}" for i in range(3)] * 4
    (tmp_path / "g.bgr").write_text(source)
    lots_file(tmp_path / "lots.geojson", n=3)
    outs = []
    for workers in ("1", "2"):
        proc = cli("derive", "g.bgr", "--lot", "lots.geojson", "-o", f"o{workers}.glb",
                   "--workers", workers, cwd=tmp_path)  # fmt: skip
        assert proc.returncode == 0, proc.stderr
        outs.append([line for line in proc.stderr.splitlines() if line.startswith("floor")])
    assert outs[0] == outs[1] == (["floors: 3"] + [f"floor {i}" for i in range(3)] * 4) * 3
