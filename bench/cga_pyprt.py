"""Any rule package's CGA against CityEngine's own output: triangles and report sums.

    python bench/cga_pyprt.py RPK_FOLDER rules/typology/envelope2002.cga \\
        [--pyprt PYTHON --rpk envelope2002.rpk] [--lot 40,30]

RPK_FOLDER is an Esri rule package (a 7-zip archive) extracted: its ``rules/`` and ``assets/``.
bgr imports the named CGA file (and what it imports: ``bgr import-cga``), derives it on a W x D
lot with its default attributes and counts its triangles and its reports (each key's count and
sum).  With ``--pyprt`` (the Python of a separate environment with ``pip install pyprt``; PyPRT's
runtime may not be redistributed, so it is never a dependency of bgr) the package itself is
generated on the same lot by CityEngine's procedural runtime and measured the same way (each
n-gon as n - 2 triangles).  bench/cga_candler.py does this for Candler's two modes.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import tempfile
from pathlib import Path

import bgr
from bgr.cga.files import translate_file

PYPRT = """
import json, sys, pyprt
rpk, w, d = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
# the first edge (the scope's x, as bgr's --lot W,D) along +x and W long, the normal up
lot = [0, 0, d, w, 0, d, w, 0, 0, 0, 0, 0]
model = pyprt.ModelGenerator([pyprt.InitialShape(lot)])
g = model.generate_model([{}], rpk, "com.esri.pyprt.PyEncoder",
                         {"emitReport": True, "emitGeometry": True})[0]
report = g.get_report()
keys = sorted({k.rsplit("_", 1)[0] for k in report})
print(json.dumps({
    "triangles": sum(max(n - 2, 0) for n in g.get_faces()),
    "reports": {k: [report.get(k + "_n", 0), report.get(k + "_sum", 0)] for k in keys},
}))
"""


def measure_bgr(folder: Path, rule: str, lot: tuple[float, float]) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / (Path(rule).stem + ".bgr")
        result = translate_file(folder / rule, out)
        for path, text in result.outputs.items():
            path.write_text(text, encoding="utf-8")
        derived = bgr.derive(bgr.load(out, allow_paths=[folder]), lot=lot)
        (lot_reports,) = derived.reports
        return {
            "triangles": int(len(derived.mesh.faces)),
            "reports": {
                k: [v["count"], v.get("sum", 0.0)] for k, v in lot_reports["reports"].items()
            },
            "untranslated": len(result.warnings),
        }


def run_pyprt(python: str, script: str, rpk: str, lot: tuple[float, float]) -> dict:
    """What ``script`` prints last (JSON) when run by ``python`` (a separate environment with
    PyPRT) on the package and a W x D lot: CityEngine's own measurements."""
    done = subprocess.run(
        [python, "-c", script, rpk, str(lot[0]), str(lot[1])],
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def _shown(value) -> str:
    """A report's number to one decimal; a string report's value as it is."""
    return f"{value:.1f}" if isinstance(value, (int, float)) else repr(value)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("folder", type=Path, help="the rule package extracted")
    ap.add_argument("rule", help="the CGA file, relative to the folder")
    ap.add_argument("--pyprt", help="a Python with pyprt installed")
    ap.add_argument("--rpk", help="the rule package itself, for PyPRT")
    ap.add_argument("--lot", default="40,30")
    args = ap.parse_args()
    w, d = (float(v) for v in args.lot.split(","))
    ours = measure_bgr(args.folder, args.rule, (w, d))
    theirs = run_pyprt(args.pyprt, PYPRT, args.rpk, (w, d)) if args.pyprt else None
    print(f"constructs not translated: {ours['untranslated']}")
    line = f"triangles: bgr {ours['triangles']:,}"
    if theirs:
        line += f", CityEngine {theirs['triangles']:,}"
    print(line)
    keys = sorted(set(ours["reports"]) | set(theirs["reports"] if theirs else {}))
    for key in keys:
        mine = ours["reports"].get(key, [0, 0.0])
        line = f"report {key!r}: bgr n={mine[0]} sum={_shown(mine[1])}"
        if theirs:
            other = theirs["reports"].get(key, [0, 0.0])
            line += f"; CityEngine n={_shown(other[0])} sum={_shown(other[1])}"
        print(line)


if __name__ == "__main__":
    main()
