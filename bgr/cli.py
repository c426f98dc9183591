"""The ``bgr`` command: a thin layer over the Python API.

Exit status (LANGUAGE.md section 12): 0 success, 1 bad input (with a message), 2 bad usage.
No input produces a Python traceback: every failure a user can cause is a BgrError, printed as
``path:line:col: error: ...``; anything else is reported as an internal error, with the
traceback only when BGR_DEBUG=1.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import signal
import sys
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

from . import __version__
from .formats.atomic import Terminated, on_sigterm, reset_termination
from .grammar.errors import BgrError, Diagnostic, terminal_text
from .grammar.formatter import format_module
from .grammar.loader import decode, load, read_source
from .grammar.parser import parse
from .interpreter.limits import (
    DEFAULT_MAX_DEPTH,
    DEFAULT_MAX_SHAPES,
    DEFAULT_MAX_TRIANGLES,
    default_max_memory,
    format_bytes,
    memory_ceiling,
    parse_memory,
)

EXIT_OK, EXIT_INPUT, EXIT_USAGE = 0, 1, 2
EXIT_INTERRUPTED, EXIT_TERMINATED = 130, 143  # 128 + SIGINT, 128 + SIGTERM, as shells report

ALLOW_PATH_HELP = (
    "also let imports and assets read files under DIR (repeatable); by default they must stay "
    "in the grammar's own folder or the stdlib"
)


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # bad usage: exit 2 with a one-line reason
        self.print_usage(sys.stderr)
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="bgr",
        description="bgr: a building-grammar toolkit. "
        "Write .bgr shape grammars, check and format them, derive them into meshes.",
        epilog="Exit status: 0 success, 1 bad input, 2 bad usage, 130 interrupted, 143 terminated "
        "(SIGTERM). Imports and assets stay in the grammar's folder and the stdlib unless "
        "--allow-path widens them; inputs and outputs must be regular files. "
        "Language reference: docs/language.md; files: docs/cli.md.",
    )
    parser.add_argument("--version", action="version", version=f"bgr {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    check = commands.add_parser(
        "check",
        help="parse, resolve names and report every error",
        description="Parse each file, resolve its imports and names, and "
        "report every error found. Exit 0 when all files are clean.",
    )
    check.add_argument(
        "files", nargs="+", metavar="FILE", help=".bgr files ('-' reads standard input)"
    )
    check.add_argument("-q", "--quiet", action="store_true", help="print nothing for clean files")
    check.add_argument(
        "--allow-path",
        action="append",
        default=[],
        metavar="DIR",
        help=ALLOW_PATH_HELP,
    )

    derive = commands.add_parser(
        "derive",
        help="derive a grammar into a mesh or a terminal list",
        description="Derive FILE.bgr on a lot and write the result; the "
        "format follows the output's extension "
        "(.glb .gltf .obj .ply .stl .json .city.json .city.jsonl).",
    )
    derive.add_argument("file", metavar="FILE.bgr")
    derive.add_argument(
        "-o", "--output", metavar="OUT", help="output file ('-' with --format json: stdout)"
    )
    derive.add_argument(
        "--format",
        choices=["glb", "gltf", "obj", "ply", "stl", "json", "city.json", "city.jsonl"],
        help="output format when the extension does not say it (json for stdout)",
    )
    derive.add_argument("--seed", type=_whole, default=0, help="global random seed (default 0)")
    derive.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="override an attr; repeatable",
    )
    derive.add_argument(
        "--lot",
        metavar="W,D|LOTS.geojson",
        help="the lot: W,D (or WxD) in metres (default 20,20) or GeoJSON footprints",
    )
    add_lot_options(derive)
    derive.add_argument(
        "--group-by",
        choices=["lot", "label", "none"],
        default="lot",
        help="glTF scene tree: a node per lot holding a node per terminal label (lot, the "
        "default), a node per label (label), or one node (none)",
    )
    derive.add_argument(
        "--reports",
        metavar="FILE.json",
        help="write each lot's report() values, counted, summed and averaged per key, and the "
        "run's total, as JSON (as CityEngine's reports)",
    )
    derive.add_argument(
        "--instancing",
        action="store_true",
        help="glTF: store repeated parts once with EXT_mesh_gpu_instancing (smaller files; "
        "the extension is then required, so readers without it refuse the file)",
    )
    parallel = derive.add_argument_group("many lots")
    parallel.add_argument(
        "--workers",
        type=_count,
        default=1,
        metavar="N",
        help="derive lots on N local processes (0: one per core; default 1, this process, "
        "which then streams a lot file's GLB, CityJSON Sequence or JSON through a second "
        "process that writes it, when there is a second core); the files are the same bytes "
        "whatever N",
    )
    parallel.add_argument(
        "--dask",
        metavar="ADDRESS",
        help="derive lots on a Dask cluster: a scheduler address (tcp://host:8786), or 'local' "
        "for a cluster of --workers processes on this machine (needs pip install 'bgr[dask]')",
    )
    add_budget_options(derive)
    derive.add_argument(
        "--strict",
        action="store_true",
        help="treat warnings as errors: a footprint that cannot be used, a property that does "
        "not fit its attr, a roof built as another kind",
    )
    derive.add_argument(
        "--allow-path",
        action="append",
        default=[],
        metavar="DIR",
        help=ALLOW_PATH_HELP,
    )

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
        "--seed", type=_whole, default=None, help="global random seed for a .bgr (default 0)"
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
    render.add_argument(
        "--allow-path",
        action="append",
        default=[],
        metavar="DIR",
        help=ALLOW_PATH_HELP,
    )

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
        "--seed", type=_whole, default=0, help="seed for deriving a .bgr input (default 0)"
    )
    infer.add_argument("--lot", metavar="W,D|LOTS.geojson", help="lot for deriving a .bgr input")
    infer.add_argument(
        "--allow-path",
        action="append",
        default=[],
        metavar="DIR",
        help=ALLOW_PATH_HELP,
    )
    add_memory_option(infer)

    from .inverse.style.command import add_infer_options, add_restyle_parser

    add_infer_options(infer)
    from .inverse.image.command import add_facade_options

    add_facade_options(infer)
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
        type=_whole,
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

    add_restyle_parser(commands, ALLOW_PATH_HELP, add_memory_option)
    retarget = commands.add_parser(
        "retarget",
        help="resize a box hierarchy, replicating, scaling and fixing its boxes",
        description="Structure-preserving retargeting of a box hierarchy (docs/inverse-boxes.md): "
        "resize it to --size one axis at a time, R boxes replicated or deleted, S boxes "
        "scaled, F boxes kept, alignments kept where they can be. Writes the retargeted boxes "
        "(.json, itself a valid input) or a model with each box's mesh fitted (.glb .gltf .obj "
        ".ply .stl .city.json; a cube for a leaf without one).",
    )
    retarget.add_argument("input", metavar="BOXES.json", help="the box hierarchy")
    retarget.add_argument(
        "--size", required=True, metavar="W,H,D", help="the new size in metres: x, y (up), z"
    )
    retarget.add_argument(
        "--order",
        default="xyz",
        metavar="AXES",
        help="the axes in the order they are retargeted (default xyz); the order changes the "
        "result, e.g. yx against xy",
    )
    retarget.add_argument(
        "-o", "--output", metavar="OUT", help="OUT.json or a model file (default: JSON on stdout)"
    )
    retarget.add_argument(
        "--max-boxes",
        type=_whole,
        default=200_000,
        metavar="N",
        help="refuse an input or a result of more than N boxes (default 200000: about 1 GB "
        "and 10 s)",
    )
    add_memory_option(retarget)
    retarget.add_argument(
        "--allow-path",
        action="append",
        default=[],
        metavar="DIR",
        help="also let box meshes be read from under DIR (repeatable); by default they must "
        "stay in the boxes file's folder",
    )

    fmt = commands.add_parser(
        "fmt",
        help="print files in the canonical layout",
        description="Format .bgr files in the canonical layout, keeping "
        "comments. Without options the result goes to standard output.",
    )
    fmt.add_argument(
        "files", nargs="+", metavar="FILE", help=".bgr files ('-' reads standard input)"
    )
    mode = fmt.add_mutually_exclusive_group()
    mode.add_argument(
        "--check", action="store_true", help="change nothing; exit 1 if a file is not formatted"
    )
    mode.add_argument("-w", "--write", action="store_true", help="rewrite the files in place")
    from .cga import command as cga_command

    cga_command.add_parser(commands)
    return parser


def add_lot_options(command: argparse.ArgumentParser) -> None:
    """--map and --front: how the footprints of a GeoJSON --lot become lots (docs/cli.md, Lots)."""
    command.add_argument(
        "--map",
        action="append",
        default=[],
        type=_argument("parse_map"),
        metavar="NAME=PROPERTY[:TYPE]",
        help="set attr NAME from each footprint's PROPERTY (it may hold colons), coerced to "
        "TYPE int (rounded, halves away from zero), float, str or bool; repeatable, e.g. "
        "--map floors=building:levels:int",
    )
    command.add_argument(
        "--front",
        type=_argument("parse_front"),
        metavar="first|longest|street:LINES.geojson",
        help="each footprint's front edge (the scope's x): its first edge (default), its longest, "
        "or the one nearest to a line of a GeoJSON street file in the lots' CRS",
    )


def _argument(parser: str):
    """An argparse type from a parser of interpreter/lots.py (imported when used: numpy and
    shapely are slow to load for bgr check) that raises BgrError: a bad value is a usage error."""

    def convert(text: str):
        from .interpreter import lots

        try:
            return getattr(lots, parser)(text)
        except BgrError as e:
            raise argparse.ArgumentTypeError(e.message) from None

    return convert


def lot_options(args):
    """The LotOptions of --front and --map, None without them, or what is wrong with them."""
    from .interpreter.lots import LotOptions

    if not args.map and args.front is None:
        return None
    lot = args.lot or ""
    if not lot or ("," in lot and not lot.lower().endswith((".json", ".geojson"))):
        return "--front and --map apply to a GeoJSON lot file: give --lot LOTS.geojson"
    front, streets = args.front or ("first", None)
    return LotOptions(front=front, streets=streets, mapping=tuple(args.map))


def add_budget_options(command: argparse.ArgumentParser) -> None:
    """The limits a derivation runs under (interpreter/limits.py, docs/limits.md)."""
    command.add_argument(
        "--max-depth",
        type=_whole,
        default=DEFAULT_MAX_DEPTH,
        metavar="N",
        help=f"rule depth limit (default {DEFAULT_MAX_DEPTH})",
    )
    command.add_argument(
        "--max-shapes",
        type=_whole,
        default=DEFAULT_MAX_SHAPES,
        metavar="N",
        help=f"shape budget of the run, or of each lot when derive streams its output "
        f"(.glb .city.jsonl .json) (default {DEFAULT_MAX_SHAPES:,})",
    )
    command.add_argument(
        "--max-triangles",
        type=_whole,
        default=DEFAULT_MAX_TRIANGLES,
        metavar="N",
        help=f"triangle budget of the terminals, of the run or of each lot as --max-shapes "
        f"(default {DEFAULT_MAX_TRIANGLES:,})",
    )
    add_memory_option(command)


def add_memory_option(command: argparse.ArgumentParser) -> None:
    """--max-memory: derive and render, and the commands that read data (infer, retarget)."""
    command.add_argument(
        "--max-memory",
        metavar="SIZE",
        help="memory ceiling on what the run allocates, e.g. 4G or 512M (default: 80%% of the "
        "memory available at start)",
    )


def memory_limit(args) -> int | None | str:
    """The --max-memory ceiling in bytes (None: unknown, none enforced), or what is wrong with
    it.  The process's address space is capped a little above it (:func:`cap_address_space`)."""
    if args.max_memory is None:
        memory = default_max_memory()
    else:
        memory = parse_memory(args.max_memory)
        if memory is None:
            return f"--max-memory {args.max_memory}: write a size such as 4G, 512M or 1.5GB"
    args.memory_ceiling = memory  # for main()'s out-of-memory message
    if memory is not None:
        cap_address_space(memory)
    return memory


