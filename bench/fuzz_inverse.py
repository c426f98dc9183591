"""Mutation fuzzing of the inverse modules' readers (issue 25): every mutant of a city model,
a box hierarchy or a captured model makes ``bgr infer`` / ``bgr retarget`` succeed (exit 0) or
fail cleanly (exit 1, a message, no traceback, no "internal error"), within 10 s and 2 GB.

The seeds are built at run time (never committed): small models made here, slices of the real
cities in ../shared/data/cities (the first objects of each file), the models bgr derives from
examples/, examples/boxes/*.json and examples/captured/*.json.  Each case applies one to three
mutations (truncation, byte flips, hostile numbers and indices, wrong JSON types, lying headers,
deep nesting, long strings, NUL bytes) and runs the real command in a child process.

To be fast, no interpreter is started per case: each of ``--workers`` processes imports bgr
once and fork()s one child per case, which sets RLIMIT_AS, redirects its output to files and
calls ``bgr.cli.main(argv)``; the worker kills it after ``--timeout`` seconds.  A failure (a
signal, a hang, an internal error, a traceback, a usage error for a valid command, "out of
memory" from a small file, a temporary file left behind) is saved to ``OUT/failures/`` with the
command and its output.  Results go in docs/fuzzing.md.

    python bench/fuzz_inverse.py --cases 10000 --seed 1 --out /tmp/fuzz-inverse
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import random
import re
import shutil
import signal
import struct
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared" / "data" / "cities"
SURFACES = ("obj", "ply", "gltf", "glb", "cityjson", "boxes", "captured")
LIMIT_BYTES = 2 << 30  # RLIMIT_AS of a case
TIMEOUT_S = 10.0

HOSTILE_NUMBERS = (
    "nan", "NaN", "inf", "-inf", "Infinity", "-Infinity", "1e308", "-1e308", "1e400", "-1e400",
    "1e-320", "0", "-0", "-1", "-2", "2147483647", "2147483648", "4294967296",
    "9223372036854775807", "9223372036854775808", "-9223372036854775809", "1e18", "1e9",
    "123456789012345678901234567890", "3.5", "1e8", "-1e8", "100000001",
)  # fmt: skip
HOSTILE_JSON = (
    float("nan"), float("inf"), -float("inf"), 1e308, -1e308, 10**400, 2**63, -(2**63), -1, 0,
    1e-320, 10**9, 2**31, True, False, None, "", "x\x00y", "a" * 100_000, "\n#-->\"'", "1e400",
    [], {}, [[]], [None], {"": None}, [1e308, float("nan"), -1], "../../../etc/passwd",
)  # fmt: skip


@dataclass
class Seed:
    surface: str
    name: str  # the file name the case is written as
    data: bytes
    extra: dict[str, bytes]  # other files beside it (a glTF's .bin)


# ---------------------------------------------------------------- seeds


def _obj_slice(path: Path, objects: int) -> bytes:
    """The first ``objects`` objects of an OBJ file, with only the vertices they use."""
    verts: list[str] = []
    kept: list[tuple[str, list[str]]] = []
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("v "):
            verts.append(line)
        elif line.startswith(("o ", "g ")):
            if len(kept) == objects:
                break
            kept.append((line, []))
        elif line.startswith("f ") and kept:
            kept[-1][1].append(line)
    used: dict[int, int] = {}
    out_objects = []
    for head, faces in kept:
        lines = [head]
        for face in faces:
            idx = [int(tok.split("/")[0]) for tok in face.split()[1:]]
            new = [used.setdefault(i, len(used) + 1) for i in idx]
            lines.append("f " + " ".join(map(str, new)))
        out_objects.append("\n".join(lines))
    vs = [verts[i - 1] for i in sorted(used, key=used.__getitem__)]
    return ("\n".join(vs) + "\n" + "\n".join(out_objects) + "\n").encode()


BOX_OBJ = b"""# two boxes
v 0 0 0\nv 4 0 0\nv 4 3 0\nv 0 3 0\nv 0 0 5\nv 4 0 5\nv 4 3 5\nv 0 3 5
v 6 0 0\nv 9 0 0\nv 9 2 0\nv 6 2 0\nv 6 0 7\nv 9 0 7\nv 9 2 7\nv 6 2 7
o house_a
f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1
o house_b
f 9 10 11 12\nf 13 16 15 14\nf 9 13 14 10\nf 10 14 15 11\nf 11 15 16 12\nf 12 16 13 9
"""


def _cityjson_slice(path: Path, objects: int) -> bytes:
    """The first ``objects`` city objects of a CityJSON file (and their parts), re-indexed."""
    doc = json.loads(path.read_text(encoding="utf-8"))
    names = list(doc["CityObjects"])[:objects]
    keep = set(names)
    for name in names:
        keep.update(doc["CityObjects"][name].get("children", []))
    used: dict[int, int] = {}

    def remap(node):
        if isinstance(node, list):
            return [remap(x) for x in node]
        return used.setdefault(node, len(used))

    city = {}
    for name, obj in doc["CityObjects"].items():
        if name not in keep:
            continue
        obj = dict(obj)
        for rel in ("children", "parents"):
            if rel in obj:
                obj[rel] = [x for x in obj[rel] if x in keep]
        obj["geometry"] = [
            dict(g, boundaries=remap(g["boundaries"])) for g in obj.get("geometry", [])
        ]
        city[name] = obj
    vertices = [doc["vertices"][i] for i in sorted(used, key=used.__getitem__)]
    return json.dumps(dict(doc, CityObjects=city, vertices=vertices)).encode()


def _obj_mesh(data: bytes):
    import trimesh

    return trimesh.load(io.BytesIO(data), file_type="obj", process=False, force="mesh")


def _derived(grammar: Path, fmt: str, tmp: Path) -> dict[str, bytes]:
    """The files ``bgr derive GRAMMAR --format FMT`` writes (a .gltf may have a .bin beside)."""
    from bgr.cli import main

    out = tmp / f"{grammar.stem}-{fmt.replace('.', '_')}"
    out.mkdir()
    target = out / f"model.{fmt}"
    with contextlib.redirect_stderr(io.StringIO()):
        status = main(["derive", str(grammar), "-o", str(target), "--max-shapes", "3000"])
    if status != 0:
        raise SystemExit(f"cannot derive the seed {grammar} as {fmt}")
    return {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}


def _external_bin(gltf: bytes) -> Seed:
    """A .gltf whose embedded buffer is moved to a model.bin beside it, so that mutations of
    the JSON reach the accessors rather than the base64 text."""
    import base64

    doc = json.loads(gltf)
    uri = doc["buffers"][0]["uri"]
    doc["buffers"][0]["uri"] = "model.bin"
    data = base64.b64decode(uri.split(",", 1)[1])
    return Seed("gltf", "external.gltf", json.dumps(doc).encode(), {"model.bin": data})


def build_seeds(tmp: Path) -> dict[str, list[Seed]]:
    """The seed files of every surface (made here or sliced from the shared data)."""
    objs = {"boxes.obj": BOX_OBJ}
    for name, count in (("delft.obj", 6), ("zurich_lod2.obj", 3)):
        if (SHARED / name).is_file():
            objs[f"{name[:-4]}_slice.obj"] = _obj_slice(SHARED / name, count)
    seeds: dict[str, list[Seed]] = {s: [] for s in SURFACES}
    seeds["obj"] = [Seed("obj", n, d, {}) for n, d in objs.items()]
    for name, data in list(objs.items())[:2]:
        mesh = _obj_mesh(data)
        for enc in ("ascii", "binary"):
            seeds["ply"].append(
                Seed(
                    "ply", f"{name[:-4]}_{enc}.ply", mesh.export(file_type="ply", encoding=enc), {}
                )
            )
    for grammar in (ROOT / "examples/house.bgr", ROOT / "examples/l_building.bgr"):
        for fmt in ("glb", "gltf", "city.json"):
            files = _derived(grammar, fmt, tmp)
            main_name = f"model.{fmt}"
            extra = {k: v for k, v in files.items() if k != main_name}
            surface = "cityjson" if fmt == "city.json" else fmt
            seeds[surface].append(Seed(surface, main_name, files[main_name], extra))
            if fmt == "gltf":
                seeds[surface].append(_external_bin(files[main_name]))
    mesh = _obj_mesh(BOX_OBJ)
    seeds["glb"].append(Seed("glb", "trimesh.glb", mesh.export(file_type="glb"), {}))
    for name, count in (("3dbag_multi_lod.city.json", 4), ("zurich_lod2.city.json", 3)):
        if (SHARED / name).is_file():
            data = _cityjson_slice(SHARED / name, count)
            seeds["cityjson"].append(Seed("cityjson", f"slice_{name}", data, {}))
    for path in sorted((ROOT / "examples/boxes").glob("*.json")):
        seeds["boxes"].append(Seed("boxes", path.name, path.read_bytes(), {}))
    for path in sorted((ROOT / "examples/captured").glob("*.json")):
        seeds["captured"].append(Seed("captured", path.name, path.read_bytes(), {}))
    return seeds


# ---------------------------------------------------------------- mutators


def _json_paths(node, path=()):
    """Every (path, value) of a JSON document, depth first."""
    yield path, node
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _json_paths(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _json_paths(v, (*path, i))


def _set(doc, path, value):
    if not path:
        return value
    parent = doc
    for key in path[:-1]:
        parent = parent[key]
    parent[path[-1]] = value
    return doc


def _hostile_value(rng: random.Random, old):
    """A hostile replacement for a JSON value: non-finite, huge, wrong type, deep, long."""
    roll = rng.random()
    if roll < 0.5:
        return rng.choice(HOSTILE_JSON)
    if roll < 0.6:
        return [old] * rng.choice((2, 50, 5000))
    if roll < 0.7:
        deep = old
        for _ in range(rng.choice((5, 100, 990, 5000))):
            deep = [deep]
        return deep
    if roll < 0.8 and isinstance(old, (int, float)) and not isinstance(old, bool):
        return old * rng.choice((-1, 1e6, 1e12, 1e300, 0.5)) + rng.choice((0, 1, -1))
    if roll < 0.9 and isinstance(old, str):
        return old + rng.choice(("\x00", "\n", "/../../x", "é" * 3, "💥", "\ud800"[:0]))
    return rng.uniform(-1e9, 1e9) if rng.random() < 0.5 else rng.randint(-(2**40), 2**40)


def _dumps(doc) -> bytes:
    try:
        return json.dumps(doc, allow_nan=True).encode("utf-8", "surrogatepass")
    except (RecursionError, ValueError):
        return b"[" * 100_000 + b"]" * 100_000


def mutate_json(rng: random.Random, data: bytes) -> bytes:
    """A structural mutation of a JSON document: a value replaced, deleted or duplicated."""
    try:
        doc = json.loads(data)
    except (ValueError, RecursionError):
        return mutate_bytes(rng, data)
    paths = list(_json_paths(doc))
    path, value = rng.choice(paths)
    roll = rng.random()
    if roll < 0.7 or not path:
        doc = _set(doc, path, _hostile_value(rng, value))
    elif roll < 0.85:
        parent = doc
        for key in path[:-1]:
            parent = parent[key]
        del parent[path[-1]]
    else:  # a sibling key or item made a copy of this one
        parent = doc
        for key in path[:-1]:
            parent = parent[key]
        if isinstance(parent, list):
            parent.extend([value] * rng.choice((1, 100, 3000)))
        else:
            parent[rng.choice(("name", "type", "id", "uri", "count", "x" * 200))] = value
    return _dumps(doc)


_NUMBER = re.compile(rb"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")
_PY_WARNING = re.compile(r"\.py:\d+: \w*Warning")  # a Python warning leaked to the user


def mutate_numbers(rng: random.Random, data: bytes) -> bytes:
    """A number of the text replaced by a hostile one (NaN, inf, huge, negative, index-like)."""
    matches = list(_NUMBER.finditer(data[:2_000_000]))
    if not matches:
        return mutate_bytes(rng, data)
    m = rng.choice(matches)
    new = rng.choice(HOSTILE_NUMBERS).encode()
    return data[: m.start()] + new + data[m.end() :]


def mutate_bytes(rng: random.Random, data: bytes) -> bytes:
    """Truncation, byte flips, a NUL, a block repeated or deleted."""
    if not data:
        return b"\x00"
    roll = rng.random()
    b = bytearray(data)
    if roll < 0.3:
        return bytes(b[: rng.randrange(len(b))])
    if roll < 0.65:
        for _ in range(rng.choice((1, 2, 8, 64))):
            b[rng.randrange(len(b))] = rng.randrange(256)
        return bytes(b)
    if roll < 0.75:
        b.insert(rng.randrange(len(b)), 0)
        return bytes(b)
    i = rng.randrange(len(b))
    j = min(len(b), i + rng.choice((1, 16, 200, 5000)))
    if roll < 0.88:
        return bytes(b[:j] + b[i:j] * rng.choice((2, 30, 1000)) + b[j:])
    return bytes(b[:i] + b[j:])


def mutate_lines(rng: random.Random, data: bytes) -> bytes:
    """OBJ/ASCII lines: one duplicated many times, dropped, or given a hostile field."""
    lines = data.split(b"\n")
    i = rng.randrange(len(lines))
    roll = rng.random()
    if roll < 0.25:
        lines[i:i] = [lines[i]] * rng.choice((10, 1000, 100_000))
    elif roll < 0.4:
        del lines[i]
    elif roll < 0.6:
        word = rng.choice(
            (b"o ", b"g ", b"usemtl ", b"f ", b"v ", b"vn ", b"mtllib ", b"s ", b"l ")
        )
        tail = rng.choice((b"", b"a" * 100_000, b"\x00", b"x\ny", b"1 2", b"-1 -2 -3", b"0 0 0"))
        lines.insert(i, word + tail)
    else:
        fields = lines[i].split(b" ")
        k = rng.randrange(len(fields))
        fields[k] = rng.choice(HOSTILE_NUMBERS).encode() + rng.choice((b"", b"/1", b"//", b"/x"))
        lines[i] = b" ".join(fields)
    return b"\n".join(lines)


def mutate_ply_header(rng: random.Random, data: bytes) -> bytes:
    """A lying PLY header: an element count, a property type or the format changed."""
    end = data.find(b"end_header")
    if end < 0:
        return mutate_bytes(rng, data)
    head, body = data[:end], data[end:]
    lines = head.split(b"\n")
    counts = [i for i, line in enumerate(lines) if line.startswith(b"element")]
    roll = rng.random()
    if counts and roll < 0.6:
        i = rng.choice(counts)
        parts = lines[i].split(b" ")
        counts = (*HOSTILE_NUMBERS[:4], "0", "-1", "1000000000", "4294967295", "9" * 20)
        parts[-1] = rng.choice(counts).encode()
        lines[i] = b" ".join(parts)
    elif roll < 0.8:
        i = rng.randrange(len(lines))
        lines[i] = lines[i].replace(b"float", rng.choice((b"double", b"uchar", b"list", b"int")))
        lines[i] = lines[i].replace(b"uchar", rng.choice((b"int", b"double", b"uint")))
    else:
        lines = [
            line.replace(b"ascii", b"binary_little_endian").replace(
                b"binary_little_endian", rng.choice((b"ascii", b"binary_big_endian"))
            )
            for line in lines
        ]
    return b"\n".join(lines) + body


def mutate_glb(rng: random.Random, data: bytes) -> bytes:
    """GLB: the JSON chunk mutated structurally (lengths kept right), or lying lengths."""
    if len(data) < 20 or data[:4] != b"glTF":
        return mutate_bytes(rng, data)
    json_len = struct.unpack_from("<I", data, 12)[0]
    roll = rng.random()
    if roll < 0.6:
        doc = data[20 : 20 + json_len]
        new = mutate_json(rng, doc)
        new += b" " * (-len(new) % 4)
        rest = data[20 + json_len :]
        body = struct.pack("<II", len(new), 0x4E4F534A) + new + rest
        return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body
    b = bytearray(data)
    offsets = [8, 12]
    if 20 + json_len + 8 <= len(data):
        offsets.append(20 + json_len)
    where = rng.choice(offsets)
    value = rng.choice((0, 1, 3, 0xFFFFFFFF, 0x7FFFFFFF, len(data) * 2, len(data) - 1))
    struct.pack_into("<I", b, where, value)
    return bytes(b)


def mutate_gltf_uri(rng: random.Random, data: bytes) -> bytes:
    """glTF: a buffer or image URI pointed elsewhere (outside, a device, a huge data: URI)."""
    try:
        doc = json.loads(data)
        buffers = doc["buffers"]
    except (ValueError, KeyError, TypeError, RecursionError):
        return mutate_json(rng, data)
    if not buffers:
        return mutate_json(rng, data)
    buf = rng.choice(buffers)
    buf["uri"] = rng.choice(
        (
            "../../../../etc/passwd", "/etc/passwd", "/dev/zero", "/proc/self/mem", "missing.bin",
            "data:application/octet-stream;base64," + "A" * 4_000_000,
            "data:application/octet-stream;base64,@@@", "data:,", "file:///etc/passwd",
            "http://example.com/x.bin", "%2e%2e/%2e%2e/etc/passwd", "model.bin\x00.txt", "",
        )
    )  # fmt: skip
    if rng.random() < 0.3:
        buf["byteLength"] = rng.choice((0, -1, 2**62, 10**12, 1.5))
    return _dumps(doc)


MUTATORS = {
    "obj": (mutate_lines, mutate_numbers, mutate_bytes),
    "ply": (mutate_ply_header, mutate_numbers, mutate_bytes),
    "gltf": (mutate_json, mutate_gltf_uri, mutate_numbers, mutate_bytes),
    "glb": (mutate_glb, mutate_bytes),
    "cityjson": (mutate_json, mutate_numbers, mutate_bytes),
    "boxes": (mutate_json, mutate_numbers, mutate_bytes),
    "captured": (mutate_json, mutate_numbers, mutate_bytes),
}
WEIGHTS = {"mutate_bytes": 1, "mutate_numbers": 2}  # the structural mutators get 3


def mutant(rng: random.Random, seed: Seed) -> bytes:
    """One to three mutations of a seed file."""
    data = seed.data
    mutators = MUTATORS[seed.surface]
    weights = [WEIGHTS.get(m.__name__, 3) for m in mutators]
    for _ in range(rng.choice((1, 1, 1, 2, 3))):
        data = rng.choices(mutators, weights)[0](rng, data)
        if len(data) > 50_000_000:
            data = data[:50_000_000]
    return data


def command(surface: str, name: str, rng: random.Random) -> list[str]:
    """The bgr command of a case, run in the case's folder."""
    if surface == "boxes":
        if rng.random() < 0.5:
            return ["retarget", name, "--size", rng.choice(("12,9,30", "3,3,3", "40,2,8")),
                    "-o", "out.bgr"]  # fmt: skip
        return ["infer", name, "--kind", "boxes", "-o", "out.bgr"]
    if surface == "captured":
        return ["infer", name, "--kind", "schema", "-o", "out.bgr"]
    return ["infer", name, "-o", "out.bgr", "--no-progress"]


