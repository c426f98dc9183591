"""Train the façade style classifier of bgr.inverse.image.facade_style on renders of the stdlib's
sixteen façade rules (issue 28, section 5.3 of Nishida et al. 2018), report held-out accuracy
and the confusions, and write the weights.

    python bench/train_facade_style.py [--renders 45] [--out inverse/image/facade_styles.npz]

As bench/train_windows.py does for the windows: the project has no façades labelled with its
rules, but it has the rules.  Each sample is one rule of ``stdlib/facade.bgr`` on a slab whose
width and height fit a random number of tiles and floors, with random storey, ground and top
heights, tile and window sizes, sills, margins, entrances, projections, wall / trim / accent
colours and (half the time) a middle-floor window rule other than the rule's own; rendered
front-on by bgr's renderer at 260-480 pixels high, cropped to the façade (a few per cent more
or less, as a rectification crops), degraded lightly (wall texture, a shading gradient,
brightness, contrast and colour casts, blur, noise, JPEG) :data:`AUGMENT` times, and each
version run through :func:`~bgr.inverse.image.facade.parse_facade`, whose parse the features
are computed on: the classifier learns what the parse makes of each family.

80 % of the renders (all their versions) train, the other 20 % score (no render on both sides).
Logistic regression and a one-hidden-layer perceptron are fitted on the same features
(train_windows.fit) and both reported; the perceptron ships.  Everything is seeded.

Measured (the shipped weights, the defaults; 14 minutes on one core of a loaded two-core
machine, nearly all of it the parses): held-out perceptron 0.812 of 288 parses, logistic
regression 0.767; with the fallback 0.80 keep their family, 0.905 of those right.  On 784
renders of another run (``--renders 50`` with one version a render; the first of each family
left out, it is also in this run's) 0.80.  ``--renders 25`` runs in 9 minutes and scores 0.72
on those.  ``--cmp DIR`` prints the families picked on the CMP façades instead.
"""

from __future__ import annotations

import argparse
import gzip
import io
import pickle
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image, ImageFilter

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

from train_windows import _hsv, _smooth_noise, fit, wall_colour  # noqa: E402

SEED = 53
AUGMENT = 2  # degraded versions of each render
HIDDEN = 128
EPOCHS = 300
DECAY = 3e-3

TEMPLATE = """version 1
import stdlib.facade as fac
import stdlib.window as win
terminal Wall
attr W = 15
attr H = 12
attr fh = 3.2
attr tw = 3
attr ww = 1.2
attr wh = 1.6
attr sh = 0.9
attr mg = 0.5
attr gh = 4
attr th = 2.4
attr dw = 1.6
attr dh = 2.8
attr pj = 0.4
attr wc = "#c0a080"
attr tc = "#e0d8c8"
attr ac = "#a08060"
Lot --> s(W, 0, 0.3) extrude(H) comp(f) { front: CALL | all: NIL }
"""

WINDOWS = ("Plain", "Sill", "TwoPane", "Pediment", "SillLintel", "Arched")
"""Middle-floor window rules drawn instead of the rule's own half the time."""


def call(rule: str, window: str) -> str:
    from bgr.inverse.image.facade_style import DOOR, GROUND, TOP

    args = ["floor_h = fh", "tile_w = tw", "win_w = ww", "win_h = wh", "sill_h = sh"]
    args += ["margin = mg", "wall_color = wc"]
    if rule not in ("Grid", "CentralBalconies", "Symmetric"):
        args.append("trim_color = tc")
    if rule in GROUND:
        args.append("ground_h = gh")
    if rule in TOP:
        args.append("top_h = th")
    if rule in DOOR:
        args += ["door_w = dw", "door_h = dh"]
    if rule in ("Pavilions", "Risalit", "Manor"):
        args.append("proj = pj")
    if rule in ("Pavilions", "Symmetric"):
        args.append("accent_color = ac")
    if window:
        args.append(f"window = win.{window}")
    return f"fac.{rule}({', '.join(args)})"