def budgets(args) -> dict | str:
    """The derive() keywords of the budget options, or what is wrong with them.

    The memory ceiling is enforced twice: the engine measures the process as it derives (a
    located error), and the process's address space is capped a little above the ceiling, so
    an allocation that would pass it in one go (a writer's arrays) fails as MemoryError, which
    main() reports in one line instead of the system killing the process.
    """
    if args.max_depth < 1 or args.max_shapes < 1 or args.max_triangles < 1:
        return "--max-depth, --max-shapes and --max-triangles must be positive"
    memory = memory_limit(args)
    if isinstance(memory, str):
        return memory
    return {
        "max_depth": args.max_depth,
        "max_shapes": args.max_shapes,
        "max_triangles": args.max_triangles,
        "max_memory": memory,
    }


def cap_address_space(ceiling: int) -> None:
    """Lower RLIMIT_AS to what the process has mapped now, plus the ceiling and 1 GB of slack
    for the mappings that are reserved but never touched (thread stacks, malloc arenas)."""
    try:
        import resource

        with open("/proc/self/statm", "rb") as f:
            mapped = int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (ImportError, OSError, ValueError, IndexError):
        return  # not Linux: the engine's own measurement is the only ceiling
    wanted = mapped + ceiling + 2**30
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    if soft == resource.RLIM_INFINITY or wanted < soft:
        limit = wanted if hard == resource.RLIM_INFINITY else min(wanted, hard)
        with contextlib.suppress(ValueError, OSError, OverflowError):
            resource.setrlimit(resource.RLIMIT_AS, (limit, hard))