# ---------------------------------------------------------------- running a case


@dataclass
class Outcome:
    kind: str  # "success", "error" or a failure: "signal N", "timeout", "internal", ...
    seconds: float
    stderr: str

    @property
    def failed(self) -> bool:
        return self.kind not in ("success", "error")


def _child(argv: list[str], folder: Path, limit_bytes: int) -> None:
    """In the forked child: limits, output to files, bgr.cli.main, _exit."""
    import resource

    from bgr.cli import main

    code = 70
    try:
        os.chdir(folder)
        resource.setrlimit(resource.RLIMIT_AS, (limit_bytes, limit_bytes))
        for fd, name in ((1, "stdout.txt"), (2, "stderr.txt")):
            out = os.open(name, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            os.dup2(out, fd)
            os.close(out)
        # the streams, too: under pytest sys.stderr is its capture, not file descriptor 2
        sys.stdout = open(1, "w", encoding="utf-8", errors="replace", closefd=False)  # noqa: SIM115
        sys.stderr = open(2, "w", encoding="utf-8", errors="replace", closefd=False)  # noqa: SIM115
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        _print_warnings()
        code = main(argv)
    except SystemExit as e:
        code = e.code if isinstance(e.code, int) else 2
    except BaseException:  # noqa: BLE001  (what main() let through is the failure itself)
        import traceback

        traceback.print_exc()
        code = 71
    finally:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(code)


def _print_warnings() -> None:
    """Warnings to standard error, as a user sees them, even in a child of pytest (which
    records them): a leaked numpy or trimesh warning is a finding."""
    import warnings

    def show(message, category, filename, lineno, file=None, line=None) -> None:
        sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))

    warnings.showwarning = show


