"""``bgr infer --kind style`` and ``bgr restyle``: the command-line side (options, paths,
all-or-nothing writing)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from bgr.grammar.errors import terminal_text
from bgr.grammar.safe_text import comment_text, unwritable

USAGE = 2
MAX_TEXTURE_SIZE = 512


def _positive(text: str) -> int:
    import argparse

    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
    if not 1 <= value <= 16384:
        raise argparse.ArgumentTypeError("must be 1 to 16384 pixels")
    return value


def add_infer_options(infer) -> None:
    """The ``--kind style`` options of ``bgr infer``."""
    style = infer.add_argument_group("--kind style")
    style.add_argument(
        "--building",
        metavar="ID",
        help="capture this building (a CityGML gml:id; an OBJ object or glTF node) only; by "
        "default every textured building of a CityGML file gets its own section, and an OBJ "
        "or glTF model is one building",
    )
    style.add_argument(
        "--max-texture-size",
        type=_positive,
        default=MAX_TEXTURE_SIZE,
        metavar="PX",
        help=f"each texture crop at most PX pixels a side (default {MAX_TEXTURE_SIZE})",
    )


def add_restyle_parser(commands, allow_help: str, add_memory_option) -> None:
    restyle = commands.add_parser(
        "restyle",
        help="decorate an untextured mass with a captured style sheet",
        description="Put a style sheet (bgr infer --kind style) on a mass model "
        "(docs/inverse-style.md): the mass's blocks are found by their floor areas (section "
        "4.2 of Zhang et al. 2013), each takes the source block that costs least to stretch "
        "onto it (equations 6-7; the bottom and top blocks take the source's bottom and top), "
        "and its walls are split by the sheet's rules.",
    )
    restyle.add_argument("input", metavar="MASS", help="the mass: .glb, .gltf or .obj")
    restyle.add_argument("--style", required=True, metavar="STYLE.bgr", help="the style sheet")
    restyle.add_argument(
        "-o", "--output", required=True, metavar="OUT", help="the styled model (.glb, .obj, ...)"
    )
    restyle.add_argument("--seed", type=int, default=0, help="derivation seed (default 0)")
    restyle.add_argument(
        "--section",
        type=int,
        default=0,
        metavar="N",
        help="which captured building of a style sheet that holds several (its attr style; "
        "default 0, the first)",
    )
    restyle.add_argument(
        "--allow-path", action="append", default=[], metavar="DIR", help=allow_help
    )
    add_memory_option(restyle)


def _assets_dir(args, output: Path | None) -> Path:
    if args.assets:
        return Path(args.assets)
    if output is not None:
        stem = output.name[: -len(".bgr")] if output.name.endswith(".bgr") else output.name
        return output.with_name(stem + ".assets")
    return Path("style.assets")


def run_infer(args) -> int:
    """``bgr infer MODEL --kind style [-o STYLE.bgr] [--assets DIR]``."""
    from bgr.formats.assets_folder import assets_written
    from bgr.formats.atomic import write_text
    from bgr.inverse.city.command import check_outputs

    from .capture import infer_style

    output = None if args.output in (None, "-") else Path(args.output)
    assets_dir = _assets_dir(args, output)
    check_outputs(output, assets_dir, Path(args.input))  # before the capture
    base = output.parent if output is not None else Path(".")
    named = Path(os.path.relpath(assets_dir.resolve(), base.resolve())).as_posix()
    if unwritable(named):
        print(
            f"bgr infer: the assets folder {comment_text(named)} holds {unwritable(named)}, "
            "which a grammar cannot name: choose another with --assets DIR",
            file=sys.stderr,
        )
        return USAGE
    text, files, captured = infer_style(
        args.input, args.building, assets=named, max_texture_size=args.max_texture_size
    )
    keep = (Path(args.input), *(() if output is None else (output,)))
    with assets_written(assets_dir, files, keep=keep, written_by="bgr infer --kind style"):
        if output is None:
            sys.stdout.write(text)
        else:
            write_text(output, text)
    faces = sum(len(c.capture.faces) for c in captured)
    textured = sum(f.texture is not None for c in captured for f in c.capture.faces)
    blocks = sum(len(c.capture.blocks) for c in captured)
    wrote = "" if output is None else f"; wrote {terminal_text(str(output), keep='')}"
    print(
        f"{terminal_text(args.input, keep='')}: {len(captured)} buildings, {blocks} blocks, "
        f"{faces} faces ({textured} textured){wrote} and {len(files)} texture crops in "
        f"{terminal_text(str(assets_dir), keep='')}",
        file=sys.stderr,
    )
    return 0


def run_restyle(args) -> int:
    """``bgr restyle MASS --style STYLE.bgr -o OUT``."""
    from .restyle import restyle

    result, report = restyle(
        args.input, args.style, seed=args.seed, section=args.section, allow_paths=args.allow_path
    )
    result.save(args.output)
    print(
        f"{terminal_text(args.output, keep='')}: {report} ({len(result)} terminals)",
        file=sys.stderr,
    )
    return 0