@contextlib.contextmanager
def _address_space_restored():
    """Put back the address-space limit cap_address_space() lowered: main() may be called in a
    process that goes on (a test, a server), whose later work must not inherit the ceiling."""
    try:
        import resource

        before = resource.getrlimit(resource.RLIMIT_AS)
    except ImportError:
        yield
        return
    try:
        yield
    finally:
        with contextlib.suppress(ValueError, OSError):
            resource.setrlimit(resource.RLIMIT_AS, before)


def _read(name: str) -> tuple[str, str]:
    if name == "-":
        return decode(sys.stdin.buffer.read(), "<stdin>"), "<stdin>"
    return read_source(name), name


def _import_cga(args) -> int:
    from .cga.command import run

    return run(args)


def cmd_check(args) -> int:
    status = EXIT_OK
    for name in args.files:
        shown = "<stdin>" if name == "-" else name
        try:
            source = _read(name)[0] if name == "-" else Path(name)
            grammar = load(source, path=shown, allow_paths=args.allow_path)
        except BgrError as e:
            print(e.render(), file=sys.stderr)
            status = EXIT_INPUT
            continue
        print(*(w.render() + "\n" for w in grammar.warnings), sep="", end="", file=sys.stderr)
        count = len(grammar.warnings)  # the file checks: warnings leave the status at 0
        if not args.quiet:
            print(f"{shown}: ok" + (f" ({count} warning{'s' * (count > 1)})" if count else ""))
    return status


