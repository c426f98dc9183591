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

Prints the figures (means over the façades) of the shipped weights (trained on all of them:
``bench/train_facade.py`` prints the cross-validated ones); ``--no-refine`` parses without
section 5.2's boundary refinement.
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


def evaluate(
    photos: list[Path], net: dict | None = None, refine: bool | None = None
) -> list[tuple]:
    """A row of measures for each façade: (pixel accuracy, window TP, FP, FN, floors error,
    windows-per-floor error, seconds); ``refine`` False: without section 5.2's refinement."""
    from bgr.inverse.image import facade

    rows = []
    for photo in photos:
        rgb = np.asarray(Image.open(photo).convert("RGB"))
        start = time.perf_counter()
        if refine is None:
            parse = facade.parse_facade(rgb, net)
        else:
            weights = net if net is not None else facade.load_weights()
            work = facade.working_image(rgb)
            prob = facade.window_probability(work, weights)
            parse = facade.parse_probability(rgb, work, prob, weights, refine=refine)
        rows.append(measure(parse, photo, time.perf_counter() - start))
    return rows


def measure(parse, photo: Path, seconds: float = 0.0) -> tuple:
    """The row of :func:`evaluate` of a parse of ``photo`` (its labels and boxes beside it)."""
    labels = np.asarray(Image.open(photo.with_suffix(".png")))
    floors, per_floor = truth_grid(photo.with_suffix(".xml").read_text())
    counts = parse.windows_per_floor()
    got_per_floor = int(statistics.median(counts or [0]))
    accuracy, tp, fp, fn = scores(parse.label_map(), labels)
    return (accuracy, tp, fp, fn, len(counts) - floors, got_per_floor - per_floor, seconds)


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
    ap.add_argument(
        "--no-refine", action="store_true", help="without section 5.2's boundary refinement"
    )
    args = ap.parse_args()
    photos = sorted(args.cmp.glob("cmp_b*.jpg"))
    if args.limit:
        photos = photos[: args.limit]
    if not photos:
        sys.exit(f"{args.cmp}: no CMP façades here")
    rows = evaluate(photos, refine=False if args.no_refine else None)
    print(f"all {len(rows)} (the shipped weights, trained on all of them): {summary(rows)}")


if __name__ == "__main__":
    main()