def run_case(argv: list[str], folder: Path, timeout: float = TIMEOUT_S,
             limit_bytes: int = LIMIT_BYTES) -> Outcome:  # fmt: skip
    """Fork a child that runs ``bgr argv`` in ``folder``; classify what it did."""
    start = time.perf_counter()
    pid = os.fork()
    if pid == 0:
        _child(argv, folder, limit_bytes)
    status = _wait(pid, timeout)
    seconds = time.perf_counter() - start
    err_path = folder / "stderr.txt"
    stderr = err_path.read_text(errors="replace")[-4000:] if err_path.exists() else ""
    if status is None:
        return Outcome("timeout", seconds, stderr)
    if os.WIFSIGNALED(status):
        return Outcome(f"signal {os.WTERMSIG(status)}", seconds, stderr)
    code = os.WEXITSTATUS(status)
    left = [p.name for p in folder.rglob("*.tmp")]
    if left:
        return Outcome("left temporaries", seconds, stderr)
    if "Traceback" in stderr or "internal error" in stderr:
        return Outcome("internal", seconds, stderr)
    if _PY_WARNING.search(stderr):
        return Outcome("python warning", seconds, stderr)
    if "out of memory" in stderr:
        return Outcome("out of memory", seconds, stderr)
    if code == 0:
        return Outcome("success", seconds, stderr)
    if code == 1 and stderr.strip():
        return Outcome("error", seconds, stderr)
    return Outcome(f"exit {code}", seconds, stderr)