def cmd_fmt(args) -> int:
    if not (args.check or args.write) and len(args.files) > 1:
        print("bgr fmt: give one file to print, or use --check or -w with several", file=sys.stderr)
        return EXIT_USAGE
    if args.write and "-" in args.files:
        print("bgr fmt: -w cannot rewrite standard input", file=sys.stderr)
        return EXIT_USAGE
    status = EXIT_OK
    for name in args.files:
        try:
            text, shown = _read(name)
            formatted = format_module(parse(text, shown))
        except BgrError as e:
            print(e.render(), file=sys.stderr)
            status = EXIT_INPUT
            continue
        if args.check:
            if formatted != text:
                print(f"{name}: not formatted (run 'bgr fmt -w {name}')", file=sys.stderr)
                status = EXIT_INPUT
        elif args.write:
            if formatted != text:
                write_atomic(Path(name), formatted)
                print(f"{name}: formatted")
        else:
            sys.stdout.write(formatted)
    return status


def write_atomic(path: Path, text: str) -> None:
    """Write beside the target and rename over it, so a failure never leaves half a file."""
    from .formats.atomic import write_text

    write_text(path, text)


def _parse_value(text: str, item: str = ""):
    """--set values: numbers, true/false, else strings (quotes optional).

    A number is written as in the .bgr language (ASCII digits, optional sign, fraction and
    exponent; interpreter/values.py): "1_000" and "١٠" stay strings, though Python's float()
    reads both.  A number must be finite and in range, and "nan" or "inf" is refused rather
    than passed on as a string that fails later, far from the option."""
    from .interpreter.values import NUMBER_SYNTAX, is_number, number_of, number_problem

    if text in ("true", "false"):
        return text == "true"
    value = number_of(text)
    if value is None and (NUMBER_SYNTAX.fullmatch(text) or _SPECIAL.fullmatch(text)):
        value = float(text)  # 1e400, inf, nan: refused below
    if value is None:
        return text[1:-1] if len(text) >= 2 and text[0] == text[-1] == '"' else text
    problem = number_problem(value) if is_number(value) else None
    if problem:
        raise BgrError(
            Diagnostic(
                "",
                0,
                0,
                f"--set {item or text}: {text[:40]} is {problem}",
                "write a number such as 12.5, or a string in quotes: --set 'NAME=\"text\"'",
            )
        )
    return int(value) if isinstance(value, int) else value


