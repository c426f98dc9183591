"""Train the window style classifier of bgr.inverse.image.windows on renders of the stdlib's own
window rules (issue 28, section 6 of Nishida et al. 2018), report held-out accuracy and the
confusions, and write the weights.

    python bench/train_windows.py [--renders 350] [--out inverse/image/window_styles.npz]

Why renders: the paper annotated 10,000 CMP tiles by hand; the project has no window-style
annotations, but it has the rules themselves.  Each sample is one window rule of
:data:`bgr.inverse.image.windows.RULES` on a wall tile, its size, proportions and colours (wall,
frame, glass, stone, shutters, railing) and its parameters (panes, bars, arch rise, ...) drawn at
random, rendered front-on by bgr's renderer with the window box projected by the camera.  Each
render gives :data:`AUGMENT` crops, degraded so that crops of photographs look like them: glass
with reflections and curtains, wall texture, a shading gradient, the window resampled to 28-100
pixels high, blur, JPEG compression, noise, brightness / contrast / colour casts, a mirror, and
the box's edges moved by up to 8 % of its size (20 % now and then), as the parse's boxes are.

80 % of the renders (all their crops) train, the other 20 % score (the paper's split; no render
is on both sides).  Two models on the same features are fitted by Adam on the cross-entropy
with a little weight decay: multinomial logistic regression and a one-hidden-layer perceptron;
both are reported, the perceptron ships (trained on the 80 %).  Everything is seeded.
"""

from __future__ import annotations

import argparse
import colorsys
import io
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image, ImageFilter

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

SEED = 28
AUGMENT = 3  # crops per render
HIDDEN = 256
EPOCHS = 150
BATCH = 256
PX_PER_M = 60  # render resolution

TEMPLATE = """version 1
import stdlib.window as win
terminal Wall
attr W = 3
attr H = 3
attr ww = 1.2
attr wh = 1.6
attr sh = 0.7
attr wc = "#c0a080"
attr fc = "#ffffff"
attr gc = "#3b4a5a"
attr sc = "#e4ddd0"
attr oc = "#3d6b4f"
attr p1 = 0.1
attr p2 = 0.5
attr n1 = 2
attr n2 = 1
Lot --> s(W, 0, 0.3) extrude(H) comp(f) {
    front: color(wc) split(y) {
        sh: Wall
        | wh: split(x) { ~1: Wall | ww: WINDOW | ~1: Wall }
        | ~1: Wall
    }
    | all: NIL
}
"""

_COLOURS = "frame_color = fc, glass_color = gc"
INNER = {
    "Plain": "win.Plain",
    "TwoPane": "win.TwoPane",
    "Cross": "win.Cross",
    "Sash": "win.Sash",
}
"""The windows a decorated rule (shutters, balconies) is drawn round, at their defaults."""

CALLS = {
    "Plain": f"win.Plain(frame = p1, {_COLOURS})",
    "TwoPane": f"win.TwoPane(frame = p1, {_COLOURS})",
    "ThreePane": f"win.ThreePane(side = p2, frame = p1, {_COLOURS})",
    "Cross": f"win.Cross(mullion = p1, transom = p2, stone_color = sc, {_COLOURS})",
    "Transom": f"win.Transom(panes = n1, frame = p1, {_COLOURS})",
    "Sash": f"win.Sash(cols = n1, rows = n2, frame = p1, {_COLOURS})",
    "Georgian": f"win.Georgian(cols = n1, rows = n2, stone_color = sc, {_COLOURS})",
    "Arched": f"win.Arched(frame = p1, {_COLOURS})",
    "Segmental": f"win.Segmental(frame = p1, {_COLOURS})",
    "Oculus": f"win.Oculus(trim = p1, stone_color = sc, {_COLOURS})",
    "Shutters": "win.Shutters(window = INNER, shutter_color = oc)",
    "FrenchBalcony": "win.FrenchBalcony(window = INNER, height = p2, railing_color = oc)",
    "Balcony": "win.Balcony(window = INNER, overhang = p1, height = p2, slab_color = sc, "
    "railing_color = oc)",
    "Louvre": "win.Louvre(slat = p1, angle = p2, frame_color = fc, louvre_color = oc)",
}
DECORATED = ("Shutters", "FrenchBalcony", "Balcony")