def _wait(pid: int, timeout: float) -> int | None:
    """The child's wait status, or None after killing it at ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    delay = 0.002
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return status
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            return None
        time.sleep(delay)
        delay = min(delay * 1.5, 0.05)


Case = tuple[Seed, bytes, list[str], Outcome]


def fuzz_case(seeds: list[Seed], index: int, base_seed: int, tmp: Path) -> Case:
    """Case ``index`` of a surface: the same mutant and command for the same seeds."""
    rng = random.Random(f"{base_seed}:{seeds[0].surface}:{index}")
    folder = tmp / f"case{index}"
    folder.mkdir()
    return run_mutant(seeds, rng, folder)


def run_mutant(seeds: list[Seed], rng: random.Random, folder: Path) -> Case:
    """A mutant of one of ``seeds`` (drawn by ``rng``) written to ``folder`` and run there."""
    seed = rng.choice(seeds)
    data = mutant(rng, seed)
    (folder / seed.name).write_bytes(data)
    for name, extra in seed.extra.items():
        (folder / name).write_bytes(extra)
    argv = command(seed.surface, seed.name, rng)
    return seed, data, argv, run_case(argv, folder)


# ---------------------------------------------------------------- the run


def _worker(seeds, surfaces, cases, base_seed, part, parts, out: Path) -> None:
    """Run this worker's share of the cases; one JSON line per case in OUT/results-PART."""
    tmp = Path(tempfile.mkdtemp(prefix=f"bgr-fuzz-inverse-{part}-"))
    with open(out / f"results-{part}.jsonl", "w") as log:
        for surface in surfaces:
            for index in range(part, cases, parts):
                seed, data, argv, outcome = fuzz_case(seeds[surface], index, base_seed, tmp)
                row = {"surface": surface, "index": index, "kind": outcome.kind,
                       "seconds": round(outcome.seconds, 3), "seed": seed.name}  # fmt: skip
                if outcome.failed:
                    stem = out / "failures" / f"{surface}-{index}"
                    stem.mkdir(parents=True, exist_ok=True)
                    (stem / seed.name).write_bytes(data)
                    for name, extra in seed.extra.items():
                        (stem / name).write_bytes(extra)
                    (stem / "case.txt").write_text(
                        f"bgr {' '.join(argv)}\n{outcome.kind} after {outcome.seconds:.1f} s\n"
                        f"{outcome.stderr}"
                    )
                    row["stderr"] = outcome.stderr[-300:]
                log.write(json.dumps(row) + "\n")
                log.flush()
                shutil.rmtree(tmp / f"case{index}", ignore_errors=True)
    shutil.rmtree(tmp, ignore_errors=True)


