"""``bgr derive FILE.bgr -o OUT``: derive a grammar on its lots and write the model, the
terminal list or CityJSON, lot by lot (on several processes or a Dask cluster), with the run's
report() values (--reports) and a progress bar over the lots."""

from __future__ import annotations

import sys
from pathlib import Path

from ..grammar.loader import load
from .common import EXIT_OK, EXIT_USAGE, add_allow_path, count, set_values, whole
from .options import add_budget_options, add_lot_options, budgets, lot_options


def add_parser(commands) -> None:
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
    derive.add_argument("--seed", type=whole, default=0, help="global random seed (default 0)")
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
        type=count,
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
    add_allow_path(derive)


def run(args) -> int:
    from ..formats.background import background, worth_it
    from ..interpreter.batch import default_workers
    from ..interpreter.lots import names_a_file

    if args.output in (None, "-") and args.format != "json":
        print(
            "bgr derive: give an output file with -o OUT.glb (or -o - --format json for the "
            "terminal list on standard output)",
            file=sys.stderr,
        )
        return EXIT_USAGE
    attrs = set_values(args.set)
    if isinstance(attrs, str):
        print(f"bgr derive: {attrs}", file=sys.stderr)
        return EXIT_USAGE
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
        from ..grammar.paths import check_output

        check_output(args.reports)
    workers = args.workers or default_workers()
    # lots from a file, streamed to a file: written by a second process while this one derives
    # (formats.background); one lot is not worth a process
    many = args.lot is not None and names_a_file(args.lot)
    wanted = many and not args.dask and worth_it(output, fmt, args.group_by, workers)
    with background(wanted) as writer:
        return _derive(args, attrs, options, limits, workers, output, fmt, writer)


def _derive(args, attrs, options, limits, workers, output, fmt, writer) -> int:
    """run() once its arguments are checked: load, derive lot by lot, write."""
    import numpy as np

    from ..formats.sinks import open_sink, streams
    from ..interpreter.batch import derive_lots
    from ..interpreter.derive import FeatureOrder, prepare, site_of
    from ..interpreter.lots import check_mapping

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

        def first_pass(done: int) -> None:
            """A grammar that asks occlusion queries derives every lot once first (its
            occluders, for the lots around it): the bar counts that pass, then starts again."""
            bar.set_description("first pass", refresh=False)
            bar.update(done)
            if bar.n >= len(lots):
                bar.reset()
                bar.set_description("deriving")

        for result in derive_lots(
            job, lots, workers=workers, dask=args.dask, first_passes=first_pass
        ):
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

    from ..formats.atomic import write_text
    from ..interpreter.reports import document

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