def sample(rule: str, rng: np.random.Generator) -> tuple[str, dict]:
    """(window rule or "" for the rule's own, attrs) of one random instance of ``rule``."""
    from bgr.inverse.image.facade_style import BANDS, CENTRE, GROUND, TOP

    fh = rng.uniform(2.8, 3.8)
    wh = fh * rng.uniform(0.38, 0.58)
    tw = rng.uniform(2.4, 3.8)
    a: dict[str, Any] = {
        "fh": fh,
        "tw": tw,
        "ww": tw * rng.uniform(0.33, 0.55),
        "wh": wh,
        "sh": min(rng.uniform(0.5, 1.0), fh - wh - 0.4),
        "mg": rng.uniform(0.5, 1.0) if rule in ("Quoined", "Palazzo") else rng.uniform(0.2, 1.0),
        "gh": rng.uniform(3.6, 5.0),
        "th": rng.uniform(1.9, 2.8),
        "dw": rng.uniform(1.2, 2.2),
        "pj": rng.uniform(0.2, 0.6),
        "wc": wall_colour(rng),
        "tc": _hsv(rng, (0.05, 0.15), (0.0, 0.3), (0.55, 0.95)),
        "ac": wall_colour(rng),
    }
    a["dh"] = rng.uniform(2.4, min(3.4, a["gh"] - 0.4))
    cols = int(rng.choice([3, 5, 7])) if rule in CENTRE else int(rng.integers(3, 9))
    own = (rule in GROUND) + (rule in TOP)
    mids = int(rng.integers(1, 5)) if own else int(rng.integers(2, 7))
    a["W"] = 2 * min(a["mg"], 100.0) + cols * tw
    a["H"] = BANDS[rule] + a["gh"] * (rule in GROUND) + a["th"] * (rule in TOP) + mids * fh
    window = str(rng.choice(WINDOWS)) if rng.random() < 0.5 else ""
    return window, a


class Renderer:
    """Each (rule, window) grammar loaded once."""

    def __init__(self) -> None:
        import bgr

        self.bgr = bgr
        self.grammars: dict[tuple[str, str], object] = {}

    def render(self, rule: str, window: str, attrs: dict, px_per_m: float) -> np.ndarray:
        """The façade front-on, cropped to its wall: (h, w, 3) uint8."""
        from bgr.render import Camera, image_of, load_scene, rasterise

        key = (rule, window)
        if key not in self.grammars:
            self.grammars[key] = self.bgr.load(TEMPLATE.replace("CALL", call(rule, window)))
        result = self.bgr.derive(self.grammars[key], attrs=attrs)
        scene = load_scene(result)
        w, h = attrs["W"], attrs["H"]
        pad = 0.08 * max(w, h)
        lo, hi = np.array([-pad, -pad, 0.0]), np.array([w + pad, h + pad, 0.0])
        size = (int((w + 2 * pad) * px_per_m), int((h + 2 * pad) * px_per_m))
        camera = Camera.preset("front", lo, hi, size, front=scene.front)
        frame = rasterise(scene, camera, "auto")
        shaded, _ = image_of(frame, scene, "shaded")
        px, _ = camera.project(np.array([[0.0, 0.0, 0.0], [w, h, 0.0]]))
        x0, x1 = sorted(px[:, 0])
        y0, y1 = sorted(px[:, 1])
        return np.asarray(shaded)[..., :3], np.array([y0, x0, y1, x1])