def _hex(rgb: tuple[float, float, float]) -> str:
    return "#" + "".join(f"{int(np.clip(c, 0, 1) * 255):02x}" for c in rgb)


def _hsv(rng: np.random.Generator, h: tuple, s: tuple, v: tuple) -> str:
    return _hex(colorsys.hsv_to_rgb(rng.uniform(*h), rng.uniform(*s), rng.uniform(*v)))


def wall_colour(rng: np.random.Generator) -> str:
    kind = rng.random()
    if kind < 0.55:  # render, stone: pale, warm or grey
        return _hsv(rng, (0.02, 0.16), (0.0, 0.35), (0.55, 0.95))
    if kind < 0.75:  # brick
        return _hsv(rng, (0.0, 0.06), (0.35, 0.7), (0.35, 0.7))
    if kind < 0.9:  # grey, concrete, dark
        return _hsv(rng, (0.0, 1.0), (0.0, 0.12), (0.3, 0.8))
    return _hsv(rng, (0.0, 1.0), (0.1, 0.45), (0.5, 0.95))  # painted


def frame_colour(rng: np.random.Generator) -> str:
    kind = rng.random()
    if kind < 0.5:
        return _hsv(rng, (0.0, 1.0), (0.0, 0.06), (0.82, 1.0))
    if kind < 0.7:
        return _hsv(rng, (0.0, 1.0), (0.0, 0.15), (0.12, 0.45))
    if kind < 0.85:
        return _hsv(rng, (0.04, 0.1), (0.4, 0.8), (0.2, 0.5))  # timber
    return _hsv(rng, (0.0, 1.0), (0.2, 0.6), (0.25, 0.7))


def sample(rule: str, rng: np.random.Generator) -> tuple[str, dict]:
    """(inner window or "", attrs) of one random instance of ``rule``."""
    ww = rng.uniform(0.7, 1.6)
    wh = ww * rng.uniform(1.1, 2.0)
    attrs: dict = {
        "wc": wall_colour(rng),
        "fc": frame_colour(rng),
        "gc": _hsv(rng, (0.5, 0.7), (0.05, 0.4), (0.08, 0.45)),
        "sc": _hsv(rng, (0.05, 0.15), (0.0, 0.25), (0.6, 0.95)),
        "oc": _hsv(rng, (0.0, 1.0), (0.0, 0.5), (0.1, 0.35)),
        "p1": rng.uniform(0.03, 0.08),
        "p2": 0.5,
        "n1": 2,
        "n2": 1,
    }
    inner = ""
    if rule == "ThreePane":
        ww = rng.uniform(1.4, 2.6)
        wh = ww * rng.uniform(0.6, 1.1)
        attrs["p2"] = rng.uniform(0.18, 0.3)
    elif rule == "Cross":
        attrs.update(p1=rng.uniform(0.06, 0.13), p2=rng.uniform(0.6, 0.75))
    elif rule == "Transom":
        attrs["n1"] = int(rng.integers(1, 5))
    elif rule == "Sash":
        attrs.update(n1=int(rng.integers(1, 4)), n2=int(rng.integers(1, 3)))
    elif rule == "Georgian":
        attrs.update(n1=int(rng.integers(2, 4)), n2=int(rng.integers(2, 4)))
        wh = ww * rng.uniform(1.4, 2.0)
    elif rule in ("Arched", "Segmental"):
        wh = ww * rng.uniform(1.4, 2.4)
    elif rule == "Oculus":
        ww = rng.uniform(0.6, 1.2)
        wh = ww * rng.uniform(0.95, 1.05)
        attrs["p1"] = rng.uniform(0.06, 0.14)
    elif rule == "Shutters":
        inner = str(rng.choice(list(INNER)))
        attrs["oc"] = _hsv(rng, (0.0, 1.0), (0.0, 0.6), (0.15, 0.9))
    elif rule in ("FrenchBalcony", "Balcony"):
        inner = str(rng.choice(list(INNER)))
        wh = ww * rng.uniform(1.6, 2.4)
        attrs.update(p1=rng.uniform(0.15, 0.4), p2=wh * rng.uniform(0.3, 0.5))
        attrs["oc"] = _hsv(rng, (0.0, 1.0), (0.0, 0.3), (0.05, 0.3))
    elif rule == "Louvre":
        attrs.update(p1=rng.uniform(0.06, 0.15), p2=rng.uniform(30, 60))
        attrs["oc"] = _hsv(rng, (0.0, 1.0), (0.0, 0.4), (0.3, 0.9))
    side = rng.uniform(0.5, 1.2) + (ww * 0.5 if rule == "Shutters" else 0)
    attrs.update(
        ww=ww,
        wh=wh,
        sh=rng.uniform(0.6, 1.0),
        W=ww + 2 * side,
        H=0.0,
    )
    attrs["H"] = attrs["sh"] + wh + rng.uniform(0.6, 1.0)
    # where the camera looks from: a façade's width and height round the window, the window
    # anywhere in it, so that its reveals are seen at an angle as in a photograph
    span = (rng.uniform(2.5, 7.0), rng.uniform(2.5, 7.0))
    attrs["_view"] = (
        rng.uniform(-1, 1) * (span[0] - ww / 2 - 0.3),
        rng.uniform(-1, 1) * (span[1] - wh / 2 - 0.3),
        *span,
    )
    return inner, attrs


