"""How many CGA rule files `bgr import-cga` carries across: import, check, derive on a lot.

    python bench/cga_corpus.py FOLDER [--lot 40,30] [--out DIR]

Each ``*.cga`` under FOLDER is translated (its imports beside it), the grammar is loaded with its
folder and the CGA file's folder allowed (assets of rule packages), and derived on the lot with a
shape budget.  One line per file says how far it got and why it stopped; the last line counts
them.  The CGA files themselves are not in the repository (their licences vary): docs/cli.md
("bgr import-cga") says which public repositories the measured corpus came from.
"""

from __future__ import annotations

import argparse
import collections
import sys
import tempfile
from pathlib import Path

import bgr
from bgr.cga.files import translate_file
from bgr.grammar.errors import BgrError


def one(src: Path, out_dir: Path, lot: tuple[float, float]) -> tuple[str, str]:
    out = out_dir / (src.stem + ".bgr")
    try:
        result = translate_file(src, out)
    except BgrError as e:
        return "not imported", e.diagnostics[0].render().split("\n")[0]
    for path, text in result.outputs.items():
        path.write_text(text, encoding="utf-8")
    note = f"{len(result.warnings)} not translated"
    try:
        grammar = bgr.load(out, allow_paths=[src.parent, src.parent.parent])
    except BgrError as e:
        return "not checked", f"{note}; " + e.diagnostics[0].render().split("\n")[0]
    if not grammar.module.rules():
        return "no rules", note
    try:
        derived = bgr.derive(grammar, lot=lot, max_shapes=300_000)
    except BgrError as e:
        return "not derived", f"{note}; " + e.diagnostics[0].render().split("\n")[0]
    return "derived", f"{note}; {len(derived)} terminals"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("folder", type=Path)
    ap.add_argument("--lot", default="40,30")
    ap.add_argument("--pattern", default="*.cga", help="which files under FOLDER (default *.cga)")
    ap.add_argument(
        "--out", type=Path, help="where the .bgr files go (default: a temporary folder)"
    )
    args = ap.parse_args(argv)
    lot = tuple(float(v) for v in args.lot.split(","))
    files = sorted(args.folder.glob(args.pattern))
    counts: collections.Counter[str] = collections.Counter()
    with tempfile.TemporaryDirectory() as tmp:
        out_root = args.out or Path(tmp)
        for k, src in enumerate(files):
            out_dir = out_root / f"{k:03d}"
            out_dir.mkdir(parents=True, exist_ok=True)
            status, detail = one(src, out_dir, lot)  # type: ignore[arg-type]
            counts[status] += 1
            print(f"{status:12} {src.relative_to(args.folder)}: {detail}", flush=True)
    summary = ", ".join(
        f"{counts[s]} {s}"
        for s in ("derived", "no rules", "not derived", "not checked", "not imported")
        if counts[s]
    )
    print(f"{len(files)} files: {summary}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
