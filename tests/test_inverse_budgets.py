"""Sizes and coordinates the inverse commands must bound before the work (issue 34).

A city vertex at 1e308 hung GEOS past SIGTERM; a box of 10,000 children asked for 12 GB in the
pairwise analysis; ``bgr infer`` and ``bgr retarget`` had no memory ceiling although their
out-of-memory message named ``--max-memory``.  Each reproducer ends in exit 0 or in exit 1 with
one located message, within 10 s, under a 2 GB address space, leaving no output behind.
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from bgr.grammar.errors import BgrError
from bgr.inverse.boxes import analysis, model
from bgr.inverse.boxes.retarget import retarget
from bgr.inverse.city.read import read_city

CAP = 2 * 2**30  # address space of each command run: 2 GB
SECONDS = 10


def _cap() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (CAP, CAP))


def run_bgr(args: list[str], cwd: Path) -> tuple[subprocess.CompletedProcess, float]:
    """``bgr ARGS`` in a fresh process of at most 2 GB; killed (a failure) after 3 x SECONDS."""
    start = time.perf_counter()
    proc = subprocess.run(
        [sys.executable, "-m", "bgr", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        preexec_fn=_cap,
        timeout=SECONDS * 3,
    )
    return proc, time.perf_counter() - start


def assert_located(proc: subprocess.CompletedProcess, where: str, *words: str) -> None:
    """Exit 1 with one error, at ``where`` (file, or file:line:col), saying ``words``."""
    err = proc.stderr
    assert proc.returncode == 1, err
    assert "Traceback" not in err and "internal error" not in err, err
    assert err.count("error:") == 1 and err.startswith(f"{where}: error:"), err
    for word in words:
        assert word in err, err


# ---- cities: coordinates ---------------------------------------------------------------------


def two_buildings_obj(value: str) -> str:
    """Two objects of an OBJ; vertex 6, on line 7, has x = ``value``."""
    return (
        "o a\nv 0 0 0\nv 10 0 0\nv 10 0 10\nv 0 0 10\nv 0 8 0\n"
        f"v {value} 8 0\n"
        "f 1 2 3 4\nf 1 2 5\nf 2 6 5\n"
        "o b\nv 20 0 0\nv 30 0 0\nv 30 0 10\nv 20 8 0\nf 7 8 9\nf 7 8 10\n"
    )


def test_a_city_vertex_at_1e308_stops_at_its_line_not_in_geos(tmp_path):
    """bgr infer on an OBJ with a vertex at 1e308 hung in GEOS simplify (past SIGTERM): now one
    error at the vertex's line and column, before anything is written."""
    (tmp_path / "city.obj").write_text(two_buildings_obj("1e308"))
    proc, seconds = run_bgr(["infer", "city.obj", "-o", "out.bgr", "--no-progress"], tmp_path)
    assert_located(proc, "city.obj:7:3", "vertex 6", "x = 1e+308", "beyond 100,000,000 m")
    assert seconds < SECONDS
    assert sorted(p.name for p in tmp_path.iterdir()) == ["city.obj"]


@pytest.mark.parametrize(
    ("value", "words"),
    [
        ("1e308", "x = 1e+308 is beyond"),
        ("-2e8", "x = -2e+08 is beyond"),
        ("nan", "not a finite number"),
        ("-inf", "not a finite number"),
    ],
)
def test_a_bad_obj_vertex_is_an_error_at_its_line(tmp_path, value, words):
    path = tmp_path / "city.obj"
    path.write_text(two_buildings_obj(value))
    with pytest.raises(BgrError) as caught:
        read_city(path)
    error = caught.value
    assert (error.path, error.line, error.column) == (str(path), 7, 3)
    assert words in error.message


def test_a_city_at_the_bound_is_read(tmp_path):
    """1e8 m is as far as a lot may be: such a city is read (and re-centred)."""
    path = tmp_path / "city.obj"
    path.write_text(two_buildings_obj("1e8"))
    scene = read_city(path)
    assert [o.name for o in scene.objects] == ["a", "b"]


def ply_with(value: str) -> str:
    """An ASCII PLY of two triangles (doubles); vertex 4 has x = ``value``."""
    head = "ply\nformat ascii 1.0\nelement vertex 4\n"
    head += "".join(f"property double {a}\n" for a in "xyz")
    head += "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
    return head + f"0 0 0\n10 0 0\n10 10 0\n{value} 10 0\n3 0 1 2\n3 0 2 3\n"


@pytest.mark.parametrize("value", ["1e308", "nan", "inf"])
def test_a_bad_ply_vertex_is_named(tmp_path, value):
    path = tmp_path / "city.ply"
    path.write_text(ply_with(value))
    with pytest.raises(BgrError) as caught:
        read_city(path)
    assert caught.value.path == str(path)
    assert caught.value.message.startswith("vertex 4 (counted from 1): x = ")


