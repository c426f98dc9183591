"""Benchmark: style sheets (issue 27: "capture of a 5,000-polygon textured model under 3 s and
one retargeted generation under 1 s; the paper: about 30 s and 10 s").

    python bench/style.py [--runs 5] [--plateau ../shared/data/textured/plateau_tokyo/...gml]

1. **Capture** = ``bgr.inverse.style.capture.infer_style(path)``, what ``bgr infer --kind
   style`` computes before it writes the grammar and its crops (timed apart, once): reading the
   model, the standard view and remeshed floors, blocks and walls, the face textures, the
   groups and their rules, the grammar's text and the PNG crops.  Inputs: the PLATEAU file
   (10 textured buildings; its polygon and triangle counts are printed: the 5,000 of the issue
   are triangles, what a renderer draws and what the readers hold) and the synthetic wedding
   cake of tests/style_synth.py (kind 2, three blocks) with each storey face tessellated into
   tiles under its one projection until it has about 5,000 triangles.
2. **One retargeted generation** = ``bgr restyle MASS --style STYLE`` in-process: loading and
   checking the style sheet, reading the mass GLB, its floors and blocks, matching them to the
   sheet's blocks (equations 6-7), deriving every block with the sheet's rules (equations 8-9
   in the grammar, every crop image read) and writing the styled GLB.  Onto the three masses of
   examples/style (derived to GLB first), with the PLATEAU sheet's largest building (section 1)
   and with the synthetic building's sheet; once loading the sheet in every run (of PLATEAU's,
   section 1 alone: inverse/style/sections.py), once with the sheet loaded beforehand
   (``restyle`` takes a loaded Grammar: a designer styles many masses with one sheet).  And
   ``bgr derive STYLE --lot 32,16 -o out.glb``: load, derive, write.

Texture images are decoded once per process (grammar/textures.py): the warm-up run decodes the
crops and the timed runs read their bytes and find them decoded, as a second ``restyle`` in one
process does (a fresh ``bgr restyle`` process decodes each crop once).

Each figure is the median of ``--runs`` runs in this process after one warm-up (imports and
Lark's parser tables are not counted; a fresh ``bgr`` process adds about 0.5 s of imports).
Prints Markdown table rows for docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import re
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PLATEAU = (
    ROOT.parent / "shared" / "data" / "textured" / "plateau_tokyo" / "53392633_bldg_6697_2_op.gml"
)
MASSES = ROOT / "examples" / "style"
sys.path.insert(0, str(ROOT / "tests"))


def timed(fn: Callable[[], object], runs: int) -> tuple[float, list[float]]:
    """Median seconds of ``runs`` calls after one warm-up call, and every run's seconds."""
    fn()
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), times


def capture(path: Path) -> tuple[str, dict[str, bytes]]:
    """What ``bgr infer --kind style`` computes: the sheet's text and its crops' PNG bytes."""
    from bgr.inverse.style.capture import infer_style

    text, files, _ = infer_style(str(path), assets="style.assets")
    return text, files


def write(text: str, files: dict[str, bytes], out: Path) -> float:
    """Seconds to write the sheet and its crops as ``bgr infer`` does (timed once, apart: this
    VM's disk is shared, and rewriting 3,000 small files takes 0.2 s or 6 s by its mood)."""
    start = time.perf_counter()
    (out / "style.bgr").write_text(text)
    assets = out / "style.assets"
    assets.mkdir(exist_ok=True)
    for name, data in files.items():
        (assets / name).write_bytes(data)
    return time.perf_counter() - start


def tessellated(folder: Path, tile: float) -> Path:
    """The synthetic wedding cake (tests/style_synth.py, kind 2) with every storey face split
    into ``tile``-metre tiles under its one projection: the same façades, more triangles."""
    from style_synth import make_building

    import bgr

    _, truth = make_building(2, folder)
    text = truth.grammar.read_text().replace("terminal Storey", "terminal Tile")
    text += f"Storey --> split(x) {{ {{ ~{tile}: Tile }}* }}\n"
    grammar = folder / "tessellated.bgr"
    grammar.write_text(text)
    glb = folder / "tessellated.glb"
    bgr.derive(grammar).save(glb)
    return glb


