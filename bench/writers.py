"""Benchmark: write one ~1M-triangle terminal table in every format bgr writes.

    python bench/writers.py [--triangles 1000000] [--repeat 5] [--out DIR]

The table holds N boxes (12 triangles, one shared unit mesh, 4 colours, random rotations about y)
and N quads that each have their own unit mesh (like polygons and roof faces), with N chosen so
that 14 N reaches the requested triangle count.  The GLB bakes every terminal (the default);
with ``--instancing`` boxes are instanced (EXT_mesh_gpu_instancing) and quads baked.  Each
repeat writes every format once, in turn, so that a busy machine slows them alike; the script
prints the median and best wall time of ``bgr.formats.write`` (everything from the table to the
renamed file), the median CPU time of the process, the file sizes, and each format's median time
over the (default) GLB's; then .city.json and .city.jsonl (:func:`cityjson_rows`, timed on
their own).  Target (issue 11): OBJ within 2x of the GLB.
"""

from __future__ import annotations

import argparse
import functools
import os
import platform
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from bgr.formats import write
from bgr.interpreter.terminals import TerminalTable, UnitMesh

BOX_V = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
BOX_F = np.array(
    [
        [0, 1, 3],
        [0, 3, 2],
        [4, 6, 7],
        [4, 7, 5],
        [0, 4, 5],
        [0, 5, 1],
        [2, 3, 7],
        [2, 7, 6],
        [0, 2, 6],
        [0, 6, 4],
        [1, 5, 7],
        [1, 7, 3],
    ]
)
QUAD_F = np.array([[0, 1, 2], [0, 2, 3]])


def table(n: int, seed: int = 0) -> TerminalTable:
    rng = np.random.default_rng(seed)
    t = TerminalTable()
    box = t.library.add(UnitMesh("cube", BOX_V, BOX_F))
    angle = rng.uniform(0, 2 * np.pi, n)
    c, s = np.cos(angle), np.sin(angle)
    z, o = np.zeros(n), np.ones(n)
    rot = np.stack([np.stack([c, z, -s], 1), np.stack([z, o, z], 1), np.stack([s, z, c], 1)], 1)
    palette = np.array([[0.8, 0.3, 0.2], [0.9, 0.9, 0.85], [0.2, 0.3, 0.4], [0.5, 0.5, 0.5]])
    # quads: each its own unit mesh (a random convex quadrilateral in the unit square)
    jitter = rng.uniform(0, 0.2, (n, 4, 2))
    corners = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    quad_v = np.zeros((n, 4, 3))
    quad_v[:, :, :2] = np.abs(corners - jitter)
    quads = [t.library.add(UnitMesh("polygon", quad_v[i], QUAD_F), key=("q", i)) for i in range(n)]

    t.label = ["Box"] * n + ["Quad"] * n
    t.rule = list(t.label)
    t.path = [f"Lot/Box.{i}" for i in range(n)] + [f"Lot/Quad.{i}" for i in range(n)]
    t.origin = np.concatenate([rng.uniform(0, 1000, (n, 3)), rng.uniform(0, 1000, (n, 3))])
    t.axes = np.concatenate([rot, np.broadcast_to(np.eye(3), (n, 3, 3))])
    t.size = np.concatenate(
        [rng.uniform(1, 20, (n, 3)), np.column_stack([rng.uniform(1, 5, (n, 2)), z])]
    )
    t.color = np.concatenate([palette[rng.integers(0, 4, n)], palette[rng.integers(0, 4, n)]])
    t.material = [None] * (2 * n)
    t.mesh = [box] * n + quads
    return t.freeze()


def _glb(t, path: Path, instancing: str | bool) -> None:
    write(t, path, seed=0, attrs={}, gltf={"instancing": instancing})


def cases(t) -> list[tuple[str, str, Callable[[Path], None]]]:
    """(name, file extension, writer of that file) for every format."""
    plain = [
        (ext, ext, functools.partial(lambda ext, path: write(t, path, seed=0, attrs={}), ext))
        for ext in ["obj", "ply", "stl", "json"]
    ]
    return [
        ("glb", "glb", lambda path: _glb(t, path, False)),
        ("glb --instancing", "glb", lambda path: _glb(t, path, "auto")),
        *plain,
    ]


def size(path: Path) -> float:
    """Megabytes written: the file, and for .obj its .mtl."""
    extra = path.with_suffix(".mtl") if path.suffix == ".obj" else None
    return (path.stat().st_size + (extra.stat().st_size if extra else 0)) / 1e6


def timed(fn, repeat: int) -> tuple[float, float]:
    runs = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        runs.append(time.perf_counter() - start)
    return statistics.median(runs), min(runs)


def cityjson_rows(t: TerminalTable, folder: Path, repeat: int) -> None:
    """CityJSON and CityJSON Text Sequences of the table (one Building: it has no lots; its
    terminals are cut into BuildingParts wherever gaps separate them in plan)."""
    for ext in ("city.json", "city.jsonl"):
        path = folder / f"bench.{ext}"
        median, best = timed(functools.partial(write, t, path, seed=0, attrs={}), repeat)
        size = path.stat().st_size / 1e6
        print(f"{ext:21s}: median {median:.3f} s, best {best:.3f} s, {size:.1f} MB")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--triangles", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument(
        "--out", type=Path, default=None, help="folder for the files (default: a temp dir)"
    )
    args = ap.parse_args()
    n = max(1, args.triangles // 14)
    start = time.perf_counter()
    t = table(n)
    print(
        f"table: {len(t):,} terminals, {t.triangle_count():,} triangles "
        f"(built in {time.perf_counter() - start:.2f} s)"
    )
    print(
        f"python {platform.python_version()}, numpy {np.__version__}, {platform.machine()}, "
        f"{os.cpu_count()} cpus, load average {os.getloadavg()[0]:.2f} at start"
    )
    with tempfile.TemporaryDirectory(dir=args.out) as tmp:
        runs: dict[str, list[tuple[float, float]]] = {}
        paths: dict[str, Path] = {}
        for _ in range(args.repeat):
            for i, (name, ext, fn) in enumerate(cases(t)):
                paths[name] = path = Path(tmp) / f"bench{i}.{ext}"
                wall, cpu = time.perf_counter(), time.process_time()
                fn(path)
                runs.setdefault(name, []).append(
                    (time.perf_counter() - wall, time.process_time() - cpu)
                )
        glb = statistics.median(w for w, _ in runs["glb"])
        print(f"{args.repeat} runs each; load average {os.getloadavg()[0]:.2f} at the end")
        print(
            f"{'format':18s} {'median s':>9s} {'best s':>7s} {'cpu s':>6s} {'MB':>6s} {'/ glb':>6s}"
        )
        for name, times in runs.items():
            wall = statistics.median(w for w, _ in times)
            print(
                f"{name:18s} {wall:9.3f} {min(w for w, _ in times):7.3f} "
                f"{statistics.median(c for _, c in times):6.3f} {size(paths[name]):6.1f} "
                f"{wall / glb:6.2f}"
            )
        cityjson_rows(t, Path(tmp), min(args.repeat, 3))


if __name__ == "__main__":
    main()