@pytest.mark.parametrize(
    ("vertex", "scale", "shown"),
    [([10**20, 10, 0], 1, "x = 1e+20 is beyond"), ([0, 10, 0], 1e300, "x = 1e+301 is beyond")],
)
def test_a_far_cityjson_vertex_names_its_city_object(tmp_path, vertex, scale, shown):
    """A huge vertex, or a transform that makes one, is an error naming the city object."""
    doc = {
        "type": "CityJSON",
        "version": "2.0",
        "transform": {"scale": [scale, 1, 1], "translate": [0, 0, 0]},
        "CityObjects": {
            "b1": {
                "type": "Building",
                "geometry": [
                    {"type": "MultiSurface", "lod": "1", "boundaries": [[[0, 1, 2]], [[0, 2, 3]]]}
                ],
            }
        },
        "vertices": [[0, 0, 0], [10, 0, 0], [10, 10, 0], vertex],
    }
    path = tmp_path / "city.city.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(BgrError) as caught:
        read_city(path)
    assert caught.value.path == str(path)
    assert caught.value.message.startswith("a vertex of Building 'b1': ")
    assert shown in caught.value.message


def test_a_far_gltf_vertex_names_its_node(tmp_path):
    import trimesh

    scene = trimesh.Scene()
    for name, x in (("near", 0.0), ("far", 1e30)):
        box = trimesh.creation.box((10, 8, 10))
        box.vertices[0, 0] += x
        scene.add_geometry(box, node_name=name, geom_name=name)
    path = tmp_path / "city.glb"
    path.write_bytes(scene.export(file_type="glb"))
    with pytest.raises(BgrError) as caught:
        read_city(path)
    assert caught.value.path == str(path)
    assert "object 'far'" in caught.value.message and "is beyond" in caught.value.message


@pytest.mark.parametrize(("key", "value"), [("origin", [1e308, 0, 0]), ("size", [1e308, 1e308, 1])])
def test_a_far_terminal_of_a_terminal_list_is_named(key, value):
    """bgr infer --kind schema took a terminal at 1e308, then blamed itself: the grammar it
    inferred did not derive ("this is a bug in bgr infer")."""
    from bgr.inverse.schema.terminals import read_terminals

    terminal = {
        "label": "Wall",
        "rule": "Wall",
        "path": "Lot/Wall.0",
        "origin": [0, 0, 0],
        "axes": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
        "size": [10, 8, 0],
        "geometry": "polygon",
    }
    terminal[key] = value
    with pytest.raises(BgrError) as caught:
        read_terminals({"terminals": [terminal]}, "house.json")
    assert caught.value.path == "house.json"
    assert caught.value.message.startswith(f"terminals[0].{key} must be a list of 3 finite")


# ---- boxes: sizes ------------------------------------------------------------------------------


def row_of_boxes(n: int, tag: str = "R") -> dict:
    """A root of ``n`` 1 m boxes side by side along x."""
    kids = [
        {"id": f"w{i}", "min": [i, 0, 0], "max": [i + 1, 3, 1], "behavior": {"x": tag}}
        for i in range(n)
    ]
    return {"root": {"id": "root", "min": [0, 0, 0], "max": [n, 3, 1], "children": kids}}


@pytest.mark.parametrize(
    "command",
    [
        ["retarget", "boxes.json", "--size", "20000,3,1", "-o", "out.json"],
        ["infer", "--kind", "boxes", "boxes.json", "-o", "out.bgr"],
    ],
)
def test_a_box_of_10000_children_is_refused_before_the_pairwise_work(tmp_path, command):
    """The analysis compares every two children of a box: 10,000 asked for 12 GB and ran out
    of memory; now the reader refuses the box, naming it and the limit, at once."""
    (tmp_path / "boxes.json").write_text(json.dumps(row_of_boxes(10_000)))
    proc, seconds = run_bgr(command, tmp_path)
    assert_located(proc, "boxes.json", "box 'root' has 10,000 children", f"{model.MAX_CHILDREN:,}")
    assert "hint: group them" in proc.stderr
    assert seconds < SECONDS
    assert sorted(p.name for p in tmp_path.iterdir()) == ["boxes.json"]


def test_an_input_of_more_boxes_than_max_boxes_is_refused_before_the_analysis(tmp_path):
    (tmp_path / "boxes.json").write_text(json.dumps(row_of_boxes(30)))
    proc, _ = run_bgr(
        ["retarget", "boxes.json", "--size", "20,3,1", "--max-boxes", "20", "-o", "o.json"],
        tmp_path,
    )
    assert_located(proc, "boxes.json", "31 boxes, more than the 20", "--max-boxes")
    assert not (tmp_path / "o.json").exists()


def test_copies_past_the_children_limit_are_refused_along_the_next_axis(monkeypatch):
    """Copies made along x become children analysed along y: past the limit, a clear error
    (not a 10,000 x 10,000 analysis)."""
    monkeypatch.setattr(analysis, "MAX_CHILDREN", 30)
    root = model.parse(json.dumps(row_of_boxes(20)), "row.json")
    assert len(retarget(root, (28, 3, 1), "xy").children) == 28  # within the limit: done
    with pytest.raises(BgrError) as caught:
        retarget(root, (40, 4, 1), "xy")
    assert caught.value.message.startswith("along y, box 'root' has 40 children")
    assert "--order" in caught.value.hint


