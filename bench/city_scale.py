"""Benchmark: a synthetic city of N lots derived and streamed to a GLB, in one process, on a
local process pool and on a Dask LocalCluster.

    python bench/city_scale.py [--lots 10000 100000] [--modes serial pool2 dask2]
                               [--grammar bench/city_scale.bgr] [--format glb]

Each (N, mode) runs in a fresh Python process, so the peak resident memory it reports is that
run's parent process alone (ru_maxrss; the workers are other processes).  The lots are made
lazily, a grid of 25 m cells each holding a 10-14 x 9-11 m rectangle, and never held together:
the parent holds a few batches of lots and one lot's terminals at a time, so its memory must
not grow with N.  Prints lots per second (everything: worker start-up, deriving, writing and
renaming the file), the speed-up over the serial run, the parent's peak memory and the file
size, as a Markdown table for docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

CHILD = r"""
import json, math, resource, sys, time
t0 = time.perf_counter()
import numpy as np
from bgr.formats.sinks import open_sink
from bgr.interpreter.batch import derive_lots
from bgr.interpreter.derive import prepare
from bgr.interpreter.lots import footprint

grammar, n, mode, out = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
job, _, _ = prepare(grammar, seed=1, per_lot=True)
side = math.ceil(math.sqrt(n))

def lots():
    for i in range(n):
        x, z = 25.0 * (i % side), 25.0 * (i // side)
        w, d = 10.0 + (i * 7 % 5), 9.0 + (i * 3 % 3)
        yield footprint([(x, z), (x + w, z), (x + w, z + d), (x, z + d)])

how = {"serial": {}, "pool2": {"workers": 2}, "dask2": {"dask": "local", "workers": 2}}[mode]
terminals = triangles = 0
t1 = time.perf_counter()
with open_sink(out, seed=1, attrs=job.values) as sink:
    for result in derive_lots(job, lots(), count=n, **how):
        sink.add(result.table)
t2 = time.perf_counter()
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
import os
print(json.dumps({
    "lots": n, "mode": mode, "seconds": t2 - t1, "startup_s": t1 - t0,
    "terminals": sink.terminals, "triangles": sink.triangles,
    "peak_mb": peak / 1e6, "bytes": os.path.getsize(out),
}))
"""


def run(grammar: Path, n: int, mode: str, fmt: str, folder: Path) -> dict:
    out = folder / f"city_{n}_{mode}.{fmt}"
    proc = subprocess.run(
        [sys.executable, "-c", CHILD, str(grammar), str(n), mode, str(out)],
        capture_output=True,
        text=True,
        check=False,
    )
    if proc.returncode:
        raise SystemExit(f"{mode} on {n} lots failed:\n{proc.stderr[-3000:]}")
    out.unlink()
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lots", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--modes", nargs="+", default=["serial", "pool2", "dask2"])
    parser.add_argument("--grammar", type=Path, default=ROOT / "bench" / "city_scale.bgr")
    parser.add_argument("--format", default="glb", choices=["glb", "city.jsonl", "json"])
    args = parser.parse_args()
    print(
        f"# {platform.node()} {platform.processor() or platform.machine()}, "
        f"{os.cpu_count()} cores, Python {platform.python_version()}, "
        f"{time.strftime('%Y-%m-%d')}",
        flush=True,
    )
    rows = []
    with tempfile.TemporaryDirectory(prefix="bgr-city-") as tmp:
        for n in args.lots:
            serial = None
            for mode in args.modes:
                r = run(args.grammar, n, mode, args.format, Path(tmp))
                rate = r["lots"] / r["seconds"]
                if mode == "serial":
                    serial = rate
                r["rate"], r["speedup"] = rate, (rate / serial if serial else float("nan"))
                rows.append(r)
                print(json.dumps(r), flush=True)
    print()
    print(
        "| lots | mode | seconds | lots/s | speed-up | parent peak MB | terminals | triangles "
        "| file MB |"
    )
    print("|---:|---|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        print(
            f"| {r['lots']:,} | {r['mode']} | {r['seconds']:.1f} | {r['rate']:.0f} | "
            f"{r['speedup']:.2f}x | {r['peak_mb']:.0f} | {r['terminals']:,} | "
            f"{r['triangles']:,} | {r['bytes'] / 1e6:.0f} |"
        )


if __name__ == "__main__":
    main()
