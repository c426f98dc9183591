"""Benchmark: analysis and retargeting of a ~300-box hierarchy (issue 14; the paper's largest
model had 300 boxes: 1.5 min of analysis, under 1 s a retargeting).

    python bench/boxes.py [--storeys 6] [--repeat 7] [--seed 1]   # 6 storeys: 325 boxes
    python bench/boxes.py --validity 99   # is every retargeting of 99 random façades valid?

The hierarchy is an irregular façade: storeys (R up) of bays of random widths (R across, S
walls between them, a fixed door in the ground storey), each bay a sill, a window and a lintel
— offset columns, so alignment groups and secondary sequences have work to do.  Timed, median
and best of ``--repeat`` runs in this process:

* **analysis**: alignment groups, compatibility graphs and sequences of every node, along all
  three axes (what the paper does offline);
* **one retargeting**: one axis (x, to 150 %) from its analysis — the paper's interactive step;
* **retarget x then y**: ``retarget()`` to 150 % x 130 %, re-analysing the grown hierarchy for y,
  as ``bgr retarget`` does.

``--validity N`` instead retargets N random façades (seeds 1..N: 3 to 8 storeys, each axis to
60 %, 80 %, 150 % or 250 %, order xy or yx) and counts the results that are valid hierarchies of
the size asked, the sizes refused (shorter than the fixed boxes need), the results with a hole
(empty space in a box whose children filled it in the input), and the nodes whose placement had
to be fitted (inverse/boxes/repair.py).
"""

from __future__ import annotations

import argparse
import json
import platform
import random
import statistics
import time

import numpy as np

from bgr.grammar.errors import BgrError
from bgr.inverse.boxes import retarget as retargeting
from bgr.inverse.boxes.analysis import analyse
from bgr.inverse.boxes.model import check, holes, parse
from bgr.inverse.boxes.retarget import retarget, retarget_axis


def facade(storeys: int, seed: int) -> dict:
    rng = random.Random(seed)
    width, depth, height = 40.0, 0.5, 3.0
    kids = []
    for s in range(storeys):
        y0, y1 = s * height, (s + 1) * height
        x, k = 0.0, 0
        while x < width - 4:
            wall = rng.choice([0.8, 1.0, 1.2])
            bay = rng.choice([1.2, 1.5, 2.0, 2.5])
            if x + wall + bay > width - 1:
                break
            kids.append(_box(f"wall-{s}-{k}", (x, y0, 0), (x + wall, y1, depth), "SSF"))
            x += wall
            if s == 0 and k == 3:
                kids.append(_box(f"door-{s}", (x, y0, 0), (x + bay, y1, depth), "FFF"))
            else:
                parts = [("sill", y0, y0 + 0.9, "S"), ("window", y0 + 0.9, y1 - 0.5, "F"),
                         ("lintel", y1 - 0.5, y1, "S")]  # fmt: skip
                for name, a, b, tag in parts:
                    kids.append(
                        _box(f"{name}-{s}-{k}", (x, a, 0), (x + bay, b, depth), "R" + tag + "F")
                    )
            x += bay
            k += 1
        kids.append(_box(f"wall-{s}-end", (x, y0, 0), (width, y1, depth), "SSF"))
    return {"root": _box("facade", (0, 0, 0), (width, storeys * height, depth), "SSF", kids)}


def _box(id, lo, hi, tags, children=None):
    behavior = dict(zip("xyz", tags, strict=True))
    return {
        "id": id,
        "min": list(lo),
        "max": list(hi),
        "behavior": behavior,
        "children": list(children or []),
    }


def timed(fn, repeat: int) -> tuple[float, float]:
    """Median and best wall time; ``fn`` may return its own timing of the part that counts."""
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        own = fn()
        times.append(own if own is not None else time.perf_counter() - t)
    return statistics.median(times), min(times)


def validity(n: int) -> None:
    fitted = 0
    fit = retargeting.fit

    def counting(*args):
        nonlocal fitted
        fitted += 1
        return fit(*args)

    retargeting.fit = counting
    valid = invalid = refused = holed = 0
    for seed in range(1, n + 1):
        rng = random.Random(seed)
        root = parse(json.dumps(facade(rng.randint(3, 8), seed)))
        factors = [rng.choice([0.6, 0.8, 1.5, 2.5]) for _ in range(2)]
        size = (root.size[0] * factors[0], root.size[1] * factors[1], root.size[2])
        try:
            result = retarget(root, size, rng.choice(["xy", "yx"]))
        except BgrError:
            refused += 1
            continue
        if check(result) or not np.allclose(result.size, size):
            invalid += 1
        else:
            valid += 1
        holed += bool(holes(root, result))
    retargeting.fit = fit
    print(f"{n} random façades: {valid} valid, {invalid} invalid, {refused} refused (too short);")
    print(f"{holed} with a hole in a wall the input closed; {fitted} node placements fitted")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--storeys", type=int, default=6)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--validity", type=int, metavar="N", help="check N random retargetings")
    args = ap.parse_args()
    if args.validity:
        validity(args.validity)
        return
    root = parse(json.dumps(facade(args.storeys, args.seed)))
    boxes = sum(1 for _ in root.walk())
    size = root.size

    def analysis():
        for axis in range(3):
            analyse(root, axis)

    x_analysis = analyse(root, 0)

    def one_axis():
        """Only the retargeting is timed: each run gets a fresh copy and its analysis."""
        copy = root.copy()
        ready = analyse(copy, 0)
        t = time.perf_counter()
        retarget_axis(copy, 0, size[0] * 1.5, analysis=ready)
        return time.perf_counter() - t

    def two_axes():
        retarget(root, (size[0] * 1.5, size[1] * 1.3, size[2]), "xy")

    print(f"# {platform.processor() or platform.machine()}, Python {platform.python_version()}")
    print(f"{boxes} boxes ({args.storeys} storeys), {x_analysis.sequence_count} sequences along x")
    for name, fn in (("analysis (3 axes)", analysis), ("one retargeting (x)", one_axis),
                     ("retarget x then y", two_axes)):  # fmt: skip
        median, best = timed(fn, args.repeat)
        print(f"{name:22s} median {median * 1000:8.1f} ms   best {best * 1000:8.1f} ms")


if __name__ == "__main__":
    main()
