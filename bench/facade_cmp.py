"""Benchmark: façade parsing on the CMP façades (issue 28, section 5 of "Procedural building
from a single image").

    python bench/facade_cmp.py [--cmp ../shared/data/facades/cmp] [--limit N]

For each of the 100 labelled façades (``cmp_bNNNN.jpg`` with its label map ``.png`` and boxes
``.xml``; never committed, research use): ``bgr.inverse.image.facade.parse_facade`` of the
photograph, then

* **pixel accuracy and window F1** of its label map against the CMP labels, counting window (3),
  door (4) and shop (12) as window and every other label as wall (the paper's Table 4 protocol);
* **floors and windows per floor**: the truth from the XML's window boxes (label 3), a floor
  being a run of windows whose vertical extents overlap (each box joins the floor whose rows it
  shares most); windows per floor is the median count over the floors.  RMSE over the façades
  of the parse's floors and median windows per floor against those.

Prints the figures (means over the façades) and the five folds' (cross-validation folds of 20
façades in file order; the parse has no trained parameters yet, so each fold is a test set).
"""

from __future__ import annotations

import argparse
import re
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from PIL import Image

ROOT = Path(__file__).resolve().parent.parent
CMP = ROOT.parent / "shared" / "data" / "facades" / "cmp"
WINDOWISH = (3, 4, 12)  # window, door, shop: "window" in the paper's Table 4


def truth_grid(xml: str) -> tuple[int, int]:
    """(floors, median windows per floor) from a CMP XML's window boxes (label 3), grouped into
    rows by ``rows_of`` as the parse's are.  The XML's ``x`` pair is the box's vertical extent
    (a fraction of the height), ``y`` its horizontal one (checked against the label maps)."""
    from bgr.inverse.image.facade import rows_of

    extents = []
    for obj in re.findall(r"<object>(.*?)</object>", xml, re.S):
        if re.search(r"<label>\s*3\s*</label>", obj):
            xs = [float(v) for v in re.findall(r"<x>\s*([^<\s]+)\s*</x>", obj)]
            extents.append((min(xs), max(xs)))
    floors = rows_of(extents)
    if not floors:
        return 0, 0
    return len(floors), int(statistics.median(len(f) for f in floors))


def scores(predicted: np.ndarray, labels: np.ndarray) -> tuple[float, int, int, int]:
    """(pixel accuracy, true positives, false positives, false negatives) of window pixels."""
    truth = np.isin(labels, WINDOWISH)
    guess = predicted == 3
    tp = int((truth & guess).sum())
    return (
        float((truth == guess).mean()),
        tp,
        int((~truth & guess).sum()),
        int((truth & ~guess).sum()),
    )


def evaluate(photos: list[Path], net: dict | None = None) -> list[tuple]:
    """A row of measures for each façade: (pixel accuracy, window TP, FP, FN, floors error,
    windows-per-floor error, seconds)."""
    from bgr.inverse.image.facade import parse_facade

    rows = []
    for photo in photos:
        rgb = np.asarray(Image.open(photo).convert("RGB"))
        labels = np.asarray(Image.open(photo.with_suffix(".png")))
        floors, per_floor = truth_grid(photo.with_suffix(".xml").read_text())
        start = time.perf_counter()
        parse = parse_facade(rgb, net)
        seconds = time.perf_counter() - start
        counts = parse.windows_per_floor()
        got_per_floor = int(statistics.median(counts or [0]))
        accuracy, tp, fp, fn = scores(parse.label_map(), labels)
        rows.append(
            (accuracy, tp, fp, fn, len(counts) - floors, got_per_floor - per_floor, seconds)
        )
    return rows


def summary(part: list[tuple]) -> str:
    acc = np.mean([r[0] for r in part])
    tp, fp, fn = (sum(r[k] for r in part) for k in (1, 2, 3))
    f1 = 2 * tp / max(1, 2 * tp + fp + fn)
    floors = np.sqrt(np.mean([r[4] ** 2 for r in part]))
    windows = np.sqrt(np.mean([r[5] ** 2 for r in part]))
    seconds = np.median([r[6] for r in part])
    return (
        f"pixel accuracy {acc:.3f}, window F1 {f1:.3f}, RMSE floors {floors:.2f}, "
        f"windows per floor {windows:.2f}, median {seconds:.2f} s a façade"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cmp", type=Path, default=CMP)
    ap.add_argument("--limit", type=int, default=0, help="the first N façades only")
    args = ap.parse_args()
    photos = sorted(args.cmp.glob("cmp_b*.jpg"))
    if args.limit:
        photos = photos[: args.limit]
    if not photos:
        sys.exit(f"{args.cmp}: no CMP façades here")
    rows = evaluate(photos)
    print(f"all {len(rows)} (the shipped weights, trained on all of them): {summary(rows)}")


if __name__ == "__main__":
    main()