# what float() reads as infinite or not a number
_SPECIAL = re.compile(r"[+-]?(inf|infinity|nan)", re.IGNORECASE)


def _whole(text: str) -> int:
    """An argparse type: a whole number in ASCII digits (int() also takes "1_000" and "١٠")."""
    if not re.fullmatch(r"\s*[+-]?[0-9]{1,30}\s*", text):
        raise argparse.ArgumentTypeError(f"{text[:40]!r} is not a whole number")
    return int(text)


def _count(text: str) -> int:
    """An argparse type: a whole number of at least 0 (a count of workers)."""
    value = _whole(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"{text[:40]!r} is not 0 or more")
    return value


def cmd_derive(args) -> int:
    from .formats.background import background, worth_it
    from .interpreter.batch import default_workers
    from .interpreter.lots import names_a_file

    if args.output in (None, "-") and args.format != "json":
        print(
            "bgr derive: give an output file with -o OUT.glb (or -o - --format json for the "
            "terminal list on standard output)",
            file=sys.stderr,
        )
        return EXIT_USAGE
    attrs = {}
    for item in args.set:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            print(f"bgr derive: --set {item}: write NAME=VALUE", file=sys.stderr)
            return EXIT_USAGE
        attrs[name.strip()] = _parse_value(value.strip(), item)
    options = lot_options(args)
    if isinstance(options, str):
        print(f"bgr derive: {options}", file=sys.stderr)
        return EXIT_USAGE
    limits = budgets(args)
    if isinstance(limits, str):
        print(f"bgr derive: {limits}", file=sys.stderr)
        return EXIT_USAGE
    output = "-" if args.output in (None, "-") else args.output
    fmt = args.format if output != "-" else "json"
    if args.reports is not None:  # refused now, not after a long derivation
        from .grammar.paths import check_output

        check_output(args.reports)
    workers = args.workers or default_workers()
    # lots from a file, streamed to a file: written by a second process while this one derives
    # (formats.background); one lot is not worth a process
    many = args.lot is not None and names_a_file(args.lot)
    wanted = many and not args.dask and worth_it(output, fmt, args.group_by, workers)
    with background(wanted) as writer:
        return _derive(args, attrs, options, limits, workers, output, fmt, writer)


