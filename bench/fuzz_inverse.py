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
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import fuzz_textured  # noqa: E402
from fuzz_mutations import mutant  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared" / "data" / "cities"
SURFACES = ("obj", "ply", "gltf", "glb", "cityjson", "boxes", "captured", *fuzz_textured.SURFACES)
LIMIT_BYTES = 2 << 30  # RLIMIT_AS of a case
TIMEOUT_S = 10.0


@dataclass
class Seed:
    surface: str
    name: str  # the file name the case is written as
    data: bytes
    extra: dict[str, bytes]  # other files beside it (a glTF's .bin, images), by relative path

    def write(self, folder: Path, data: bytes | None = None) -> None:
        """The seed's files (its model replaced by ``data``) written in ``folder``."""
        (folder / self.name).write_bytes(self.data if data is None else data)
        for name, extra in self.extra.items():
            (folder / name).parent.mkdir(parents=True, exist_ok=True)
            (folder / name).write_bytes(extra)


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
    # bgr infer's own assets file: meshopt-compressed views, 16-bit quantized positions
    from bgr.inverse.city.container import Mesh, pack

    packed = pack([Mesh("box", mesh.vertices, mesh.faces)], compress=True)
    seeds["glb"].append(Seed("glb", "meshopt.glb", packed, {}))
    for name, count in (("3dbag_multi_lod.city.json", 4), ("zurich_lod2.city.json", 3)):
        if (SHARED / name).is_file():
            data = _cityjson_slice(SHARED / name, count)
            seeds["cityjson"].append(Seed("cityjson", f"slice_{name}", data, {}))
    for path in sorted((ROOT / "examples/boxes").glob("*.json")):
        seeds["boxes"].append(Seed("boxes", path.name, path.read_bytes(), {}))
    for path in sorted((ROOT / "examples/captured").glob("*.json")):
        seeds["captured"].append(Seed("captured", path.name, path.read_bytes(), {}))
    seeds.update(fuzz_textured.build_seeds(tmp, Seed))
    return seeds


_PY_WARNING = re.compile(r"\.py:\d+: \w*Warning")  # a Python warning leaked to the user


def command(surface: str, name: str, rng: random.Random) -> list[str]:
    """The bgr command of a case, run in the case's folder."""
    if surface in fuzz_textured.SURFACES:
        return fuzz_textured.command(name)
    if surface == "boxes":
        if rng.random() < 0.5:
            return ["retarget", name, "--size", rng.choice(("12,9,30", "3,3,3", "40,2,8")),
                    "-o", rng.choice(("out.json", "out.glb"))]  # fmt: skip
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
        if code == 0 and argv[0] == "render":
            code = _check_png(Path("out.png"), fuzz_textured.SIZE)
        elif code == 0:
            code = _check_output(Path("out.bgr"))
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


def _check_output(path: Path) -> int:
    """0 when the grammar a case wrote parses and holds nothing its input injected (an attr
    ``evil`` or an import of ``x.bgr``: the hostile names' payloads, bench/fuzz_structure.py),
    else a failure's status with what is wrong on standard error."""
    from bgr.grammar import nodes as n
    from bgr.grammar.errors import BgrError
    from bgr.grammar.parser import parse

    if not path.exists():
        return 0
    text = path.read_text(encoding="utf-8")
    try:
        module = parse(text, str(path))
    except BgrError as exc:
        print(f"unparsable output: {exc}", file=sys.stderr)
        return 72
    for item in module.items:
        if (isinstance(item, n.Attr) and item.name == "evil") or (
            isinstance(item, n.Import) and "x.bgr" in str(item.path)
        ):
            print(f"injected output: {item}", file=sys.stderr)
            return 73
    if any(not line.isprintable() for line in text.split("\n")):
        print("injected output: a line holds a control character", file=sys.stderr)
        return 73
    return 0


def _check_png(path: Path, size: tuple[int, int]) -> int:
    """0 when ``bgr render`` (exit 0) wrote a readable PNG of ``size``, else a failure's status
    with what is wrong on standard error."""
    from PIL import Image

    try:
        with Image.open(path) as image:
            image.load()
            found = (image.format, image.size)
    except Exception as exc:  # noqa: BLE001  (whatever it is, the output is not a PNG)
        print(f"unreadable output: {type(exc).__name__}: {exc}", file=sys.stderr)
        return 74
    if found != ("PNG", size):
        print(f"wrong output: {found}, expected a PNG of {size}", file=sys.stderr)
        return 74
    return 0


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
    # the files of the case (a model and the files beside it: an MTL, images) may be named
    beside = [str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file()]
    start = time.perf_counter()
    pid = os.fork()
    if pid == 0:
        _child(argv, folder, limit_bytes)
    status = _wait(pid, timeout)
    seconds = time.perf_counter() - start
    err_path = folder / "stderr.txt"
    whole = err_path.read_text(errors="replace") if err_path.exists() else ""
    stderr = whole[-4000:]
    if status is None:
        return Outcome("timeout", seconds, stderr)
    if os.WIFSIGNALED(status):
        return Outcome(f"signal {os.WTERMSIG(status)}", seconds, stderr)
    code = os.WEXITSTATUS(status)
    left = [p.name for p in folder.rglob("*.tmp")]
    if left:
        return Outcome("left temporaries", seconds, stderr)
    head = whole[:4000]  # a long message may push "internal error" out of the tail
    if any(word in text for word in ("Traceback", "internal error") for text in (head, stderr)):
        return Outcome("internal", seconds, stderr)
    if _PY_WARNING.search(stderr):
        return Outcome("python warning", seconds, stderr)
    if "out of memory" in stderr:
        return Outcome("out of memory", seconds, stderr)
    if code == 0:
        return Outcome("success", seconds, stderr)
    if code == 1 and stderr.strip():
        # located: the message starts with the input or the output file (FILE:LINE:COL: ...),
        # or a file beside the input that it names (model.mtl:3:1: ...)
        files = [argv[1], *(argv[k + 1] for k, a in enumerate(argv[:-1]) if a == "-o"), *beside]
        located = whole.lstrip().startswith(tuple(files)) if len(argv) > 1 else True
        return Outcome("error" if located else "unlocated error", seconds, stderr)
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
    folder = tmp / f"{seeds[0].surface}{index}"
    folder.mkdir()
    return run_mutant(seeds, rng, folder)