class Renderer:
    """The grammars of every (rule, inner window) loaded once; a sample then derives in
    milliseconds (loading one costs most of a second)."""

    def __init__(self) -> None:
        import bgr

        self.bgr = bgr
        self.grammars: dict[tuple[str, str], object] = {}

    def grammar(self, rule: str, inner: str) -> object:
        key = (rule, inner)
        if key not in self.grammars:
            call = CALLS[rule].replace("INNER", INNER.get(inner, ""))
            self.grammars[key] = self.bgr.load(TEMPLATE.replace("WINDOW", call))
        return self.grammars[key]

    def render(
        self, rule: str, inner: str, attrs: dict
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(shaded image, glass mask, window box (top, left, bottom, right)) of one sample."""
        from bgr.render import Camera, image_of, load_scene, rasterise

        view = attrs.get("_view", (0.0, 0.0, attrs["W"] / 2, attrs["H"] / 2))
        grammar_attrs = {k: v for k, v in attrs.items() if not k.startswith("_")}
        result = self.bgr.derive(self.grammar(rule, inner), attrs=grammar_attrs)
        scene = load_scene(result)
        w = attrs["W"]
        # the camera framed on a box of the view's size round a point off the window's centre,
        # whatever projects from the wall
        cx, cy = w / 2 + view[0], attrs["sh"] + attrs["wh"] / 2 + view[1]
        lo = np.array([cx - view[2], cy - view[3], 0.0])
        hi = np.array([cx + view[2], cy + view[3], 0.12])
        size = (int(2 * view[2] * PX_PER_M), int(2 * view[3] * PX_PER_M))
        camera = Camera.preset("front", lo, hi, size, front=scene.front)
        frame = rasterise(scene, camera, "auto")
        shaded, _ = image_of(frame, scene, "shaded")
        labels, legend = image_of(frame, scene, "labels")
        assert legend is not None
        glass = np.zeros(labels.shape[:2], dtype=bool)
        code = legend["labels"].get("Glass")
        if code is not None:
            rgb = [int(code[i : i + 2], 16) for i in (1, 3, 5)]
            glass = (labels == rgb).all(axis=2)
        x0 = (w - attrs["ww"]) / 2
        y0 = attrs["sh"]
        corners = np.array([[x0, y0, 0.0], [x0 + attrs["ww"], y0 + attrs["wh"], 0.0]])
        px, _ = camera.project(corners)
        box = np.array([px[:, 1].min(), px[:, 0].min(), px[:, 1].max(), px[:, 0].max()])
        # only the box and half its size round it can reach a crop: the rest is not degraded
        bh, bw = box[2] - box[0], box[3] - box[1]
        t, le = int(max(0, box[0] - bh / 2)), int(max(0, box[1] - bw / 2))
        b, r = int(box[2] + bh / 2) + 1, int(box[3] + bw / 2) + 1
        box = box - np.array([t, le, t, le])
        return np.asarray(shaded)[t:b, le:r], glass[t:b, le:r], box


def _smooth_noise(rng: np.random.Generator, shape: tuple[int, int], scale: int) -> np.ndarray:
    small = rng.normal(size=(max(2, shape[0] // scale), max(2, shape[1] // scale)))
    img = Image.fromarray(small.astype(np.float32), mode="F").resize(
        (shape[1], shape[0]), Image.Resampling.BICUBIC
    )
    return np.asarray(img)


def _courses(rng: np.random.Generator, x: np.ndarray, box: np.ndarray) -> np.ndarray:
    """``x`` with mortar joints outside the box: horizontal courses (brick, ashlar, rustication)
    and, for brick, staggered vertical joints; a photo's horizontal wall texture is no louvre."""
    h, w = x.shape[:2]
    period = rng.uniform(4, 30)
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float64)
    phase = rng.uniform(0, period)
    joint = ((yy + phase) % period) < max(1.0, period * rng.uniform(0.08, 0.2))
    if period < 10 and rng.random() < 0.7:
        course = np.floor((yy + phase) / period)
        length = period * rng.uniform(2.5, 3.5)
        joint |= ((xx + course * length / 2) % length) < 1.0
    outside = ~((yy >= box[0] - 2) & (yy <= box[2] + 2) & (xx >= box[1] - 2) & (xx <= box[3] + 2))
    dark = 1 - rng.uniform(0.1, 0.35) * (joint & outside)
    return x * dark[:, :, None]


