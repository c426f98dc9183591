"""``bgr infer INPUT``: write a grammar from data.  The kind of data (--kind, or guessed from
the input) picks the inverse module that reads it: Build-by-Number schemas (inverse/schema), box
hierarchies (inverse/boxes), a whole city (inverse/city), a textured building's style sheet
(inverse/style), a façade or a building photograph (inverse/image).  Each module's own options
come from its command.py; the city's are declared here, as that module loads numpy."""

from __future__ import annotations

import contextlib
import re
import sys
from pathlib import Path

from ..grammar.errors import terminal_text
from ..grammar.formatter import format_module
from ..inverse.image.command import add_facade_options
from ..inverse.style.command import add_infer_options
from .common import EXIT_OK, EXIT_USAGE, add_allow_path, whole, write_atomic
from .options import add_memory_option, under_ceiling


def add_parser(commands) -> None:
    infer = commands.add_parser(
        "infer",
        help="write a grammar from data: face schemas, a box hierarchy, a whole city, or a "
        "textured building's style sheet",
        description="Infer a .bgr grammar from data. --kind city (the default for .obj, .ply, "
        ".glb, .gltf and CityJSON inputs): city-scale proceduralization of a 3D city, a "
        "grammar of component types (footprints extruded written as polygon() extrude(), "
        "other shapes as meshes in one GLB in an assets folder beside it) "
        "(docs/inverse-city.md). --kind schema (the default for other .json and .bgr): "
        "Build-by-Number face, floor and model schemas of a labelled, subdivided "
        "building: a terminal list (bgr derive -o x.json), a captured-model JSON "
        "(docs/inverse-schema.md) or a .bgr (derived first); the grammar, derived "
        'with --lot, styles a new mass. --kind boxes (the default for a .json with a "root" '
        "box): a box hierarchy as nested splits whose derivation at other sizes (--set width, "
        "height, length) follows bgr retarget (docs/inverse-boxes.md). --kind style (the "
        "default for CityGML .gml and .xml): the style sheet of a textured Manhattan-world "
        "building (CityGML with appearances, OBJ + MTL, glTF), its blocks, walls and per-face "
        "window rules with texture crops in an assets folder, to derive on a lot or put on a "
        "mass with bgr restyle (docs/inverse-style.md).",
    )
    infer.add_argument(
        "input",
        metavar="INPUT",
        help="a city (.obj, .ply, .glb, .gltf, .city.json, .city.jsonl), a box hierarchy "
        ".json for --kind boxes, a terminal list .json, captured-model .json or .bgr for "
        "--kind schema, a textured model (.gml, .xml, .obj, .glb, .gltf) for --kind style, a "
        "rectified façade photograph (.jpg, .png) for --kind facade, or a photograph of a "
        "building for --kind image",
    )
    infer.add_argument(
        "--kind",
        choices=["schema", "city", "boxes", "style", "facade", "image"],
        default=None,
        help="what to infer (default: city for 3D models and CityJSON, boxes for a box "
        "hierarchy .json, style for CityGML, schema otherwise; facade parses a rectified "
        "façade photograph; image fits a building to a photograph and its outline)",
    )
    infer.add_argument(
        "-o", "--output", metavar="OUT.bgr", help="write here (default: standard output)"
    )
    infer.add_argument(
        "--fixed",
        metavar="LABEL,...",
        default="",
        help="labels whose size is fixed (default: window-, door- and entrance-like labels)",
    )
    infer.add_argument(
        "--stretch",
        metavar="LABEL,...",
        default="",
        help="labels that stretch (default: every other label)",
    )
    infer.add_argument(
        "--seed", type=whole, default=0, help="seed for deriving a .bgr input (default 0)"
    )
    infer.add_argument("--lot", metavar="W,D|LOTS.geojson", help="lot for deriving a .bgr input")
    add_allow_path(infer)
    add_memory_option(infer)

    add_infer_options(infer)
    add_facade_options(infer)
    _add_city_options(infer)


