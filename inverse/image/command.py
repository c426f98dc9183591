"""``bgr infer FACADE.jpg --kind facade -o f.bgr [--label-map L.png]``: a rectified façade
photograph parsed (:mod:`.facade`) and written as a grammar of the stdlib's façade it is likeliest
to be (:mod:`.facade_style`; ``fac.Grid`` when unsure)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from bgr.grammar.errors import BgrError, Diagnostic, terminal_text

from .facade_grid import grid_values

if TYPE_CHECKING:  # the parser pulls in scipy.ndimage: every bgr command's start paid for it
    from .facade import FacadeParse

# the CMP palette's first colours, so that a label map opens in any viewer as CMP's do
PALETTE = [0, 0, 0, 0, 0, 170, 0, 0, 255, 0, 85, 255, 0, 170, 255]


def add_facade_options(infer) -> None:
    group = infer.add_argument_group("--kind facade")
    group.add_argument(
        "--label-map",
        metavar="PNG",
        help="also write the parse as a palette PNG of the photograph's size with the CMP "
        "label ids (2 facade, 3 window)",
    )
    group.add_argument(
        "--floor-height",
        type=float,
        default=3.2,
        metavar="M",
        help="storey height in metres that scales the photograph (default 3.2)",
    )
    image = infer.add_argument_group("--kind image")
    image.add_argument(
        "--silhouette",
        metavar="SIL",
        help="the building's outline in the photograph: a JSON list of [x, y] pixel points or "
        "a mask PNG (white on black)",
    )
    image.add_argument(
        "--preview",
        metavar="PNG",
        help="also write the fitted model rendered over the photograph, with the outline",
    )


def read_photo(path: str) -> np.ndarray:
    """(h, w, 3) uint8 of a photograph (a regular file Pillow reads, at most 8192 x 4096
    pixels as every image bgr reads), or a located error."""
    from PIL import UnidentifiedImageError

    from bgr.grammar.paths import read_input
    from bgr.grammar.textures import open_image

    try:
        data = read_input(path, "photograph")
    except FileNotFoundError:
        raise BgrError(Diagnostic(path, 0, 0, "no such file", "check the path")) from None
    except OSError as exc:
        raise BgrError(
            Diagnostic(path, 0, 0, f"cannot read the photograph: {exc.strerror or exc}", "")
        ) from None
    try:
        with open_image(data) as image:
            rgb = np.asarray(image.convert("RGB"))
    except Exception as exc:  # Pillow raises many kinds for bytes that are no image
        unread = isinstance(exc, UnidentifiedImageError)
        why = "it is not an image Pillow reads" if unread else str(exc)
        raise BgrError(
            Diagnostic(path, 0, 0, f"cannot read the photograph: {why}", "give a JPEG or PNG")
        ) from None
    if min(rgb.shape[:2]) < 16:
        raise BgrError(
            Diagnostic(
                path,
                0,
                0,
                f"the photograph is {rgb.shape[1]} x {rgb.shape[0]} pixels: too small to parse",
                "give a façade photograph at least 16 pixels on each side",
            )
        )
    return rgb


def facade_grammar(
    parse: FacadeParse,
    source: str,
    floor_height: float,
    window: str = "Plain",
    style: tuple[str, dict[str, float]] | None = None,
) -> str:
    """The parse as a grammar: a slab the photograph's size (scaled so that the floors are
    ``floor_height`` metres apart) whose front is the stdlib façade ``style`` = (rule, its
    fitted parameters, :func:`.facade_style.facade_style`), by default ``fac.Grid`` with the
    parse's floors, tiles and windows; with the parse's colour and ``window`` rule (of
    stdlib.window)."""
    from .facade_style import facade_call

    rule, values = style if style is not None else ("Grid", grid_values(parse, floor_height))
    counts = parse.windows_per_floor()
    attrs, call = facade_call(rule, values, parse.color, window)
    lines = [
        f"# {_comment(Path(source).name)}: a façade parsed by bgr infer --kind facade, "
        f"{len(counts)} floors of {', '.join(map(str, counts)) or 'no'} windows",
        f"# (scaled so that its floors are {floor_height:g} m apart)",
        "version 1",
        "",
        "import stdlib.facade as fac",
        "import stdlib.window as win",
        "",
        *(f"attr {k} = {values[k]:.3f}".rstrip("0").rstrip(".") for k in ("width", "height")),
        *attrs,
        "",
        "Lot --> s(width, 0, 0.3) extrude(height) "
        "comp(f) { front: Facade | all: color(wall_color) }",
        f"Facade --> {call}",
    ]
    from bgr.grammar.formatter import format_source

    return format_source("\n".join(lines) + "\n")


def _comment(text: str) -> str:
    return terminal_text(text, keep="").replace("\n", " ")


def run_facade(args) -> int:
    from PIL import Image

    from bgr.formats.atomic import atomic_files, write_text

    if not args.floor_height > 0 or not np.isfinite(args.floor_height):
        print("bgr infer: --floor-height must be a positive number of metres", file=sys.stderr)
        return 2
    from bgr.grammar.paths import check_output

    for target in (args.output, args.label_map):
        if target not in (None, "-"):
            check_output(target)
    from .facade_style import describe, facade_style
    from .windows import window_style

    photo = read_photo(args.input)
    from .facade import parse_facade

    parse = parse_facade(photo)
    window, _ = window_style(photo, parse.windows)
    rule, values, proba = facade_style(parse, photo, args.floor_height)
    text = facade_grammar(parse, args.input, args.floor_height, window, (rule, values))
    if args.label_map:
        labels = Image.fromarray(parse.label_map(), mode="P")
        labels.putpalette(PALETTE)
        with atomic_files([Path(args.label_map)]) as (out,):
            labels.save(out, format="PNG")
    if args.output in (None, "-"):
        sys.stdout.write(text)
    else:
        write_text(Path(args.output), text)
    counts = parse.windows_per_floor()
    print(
        f"{terminal_text(args.input, keep='')}: {len(counts)} floors, "
        f"{sum(counts)} windows of win.{window}, façade {describe(rule, proba)}, colour "
        f"#{'{:02x}{:02x}{:02x}'.format(*parse.color)}",
        file=sys.stderr,
    )
    return 0