def _derive(args, attrs, options, limits, workers, output, fmt, writer) -> int:
    """cmd_derive once its arguments are checked: load, derive lot by lot, write."""
    import numpy as np

    from .formats.sinks import open_sink, streams
    from .interpreter.batch import derive_lots
    from .interpreter.derive import FeatureOrder, prepare, site_of
    from .interpreter.lots import check_mapping

    grammar = load(Path(args.file), path=args.file, allow_paths=args.allow_path)
    check_mapping(options, grammar.attrs, args.file)
    job, lots, warnings = prepare(
        grammar,
        seed=args.seed,
        attrs=attrs,
        lot=args.lot,
        strict=args.strict,
        lot_options=options,
        # a streamed file holds one lot at a time: the shape and triangle budgets are per lot
        per_lot=streams(output, fmt, args.group_by),
        **limits,
    )
    shown: set[tuple] = set()

    def show(items, bar) -> None:
        """Each warning once, above the progress bar."""
        for d in items:
            if (key := (d.path, d.line, d.column, d.message)) not in shown:
                shown.add(key)
                bar.write(d.render(), file=sys.stderr)

    read = FeatureOrder(warnings)  # the lot file's warnings, among the lots' in feature order
    reported: list[dict] = []
    with (
        (writer.open_sink if writer is not None else open_sink)(
            output,
            seed=args.seed,
            attrs=job.values,
            fmt=fmt,
            site=site_of(lots, grammar),
            grammar=str(grammar.path or ""),
            gltf={"group_by": args.group_by, "instancing": "auto" if args.instancing else False},
            lot_origins=np.array([lot.shape.origin for lot in lots]),
        ) as sink,
        _progress(len(lots), output) as bar,
    ):
        for result in derive_lots(job, lots, workers=workers, dask=args.dask):
            show(read.before(lots[result.index]) + result.warnings, bar)
            for lot in result.table.lots:  # the grammar's print() calls, as CGA's console
                for text in lot.get("prints", ()):
                    bar.write(text, file=sys.stderr)
            if args.reports is not None:  # a lot's name, id and report() calls: not its attrs
                reported += [
                    {
                        "name": lot.get("name"),
                        "id": lot.get("id"),
                        "reports": lot.get("reports", []),
                    }
                    for lot in result.table.lots
                ]
            sink.add(result.table)
            bar.update()
        show(read.before(None), bar)
        if args.reports is not None:  # inside the block: no output without its reports
            _write_reports(args, reported, grammar)
    if output != "-":
        several = f" on {len(lots):,} lots" if len(lots) > 1 else ""
        print(
            f"{args.output}: {sink.terminals:,} terminals, {sink.triangles:,} triangles{several}",
            file=sys.stderr,
        )
    return EXIT_OK


def _write_reports(args, lots: list[dict], grammar) -> None:
    """``--reports FILE.json``: every lot's report() values summed up, and the run's."""
    import json

    from .formats.atomic import write_text
    from .interpreter.reports import document

    doc = document(lots, str(grammar.path or ""), args.seed)
    write_text(Path(args.reports), json.dumps(doc, indent=1, allow_nan=False) + "\n")


def _progress(lots: int, output: str):
    """A bar of lots done, their rate and the time left, on a terminal when there are several
    (and standard output is not the file being written)."""
    from tqdm import tqdm

    return tqdm(
        total=lots,
        unit="lot",
        desc="deriving",
        disable=lots < 2 or not sys.stderr.isatty() or output == "-",
        file=sys.stderr,
        leave=False,
        dynamic_ncols=True,
    )


def cmd_infer(args) -> int:
    return _under_ceiling(args, "infer", "infer from a smaller input", _infer)


def _under_ceiling(args, command: str, advice: str, run: Callable[[Any], int]) -> int:
    """``run(args)`` under the run's memory ceiling (--max-memory; the inverse modules check
    it at their expensive steps, ``advice`` is what the message suggests)."""
    memory = memory_limit(args)
    if isinstance(memory, str):
        print(f"bgr {command}: {memory}", file=sys.stderr)
        return EXIT_USAGE
    with memory_ceiling(memory, args.input, advice):
        return run(args)