def degrade(rng: np.random.Generator, image: np.ndarray, box: np.ndarray) -> np.ndarray:
    """A lightly degraded crop of the façade ``box`` (top, left, bottom, right) of ``image``."""
    bh, bw = box[2] - box[0], box[3] - box[1]
    jitter = rng.uniform(-0.03, 0.03, 4) * np.array([bh, bw, bh, bw])
    t, le, b, r = (int(round(v)) for v in box + jitter)
    h, w = image.shape[:2]
    x = image[max(0, t) : min(h, b), max(0, le) : min(w, r)].astype(np.float32) / 255.0
    h, w = x.shape[:2]
    x *= (1 + rng.uniform(0.0, 0.06) * _smooth_noise(rng, (h, w), 8))[:, :, None]
    yy, xx = np.mgrid[0:h, 0:w] / max(h, w)
    x *= (1 + rng.uniform(-0.2, 0.2) * (xx - 0.5) + rng.uniform(-0.2, 0.2) * (yy - 0.5))[:, :, None]
    x = np.clip(x * rng.uniform(0.75, 1.15) + rng.uniform(-0.06, 0.06), 0, 1)
    x = np.clip((x - 0.5) * rng.uniform(0.75, 1.2) + 0.5, 0, 1) ** rng.uniform(0.8, 1.25)
    x = np.clip(x * (1 + rng.normal(0, 0.04, 3)), 0, 1)
    pil = Image.fromarray((x * 255).astype(np.uint8))
    if rng.random() < 0.7:
        pil = pil.filter(ImageFilter.GaussianBlur(rng.uniform(0.3, 1.2)))
    if rng.random() < 0.6:
        buf = io.BytesIO()
        pil.save(buf, format="JPEG", quality=int(rng.integers(40, 92)))
        pil = Image.open(io.BytesIO(buf.getvalue())).convert("RGB")
    out = np.asarray(pil, dtype=np.float32) + rng.normal(0, rng.uniform(0, 5), (h, w, 3))
    return np.clip(out, 0, 255).astype(np.uint8)


def make_data(renders: int, seed: int) -> tuple[list, np.ndarray, np.ndarray]:
    """([(parse, photo reduced to 96 rows)], labels, render ids): the parses, not the features,
    so that the features can change without rendering again."""
    from bgr.inverse.image.facade import parse_facade
    from bgr.inverse.image.facade_style import RULES

    renderer = Renderer()
    out, labels, ids = [], [], []
    start = time.time()
    for r, rule in enumerate(RULES):
        rng = np.random.default_rng([seed, r])
        for i in range(renders):
            window, attrs = sample(rule, rng)
            px = rng.uniform(260, 480) / max(attrs["H"], 0.6 * attrs["W"])
            image, box = renderer.render(rule, window, attrs, px)
            for _ in range(AUGMENT):
                photo = degrade(rng, image, box)
                parse = parse_facade(photo)
                small = Image.fromarray(photo).resize(
                    (max(8, round(photo.shape[1] * 96 / photo.shape[0])), 96),
                    Image.Resampling.BILINEAR,
                )
                out.append((parse, np.asarray(small)))
                labels.append(r)
                ids.append(r * renders + i)
        print(f"  {rule:16s} {renders} renders, {time.time() - start:.0f} s", flush=True)
    return out, np.array(labels), np.array(ids)


def confusion(pred: np.ndarray, y: np.ndarray, rules: tuple[str, ...]) -> None:
    k = len(rules)
    table = np.zeros((k, k), dtype=np.int64)
    np.add.at(table, (y, pred), 1)
    print("confusion (rows: true, columns: predicted)")
    print(" " * 17 + " ".join(f"{r[:4]:>4s}" for r in rules) + "  recall")
    for i, rule in enumerate(rules):
        recall = table[i, i] / max(table[i].sum(), 1)
        print(f"{rule:17s}" + " ".join(f"{c:4d}" for c in table[i]) + f"  {recall:.2f}")
    pairs = [(table[i, j], rules[i], rules[j]) for i in range(k) for j in range(k) if i != j]
    pairs.sort(reverse=True)
    print("largest confusions: " + ", ".join(f"{a} -> {b} {c}" for c, a, b in pairs[:8]))


