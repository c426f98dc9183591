"""Many lots: derived in this process, on a process pool (--workers) and on a Dask cluster
(--dask), written as they come (streamed GLB, CityJSON Sequence, terminal list) — always the
same bytes as a serial run, nothing left behind on failure."""

import json
import subprocess
import sys
import tracemalloc

import numpy as np
import pytest
from conftest import ROOT

import bgr
from bgr.formats import write
from bgr.formats.sinks import open_sink
from bgr.interpreter.batch import derive_lots
from bgr.interpreter.derive import prepare, site_of
from bgr.interpreter.lots import rectangle
from bgr.interpreter.terminals import concat, lot_tables

STREET = ROOT / "examples" / "stdlib_street.bgr"


def cli(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "bgr", *args], capture_output=True, text=True, cwd=cwd
    )


def lot_file(path, n=12, seed=0):
    """A GeoJSON of n footprints in metres: rectangles and L shapes of varied sizes, ids and
    levels (a stand-in for a street of real parcels)."""
    rng = np.random.default_rng(seed)
    features = []
    for i in range(n):
        x0, w, d = 40.0 * i, rng.uniform(8, 20), rng.uniform(8, 16)
        ring = [[x0, 0], [x0 + w, 0], [x0 + w, d], [x0, d]]
        if i % 3 == 2:  # an L
            ring = [
                [x0, 0],
                [x0 + w, 0],
                [x0 + w, d / 2],
                [x0 + w / 2, d / 2],
                [x0 + w / 2, d],
                [x0, d],
            ]
        features.append(
            {
                "type": "Feature",
                "id": f"b{i}",
                "properties": {"height": float(rng.integers(6, 20))},
                "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]},
            }
        )
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


@pytest.fixture(scope="module")
def lots(tmp_path_factory):
    return lot_file(tmp_path_factory.mktemp("lots") / "street.geojson")


@pytest.mark.parametrize("name", ["out.glb", "out.city.jsonl", "out.json"])
def test_two_workers_write_the_bytes_one_process_writes(tmp_path, lots, name):
    one, two = tmp_path / "one", tmp_path / "two"
    one.mkdir(), two.mkdir()
    serial = cli("derive", str(STREET), "--lot", str(lots), "--seed", "5", "-o", str(one / name))
    assert serial.returncode == 0, serial.stderr
    pooled = cli(
        "derive", str(STREET), "--lot", str(lots), "--seed", "5", "-o", str(two / name),
        "--workers", "2",
    )  # fmt: skip
    assert pooled.returncode == 0, pooled.stderr
    assert (one / name).read_bytes() == (two / name).read_bytes()
    assert "12 lots" in pooled.stderr
    # and the streamed file is the one the library writes from the whole table
    whole = tmp_path / ("whole" + name[3:])
    bgr.derive(STREET, seed=5, lot=lots).save(whole)
    assert whole.read_bytes() == (one / name).read_bytes()


def test_a_dask_local_cluster_writes_the_bytes_one_process_writes(tmp_path, lots):
    """A real dask.distributed LocalCluster of two worker processes."""
    distributed = pytest.importorskip("distributed")
    job, lot_list, _ = prepare(STREET, seed=2, lot=lots, per_lot=True)
    outputs = []
    for how in ({}, {"dask": "local", "workers": 2}):
        path = tmp_path / f"city{len(outputs)}.glb"
        with open_sink(
            path,
            seed=2,
            attrs=job.values,
            site=site_of(lot_list),
            grammar=str(job.grammar.path),
            lot_origins=np.array([lot.shape.origin for lot in lot_list]),
        ) as sink:
            for result in derive_lots(job, lot_list, batch_size=2, **how):
                sink.add(result.table)
        outputs.append(path.read_bytes())
    assert outputs[0] == outputs[1]
    # a cluster someone else started: its scheduler's address
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        path = tmp_path / "remote.glb"
        proc = cli(
            "derive", str(STREET), "--lot", str(lots), "--seed", "2", "-o", str(path),
            "--dask", cluster.scheduler_address,
        )  # fmt: skip
        assert proc.returncode == 0, proc.stderr
        assert path.read_bytes() == outputs[0]


def test_an_unreachable_dask_scheduler_is_one_clear_line(tmp_path, lots):
    pytest.importorskip("distributed")
    out = tmp_path / "x.glb"
    proc = cli(
        "derive", str(STREET), "--lot", str(lots), "-o", str(out), "--dask", "tcp://127.0.0.1:9",
    )  # fmt: skip
    assert proc.returncode == 1
    assert "cannot reach a Dask scheduler" in proc.stderr and "Traceback" not in proc.stderr
    assert not out.exists()