def _infer(args) -> int:
    from .inverse.inputs import check_input

    kind = args.kind or _infer_kind(args.input)
    if args.kind in (None, "schema", "city", "boxes") and kind != "style":
        check_input(args.input, args.kind)  # a photo or a binary file: say what is read
    if kind == "city":
        from .inverse.city.command import run

        return run(args)
    if kind == "boxes":
        from .inverse.boxes.command import run_infer

        return run_infer(args)
    if kind == "style":
        from .inverse.style.command import run_infer as run_style

        return run_style(args)
    if kind == "facade":
        from .inverse.image.command import run_facade

        return run_facade(args)
    if kind == "image":
        from .inverse.image.photo import run_image

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
    from .inverse.schema import infer

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


def _parse_size(text: str) -> tuple[int, int] | None:
    """``WxH`` in ASCII digits (str.isdigit() also takes "²" and "١٠"), within the camera's
    limits (render.camera.size_problem), or None."""
    from .render.camera import size_problem

    match = re.fullmatch(r"\s*([0-9]{1,6})\s*[xX]\s*([0-9]{1,6})\s*", text)
    if match is None:
        return None
    size = int(match[1]), int(match[2])
    return None if size_problem(*size) else size


def cmd_render(args) -> int:
    from .render import (
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
    attrs = {}
    for item in args.set:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            return usage(f"--set {item}: write NAME=VALUE")
        attrs[name.strip()] = _parse_value(value.strip(), item)
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


def cmd_restyle(args) -> int:
    from .inverse.style.command import run_restyle

    return _under_ceiling(args, "restyle", "give a smaller mass", run_restyle)


def cmd_retarget(args) -> int:
    from .inverse.boxes.command import run_retarget

    return _under_ceiling(args, "retarget", "ask a smaller size, or give fewer boxes", run_retarget)


COMMANDS = {
    "retarget": cmd_retarget,
    "check": cmd_check,
    "fmt": cmd_fmt,
    "import-cga": lambda args: _import_cga(args),
    "derive": cmd_derive,
    "render": cmd_render,
    "infer": cmd_infer,
    "restyle": cmd_restyle,
}


# what main()'s out-of-memory message advises besides --max-memory, by command
OUT_OF_MEMORY = {
    "derive": "derive fewer or smaller shapes",
    "render": "derive fewer or smaller shapes",
    "infer": "infer from a smaller input",
    "retarget": "ask a smaller size, or give fewer boxes",
    "restyle": "give a smaller mass",
}


def _ceiling(args) -> str:
    memory = getattr(args, "memory_ceiling", None)
    return format_bytes(memory) if memory else "the machine's memory"


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    reset_termination()
    previous = _on_sigterm(on_sigterm)
    try:
        with _address_space_restored():
            return COMMANDS[args.command](args)
    except BgrError as e:
        print(e.render(), file=sys.stderr)
        return EXIT_INPUT
    except Terminated:
        print("bgr: terminated", file=sys.stderr)
        return EXIT_TERMINATED
    except KeyboardInterrupt:
        print("bgr: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except MemoryError:
        smaller = OUT_OF_MEMORY.get(args.command, OUT_OF_MEMORY["derive"])
        print(
            f"bgr {args.command}: out of memory (the ceiling is "
            f"{_ceiling(args)}); {smaller}, or raise it with --max-memory",
            file=sys.stderr,
        )
        return EXIT_INPUT
    except BrokenPipeError:
        sys.stderr.close()  # the reader went away (bgr fmt x | head): not an error of ours
        return EXIT_OK
    except Exception as e:  # a bug of ours: say so without a traceback unless asked
        if os.environ.get("BGR_DEBUG"):
            traceback.print_exc()
        print(
            f"bgr: internal error: {type(e).__name__}: {e} (please report it; "
            "BGR_DEBUG=1 shows the traceback)",
            file=sys.stderr,
        )
        return EXIT_INPUT
    finally:
        if previous is not None:
            _on_sigterm(previous)


def _on_sigterm(handler):
    """Install ``handler`` for SIGTERM and return the previous one; None where signals cannot
    be set (not the main thread, or no SIGTERM)."""
    try:
        return signal.signal(signal.SIGTERM, handler)
    except (ValueError, AttributeError, OSError):
        return None


if __name__ == "__main__":
    sys.exit(main())
