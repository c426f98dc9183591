"""``bgr infer --kind city``: the command-line side (paths, options, statistics)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from bgr.grammar.errors import BgrError, terminal_text
from bgr.grammar.safe_text import comment_text, unwritable

from .components import FEATURES
from .pipeline import MESHES, Options, infer_city, level_stats, to_text, write

USAGE = 2


def _weights(text: str) -> dict[str, float]:
    """``height=3,rotation=0`` -> {"height": 3.0, "rotation": 0.0}; feature names take - or
    spaces."""
    out: dict[str, float] = {}
    for item in filter(None, (x.strip() for x in text.split(","))):
        name, _, value = item.partition("=")
        feature = name.strip().replace("-", " ").replace("_", " ")
        if feature not in FEATURES:
            raise ValueError(
                f"--weights: no feature '{name.strip()}'; the features are "
                + ", ".join(f.replace(" ", "-") for f in FEATURES)
            )
        try:
            out[feature] = float(value)
        except ValueError:
            raise ValueError(f"--weights: '{item}' is not FEATURE=NUMBER") from None
        if not 0 <= out[feature] < float("inf"):
            raise ValueError(f"--weights: the weight of {name.strip()} must be 0 or more")
    return out


def run(args) -> int:
    try:
        weights = _weights(args.weights)
        for option, value in (("--w-mu", args.w_mu), ("--w-sigma", args.w_sigma)):
            if not 0 <= value < float("inf"):
                raise ValueError(f"{option} must be a number, 0 or more")
        if args.tau is not None and not 0 < args.tau < float("inf"):
            raise ValueError("--tau must be a distance over 0 metres")
        if not 0 < args.tolerance <= 1:
            raise ValueError("--tolerance must be a distance over 0 and at most 1 metre")
        if args.threshold is not None and not 0 <= args.threshold < float("inf"):
            raise ValueError("--threshold must be a number, 0 or more")
    except ValueError as e:
        print(f"bgr infer: {e}", file=sys.stderr)
        return USAGE
    output = None if args.output in (None, "-") else Path(args.output)
    if args.assets:
        assets_dir = Path(args.assets)
    elif output is not None:
        stem = output.name[: -len(".bgr")] if output.name.endswith(".bgr") else output.name
        assets_dir = output.with_name(stem + ".assets")
    else:
        assets_dir = Path("city.assets")
    check_outputs(output, assets_dir, Path(args.input))  # before the (slow) inference
    base = output.parent if output is not None else Path(".")
    named = Path(os.path.relpath(assets_dir.resolve(), base.resolve())).as_posix()
    if unwritable(named):  # the grammar names the folder in a string (UTF-8 text)
        print(
            f"bgr infer: the assets folder {comment_text(named)} holds {unwritable(named)}, "
            "which a grammar cannot name: choose another with --assets DIR",
            file=sys.stderr,
        )
        return USAGE
    options = Options(
        up=args.up,
        level=args.level,
        threshold=args.threshold,
        feature_weights=weights,
        w_mu=args.w_mu,
        w_sigma=args.w_sigma,
        tau=args.tau,
        representative=args.representative,
        compress=not args.plain_assets,
        lod=args.lod,
        tolerance=args.tolerance,
        assets=named,
        progress=not args.no_progress and sys.stderr.isatty(),
    )
    grammar = infer_city(args.input, options)
    text = to_text(grammar)
    write(grammar, text, output, assets_dir, keep=(Path(args.input),))
    placed = grammar.placed
    wrote = "" if output is None else f"; wrote {terminal_text(str(output), keep='')}"
    extruded = sum(t.prism is not None for t in placed.terminals)
    houses = sum(t.house is not None for t in placed.terminals)
    meshes = len(placed.terminals) - extruded - houses + len(placed.carried)
    print(
        f"{terminal_text(args.input, keep='')}: {len(grammar.scene.objects)} objects, "
        f"{placed.components} components, {len(placed.terminals)} types at level "
        f"{placed.level.index} ({extruded} footprints extruded"
        + (f", {houses} house{'s' if houses > 1 else ''} roofed" if houses else "")
        + f"), {len(placed.rules)} rules{wrote}"
        + (
            f" and {meshes} meshes in {terminal_text(str(assets_dir / MESHES), keep='')}"
            if meshes
            else ""
        ),
        file=sys.stderr,
    )
    if args.stats:
        print(stats_table(level_stats(args.input, grammar, options)), file=sys.stderr)
    return 0


def check_outputs(output: Path | None, assets_dir: Path, source: Path) -> None:
    """Refuse, before any work, outputs the run could not write or would lose data writing:
    a folder or a device as the grammar, and an assets folder bgr did not write
    (formats/assets_folder.check_folder)."""
    from bgr.formats.assets_folder import check_folder
    from bgr.formats.atomic import cannot_write
    from bgr.grammar.errors import Diagnostic
    from bgr.grammar.paths import check_output

    if output is not None:
        if output.is_dir():
            raise BgrError(
                Diagnostic(
                    str(output),
                    0,
                    0,
                    "cannot write the grammar: it is a folder",
                    "name a file for -o, such as city.bgr",
                )
            )
        check_output(output)
        made = assets_dir.resolve().parents  # write() makes the assets folder's parents
        if not output.parent.is_dir() and output.parent.resolve() not in made:
            raise cannot_write(output, FileNotFoundError(2, "no such folder"))
    check_folder(assets_dir, [source, *(() if output is None else (output,))])


def stats_table(rows: list[dict]) -> str:
    """The --stats table (Markdown, so that docs/benchmarks.md can take it as it is)."""
    head = (
        "| level | components | terminals | non-terminals | rules | input triangles | "
        "output triangles | input bytes | output bytes | Hausdorff (m) | Chamfer (m) |"
    )
    lines = [head, "|" + "---|" * 11]
    for r in rows:
        lines.append(
            f"| {r['level']} | {r['components']} | {r['terminals']} | {r['nonterminals']} | "
            f"{r['rules']} | {r['input_triangles']:,} | {r['output_triangles']:,} | "
            f"{r['input_bytes']:,} | {r['output_bytes']:,} | {r['hausdorff']:.4g} | "
            f"{r['chamfer']:.4g} |"
        )
    return "\n".join(lines)


__all__ = ["run", "stats_table", "BgrError"]