def test_a_lot_that_fails_on_a_worker_names_itself_and_leaves_no_file(tmp_path, lots):
    grammar = tmp_path / "bad.bgr"
    # the footprint's height property reaches the grammar: one lot divides by zero
    grammar.write_text("attr height = 10\nLot --> extrude(100 / (height - 12)) Box\nterminal Box\n")
    data = json.loads(lots.read_text())
    data["features"][7]["properties"]["height"] = 12
    bad = tmp_path / "lots.geojson"
    bad.write_text(json.dumps(data))
    for workers in ("1", "2"):
        out = tmp_path / "out.glb"
        proc = cli("derive", str(grammar), "--lot", str(bad), "-o", str(out), "--workers", workers)
        assert proc.returncode == 1, proc.stderr
        assert "feature 7 (id b7)" in proc.stderr and "division by zero" in proc.stderr
        assert "Traceback" not in proc.stderr
        assert not out.exists() and list(tmp_path.glob("*.glb*")) == []


def test_budgets_hold_per_lot_when_streaming_and_for_the_run_when_gathering(tmp_path, lots):
    """A streamed file holds one lot at a time; a gathered one (OBJ) holds them all."""
    grammar = tmp_path / "boxes.bgr"
    grammar.write_text("Lot --> extrude(3) split(x) { ~1: Box }* \nterminal Box\n")
    one_lot = len(bgr.derive(grammar, lot=(20, 10)))
    limit = str(one_lot * 3)  # room for three lots, not twelve
    for name, ok in (("out.glb", True), ("out.city.jsonl", True), ("out.obj", False)):
        out = tmp_path / name
        proc = cli(
            "derive", str(grammar), "--lot", str(lots), "-o", str(out), "--max-shapes", limit
        )
        assert (proc.returncode == 0) == ok, (name, proc.stderr)
        assert out.exists() == ok
        if not ok:
            assert "more than" in proc.stderr and "shapes" in proc.stderr


def test_the_terminal_list_streams_to_standard_output(lots):
    proc = cli(
        "derive", str(STREET), "--lot", str(lots), "-o", "-", "--format", "json", "--workers", "2"
    )
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)
    assert [lot["name"] for lot in data["lots"]] == [f"b{i}" for i in range(12)]
    assert data["terminals"] and data["terminals"][0]["path"].startswith("Lot.0")
    text = bgr.derive(STREET, lot=lots)
    assert proc.stdout == bgr.formats.terminal_json.dumps(text.terminals, seed=0, attrs=text.attrs)


def test_lot_tables_and_concat_undo_each_other(lots):
    table = bgr.derive(STREET, seed=1, lot=lots).terminals
    parts = lot_tables(table)
    assert len(parts) == 12 and sum(len(p) for p in parts) == len(table)
    assert all(p.lots[0]["rows"] == [0, len(p)] for p in parts)
    # each part keeps only the meshes it uses
    assert all(len(p.library.meshes) == len(np.unique(p.mesh)) for p in parts)
    again = concat(parts, site=table.site, grammar=table.grammar)
    assert again.lots == table.lots and again.label == table.label
    for column in ("origin", "axes", "size", "color"):
        assert np.array_equal(getattr(again, column), getattr(table, column))
    assert again.geometry_names() == table.geometry_names()


def test_streaming_memory_does_not_grow_with_the_number_of_lots(tmp_path):
    """Python allocations while deriving and streaming 50 and 500 lots to a GLB: the peak is
    that of a lot or two and the spools' memory buffers (1 MB each), not of the city."""
    grammar = tmp_path / "block.bgr"
    grammar.write_text(
        "Lot --> extrude(12) comp(f) { side: Facade | top: Roof }\n"
        "Facade --> split(y) { ~3: split(x) { ~2: Win }* }*\n"
        "terminal Win\nterminal Roof\n"
    )
    peaks = []
    for n in (50, 500):
        job, _, _ = prepare(grammar, lot=(20, 12), per_lot=True)
        lots = (rectangle(20, 12) for _ in range(n))
        tracemalloc.start()
        with open_sink(tmp_path / f"c{n}.glb", seed=0, attrs=job.values) as sink:
            for result in derive_lots(job, lots, count=n):
                sink.add(result.table)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    assert (tmp_path / "c500.glb").stat().st_size > 9 * (tmp_path / "c50.glb").stat().st_size
    assert peaks[1] < peaks[0] + 4_000_000, peaks


def test_workers_option_is_checked():
    proc = cli("derive", str(STREET), "-o", "x.glb", "--workers", "-2")
    assert proc.returncode == 2 and "--workers" in proc.stderr


def test_a_written_city_reads_back_lot_by_lot(tmp_path, lots):
    """The streamed GLB holds a node per lot with its triangles, as the gathered one does."""
    out = tmp_path / "c.glb"
    assert (
        cli("derive", str(STREET), "--lot", str(lots), "-o", str(out), "--workers", "2").returncode
        == 0
    )
    scene = bgr.formats.read_glb(out)
    table = bgr.derive(STREET, lot=lots).terminals
    assert len(scene.faces) == table.triangle_count()
    gathered = tmp_path / "g.gltf"
    write(table, gathered, seed=0, attrs={})
    nodes = json.loads(gathered.read_text())["nodes"]
    assert [n["name"] for n in nodes[0:1]] == ["bgr"]
    assert {n["name"] for n in nodes if "extras" in n and "path" in n["extras"]} == {
        f"b{i}" for i in range(12)
    }
