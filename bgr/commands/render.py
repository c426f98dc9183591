"""``bgr render FILE -o OUT.png``: derive a grammar (or read a model) and draw it headless
into a PNG: shaded, silhouette, lines or labels, on OpenGL or the numpy rasteriser."""

from __future__ import annotations

import re
import sys
from pathlib import Path

from ..grammar.errors import BgrError, Diagnostic
from .common import EXIT_OK, EXIT_USAGE, add_allow_path, set_values, whole
from .options import add_budget_options, add_lot_options, budgets, lot_options


def add_parser(commands) -> None:
    render = commands.add_parser(
        "render",
        help="draw a grammar or a model into a PNG preview",
        description="Derive FILE.bgr (or read a model: .glb, .gltf, .obj with its .mtl, .ply, "
        "a CityGML 2.0 .gml) and draw it headless into a PNG: shaded (with its textures), "
        "silhouette, lines or labels.",
    )
    render.add_argument(
        "file",
        metavar="FILE.bgr|MODEL",
        help="a grammar, or a model: .glb, .gltf, .obj (with its .mtl), .ply or CityGML 2.0 .gml "
        "(textured models and grammars are drawn with their textures)",
    )
    render.add_argument("-o", "--output", metavar="OUT.png", help="the PNG to write")
    render.add_argument(
        "--mode",
        choices=["shaded", "silhouette", "lines", "labels"],
        default="shaded",
        help="what to draw (default shaded)",
    )
    render.add_argument(
        "--view",
        default="iso",
        metavar="front|iso|top|CAMERA.json",
        help="a view fitted to the model (default iso) or a camera file",
    )
    render.add_argument(
        "--size",
        metavar="WxH",
        help="image size in pixels (default 1024x768, or the camera file's)",
    )
    render.add_argument(
        "--backend",
        choices=["auto", "gl", "numpy"],
        default="auto",
        help="rasteriser: OpenGL (EGL), numpy, or auto: GL when it can (default)",
    )
    render.add_argument(
        "--legend",
        action="store_true",
        help="with --mode labels: also write OUT.legend.json (label -> colour)",
    )
    render.add_argument(
        "--seed", type=whole, default=None, help="global random seed for a .bgr (default 0)"
    )
    render.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="override an attr of a .bgr; repeatable",
    )
    render.add_argument(
        "--lot", metavar="W,D|LOTS.geojson", help="the lot of a .bgr, as for derive"
    )
    add_lot_options(render)
    add_budget_options(render)
    render.add_argument(
        "--strict", action="store_true", help="treat a .bgr's warnings as errors, as for derive"
    )
    add_allow_path(render)


def _parse_size(text: str) -> tuple[int, int] | None:
    """``WxH`` in ASCII digits (str.isdigit() also takes "²" and "١٠"), within the camera's
    limits (render.camera.size_problem), or None."""
    from ..render.camera import size_problem

    match = re.fullmatch(r"\s*([0-9]{1,6})\s*[xX]\s*([0-9]{1,6})\s*", text)
    if match is None:
        return None
    size = int(match[1]), int(match[2])
    return None if size_problem(*size) else size


def run(args) -> int:
    from ..render import (
        VIEWS,
        image_of,
        legend_path,
        load_scene,
        make_camera,
        rasterise,
        save_legend,
        save_png,
    )

    def usage(message: str) -> int:
        print(f"bgr render: {message}", file=sys.stderr)
        return EXIT_USAGE

    if args.output in (None, "-"):
        return usage("give the output file with -o OUT.png")
    size = None
    if args.size is not None:
        size = _parse_size(args.size)
        if size is None:
            return usage(
                f"--size {args.size}: write WIDTHxHEIGHT, e.g. 1024x768 (1 to 8192 pixels each, "
                "at most 4096x4096 pixels in all)"
            )
    if args.view not in VIEWS and not args.view.lower().endswith(".json"):
        return usage(f"--view {args.view}: give {', '.join(VIEWS)} or a camera file CAMERA.json")
    if args.legend and args.mode != "labels":
        return usage("--legend goes with --mode labels")
    is_grammar = Path(args.file).suffix.lower() == ".bgr"
    if not is_grammar and (
        args.seed is not None
        or args.set
        or args.lot is not None
        or args.strict
        or args.map
        or args.front
    ):
        return usage(
            "--seed, --set, --lot, --map, --front and --strict apply to a .bgr grammar, not to "
            "a model file"
        )
    options = lot_options(args)
    if isinstance(options, str):
        return usage(options)
    attrs = set_values(args.set)
    if isinstance(attrs, str):
        return usage(attrs)
    limits = budgets(args) if is_grammar else {}
    if isinstance(limits, str):
        return usage(limits)
    out = Path(args.output)
    if out.suffix.lower() != ".png":  # before deriving: a typo should not cost a derivation
        shown = (
            f"unknown output extension '{out.suffix}'"
            if out.suffix
            else "the output file name has no extension"
        )
        raise BgrError(Diagnostic(args.output, 0, 0, shown, "bgr render writes .png files"))

    scene = load_scene(
        args.file,
        seed=args.seed or 0,
        attrs=attrs,
        lot=args.lot,
        strict=args.strict,
        **limits,
        allow_paths=args.allow_path,
        lot_options=options,
    )
    for warning in scene.warnings:
        print(warning.render(), file=sys.stderr)
    camera = make_camera(args.view, scene, size)

    def fallback(reason: str) -> None:
        print(f"bgr render: {reason}; using the numpy renderer (slower)", file=sys.stderr)

    frame = rasterise(scene, camera, args.backend, on_fallback=fallback)
    image, legend = image_of(frame, scene, args.mode)
    save_png(image, out)
    if args.legend and legend is not None:
        save_legend(legend, legend_path(out))
    width, height = camera.size
    view = args.view if args.view in VIEWS else Path(args.view).name
    print(
        f"{args.output}: {width}x{height} {args.mode}, view {view}, {len(scene):,} triangles "
        f"({frame.backend})",
        file=sys.stderr,
    )
    return EXIT_OK