def cmp_histogram(folder: Path, weights: str) -> None:
    """The families picked on the CMP façades (``cmp_b*.jpg``; research use, never committed):
    there is no truth to score against, only the spread."""
    from bgr.inverse.image.facade import parse_facade
    from bgr.inverse.image.facade_style import RULES, classify, facade_style

    top: dict[str, int] = {}
    kept: dict[str, int] = {}
    photos = sorted(folder.glob("cmp_b*.jpg"))
    start = time.time()
    for path in photos:
        rgb = np.asarray(Image.open(path).convert("RGB"))
        parse = parse_facade(rgb)
        best, p = next(iter(classify(parse, rgb, weights).items()))
        top[best] = top.get(best, 0) + 1
        final = facade_style(parse, rgb, weights=weights)[0]
        kept[final] = kept.get(final, 0) + 1
    print(f"CMP: {len(photos)} façades, {time.time() - start:.0f} s")
    print(f"{'family':17s} likeliest  written (after the fallback)")
    for rule in RULES:
        print(f"{rule:17s} {top.get(rule, 0):9d}  {kept.get(rule, 0):7d}")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--renders", type=int, default=45, help="renders per rule")
    parser.add_argument("--out", default=str(ROOT / "inverse/image/facade_styles.npz"))
    parser.add_argument("--cache", default="", help="a .pkl.gz to keep the parses in")
    parser.add_argument("--cmp", default="", help="only print the families picked on CMP")
    args = parser.parse_args(argv)
    if args.cmp:
        cmp_histogram(Path(args.cmp), args.out)
        return

    from bgr.inverse.image.facade_style import RATIO, RULES, THRESHOLD, features
    from bgr.inverse.image.windows import predict_proba

    cache = Path(args.cache) if args.cache else None
    if cache is not None and cache.exists():
        with gzip.open(cache, "rb") as fh:
            data, y, ids = pickle.load(fh)
    else:
        print(f"rendering {args.renders} x {len(RULES)} façades, {AUGMENT} versions each")
        data, y, ids = make_data(args.renders, SEED)
        if cache is not None:
            with gzip.open(cache, "wb") as fh:
                pickle.dump((data, y, ids), fh)
    x = np.stack([features(parse, small) for parse, small in data])
    held = np.random.default_rng(SEED).permutation(ids.max() + 1)[: (ids.max() + 1) // 5]
    test = np.isin(ids, held)
    print(f"{(~test).sum()} training parses, {test.sum()} held-out parses ({x.shape[1]} features)")
    start = time.time()
    linear = fit(x[~test], y[~test], len(RULES), 0, SEED, epochs=EPOCHS)
    acc = (predict_proba(x[test], linear).argmax(axis=1) == y[test]).mean()
    print(f"logistic regression ({time.time() - start:.0f} s): held-out accuracy {acc:.3f}")
    start = time.time()
    mlp = fit(x[~test], y[~test], len(RULES), HIDDEN, SEED, epochs=EPOCHS, decay=DECAY)
    p = predict_proba(x[test], mlp)
    pred = p.argmax(axis=1)
    acc = (pred == y[test]).mean()
    print(f"perceptron, {HIDDEN} tanh units ({time.time() - start:.0f} s): held-out {acc:.3f}")
    sure = (p.max(axis=1) >= THRESHOLD) & (p.max(axis=1) >= RATIO * p[:, 0])
    written = np.where(sure, pred, 0)
    print(
        f"with the fallback (p >= {THRESHOLD} and >= {RATIO} x Grid's): {sure.mean():.2f} of the "
        f"held-out parses keep their family, {(pred[sure] == y[test][sure]).mean():.3f} of those "
        f"right; the family written is right for {(written == y[test]).mean():.3f}"
    )
    confusion(pred, y[test], RULES)
    arrays: dict[str, Any] = {k: v.astype(np.float32) for k, v in mlp.items()}
    np.savez_compressed(args.out, rules=np.array(RULES), **arrays)
    print(f"wrote {args.out} ({Path(args.out).stat().st_size // 1024} KB)")


if __name__ == "__main__":
    main()