def augment(
    rng: np.random.Generator, image: np.ndarray, glass: np.ndarray, box: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(degraded image as uint8, jittered box in its pixels): one photo-like version."""
    x = image.astype(np.float32) / 255.0
    h, w = glass.shape
    # glass: reflections of sky and buildings, curtains; wall: texture and stains
    g = glass[:, :, None]
    reflect = rng.uniform(0.6, 2.2) * (1 + rng.uniform(0.05, 0.45) * _smooth_noise(rng, (h, w), 12))
    tint = 1 + rng.normal(0, 0.08, 3)
    lit = np.clip(x * reflect[:, :, None] * tint, 0, 1)
    if rng.random() < 0.15:  # a pale curtain behind part of the glass
        curtain = rng.uniform(0.55, 0.9)
        lit = np.where(
            _smooth_noise(rng, (h, w), 20)[:, :, None] > rng.uniform(-0.3, 0.8), curtain, lit
        )
    if rng.random() < 0.2:  # a roller blind half down behind the glass
        rows = np.arange(h)[:, None] < box[0] + rng.uniform(0.15, 0.7) * (box[2] - box[0])
        blind = np.clip(rng.uniform(0.5, 0.95) * (1 + rng.normal(0, 0.05, 3)), 0, 1)
        lit = np.where(rows[:, :, None], blind, lit)
    x = np.where(g, lit, x)
    if rng.random() < 0.4:  # brick or stone courses on the wall round the opening
        x = _courses(rng, x, box)
    wall = 1 + rng.uniform(0.0, 0.08) * _smooth_noise(rng, (h, w), 6)
    x *= wall[:, :, None]
    # a shading gradient across the image
    yy, xx = np.mgrid[0:h, 0:w] / max(h, w)
    x *= (1 + rng.uniform(-0.25, 0.25) * (xx - 0.5) + rng.uniform(-0.25, 0.25) * (yy - 0.5))[
        :, :, None
    ]
    x = np.clip(x * rng.uniform(0.6, 1.25) + rng.uniform(-0.1, 0.1), 0, 1)
    x = np.clip((x - 0.5) * rng.uniform(0.6, 1.3) + 0.5, 0, 1) ** rng.uniform(0.7, 1.4)
    x = np.clip(x * (1 + rng.normal(0, 0.05, 3)), 0, 1)
    # resample so that the window is 28-100 pixels high, blur, JPEG, noise
    scale = rng.uniform(28, 100) / max(box[2] - box[0], 1.0)
    size = (max(8, int(round(w * scale))), max(8, int(round(h * scale))))
    pil = Image.fromarray((x * 255).astype(np.uint8)).resize(size, Image.Resampling.BILINEAR)
    if rng.random() < 0.6:
        pil = pil.filter(ImageFilter.GaussianBlur(rng.uniform(0.2, 1.2)))
    if rng.random() < 0.7:
        buf = io.BytesIO()
        pil.save(buf, format="JPEG", quality=int(rng.integers(25, 90)))
        pil = Image.open(io.BytesIO(buf.getvalue())).convert("RGB")
    out = np.asarray(pil, dtype=np.float32) + rng.normal(
        0, rng.uniform(0, 6), (size[1], size[0], 3)
    )
    out8 = np.clip(out, 0, 255).astype(np.uint8)
    b = box * scale
    bh, bw = b[2] - b[0], b[3] - b[1]
    spread = 0.2 if rng.random() < 0.15 else 0.08
    b = b + rng.uniform(-spread, spread, 4) * np.array([bh, bw, bh, bw])
    if rng.random() < 0.5:
        out8 = out8[:, ::-1].copy()
        b = np.array([b[0], size[0] - b[3], b[2], size[0] - b[1]])
    return out8, b


def make_data(renders: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(crops (n, rows, cols, 3) uint8, box aspects, labels, render ids) of ``renders`` renders of
    each rule, AUGMENT crops each: the crops, not their features, so that features can change
    without rendering again."""
    from bgr.inverse.image.windows import RULES, crops

    renderer = Renderer()
    out, aspects, labels, ids = [], [], [], []
    start = time.time()
    for r, rule in enumerate(RULES):
        rng = np.random.default_rng([seed, r])
        for i in range(renders):
            inner, attrs = sample(rule, rng)
            image, glass, box = renderer.render(rule, inner, attrs)
            for _ in range(AUGMENT):
                degraded, b = augment(rng, image, glass, box)
                out.append(np.rint(crops(degraded, b[None])[0] * 255).astype(np.uint8))
                aspects.append((b[2] - b[0]) / max(b[3] - b[1], 1.0))
                labels.append(r)
                ids.append(r * renders + i)
        print(f"  {rule:14s} {renders} renders, {time.time() - start:.0f} s", flush=True)
    return np.array(out), np.array(aspects), np.array(labels), np.array(ids)


def fit(
    x: np.ndarray,
    y: np.ndarray,
    classes: int,
    hidden: int,
    seed: int,
    epochs: int = EPOCHS,
    decay: float = 1e-3,
) -> dict[str, np.ndarray]:
    """A softmax model (hidden = 0: logistic regression) fitted by Adam on standardised x."""
    rng = np.random.default_rng(seed)
    mean = x.mean(axis=0)
    std = x.std(axis=0) + 1e-3
    z = (x - mean) / std
    n, f = z.shape
    params: dict[str, np.ndarray] = {}
    if hidden:
        params["w1"] = rng.normal(0, 1 / np.sqrt(f), (f, hidden))
        params["b1"] = np.zeros(hidden)
        params["w2"] = rng.normal(0, 1 / np.sqrt(hidden), (hidden, classes))
        params["b2"] = np.zeros(classes)
    else:
        params["w1"] = np.zeros((f, classes))
        params["b1"] = np.zeros(classes)
    m = {k: np.zeros_like(v) for k, v in params.items()}
    v = {k: np.zeros_like(p) for k, p in params.items()}
    onehot = np.eye(classes)[y]
    step = 0
    for epoch in range(epochs):
        lr = 2e-3 * (0.5 * (1 + np.cos(np.pi * epoch / epochs))) + 1e-5
        order = rng.permutation(n)
        for s in range(0, n, BATCH):
            idx = order[s : s + BATCH]
            a = z[idx]
            t = onehot[idx]
            pre = a @ params["w1"] + params["b1"]
            if hidden:
                hid = np.tanh(pre)
                logits = hid @ params["w2"] + params["b2"]
            else:
                logits = pre
            logits -= logits.max(axis=1, keepdims=True)
            p = np.exp(logits)
            p /= p.sum(axis=1, keepdims=True)
            d = (p - t) / len(idx)
            grads: dict[str, np.ndarray] = {}
            if hidden:
                grads["w2"] = hid.T @ d
                grads["b2"] = d.sum(axis=0)
                d = (d @ params["w2"].T) * (1 - hid * hid)
            grads["w1"] = a.T @ d
            grads["b1"] = d.sum(axis=0)
            step += 1
            for k in params:
                g = grads[k] + (decay * params[k] if k.startswith("w") else 0)
                m[k] = 0.9 * m[k] + 0.1 * g
                v[k] = 0.999 * v[k] + 0.001 * g * g
                mh = m[k] / (1 - 0.9**step)
                vh = v[k] / (1 - 0.999**step)
                params[k] = params[k] - lr * mh / (np.sqrt(vh) + 1e-8)
    return {"mean": mean, "std": std, **params}


def report(name: str, net: dict, x: np.ndarray, y: np.ndarray, rules: tuple[str, ...]) -> float:
    from bgr.inverse.image.windows import predict_proba

    pred = np.argmax(predict_proba(x, net), axis=1)
    acc = float((pred == y).mean())
    print(f"{name}: held-out accuracy {acc:.3f} ({len(y)} crops)")
    return acc


def confusion(net: dict, x: np.ndarray, y: np.ndarray, rules: tuple[str, ...]) -> None:
    from bgr.inverse.image.windows import predict_proba

    pred = np.argmax(predict_proba(x, net), axis=1)
    k = len(rules)
    table = np.zeros((k, k), dtype=np.int64)
    np.add.at(table, (y, pred), 1)
    short = [r[:5] for r in rules]
    print("confusion (rows: true, columns: predicted)")
    print(" " * 14 + " ".join(f"{s:>5s}" for s in short) + "  recall")
    for i, rule in enumerate(rules):
        recall = table[i, i] / max(table[i].sum(), 1)
        print(f"{rule:14s}" + " ".join(f"{c:5d}" for c in table[i]) + f"  {recall:.2f}")
    pairs = [(table[i, j], rules[i], rules[j]) for i in range(k) for j in range(k) if i != j]
    pairs.sort(reverse=True)
    print("largest confusions: " + ", ".join(f"{a} -> {b} {c}" for c, a, b in pairs[:6]))


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--renders", type=int, default=350, help="renders per rule")
    parser.add_argument("--out", default=str(ROOT / "inverse/image/window_styles.npz"))
    parser.add_argument("--cache", default="", help="an .npz to keep the features in")
    args = parser.parse_args(argv)

    from bgr.inverse.image.windows import RULES, features

    cache = Path(args.cache) if args.cache else None
    if cache is not None and cache.exists():
        data = np.load(cache)
        crop, aspect, y, ids = data["crops"], data["aspect"], data["y"], data["ids"]
    else:
        print(f"rendering {args.renders} x {len(RULES)} windows, {AUGMENT} crops each")
        crop, aspect, y, ids = make_data(args.renders, SEED)
        if cache is not None:
            np.savez_compressed(cache, crops=crop, aspect=aspect, y=y, ids=ids)
    x = np.concatenate(
        [features(crop[i : i + 500] / 255.0, aspect[i : i + 500]) for i in range(0, len(y), 500)]
    )
    held = np.random.default_rng(SEED).permutation(ids.max() + 1)[: (ids.max() + 1) // 5]
    test = np.isin(ids, held)
    print(f"{(~test).sum()} training crops, {test.sum()} held-out crops (renders not trained on)")
    start = time.time()
    linear = fit(x[~test], y[~test], len(RULES), 0, SEED)
    report(f"logistic regression ({time.time() - start:.0f} s)", linear, x[test], y[test], RULES)
    start = time.time()
    mlp = fit(x[~test], y[~test], len(RULES), HIDDEN, SEED)
    report(
        f"perceptron, {HIDDEN} tanh units ({time.time() - start:.0f} s)",
        mlp,
        x[test],
        y[test],
        RULES,
    )
    confusion(mlp, x[test], y[test], RULES)
    arrays: dict[str, Any] = {k: v.astype(np.float32) for k, v in mlp.items()}
    np.savez_compressed(args.out, rules=np.array(RULES), **arrays)
    print(f"wrote {args.out} ({Path(args.out).stat().st_size // 1024} KB)")


if __name__ == "__main__":
    main()
