"""Hostile glTF files (issue 34): every offset, stride, index and node of a .glb/.gltf is checked
before a byte is read, so `bgr infer` and `bgr render` end in a located error, never a crash, a
hang or process memory read as vertices, and leave nothing behind.

Each file is a small valid GLB (a 10 x 8 x 12 m box: eight float positions, 36 uint16 indices)
built here and then broken in one field.
"""

from __future__ import annotations

import copy
import json
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from bgr.cli import main

POSITIONS = np.array([[x, y, z] for x in (0, 10) for y in (0, 8) for z in (0, 12)], "<f4")
QUADS = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
INDICES = np.array([t for a, b, c, d in QUADS for t in ((a, b, c), (a, c, d))], "<u2")


def box() -> tuple[dict, bytes]:
    """A valid glTF document of one box node, and its buffer (positions, then indices)."""
    pos, idx = POSITIONS.tobytes(), INDICES.tobytes()
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "house", "mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(pos) + len(idx)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
            {"buffer": 0, "byteOffset": len(pos), "byteLength": len(idx)},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"},
        ],
    }
    return doc, pos + idx


def glb(doc: dict, blob: bytes) -> bytes:
    """The GLB container of a document and its buffer (chunks padded to 4 bytes)."""
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    blob += b"\0" * (-len(blob) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text
    body += struct.pack("<II", len(blob), 0x004E4942) + blob
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def saved(folder: Path, doc: dict, blob: bytes, name: str = "city.glb") -> Path:
    path = folder / name
    path.write_bytes(glb(doc, blob))
    return path


def run_both(path: Path, capsys) -> list[tuple[int, str]]:
    """(exit status, standard error) of `bgr infer` and of `bgr render` on ``path``, each
    checked to leave nothing behind when it fails."""
    folder = path.parent
    before = sorted(folder.iterdir())
    results = []
    for args in (
        ["infer", str(path), "-o", str(folder / "out.bgr"), "--no-progress"],
        ["render", str(path), "-o", str(folder / "out.png"), "--size", "64x48"],
    ):
        code = main(args)
        err = capsys.readouterr().err
        if code != 0:
            assert sorted(folder.iterdir()) == before, f"{args[0]} left files behind"
        assert "internal error" not in err and "Traceback" not in err, err
        results.append((code, err))
    return results


def refused(path: Path, capsys, *expected: str) -> None:
    """Both commands exit 1 with a message naming ``path`` and holding every ``expected``."""
    for code, err in run_both(path, capsys):
        assert code == 1, err
        assert str(path) in err, err
        for text in expected:
            assert text in err, err


def test_a_valid_box_reads_and_renders(tmp_path, capsys):
    doc, blob = box()
    path = saved(tmp_path, doc, blob)
    for code, err in run_both(path, capsys):
        assert code == 0, err
    assert (tmp_path / "out.bgr").is_file() and (tmp_path / "out.png").is_file()


def test_an_interleaved_view_with_a_valid_stride_reads(tmp_path):
    # positions 16 bytes apart (a float of padding after each), read with the stride
    from bgr.formats.glb_read import read_glb

    doc, blob = box()
    padded = np.zeros((8, 4), "<f4")
    padded[:, :3] = POSITIONS
    pos = padded.tobytes()
    doc["bufferViews"][0].update(byteLength=len(pos), byteStride=16)
    doc["bufferViews"][1]["byteOffset"] = len(pos)
    doc["buffers"][0]["byteLength"] = len(pos) + INDICES.nbytes
    mesh = read_glb(saved(tmp_path, doc, pos + INDICES.tobytes()))
    assert len(mesh.faces) == 12
    assert np.allclose(mesh.bounds, [[0, 0, 0], [10, 8, 12]])


def test_a_negative_byte_stride_is_refused_not_read_as_process_memory(tmp_path, capsys):
    # -64 made bgr infer exit 0 with bytes of process memory in the assets as vertices
    doc, blob = box()
    doc["bufferViews"][0]["byteStride"] = -64
    refused(
        saved(tmp_path, doc, blob),
        capsys,
        "accessor 0: byteStride -64 of bufferView 0 is not from 4 to 252",
    )


def test_a_huge_negative_byte_stride_is_refused_not_a_crash(tmp_path):
    # -1e9 was a segmentation fault in both commands: run in a child process, so that a crash
    # fails the test instead of ending pytest
    stride = -1_000_000_000
    doc, blob = box()
    doc["bufferViews"][0]["byteStride"] = stride
    path = saved(tmp_path, doc, blob)
    for args in (["infer", "-o", "out.bgr"], ["render", "-o", "out.png"]):
        run = subprocess.run(
            [sys.executable, "-m", "bgr", args[0], path.name, *args[1:]],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert run.returncode == 1, (run.returncode, run.stderr)
        assert "city.glb: error: " in run.stderr
        assert f"accessor 0: byteStride {stride} of bufferView 0" in run.stderr, run.stderr
        assert "Traceback" not in run.stderr
        assert sorted(p.name for p in tmp_path.iterdir()) == ["city.glb"]


ACCESSOR_CASES = {
    "stride shorter than an element": (
        lambda d: d["bufferViews"][0].update(byteStride=8),
        "accessor 0: byteStride 8 of bufferView 0 is not a multiple of 4 at least 12",
    ),
    "stride not a multiple of 4": (
        lambda d: d["bufferViews"][0].update(byteStride=14),
        "accessor 0: byteStride 14",
    ),
    "stride over 252": (
        lambda d: d["bufferViews"][0].update(byteStride=256),
        "accessor 0: byteStride 256 of bufferView 0 is not from 4 to 252",
    ),
    "stride past the view": (
        lambda d: d["bufferViews"][0].update(byteStride=48),
        "accessor 0: its 8 elements from byte 0 end at byte 348 of bufferView 0",
    ),
    "negative accessor offset": (
        lambda d: d["accessors"][0].update(byteOffset=-12),
        "accessor 0: byteOffset -12",
    ),
    "count past the view": (
        lambda d: d["accessors"][1].update(count=3600),
        "accessor 1: its 3600 elements",
    ),
    "negative count": (lambda d: d["accessors"][0].update(count=-1), "accessor 0: count -1"),
    "fractional count": (lambda d: d["accessors"][0].update(count=8.5), "accessor 0: count 8.5"),
    "negative view offset": (
        lambda d: d["bufferViews"][1].update(byteOffset=-96),
        "bufferView 1: byteOffset -96",
    ),
    "view past the buffer": (
        lambda d: d["bufferViews"][1].update(byteLength=1 << 40),
        "bufferView 1: bytes 96 to 1099511627872 lie outside buffer 0 of 168 bytes",
    ),
    "buffer longer than its data": (
        lambda d: d["buffers"][0].update(byteLength=1 << 30),
        "buffer 0: byteLength 1073741824 is more than the 168 bytes of its data",
    ),
    "a buffer that does not exist": (
        lambda d: d["bufferViews"][1].update(buffer=1),
        "bufferView 1: buffer 1 does not exist (the file has 1)",
    ),
    "unknown component type": (
        lambda d: d["accessors"][0].update(componentType=5124),
        "accessor 0: componentType 5124 is not one of",
    ),
    "unknown type": (lambda d: d["accessors"][0].update(type="VEC7"), "accessor 0: type 'VEC7'"),
    "sparse accessor": (
        lambda d: d["accessors"][0].update(sparse={"count": 1}),
        "accessor 0: sparse accessors are not supported",
    ),
    "no bufferView": (
        lambda d: d["accessors"][0].pop("bufferView"),
        "accessor 0: has no bufferView",
    ),
    "missing accessor": (
        lambda d: d["meshes"][0]["primitives"][0].update(indices=7),
        "indices of mesh 0 primitive 0: accessor 7 does not exist (the file has 2)",
    ),
    "signed indices": (
        lambda d: d["accessors"][1].update(componentType=5122),
        "accessor 1: SCALAR of int16 (5122), but indices of mesh 0 primitive 0 must be SCALAR",
    ),
    "int16 positions": (
        lambda d: d["accessors"][0].update(componentType=5122, count=16),
        "accessor 0: VEC3 of int16 (5122), but POSITION of mesh 0 primitive 0 must be VEC3 "
        "of float32 (5126)",
    ),
    "indices not whole triangles": (
        lambda d: d["accessors"][1].update(count=35),
        "accessor 1: its 35 indices do not make whole triangles",
    ),
}


@pytest.mark.parametrize("case", list(ACCESSOR_CASES))
def test_a_broken_accessor_is_a_located_error(tmp_path, capsys, case):
    change, expected = ACCESSOR_CASES[case]
    doc, blob = box()
    change(doc)
    refused(saved(tmp_path, doc, blob), capsys, expected)


def test_an_index_past_the_vertices_is_refused(tmp_path, capsys):
    doc, blob = box()
    bad = INDICES.copy()
    bad.reshape(-1)[5] = 99
    refused(
        saved(tmp_path, doc, POSITIONS.tobytes() + bad.tobytes()),
        capsys,
        "accessor 1: index 99 (element 5) is past the 8 vertices of accessor 0",
    )


def test_a_position_that_is_not_a_number_is_refused(tmp_path, capsys):
    doc, blob = box()
    bad = POSITIONS.copy()
    bad[3, 1] = np.inf
    refused(
        saved(tmp_path, doc, bad.tobytes() + INDICES.tobytes()),
        capsys,
        "accessor 0: element 3 holds",
        "not finite numbers",
    )


NODE_CASES = {
    "child out of range": (
        lambda d: d["nodes"][0].update(children=[7]),
        "node 0: child 7 does not exist (the file has 1 nodes)",
    ),
    "child listed twice": (
        lambda d: (d["nodes"].append({"mesh": 0}), d["nodes"][0].update(children=[1, 1])),
        "node 0: lists node 1 twice among its children",
    ),
    "a cycle": (
        lambda d: (
            d["nodes"].extend([{"children": [2]}, {"children": [1], "mesh": 0}]),
            d["nodes"][0].update(children=[1]),
        ),
        "is its own descendant (nodes 1 -> 2 -> 1)",
    ),
    "root out of range": (
        lambda d: d["scenes"][0].update(nodes=[0, 5]),
        "scene 0: node 5 does not exist",
    ),
    "infinite translation": (
        lambda d: d["nodes"][0].update(translation=[0, float("inf"), 0]),
        "node 0: translation must be 3 finite numbers",
    ),
    "short matrix": (
        lambda d: d["nodes"][0].update(matrix=[1, 0, 0, 1]),
        "node 0: matrix must be 16 finite numbers",
    ),
    "zero rotation": (
        lambda d: d["nodes"][0].update(rotation=[0, 0, 0, 0]),
        "node 0: rotation 0 is the zero quaternion",
    ),
    "scale that overflows": (
        lambda d: d["nodes"][0].update(scale=[1e308, 1e308, 1e308]),
        "node 0: its placed vertices overflow",
    ),
    "bad material colour": (
        lambda d: (
            d.update(materials=[{"pbrMetallicRoughness": {"baseColorFactor": [1, 0]}}]),
            d["meshes"][0]["primitives"][0].update(material=0),
        ),
        "material 0: baseColorFactor must be 4 finite numbers",
    ),
}


@pytest.mark.parametrize("case", list(NODE_CASES))
def test_a_broken_node_is_a_located_error(tmp_path, capsys, case):
    change, expected = NODE_CASES[case]
    doc, blob = box()
    change(doc)
    refused(saved(tmp_path, doc, blob), capsys, expected)


def test_nodes_that_each_list_the_next_twice_end_at_once(tmp_path, capsys):
    # 41 nodes, each listing the next twice: 2^40 walks before; now the duplicate is the error
    doc, blob = box()
    doc["nodes"] = [{"children": [i + 1, i + 1]} for i in range(40)] + [{"mesh": 0}]
    start = time.perf_counter()
    refused(saved(tmp_path, doc, blob), capsys, "node 0: lists node 1 twice among its children")
    assert time.perf_counter() - start < 5


def test_shared_nodes_that_double_at_each_level_are_capped_before_the_walk(tmp_path, capsys):
    # no node lists a child twice, but each pair of nodes lists both of the next pair: a
    # diamond ladder of 2^40 paths to the last nodes
    from bgr.formats.gltf_checks import MAX_NODE_VISITS

    doc, blob = box()
    levels = 40
    doc["nodes"] = [{"children": [1, 2]}]
    for k in range(levels):
        below = [3 + 2 * k, 4 + 2 * k]
        doc["nodes"] += [{"children": below} if k < levels - 1 else {"mesh": 0}] * 2
    start = time.perf_counter()
    refused(saved(tmp_path, doc, blob), capsys, f"places more than {MAX_NODE_VISITS:,} nodes")
    assert time.perf_counter() - start < 5


def test_a_small_shared_subtree_is_read_once_per_parent(tmp_path):
    # a DAG within the cap is read: the box placed under two parents, moved apart
    from bgr.formats.glb_read import read_glb

    doc, blob = box()
    doc["nodes"] = [
        {"children": [1, 2]},
        {"children": [3]},
        {"children": [3], "translation": [50, 0, 0]},
        {"mesh": 0},
    ]
    mesh = read_glb(saved(tmp_path, doc, blob))
    assert len(mesh.faces) == 24
    assert np.allclose(mesh.bounds, [[0, 0, 0], [60, 8, 12]])


def test_a_chain_of_100000_nodes_reads_without_recursion(tmp_path):
    doc, blob = box()
    n = 100_000
    doc["nodes"] = [{"children": [i + 1]} for i in range(n)] + [{"mesh": 0, "name": "deep"}]
    path = saved(tmp_path, doc, blob)
    start = time.perf_counter()
    from bgr.formats.glb_read import read_glb
    from bgr.inverse.city.read import read_city

    assert len(read_glb(path).faces) == 12  # bgr render's reader
    assert read_city(path).triangles == 12  # bgr infer's
    assert time.perf_counter() - start < 10


def instanced(doc: dict, blob: bytes, attributes: dict) -> tuple[dict, bytes]:
    """The box instanced twice (translations 0 and 20 m along x): a TRANSLATION accessor 2."""
    moves = np.array([[0, 0, 0], [20, 0, 0]], "<f4").tobytes()
    doc["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(moves)})
    doc["accessors"].append({"bufferView": 2, "componentType": 5126, "count": 2, "type": "VEC3"})
    doc["buffers"][0]["byteLength"] = len(blob) + len(moves)
    doc["nodes"][0]["extensions"] = {"EXT_mesh_gpu_instancing": {"attributes": attributes}}
    return doc, blob + moves


def test_instancing_reads(tmp_path):
    from bgr.formats.glb_read import read_glb

    mesh = read_glb(saved(tmp_path, *instanced(*box(), {"TRANSLATION": 2})))
    assert len(mesh.faces) == 24
    assert np.allclose(mesh.bounds, [[0, 0, 0], [30, 8, 12]])


@pytest.mark.parametrize(
    ("attributes", "expected"),
    [
        ({}, "node 0 EXT_mesh_gpu_instancing: has no attributes"),
        (None, "node 0 EXT_mesh_gpu_instancing: has no attributes"),
        ({"TRANSLATION": 9}, "TRANSLATION of node 0 EXT_mesh_gpu_instancing: accessor 9 does not"),
        ({"TRANSLATION": 1}, "accessor 1: SCALAR of uint16 (5123), but TRANSLATION of node 0"),
        ({"TRANSLATION": 2, "SCALE": 0}, "have different counts ([2, 8])"),
    ],
)
def test_bad_instancing_attributes_are_located_errors(tmp_path, capsys, attributes, expected):
    doc, blob = instanced(*box(), attributes)
    refused(saved(tmp_path, doc, blob), capsys, expected)


def test_instancing_past_the_triangle_budget_is_refused_before_it_is_made(tmp_path, capsys):
    # a mesh of 12 triangles referenced by 2 x 1,000,000 instances through a 1-instance-per-
    # node DAG would be 24 M triangles: refused from the counts, nothing allocated
    doc, blob = box()
    moves = np.zeros((1_000_000, 3), "<f4").tobytes()
    doc["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(moves)})
    doc["accessors"].append(
        {"bufferView": 2, "componentType": 5126, "count": 1_000_000, "type": "VEC3"}
    )
    doc["buffers"][0]["byteLength"] = len(blob) + len(moves)
    ext = {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 2}}}
    doc["nodes"] = [{"children": [1, 2]}, {"mesh": 0, "extensions": ext}]
    doc["nodes"].append({"mesh": 0, "extensions": ext})
    start = time.perf_counter()
    refused(saved(tmp_path, doc, blob + moves), capsys, "24,000,000 triangles or more")
    assert time.perf_counter() - start < 5


def gltf_text(doc: dict, uri: str) -> str:
    doc = copy.deepcopy(doc)
    doc["buffers"][0]["uri"] = uri
    return json.dumps(doc)


@pytest.mark.parametrize(
    ("uri", "expected"),
    [
        ("../secret.bin", "buffer 0: its file '../secret.bin' lies outside the model's folder"),
        ("/etc/hostname", "buffer 0: its file '/etc/hostname' lies outside the model's folder"),
        ("link.bin", "buffer 0: its file 'link.bin' lies outside the model's folder"),
        ("file:///etc/hostname", "buffer 0: uri 'file:///etc/hostname' is not a file in"),
        ("missing.bin", "buffer 0: cannot read its buffer 'missing.bin'"),
        ("data:application/octet-stream;base64," + "A" * 400, "holds more than its byteLength"),
        ("data:application/octet-stream;base64,@@@@", "not valid base64"),
        ("data:text/plain,hello", "is not base64"),
    ],
)
def test_buffer_uris_stay_in_the_models_folder(tmp_path, capsys, uri, expected):
    doc, blob = box()
    model = tmp_path / "model"
    model.mkdir()
    (tmp_path / "secret.bin").write_bytes(blob)
    (model / "link.bin").symlink_to(tmp_path / "secret.bin")
    path = model / "city.gltf"
    path.write_text(gltf_text(doc, uri))
    refused(path, capsys, expected)


def test_a_buffer_file_beside_the_model_reads_in_infer_and_render(tmp_path, capsys):
    doc, blob = box()
    (tmp_path / "my data.bin").write_bytes(blob)
    path = tmp_path / "city.gltf"
    path.write_text(gltf_text(doc, "my%20data.bin"))
    for code, err in run_both(path, capsys):
        assert code == 0, err


def test_a_glb_cut_short_is_a_located_error(tmp_path, capsys):
    doc, blob = box()
    data = glb(doc, blob)
    path = tmp_path / "city.glb"
    path.write_bytes(data[:-40] + b"")  # the header's length no longer matches
    refused(path, capsys, "not a glTF 2.0 binary")
    bad = bytearray(data)
    bad[8:12] = struct.pack("<I", len(data))
    json_len = struct.unpack_from("<I", data, 12)[0]
    bad[20 + json_len : 24 + json_len] = struct.pack("<I", 1 << 20)  # BIN chunk past the end
    path.write_bytes(bytes(bad))
    refused(path, capsys, "its BIN chunk of 1048576 bytes runs past the end of the file")


def two_buffers(folder: Path, index_length: int = INDICES.nbytes) -> Path:
    """The box as a .gltf whose positions and indices are two files, as exporters write them."""
    doc, _ = box()
    (folder / "pos.bin").write_bytes(POSITIONS.tobytes())
    (folder / "idx.bin").write_bytes(INDICES.tobytes())
    doc["buffers"] = [
        {"uri": "pos.bin", "byteLength": POSITIONS.nbytes},
        {"uri": "idx.bin", "byteLength": INDICES.nbytes},
    ]
    doc["bufferViews"][1].update(buffer=1, byteOffset=0, byteLength=index_length)
    path = folder / "city.gltf"
    path.write_text(json.dumps(doc))
    return path


def test_a_gltf_of_several_buffer_files_reads(tmp_path, capsys):
    from bgr.formats.glb_read import read_glb

    path = two_buffers(tmp_path)
    assert len(read_glb(path).faces) == 12
    for code, err in run_both(path, capsys):
        assert code == 0, err


def test_a_view_past_its_own_buffer_is_refused_even_when_another_follows(tmp_path, capsys):
    refused(
        two_buffers(tmp_path, INDICES.nbytes + 4),
        capsys,
        "bufferView 1: bytes 0 to 76 lie outside buffer 1 of 72 bytes",
    )
