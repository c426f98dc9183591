"""Make the synthetic city of the city-scale benchmark: N lots on a grid of streets, derived.

    python bench/make_city.py --buildings 10000 -o /tmp/city10k.obj [-o /tmp/city10k.glb]

``bgr infer --kind city`` (issue 12) is measured on a city "made by the project": this script
writes a GeoJSON of N rectangular lots in plain metres (coordinates outside the longitude/latitude
range, so bgr takes them as metres: interpreter/lots.py ``_project``), derives
bench/city_grammar.bgr on them in process and writes each ``-o`` file, so every lot is one OBJ
``o`` object / one GLB lot node.  The lots sit on a grid of blocks, ``--block`` x ``--block``
plots each, with a street between blocks; the width of each plot column and the depth of each
plot row are drawn from a few values, so that lots, and with them the buildings' components,
repeat exactly.  Prints the triangle count, each phase's time and each file's size.

The grid_city.bgr stress grammar at n = 100 is no substitute: it makes 25 M triangles (every
window extruded) and gives every building a random size, so nothing repeats.
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
GRAMMAR = ROOT / "bench" / "city_grammar.bgr"
WIDTHS = (12.0, 15.0, 18.0)  # metres along the street, one drawn per plot column
DEPTHS = (16.0, 20.0)  # metres into the block, one drawn per plot row
ORIGIN = (1000.0, 1000.0)  # metres: outside the longitude/latitude range, so read as metres


def grid_lots(
    n: int, *, block: int = 10, street: float = 12.0, seed: int = 0
) -> list[list[tuple[float, float]]]:
    """N rectangles (x east, y north, counter-clockwise, first edge the south one: the front)
    on a near-square grid of plots, a street of ``street`` metres after every ``block`` plots."""
    cols = max(1, math.ceil(math.sqrt(n)))
    rows = max(1, math.ceil(n / cols))
    rng = np.random.default_rng(seed)
    width = rng.choice(WIDTHS, cols)
    depth = rng.choice(DEPTHS, rows)
    # plot edges: each plot's size, plus a street after every block of plots
    x0 = (
        ORIGIN[0]
        + np.concatenate([[0.0], np.cumsum(width)])[:-1]
        + street * (np.arange(cols) // block)
    )
    y0 = (
        ORIGIN[1]
        + np.concatenate([[0.0], np.cumsum(depth)])[:-1]
        + street * (np.arange(rows) // block)
    )
    rings = []
    for i in range(n):
        r, c = divmod(i, cols)
        xa, ya = float(x0[c]), float(y0[r])
        xb, yb = xa + float(width[c]), ya + float(depth[r])
        rings.append([(xa, ya), (xb, ya), (xb, yb), (xa, yb), (xa, ya)])
    return rings


def write_geojson(rings: list[list[tuple[float, float]]], path: Path) -> None:
    """The lots as a FeatureCollection, feature ``id`` b00000, b00001, ... (the OBJ object and
    GLB node names)."""
    features = [
        {
            "type": "Feature",
            "id": f"b{i:05d}",
            "properties": {},
            "geometry": {"type": "Polygon", "coordinates": [ring]},
        }
        for i, ring in enumerate(rings)
    ]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--buildings", type=int, default=10_000)
    ap.add_argument(
        "-o",
        "--out",
        type=Path,
        action="append",
        required=True,
        help="an output file (.obj, .glb, anything bgr writes); repeatable",
    )
    ap.add_argument(
        "--lots",
        type=Path,
        default=None,
        help="where the GeoJSON of lots goes (default: beside the first output)",
    )
    ap.add_argument("--grammar", type=Path, default=GRAMMAR)
    ap.add_argument("--block", type=int, default=10, help="plots per block side")
    ap.add_argument("--street", type=float, default=12.0, help="street width, metres")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    if args.buildings < 1:
        sys.exit("--buildings must be at least 1")

    import bgr
    from bgr.formats import write

    lots = args.lots or args.out[0].with_suffix(".lots.geojson")
    start = time.perf_counter()
    write_geojson(
        grid_lots(args.buildings, block=args.block, street=args.street, seed=args.seed), lots
    )
    print(f"lots: {args.buildings:,} in {lots} ({time.perf_counter() - start:.2f} s)", flush=True)

    start = time.perf_counter()
    grammar = bgr.load(args.grammar)
    result = bgr.derive(grammar, seed=args.seed, lot=str(lots), strict=True)
    table = result.terminals
    took = time.perf_counter() - start
    print(
        f"derive: {len(table.lots):,} buildings, {len(table):,} terminals, "
        f"{table.triangle_count():,} triangles in {took:.2f} s (peak {peak_mb():.0f} MB)",
        flush=True,
    )
    for path in args.out:
        start = time.perf_counter()
        write(table, path, seed=result.seed, attrs=result.attrs)
        took = time.perf_counter() - start
        size = path.stat().st_size
        mtl = path.with_suffix(".mtl")
        extra = f" + {mtl.stat().st_size / 1e3:.1f} kB .mtl" if path.suffix == ".obj" else ""
        print(
            f"write {path}: {took:.2f} s, {size / 1e6:.1f} MB{extra} (peak {peak_mb():.0f} MB)",
            flush=True,
        )


if __name__ == "__main__":
    main()
