"""A streamed output written by a second process while this one derives (formats/background.py):
the same bytes as writing here, every failure on either side a clean error, and nothing left
behind (no file, no temporary, no process) whichever side fails, is killed or is interrupted."""

import json
import signal
import subprocess
import sys
import time

import numpy as np
import psutil
import pytest

from bgr.formats.background import Writer, background
from bgr.formats.sinks import open_sink
from bgr.interpreter.batch import default_workers, derive_lots
from bgr.interpreter.derive import prepare, site_of

pytestmark = [
    pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="POSIX signals"),
    pytest.mark.xdist_group("workers"),  # killing processes: not beside the pool's tests
]

GRAMMAR = """\
Lot --> extrude(10) Mass
Mass --> comp(f) { side: Facade | top: Roof }
Facade --> split(y) { 0.25: Row }*
Row --> split(x) { 0.25: Tile }*
terminal Tile, Roof
"""


@pytest.fixture
def street(tmp_path):
    """g.bgr and lots.geojson: n squares of 10 m (6,400 tiles each)."""
    (tmp_path / "g.bgr").write_text(GRAMMAR)
    write_lots(tmp_path / "lots.geojson", 30)
    return tmp_path


def write_lots(path, n):
    square = [[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]]
    features = [
        {
            "type": "Feature",
            "properties": {},
            "geometry": {"type": "Polygon", "coordinates": [[[x + 20 * i, y] for x, y in square]]},
        }
        for i in range(n)
    ]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))


def litter(folder) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name not in ("g.bgr", "lots.geojson"))


def sink_options(job, lots) -> dict:
    return {
        "seed": 0,
        "attrs": job.values,
        "site": site_of(lots),
        "grammar": str(job.grammar.path),
        "lot_origins": np.array([lot.shape.origin for lot in lots]),
    }


@pytest.mark.parametrize("name", ["out.glb", "out.city.jsonl", "out.json"])
def test_the_background_file_is_the_bytes_written_here(street, name):
    job, lots, _ = prepare(street / "g.bgr", lot=street / "lots.geojson", per_lot=True)
    here, there = street / f"here-{name}", street / f"there-{name}"
    with open_sink(here, **sink_options(job, lots)) as sink:
        for result in derive_lots(job, lots):
            sink.add(result.table)
    with background(True) as writer:
        assert writer is not None
        with writer.open_sink(there, **sink_options(job, lots)) as sink:
            for result in derive_lots(job, lots):
                sink.add(result.table)
        assert sink.terminals == 30 * (4 * 1600 + 1)
    assert there.read_bytes() == here.read_bytes()
    assert not writer.process.is_alive() and writer.process.exitcode == 0


def test_a_failure_here_leaves_no_file_and_stops_the_writer(street):
    job, lots, _ = prepare(street / "g.bgr", lot=street / "lots.geojson", per_lot=True)
    out = street / "out.glb"
    with pytest.raises(RuntimeError, match="a lot failed"), background(True) as writer:
        assert writer is not None
        with writer.open_sink(out, **sink_options(job, lots)) as sink:
            for k, result in enumerate(derive_lots(job, lots)):
                sink.add(result.table)
                if k == 5:
                    raise RuntimeError("a lot failed")
    assert not writer.process.is_alive()
    assert litter(street) == []


def test_the_writers_error_comes_back_here_and_leaves_nothing(street):
    """A table the writer cannot write (a mesh id past its library) fails over there: the same
    exception is raised here, by the next table sent or by the end of the run."""
    job, lots, _ = prepare(street / "g.bgr", lot=street / "lots.geojson", per_lot=True)
    out = street / "out.glb"
    with pytest.raises(IndexError), background(True) as writer:
        assert writer is not None
        with writer.open_sink(out, **sink_options(job, lots)) as sink:
            for k, result in enumerate(derive_lots(job, lots)):
                if k == 3:
                    result.table.freeze().mesh[:] = 10_000
                sink.add(result.table)
    assert not writer.process.is_alive()
    assert litter(street) == []


def test_no_process_to_be_had_means_writing_here(monkeypatch):
    def refuse(self):
        raise OSError(11, "Resource temporarily unavailable")

    monkeypatch.setattr(Writer, "__init__", refuse)
    with background(True) as writer:
        assert writer is None


def test_a_refused_output_is_reported_when_opened(street):
    writer = Writer()
    try:
        with (
            pytest.raises(Exception, match="does not exist"),
            writer.open_sink(street / "no" / "such" / "folder" / "out.glb", seed=0, attrs={}),
        ):
            pass
    finally:
        writer.close()
    assert not writer.process.is_alive()


def start(folder, *more):
    return subprocess.Popen(
        [sys.executable, "-m", "bgr", "derive", "g.bgr", "--lot", "lots.geojson"]
        + ["-o", "out.glb", *more],
        cwd=folder,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )


def the_writer(child: subprocess.Popen, seconds: float = 30.0) -> list[psutil.Process]:
    """The run's descendants (forkserver, writer, resource tracker) once the writer has a
    temporary file open, that is once the run is writing."""
    parent = psutil.Process(child.pid)
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        family = parent.children(recursive=True)
        for p in family:
            try:
                if any(f.path.endswith(".tmp") for f in p.open_files()):
                    return family
            except psutil.Error:
                continue
        time.sleep(0.05)
    child.kill()
    raise AssertionError("the writer never started writing")


def writer_of(family):
    return next(p for p in family if any(f.path.endswith(".tmp") for f in p.open_files()))


def all_gone(processes, seconds: float = 10.0) -> list:
    _, alive = psutil.wait_procs(processes, timeout=seconds)
    for p in alive:
        p.kill()
    return alive


two_cores = pytest.mark.skipif(
    default_workers() < 2, reason="bgr writes in the background only with two cores"
)


@pytest.fixture
def many(street):
    write_lots(street / "lots.geojson", 400)  # ~10 s of deriving: time to kill things
    return street


@two_cores
def test_the_cli_writes_in_the_background_on_a_second_core(many):
    child = start(many)
    family = the_writer(child)
    assert writer_of(family).pid != child.pid
    child.kill()
    child.wait(10)
    assert not all_gone(family)


@two_cores
def test_a_killed_writer_is_a_clean_error(many):
    child = start(many)
    family = the_writer(child)
    writer_of(family).send_signal(signal.SIGKILL)
    try:
        _, err = child.communicate(timeout=30)
    finally:
        child.kill()
    assert child.returncode == 1, err
    assert "writer process stopped unexpectedly" in err, err
    assert "Traceback" not in err and "internal error" not in err, err
    assert not all_gone(family)
    assert litter(many) == []  # the killed writer's temporary is removed here


@two_cores
def test_the_writer_ends_with_a_killed_parent_and_removes_its_temporary(many):
    child = start(many)
    family = the_writer(child)
    child.send_signal(signal.SIGKILL)
    child.wait(10)
    assert not all_gone(family, 10.0)
    assert litter(many) == []


@two_cores
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_to_the_process_group_ends_both_cleanly(many, signum):
    child = start(many)
    family = the_writer(child)
    psutil.os.killpg(child.pid, signum)
    try:
        _, err = child.communicate(timeout=15)
    finally:
        child.kill()
    assert child.returncode == (143 if signum == signal.SIGTERM else 130), err
    assert "Traceback" not in err and "Exception ignored" not in err, err
    assert not all_gone(family)
    assert litter(many) == []
