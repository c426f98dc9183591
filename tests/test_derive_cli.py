"""bgr derive on the command line: options, failures that leave no file, no tracebacks."""

import json
import subprocess
import sys

import pytest
from conftest import ROOT
from pygltflib import GLTF2


def bgr(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "bgr", *args], capture_output=True, text=True, cwd=cwd
    )


def test_house_glb_loads_with_pygltflib_and_is_stable(tmp_path):
    out = tmp_path / "out.glb"
    assert (
        bgr("derive", str(ROOT / "examples/house.bgr"), "--seed", "3", "-o", str(out)).returncode
        == 0
    )
    gltf = GLTF2().load(str(out))
    assert gltf.meshes and gltf.materials and gltf.buffers[0].byteLength > 0
    for acc in gltf.accessors:
        view = gltf.bufferViews[acc.bufferView]
        assert (
            view.byteOffset % 4 == 0
            and view.byteOffset + view.byteLength <= gltf.buffers[0].byteLength
        )


def test_set_and_lot_size(tmp_path):
    src = tmp_path / "box.bgr"
    src.write_text("attr h = 3\nLot --> extrude(h) Box\nterminal Box\n")
    out = bgr("derive", str(src), "--set", "h=7.5", "--lot", "12,8", "-o", "-", "--format", "json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["attrs"] == {"h": 7.5}
    assert data["terminals"][0]["size"] == [12.0, 7.5, 8.0]


@pytest.mark.parametrize(
    "grammar, message",
    [
        ("A --> B\nB --> A\n", "deeper than 256"),
        ("Lot --> split(x) { { 0.001: A }* }\nA --> B\nterminal B\n", "more than 1,000 shapes"),
        ("attr n = 0\nLot --> extrude(1 / n)\n", "division by zero"),
        ('asset col = "missing.glb"\nLot --> i(col)\n', "asset file 'missing.glb' not found"),
    ],
)
def test_runtime_faults_leave_no_file_and_no_traceback(tmp_path, grammar, message):
    src = tmp_path / "bad.bgr"
    src.write_text(grammar)
    out = tmp_path / "out.glb"
    proc = bgr("derive", str(src), "-o", str(out), "--max-shapes", "1000")
    assert proc.returncode == 1
    assert message in proc.stderr and "bad.bgr:" in proc.stderr
    assert "Traceback" not in proc.stderr and "internal error" not in proc.stderr
    assert not out.exists() and list(tmp_path.iterdir()) == [src]


def test_usage_errors(tmp_path):
    src = tmp_path / "a.bgr"
    src.write_text("Lot --> NIL\n")
    assert bgr("derive", str(src)).returncode == 2  # no output
    assert bgr("derive", str(src), "-o", "x.glb", "--set", "novalue").returncode == 2
    proc = bgr("derive", str(src), "-o", str(tmp_path / "x.dae"))
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    proc = bgr("derive", str(src), "-o", str(tmp_path / "x.glb"), "--lot", "abc,")
    assert proc.returncode == 1 and "WIDTH,DEPTH" in proc.stderr
