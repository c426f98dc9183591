"""bgr infer --kind city, measured: the scale run and the level tables of the real cities.

1. **Scale**: the synthetic city of bench/make_city.py (10,000 buildings by default; made first
   if the OBJ is not there) proceduralized by ``bgr infer`` in a fresh process: wall time, peak
   memory, components, types, rules.  The issue asks for under 60 s and 4 GB, with types far
   fewer than components.
2. **Levels**: ``bgr infer --stats`` on the Delft and Zurich data of ../shared/data/cities (when
   present): for every de-instancing level the counts, sizes, reduction factors and the
   Hausdorff/Chamfer errors of the derived city against the input.

    python bench/infer_city.py                 # both
    python bench/infer_city.py --no-levels     # the scale run only
    python bench/infer_city.py --buildings 1000 --no-levels

Results go in docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CITIES = ROOT.parent / "shared" / "data" / "cities"
REAL = ["delft.obj", "zurich_lod2.obj", "zurich_lod2.city.json"]


def run(args: list[str], cwd: str) -> tuple[float, float, str]:
    """(seconds, peak MB, standard error) of one ``bgr`` process."""
    start = time.perf_counter()
    proc = subprocess.Popen(
        [sys.executable, "-m", "bgr", *args],
        cwd=cwd,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stderr is not None
    err = proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"bgr {' '.join(args)} failed:\n{err}")
    return time.perf_counter() - start, usage.ru_maxrss / 1024, err


def scale(buildings: int, city: Path) -> None:
    if not city.is_file():
        subprocess.run(
            [
                sys.executable,
                str(ROOT / "bench" / "make_city.py"),
                "--buildings",
                str(buildings),
                "-o",
                str(city),
            ],
            check=True,
        )
    with tempfile.TemporaryDirectory() as tmp:
        seconds, peak, err = run(["infer", str(city), "-o", "city.bgr", "--no-progress"], tmp)
        found = re.search(
            r"(\d+) objects, (\d+) components, (\d+) types at level 0 "
            r"\((\d+) footprints extruded(?:, (\d+) houses? roofed)?\), (\d+) rules",
            err,
        )
        lines = (Path(tmp) / "city.bgr").read_text().count("\n")
        size = sum(p.stat().st_size for p in Path(tmp).rglob("*") if p.is_file())
    print(f"## scale: {city.name} ({city.stat().st_size / 1e6:.1f} MB)")
    print(
        "| buildings | components | types | footprints extruded | houses roofed | rules "
        "| grammar lines | grammar + assets bytes | time | peak memory |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    if found:
        b, c, t, x, h, r = (int(v or 0) for v in found.groups())
        print(
            f"| {b:,} | {c:,} | {t:,} | {x:,} | {h:,} | {r:,} | {lines:,} | {size:,} | "
            f"{seconds:.1f} s | {peak:.0f} MB |"
        )
    print()


def levels() -> None:
    for name in REAL:
        source = CITIES / name
        if not source.is_file():
            print(f"{source}: not here, skipped")
            continue
        with tempfile.TemporaryDirectory() as tmp:
            seconds, peak, err = run(
                ["infer", str(source), "-o", "city.bgr", "--stats", "--no-progress"], tmp
            )
        table = [line for line in err.splitlines() if line.startswith("|")]
        print(f"## levels: {name} (bgr infer --stats: {seconds:.1f} s, peak {peak:.0f} MB)")
        print("\n".join(table))
        rows = [line.split("|")[1:-1] for line in table[2:]]
        if rows:
            tri_in = int(rows[0][5].replace(",", ""))
            bytes_in = int(rows[0][7].replace(",", ""))
            print(
                "\nreduction (input / output): "
                + ", ".join(
                    f"level {r[0].strip()}: {tri_in / max(int(r[6].replace(',', '')), 1):.2f}x "
                    f"triangles, {bytes_in / max(int(r[8].replace(',', '')), 1):.2f}x bytes"
                    for r in rows
                )
            )
        print()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--buildings", type=int, default=10_000)
    ap.add_argument("--city", type=Path, help="the city OBJ (default /tmp/bgr-cityN.obj)")
    ap.add_argument("--no-scale", action="store_true")
    ap.add_argument("--no-levels", action="store_true")
    args = ap.parse_args()
    if not args.no_scale:
        scale(
            args.buildings,
            args.city or Path(tempfile.gettempdir()) / f"bgr-city{args.buildings}.obj",
        )
    if not args.no_levels:
        levels()


if __name__ == "__main__":
    main()
