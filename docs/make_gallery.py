"""Render the README gallery and the standard-library thumbnails with bgr's own renderer.

    python docs/make_gallery.py     # everything: examples, thumbnails, contact sheet, stdlib.md
    python docs/make_gallery.py --only examples

Writes docs/img/examples/*.png (the examples, as the README shows them, and retarget.png: the
regular façade through bgr retarget), one thumbnail per public
stdlib rule in docs/img/stdlib/<module>/<Rule>.png, a contact sheet of them all
(docs/img/stdlib/contact_sheet.png) and docs/stdlib.md.  Deterministic: the same code gives the
same pictures.  PNGs are palette-quantised to keep the repository small.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

import bgr
from bgr.grammar.stdlib_reference import MODULES, public_rules, stdlib_markdown, thumbnail_path
from bgr.render import load_scene, render, save_png
from bgr.render.camera import Camera, fit, rotation_from_angles

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
THUMB = (240, 180)
EXAMPLE_SIZE = (640, 480)

# (file, lot, seed, view) of each example in the README gallery; a view is a preset name or the
# (yaw, pitch) of a camera fitted to the model
EXAMPLES = [
    ("house.bgr", None, 3, "iso"),
    ("tower.bgr", None, 1, "iso"),
    ("l_building.bgr", "l_lot.geojson", 1, (35.0, 30.0)),  # from behind: the L's inner corner
    ("city_block.bgr", None, 2, "iso"),
    ("stdlib_street.bgr", "block.geojson", 5, "iso"),
    ("textured_house.bgr", None, 3, "iso"),
]

# How a thumbnail shows each module's rules: a wrapper rule applying lib.NAME, and the view.
WRAPPERS = {
    "mass": (None, "iso"),
    "facade": (
        "Lot --> s(14, 0, 1) extrude(11) comp(f) {{ front: lib.{name} | all: NIL }}",
        "front",
    ),
    "window": (
        "Lot --> s(1.4, 0, 1) extrude(2.2) comp(f) {{ front: lib.{name} | all: NIL }}",
        "iso",
    ),
    "roof": (
        'Lot --> s(12, 0, 9) extrude(4) comp(f) {{ top: lib.{name} | side: color("#d8c8a8") W '
        "| all: NIL }}\nterminal W",
        "iso",
    ),
}
ENTRANCE = "Lot --> s(2.2, 0, 1) extrude(3) comp(f) {{ front: lib.{name} | all: NIL }}"
# stdlib.textured: a wall with the projection its surface rules expect; its roofs on a top face,
# its window in an opening
WRAPPERS["textured"] = (
    "Lot --> s(8, 0, 1) extrude(6) comp(f) {{ front: setupProjection(0, scope.xy, ~2, ~1.2) "
    "lib.{name} | all: NIL }}",
    "front",
)
TEXTURED = {
    "Gable": ("Lot --> s(10, 0, 8) extrude(5) comp(f) {{ top: lib.{name} | all: NIL }}", "iso"),
    "Glazed": (WRAPPERS["window"][0], "front"),
}


def quantised(image: np.ndarray) -> np.ndarray:
    """The image with at most 128 colours: a third of the bytes, no visible change at this size."""
    pic = Image.fromarray(image).quantize(
        colors=128, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE
    )
    return np.asarray(pic.convert("RGB"))


def save(image: np.ndarray, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    save_png(quantised(image), path)


def examples() -> None:
    for name, lot, seed, view in EXAMPLES:
        lot_arg = str(ROOT / "examples" / lot) if lot else None
        scene = load_scene(ROOT / "examples" / name, seed=seed, lot=lot_arg)
        if isinstance(view, tuple):
            lo, hi = scene.bounds()
            view = fit(
                Camera(
                    35.0,
                    rotation_from_angles(view[0], view[1], 0.0),
                    np.zeros(3),
                    (0.0, 0.0),
                    EXAMPLE_SIZE,
                ),
                lo,
                hi,
            )
        image = render(scene, "shaded", view, EXAMPLE_SIZE)
        save(image, DOCS / "img" / "examples" / (Path(name).stem + ".png"))
        print(f"  examples/{name}", file=sys.stderr)


def captured() -> None:
    """examples/captured: the grammar inferred from corner_shop.json re-created at the captured
    size (before) and applied to a longer, taller mass on an L-shaped lot (after), side by side."""
    from bgr.inverse.schema import infer

    folder = ROOT / "examples" / "captured"
    grammar = bgr.load(
        bgr.format_module(infer(folder / "corner_shop.json")), path=folder / "corner_shop.bgr"
    )
    before = render(bgr.derive(grammar, lot=(18, 12)), "shaded", "iso", EXAMPLE_SIZE)
    after = render(
        bgr.derive(grammar, lot=str(folder / "l_lot.geojson"), attrs={"height": 18.8}),
        "shaded",
        "iso",
        EXAMPLE_SIZE,
    )
    save(np.hstack([before, after]), folder / "before_after.png")
    print("  examples/captured/before_after.png", file=sys.stderr)


def retargeted() -> None:
    """examples/boxes/regular_facade.json retargeted to 30 x 20 m, as README's command writes it
    (``bgr retarget ... -o facade.glb``), from the iso view."""
    import tempfile

    from bgr.cli import main as bgr_main

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "facade.glb"
        source = ROOT / "examples" / "boxes" / "regular_facade.json"
        if bgr_main(["retarget", str(source), "--size", "30,20,0.5", "-o", str(out)]) != 0:
            raise SystemExit("bgr retarget failed")
        image = render(load_scene(out), "shaded", "iso", EXAMPLE_SIZE)
    save(image, DOCS / "img" / "examples" / "retarget.png")
    print("  examples/boxes/regular_facade.json retargeted: retarget.png", file=sys.stderr)


def thumbnail(module: str, rule: str) -> np.ndarray:
    template, view = WRAPPERS[module]
    if module == "textured" and rule in TEXTURED:
        template, view = TEXTURED[rule]
    if module == "window" and rule.endswith("Entrance"):
        template = ENTRANCE
    if template is None:  # a mass takes the lot itself
        grammar = bgr.load(
            f"import stdlib.{module} as lib\nLot --> lib.{rule}\n", path=ROOT / "_gallery.bgr"
        )
        result = bgr.derive(grammar, seed=1, lot=(20, 15))
    else:
        src = f"import stdlib.{module} as lib\n{template.format(name=rule)}\n"
        result = bgr.derive(bgr.load(src, path=ROOT / "_gallery.bgr"), seed=1)
    return render(result, "shaded", view, THUMB)


def thumbnails() -> list[tuple[str, str, np.ndarray]]:
    made = []
    for module in MODULES:
        if module not in WRAPPERS:
            continue
        _, rules = public_rules(module)
        for rule, _doc in rules:
            image = thumbnail(module, rule.name)
            save(image, DOCS / thumbnail_path(module, rule.name))
            made.append((module, rule.name, image))
        print(f"  stdlib/{module}.bgr: {len(rules)} thumbnails", file=sys.stderr)
    return made


def contact_sheet(made: list[tuple[str, str, np.ndarray]], columns: int = 10) -> None:
    """All thumbnails on one sheet, each captioned module.Rule, at half size."""
    w, h = THUMB[0] // 2, THUMB[1] // 2
    caption = 14
    rows = -(-len(made) // columns)
    sheet = Image.new("RGB", (columns * w, rows * (h + caption)), "white")
    draw = ImageDraw.Draw(sheet)
    for i, (module, rule, image) in enumerate(made):
        x, y = (i % columns) * w, (i // columns) * (h + caption)
        sheet.paste(Image.fromarray(image).resize((w, h), Image.Resampling.LANCZOS), (x, y))
        draw.text((x + 3, y + h + 1), f"{module}.{rule}"[:22], fill=(40, 40, 40))
    save(np.asarray(sheet), DOCS / "img" / "stdlib" / "contact_sheet.png")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", choices=["examples", "stdlib"], help="render only one part")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    if args.only in (None, "examples"):
        examples()
        captured()
        retargeted()
    if args.only in (None, "stdlib"):
        made = thumbnails()
        contact_sheet(made)
        (DOCS / "stdlib.md").write_text(stdlib_markdown(), encoding="utf-8")
    print(f"done in {time.perf_counter() - start:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