_BELOW_10000 = """
import numpy as np
from bgr.inverse.boxes.analysis import _below
rng = np.random.default_rng(1)
lo = rng.uniform(0, 100, (10_000, 3))
hi = lo + rng.uniform(0.5, 3, (10_000, 3))
print(int(_below(lo, hi, 1).sum()))
"""


def test_the_pairwise_relations_of_10000_boxes_fit_in_2_gb(tmp_path):
    """analysis._below made float64 n x n temporaries (2.4 GB for 10,000 boxes, 12 GB asked
    for larger): now a block of rows at a time, only the n x n booleans kept."""
    start = time.perf_counter()
    proc = subprocess.run(
        [sys.executable, "-c", _BELOW_10000],
        capture_output=True,
        text=True,
        preexec_fn=_cap,
        timeout=SECONDS * 3,
    )
    assert proc.returncode == 0, proc.stderr
    assert int(proc.stdout) > 0
    assert time.perf_counter() - start < SECONDS


def test_the_blocks_and_the_sparse_product_give_the_dense_relations(monkeypatch):
    rng = np.random.default_rng(7)
    lo = np.round(rng.uniform(0, 20, (300, 3)))
    hi = lo + np.round(rng.uniform(1, 4, (300, 3)))
    others = [0, 2]
    across = np.ones((300, 300), dtype=bool)
    for a in others:
        across &= (
            np.minimum(hi[:, None, a], hi[None, :, a]) - np.maximum(lo[:, None, a], lo[None, :, a])
            > model.EPS
        )
    below = (hi[:, None, 1] <= lo[None, :, 1] + model.EPS) & (lo[:, None, 1] < lo[None, :, 1])
    monkeypatch.setattr(model, "PAIRS_AT_ONCE", 1000)  # many blocks
    monkeypatch.setattr(analysis, "PAIRS_AT_ONCE", 1000)
    under = analysis._below(lo, hi, 1)
    assert np.array_equal(under, below & across)
    dense = ~((under.astype(int) @ under.astype(int)) > 0)
    for cost in (0, 10**9):  # the dense and the sparse product
        monkeypatch.setattr(analysis, "SPARSE_COST", cost)
        assert np.array_equal(analysis._nothing_between(under), dense)


# ---- --max-memory ------------------------------------------------------------------------------


def sheet_obj(path: Path, m: int) -> None:
    """One object: a flat sheet of (m - 1)^2 quads (an OBJ of about 40 m^2 bytes)."""
    v = "".join(f"v {k % m} {k // m} 0\n" for k in range(m * m))
    idx = np.arange(m * m).reshape(m, m) + 1
    quads = np.stack(
        [idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()],
        axis=1,
    )
    f = "".join("f {} {} {} {}\n".format(*q) for q in quads.tolist())
    path.write_text("o sheet\n" + v + f)


def test_infer_holds_a_city_to_max_memory(tmp_path):
    sheet_obj(tmp_path / "sheet.obj", 400)  # 6 MB: reading it takes over 100 MB
    proc, seconds = run_bgr(
        ["infer", "sheet.obj", "-o", "out.bgr", "--max-memory", "50M", "--no-progress"], tmp_path
    )
    assert_located(proc, "sheet.obj", "reading the city needs more than 50 MB of memory")
    assert "--max-memory SIZE" in proc.stderr
    assert seconds < SECONDS
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sheet.obj"]


def test_retarget_holds_its_copies_to_max_memory(tmp_path):
    """100,000 copies take 60 MB: past a 50 MB ceiling, a located error before they are all
    made (the --max-boxes limit is raised out of the way)."""
    (tmp_path / "boxes.json").write_text(json.dumps(row_of_boxes(20)))
    args = ["retarget", "boxes.json", "--size", "100000,3,1", "-o", "out.json"]
    proc, seconds = run_bgr([*args, "--max-boxes", "10000000", "--max-memory", "50M"], tmp_path)
    assert_located(proc, "boxes.json", "retargeting along x", "needs more than 50 MB of memory")
    assert "--max-memory SIZE" in proc.stderr
    assert seconds < SECONDS
    assert not (tmp_path / "out.json").exists()


@pytest.mark.parametrize(
    "command",
    [["infer", "boxes.json", "-o", "o.bgr"], ["retarget", "boxes.json", "--size", "2,3,1"]],
)
def test_max_memory_of_infer_and_retarget_is_read_as_derive_reads_it(tmp_path, command):
    (tmp_path / "boxes.json").write_text(json.dumps(row_of_boxes(2)))
    proc, _ = run_bgr([*command, "--max-memory", "lots"], tmp_path)
    assert proc.returncode == 2 and "--max-memory lots: write a size" in proc.stderr
    proc, _ = run_bgr([*command, "--max-memory", "1G"], tmp_path)
    assert proc.returncode == 0, proc.stderr