def _add_city_options(infer) -> None:
    """The ``--kind city`` options (inverse/city)."""
    city = infer.add_argument_group("--kind city")
    city.add_argument(
        "--assets",
        metavar="DIR",
        help="folder for the component meshes, one meshes.glb (--kind style: the texture "
        "crops; default: "
        "OUT.assets beside -o OUT.bgr, or ./city.assets (./style.assets) when the grammar goes "
        "to standard output); it must be new, empty or one "
        "bgr wrote (with its .bgr-assets.json), as bgr replaces it whole",
    )
    city.add_argument(
        "--up",
        choices=["auto", "y", "z"],
        default="auto",
        help="the input's up axis (default auto: z for CityJSON, y for glTF, the flattest axis "
        "of an OBJ or PLY city)",
    )
    which = city.add_mutually_exclusive_group()
    which.add_argument(
        "--level",
        type=whole,
        help="de-instancing level: 0 (default) is lossless, each level up about halves the "
        "component types",
    )
    which.add_argument(
        "--threshold",
        type=float,
        metavar="T_D",
        help="the coarsest level whose components are all within T_D of their type's "
        "representative (feature units: metres, tens of degrees, outline vertices)",
    )
    city.add_argument(
        "--weights",
        metavar="FEATURE=W,...",
        default="",
        help="feature weights of the dissimilarity, e.g. 'height=3,rotation=0' (features: "
        "front-shape, side-shape, width, height, depth, rotation, roof-slope, intensity)",
    )
    city.add_argument(
        "--w-mu", type=float, default=1.0, help="weight of closeness in the distance (eq. 11)"
    )
    city.add_argument(
        "--w-sigma", type=float, default=1.0, help="weight of consistency in the distance"
    )
    city.add_argument(
        "--tau",
        type=float,
        metavar="METRES",
        help="neighbour distance between building midpoints (default: 1.5 x the median "
        "distance to the nearest building)",
    )
    city.add_argument(
        "--lod",
        metavar="LOD",
        help="CityJSON only: the level of detail to read, as the file writes it (e.g. 1.2, "
        "2.2; default: each object's highest)",
    )
    city.add_argument(
        "--tolerance",
        type=float,
        default=0.01,
        metavar="METRES",
        help="level 0's bound: components whose meshes agree within it are one type "
        "(default 0.01: 1 cm)",
    )
    city.add_argument(
        "--representative",
        choices=["mean", "fewest"],
        default="mean",
        help="a type's mesh: the member closest to the mean (default) or with fewest triangles",
    )
    city.add_argument(
        "--plain-assets",
        action="store_true",
        help="write the assets GLB as plain glTF 2.0 (larger) instead of compressed with "
        "EXT_meshopt_compression and KHR_mesh_quantization, for readers without them (trimesh)",
    )
    city.add_argument(
        "--stats",
        action="store_true",
        help="print, for every level, the counts, sizes and geometric error to standard error",
    )
    city.add_argument(
        "--no-progress", action="store_true", help="no progress bars on standard error"
    )


def run(args) -> int:
    return under_ceiling(args, "infer", "infer from a smaller input", _infer)


def _infer(args) -> int:
    from ..inverse.inputs import check_input

    kind = args.kind or _infer_kind(args.input)
    if args.kind in (None, "schema", "city", "boxes") and kind != "style":
        check_input(args.input, args.kind)  # a photo or a binary file: say what is read
    if kind == "city":
        from ..inverse.city.command import run

        return run(args)
    if kind == "boxes":
        from ..inverse.boxes.command import run_infer

        return run_infer(args)
    if kind == "style":
        from ..inverse.style.command import run_infer as run_style

        return run_style(args)
    if kind == "facade":
        from ..inverse.image.command import run_facade

        return run_facade(args)
    if kind == "image":
        from ..inverse.image.photo import run_image

        return run_image(args)
    fixed: dict[str, bool] = {}
    for option, value in (("--fixed", True), ("--stretch", False)):
        for label in filter(None, (x.strip() for x in getattr(args, option[2:]).split(","))):
            if fixed.get(label, value) != value:
                print(
                    f"bgr infer: label '{label}' is given to both --fixed and --stretch",
                    file=sys.stderr,
                )
                return EXIT_USAGE
            fixed[label] = value
    from ..inverse.schema import infer

    text = format_module(
        infer(args.input, fixed=fixed, seed=args.seed, lot=args.lot, allow_paths=args.allow_path)
    )
    if args.output in (None, "-"):
        sys.stdout.write(text)
    else:
        write_atomic(Path(args.output), text)
        shown = terminal_text(args.output, keep="")
        print(f"{shown}: {text.count(chr(10))} lines", file=sys.stderr)
    return EXIT_OK


def _infer_kind(path: str) -> str:
    """city for 3D models and CityJSON, style for CityGML, schema for everything else (.bgr,
    other .json)."""
    lower = path.lower()
    if lower.endswith((".gml", ".xml")):
        return "style"
    if lower.endswith((".obj", ".ply", ".glb", ".gltf", ".city.json", ".city.jsonl", ".jsonl")):
        return "city"
    if lower.endswith(".json"):
        with contextlib.suppress(OSError):
            with open(path, "rb") as f:
                head = f.read(4096)
            if re.search(rb'"type"\s*:\s*"CityJSON"', head):
                return "city"
            if re.match(rb'\s*\{\s*"root"\s*:', head):
                return "boxes"
    return "schema"