def table(rows: list[dict]) -> str:
    """The per-surface table of docs/fuzzing.md."""
    lines = ["| surface | cases | succeeded | clean errors | failures | slowest |",
             "|---|---|---|---|---|---|"]  # fmt: skip
    for surface in SURFACES:
        mine = [r for r in rows if r["surface"] == surface]
        if not mine:
            continue
        ok = sum(r["kind"] == "success" for r in mine)
        err = sum(r["kind"] == "error" for r in mine)
        bad = [r for r in mine if r["kind"] not in ("success", "error")]
        kinds: dict[str, int] = {}
        for r in bad:
            kinds[r["kind"]] = kinds.get(r["kind"], 0) + 1
        detail = f" ({', '.join(f'{n} {k}' for k, n in sorted(kinds.items()))})" if bad else ""
        slowest = max(r["seconds"] for r in mine)
        lines.append(f"| {surface} | {len(mine):,} | {ok:,} | {err:,} | {len(bad):,}{detail} | "
                     f"{slowest:.1f} s |")  # fmt: skip
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=200, help="cases per surface (200)")
    parser.add_argument("--surface", action="append", choices=SURFACES, help="default: all")
    parser.add_argument("--seed", type=int, default=0, help="the mutations' seed (0)")
    parser.add_argument("--workers", type=int, default=2, help="forking workers (2)")
    parser.add_argument("--out", type=Path, default=None, help="results and failures folder")
    args = parser.parse_args(argv)
    out = args.out or Path(tempfile.mkdtemp(prefix="bgr-fuzz-inverse-"))
    out.mkdir(parents=True, exist_ok=True)
    surfaces = args.surface or list(SURFACES)
    import bgr.cli  # noqa: F401  (imported once, before the forks)
    from bgr.inverse import schema as _schema  # noqa: F401
    from bgr.inverse.boxes import command as _boxes  # noqa: F401
    from bgr.inverse.city import command as _city  # noqa: F401

    with tempfile.TemporaryDirectory() as tmp:
        seeds = build_seeds(Path(tmp))
    start = time.perf_counter()
    pids = []
    for part in range(args.workers):
        pid = os.fork()
        if pid == 0:
            code = 0
            try:
                _worker(seeds, surfaces, args.cases, args.seed, part, args.workers, out)
            except BaseException:  # noqa: BLE001
                import traceback

                traceback.print_exc()
                code = 1
            os._exit(code)
        pids.append(pid)
    for pid in pids:
        os.waitpid(pid, 0)
    rows = []
    for part in range(args.workers):
        path = out / f"results-{part}.jsonl"
        if path.exists():
            rows += [json.loads(line) for line in path.read_text().splitlines() if line]
    report = table(rows)
    seconds = time.perf_counter() - start
    print(report)
    print(f"{len(rows):,} cases in {seconds:.0f} s (seed {args.seed}); results in {out}")
    (out / "table.md").write_text(report + "\n")
    return 1 if any(r["kind"] not in ("success", "error") for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
