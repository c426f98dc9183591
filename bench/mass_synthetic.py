"""The photograph stage's mass and camera on a synthetic test set (issue 28's first acceptance
point): 1,000 silhouettes rendered from held-out seeds, fitted as ``bgr infer --kind image``
fits a photograph's outline.

    python bench/mass_synthetic.py [--count 1000] [--workers 2] [--jitter]

The test silhouettes are clean renders of random masses under random cameras (the training
set's ranges and filters); ``--jitter`` moves their corners by up to 1 % of the image as the
training silhouettes' are, which no mass can reproduce exactly (the same masses and cameras).

Reports, against the truth of each render: the mass-family accuracy of the network alone and
after refinement (bgr.inverse.image.photo.fit_mass: the network's likeliest families of the
outline as given and mirrored, their cameras refined, the closest refined whole), the RMSE of
the parameters in [0, 1] units (camera and mass, for renders whose family was found, not
mirrored) before and after refinement, the silhouette IoU after refinement, and the time per
silhouette.  The renders come from seed :data:`TEST_SEED`; the network was trained on
another (bench/train_mass.py).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

TEST_SEED = 2802
SIZE = (160, 120)  # the fitting scale of a 4:3 photograph (bgr.inverse.image.photo.FIT_SIDE)


def test_views(count: int, jitter: bool = False):
    from mass_views import JITTER, sample

    from bgr.inverse.image.masses import FAMILIES

    per_family = -(-count // len(FAMILIES)) + 2  # a few masses have no accepted view
    views = sample(TEST_SEED, per_family, 1, JITTER if jitter else 0.0)
    rng = np.random.default_rng(TEST_SEED)
    # in random order, so that a run cut short is a sample of every family
    keep = rng.choice(len(views), min(count, len(views)), replace=False)
    return [views[i] for i in keep]


def fit_one(view) -> dict:
    from mass_views import draw_view

    from bgr.inverse.image.mass_fit import CANVAS, estimate
    from bgr.inverse.image.masses import FAMILIES
    from bgr.inverse.image.outline import iou
    from bgr.inverse.image.photo import fit_mass

    start = time.perf_counter()
    mask = draw_view(view, *SIZE)
    fine = draw_view(view, *CANVAS)  # the command gives the network the photo's own mask
    guess = estimate(fine, top=1)[0]
    best, mirrored = fit_mass(mask, network_mask=fine)
    shown = best.mask(*SIZE)
    truth = FAMILIES[view.family].rule
    row = {
        "family": truth,
        "net_family": guess.family.rule,
        "fit_family": best.family.rule,
        "mirrored": mirrored,
        "iou": iou(shown[:, ::-1] if mirrored else shown, mask),
        "distance": best.distance,
        "seconds": time.perf_counter() - start,
        "evaluations": best.evaluations,
    }
    for name, fit in (("net", guess), ("fit", best)):
        if fit.family.rule == truth and not (name == "fit" and mirrored):
            row[f"{name}_camera_err"] = (fit.camera - view.camera).tolist()
            row[f"{name}_mass_err"] = (fit.mass - view.mass).tolist()
    return row


def _rmse(rows: list[dict], key: str) -> float:
    errs = [e for r in rows if key in r for e in r[key]]
    return float(np.sqrt(np.mean(np.square(errs)))) if errs else float("nan")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=1000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument(
        "--jitter", action="store_true", help="corners moved as the training views' are"
    )
    parser.add_argument("--rows", help="also write each silhouette's result here (JSON lines)")
    parser.add_argument("--summary", help="only summarise a --rows file (a run cut short)")
    parser.add_argument(
        "--network-only", action="store_true", help="only the network's estimates (seconds)"
    )
    args = parser.parse_args()
    if args.summary:
        with open(args.summary) as f:
            rows = [json.loads(line) for line in f]
        report(rows, 0, 0.0)
        return
    views = test_views(args.count, args.jitter)
    kind = "jittered" if args.jitter else "clean"
    print(f"{len(views)} {kind} test silhouettes from seed {TEST_SEED}", flush=True)
    if args.network_only:
        network_report(views)
        return
    start = time.perf_counter()
    out = open(args.rows, "w") if args.rows else None  # noqa: SIM115 - written as rows come
    rows = []
    with ProcessPoolExecutor(args.workers) as pool:
        for row in pool.map(fit_one, views, chunksize=2):
            rows.append(row)
            if out:
                out.write(json.dumps(row) + "\n")
                out.flush()
    if out:
        out.close()
    report(rows, args.workers, time.perf_counter() - start)


def network_report(views) -> None:
    """The network alone on every view: top-1 and top-3 family accuracy, parameter RMSE."""
    from mass_views import draw_view

    from bgr.inverse.image.mass_fit import CANVAS, estimate
    from bgr.inverse.image.masses import FAMILIES

    top1 = top3 = 0
    cam_err, mass_err = [], []
    for view in views:
        guesses = estimate(draw_view(view, *CANVAS), top=3)
        truth = FAMILIES[view.family].rule
        top1 += guesses[0].family.rule == truth
        top3 += truth in [g.family.rule for g in guesses]
        found = [g for g in guesses if g.family.rule == truth]
        if found:
            cam_err += (found[0].camera - view.camera).tolist()
            mass_err += (found[0].mass - view.mass).tolist()
    n = len(views)
    print(f"network alone: family top-1 {top1 / n:.3f}, top-3 {top3 / n:.3f}")
    cam_rmse = np.sqrt(np.mean(np.square(cam_err)))
    mass_rmse = np.sqrt(np.mean(np.square(mass_err)))
    print(
        "parameter RMSE ([0, 1] units) where the family is among the three: "
        f"camera {cam_rmse:.4f}, mass {mass_rmse:.4f}"
    )


def report(rows: list[dict], workers: int, wall: float) -> None:
    print(f"{len(rows)} silhouettes")
    ious = np.array([r["iou"] for r in rows])
    net = np.mean([r["net_family"] == r["family"] for r in rows])
    fitted = np.mean([r["fit_family"] == r["family"] for r in rows])
    print(f"mass family accuracy: network {net:.3f}, after refinement {fitted:.3f}")
    print(
        f"parameter RMSE ([0, 1] units), network: camera {_rmse(rows, 'net_camera_err'):.4f}, "
        f"mass {_rmse(rows, 'net_mass_err'):.4f}; "
        f"refined: camera {_rmse(rows, 'fit_camera_err'):.4f}, "
        f"mass {_rmse(rows, 'fit_mass_err'):.4f}"
    )
    print(
        f"silhouette IoU after refinement: mean {ious.mean():.3f}, median {np.median(ious):.3f}, "
        f">= 0.95: {np.mean(ious >= 0.95):.3f}, 5th percentile {np.percentile(ious, 5):.3f}"
    )
    seconds = np.array([r["seconds"] for r in rows])
    print(
        f"time per silhouette: mean {seconds.mean():.2f} s, max {seconds.max():.2f} s "
        f"({workers} workers, {wall:.0f} s wall)"
    )


if __name__ == "__main__":
    main()