def run_mutant(
    seeds: list[Seed], rng: random.Random, folder: Path, timeout: float = TIMEOUT_S
) -> Case:
    """A mutant of one of ``seeds`` (drawn by ``rng``) written to ``folder`` and run there."""
    seed = rng.choice(seeds)
    if seed.surface in fuzz_textured.SURFACES:  # any of its files mutated
        data, extra = fuzz_textured.mutate_case(rng, seed.surface, seed.name, seed.data, seed.extra)
        seed = Seed(seed.surface, seed.name, seed.data, extra)
    else:
        data = mutant(rng, seed.surface, seed.data)
    seed.write(folder, data)
    argv = command(seed.surface, seed.name, rng)
    return seed, data, argv, run_case(argv, folder, timeout)


# ---------------------------------------------------------------- the run


def _worker(seeds, surfaces, cases, base_seed, part, parts, out: Path) -> None:
    """Run this worker's share of the cases; one JSON line per case in OUT/results-PART."""
    tmp = Path(tempfile.mkdtemp(prefix=f"bgr-fuzz-inverse-{part}-"))
    try:
        _cases(seeds, surfaces, cases, base_seed, part, parts, out, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _cases(seeds, surfaces, cases, base_seed, part, parts, out: Path, tmp: Path) -> None:
    with open(out / f"results-{part}.jsonl", "w") as log:
        # every surface in turn: a cut run covers all
        for index in range(cases.start + part, cases.stop, parts):
            for surface in surfaces:
                seed, data, argv, outcome = fuzz_case(seeds[surface], index, base_seed, tmp)
                row = {"surface": surface, "index": index, "kind": outcome.kind,
                       "seconds": round(outcome.seconds, 3), "seed": seed.name}  # fmt: skip
                if outcome.failed:
                    stem = out / "failures" / f"{surface}-{index}"
                    stem.mkdir(parents=True, exist_ok=True)
                    seed.write(stem, data)
                    (stem / "case.txt").write_text(
                        f"bgr {' '.join(argv)}\n{outcome.kind} after {outcome.seconds:.1f} s\n"
                        f"{outcome.stderr}"
                    )
                    row["stderr"] = outcome.stderr[-300:]
                log.write(json.dumps(row) + "\n")
                log.flush()
                shutil.rmtree(tmp / f"{surface}{index}", ignore_errors=True)


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
    parser.add_argument(
        "--first-case",
        type=int,
        default=0,
        help="index of the first case (0): a long run may be done in parts, 0-4999 then 5000-9999",
    )
    parser.add_argument("--workers", type=int, default=2, help="forking workers (2)")
    parser.add_argument("--out", type=Path, default=None, help="results and failures folder")
    args = parser.parse_args(argv)
    out = args.out or Path(tempfile.mkdtemp(prefix="bgr-fuzz-inverse-"))
    out.mkdir(parents=True, exist_ok=True)
    surfaces = args.surface or list(SURFACES)
    from PIL import Image as _image  # noqa: F401
    from pyproj import Transformer as _transformer  # noqa: F401

    import bgr.cli  # noqa: F401  (imported once, before the forks)
    from bgr.formats import citygml_read, gltf_textured, obj_textured  # noqa: F401
    from bgr.inverse import schema as _schema  # noqa: F401
    from bgr.inverse.boxes import command as _boxes  # noqa: F401
    from bgr.inverse.city import command as _city  # noqa: F401
    from bgr.render import scene as _scene  # noqa: F401
    from bgr.render import textured as _textured  # noqa: F401

    with tempfile.TemporaryDirectory() as tmp:
        seeds = build_seeds(Path(tmp))
    start = time.perf_counter()
    pids = []
    for part in range(args.workers):
        pid = os.fork()
        if pid == 0:
            code = 0
            try:
                cases = range(args.first_case, args.first_case + args.cases)
                _worker(seeds, surfaces, cases, args.seed, part, args.workers, out)
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
    if len(rows) < args.cases * len(surfaces):
        print(f"a worker stopped early: {args.cases * len(surfaces) - len(rows):,} cases not run")
    (out / "table.md").write_text(report + "\n")
    failed = any(r["kind"] not in ("success", "error") for r in rows)
    return 1 if failed or len(rows) < args.cases * len(surfaces) else 0


if __name__ == "__main__":
    sys.exit(main())