def counts(path: Path) -> str:
    from bgr.inverse.style.capture import read_model

    mesh = read_model(str(path))
    polygons = ""
    if path.suffix == ".gml":
        polygons = f"{len(re.findall(r'<gml:Polygon[ >]', path.read_text())):,} polygons, "
    return f"{polygons}{len(mesh.faces):,} triangles"


def masses(folder: Path) -> dict[str, Path]:
    import bgr

    out = {}
    for name, lot in (("slab", None), ("l_block", MASSES / "lot.geojson"), ("two_stack", None)):
        glb = folder / f"{name}.glb"
        bgr.derive(MASSES / f"{name}.bgr", lot=str(lot) if lot else None).save(glb)
        out[name] = glb
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--plateau", type=Path, default=PLATEAU)
    ap.add_argument("--tile", type=float, default=0.34, help="tile size of the synthetic model")
    args = ap.parse_args()
    from bgr.grammar.checker import Grammar
    from bgr.grammar.loader import load
    from bgr.interpreter.derive import derive
    from bgr.inverse.style.restyle import restyle
    from bgr.inverse.style.sections import load_section

    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp)
        sheets: dict[str, tuple[Path, int]] = {}
        print("| capture | model | median | runs | grammar lines | crops | writing them |")
        print("|---|---|---|---|---|---|---|")
        inputs = [("synthetic wedding cake, tessellated", tessellated(base / "synth", args.tile))]
        if args.plateau.is_file():
            inputs.insert(0, ("PLATEAU 53392633 (10 buildings)", args.plateau))
        else:
            print(f"{args.plateau}: not here, skipped", file=sys.stderr)
        for label, path in inputs:
            out = base / f"sheet{len(sheets)}"
            out.mkdir()
            median, times = timed(lambda p=path: capture(p), args.runs)
            text, files = capture(path)
            written = write(text, files, out)
            sheets[label] = (out / "style.bgr", 1 if "PLATEAU" in label else 0)
            runs = ", ".join(f"{t:.2f}" for t in times)
            print(
                f"| {label} | {counts(path)} | **{median:.2f} s** | {runs} | "
                f"{text.count(chr(10)):,} | {len(files):,} | {written:.2f} s |"
            )
        print()
        print("| retargeted generation | style sheet | sheet loaded | median | runs | triangles |")
        print("|---|---|---|---|---|---|")
        targets = masses(base)
        for label, (sheet, section) in sheets.items():
            start = time.perf_counter()
            loaded = load(sheet)
            print(
                f"| loading and checking the sheet | {label} | - | "
                f"{time.perf_counter() - start:.2f} s | 1 | - |"
            )
            start = time.perf_counter()
            _, alone = load_section(sheet, section)
            if alone:  # what bgr restyle --section N loads of a sheet of several buildings
                print(
                    f"| loading and checking section {section} alone | {label} | - | "
                    f"{time.perf_counter() - start:.2f} s | 1 | - |"
                )
            for name, glb in targets.items():
                styled = base / f"styled_{name}.glb"
                for once in (False, True):

                    def one(
                        g: Path = glb,
                        s: Path | Grammar = loaded if once else sheet,
                        k: int = section,
                        o: Path = styled,
                    ):
                        result, _ = restyle(
                            str(g), s if isinstance(s, Grammar) else str(s), section=k
                        )
                        result.save(o)
                        return result

                    median, times = timed(one, args.runs)
                    tris = len(one().mesh.faces)
                    runs = ", ".join(f"{t:.2f}" for t in times)
                    where = f"{label}, section {section}" if "PLATEAU" in label else label
                    print(
                        f"| bgr restyle {name}.glb | {where} | {'once' if once else 'each run'} "
                        f"| **{median:.2f} s** | {runs} | {tris:,} |"
                    )
            out = base / "derived.glb"

            def lot(s: Path = sheet, k: int = section, o: Path = out):
                result = derive(s, lot=(32.0, 16.0), attrs={"style": k} if k else None)
                result.save(o)
                return result

            median, times = timed(lot, args.runs)
            runs = ", ".join(f"{t:.2f}" for t in times)
            print(
                f"| bgr derive --lot 32,16 | {label} | each run | **{median:.2f} s** | {runs} | "
                f"{len(lot().mesh.faces):,} |"
            )


if __name__ == "__main__":
    main()
