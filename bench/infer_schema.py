"""Time `bgr infer --kind schema` on models of 5,000 subfaces and more (issue 5: under 2 s).

    python bench/infer_schema.py [--sizes 5000 20000] [--repeats 5]

Each model is the terminal list of a façade grammar (shops, a corner entrance, window tiles with
sills, a cornice) derived on a lot sized to give about the asked number of subfaces; the timed
part is what `bgr infer terminals.json` does: read the JSON, rebuild the faces, infer the
schemas, print the grammar.  Prints one line per size: subfaces, median and best seconds, rules.
"""

from __future__ import annotations

import argparse
import io
import json
import math
import statistics
import time

import bgr
from bgr.formats import write_json
from bgr.inverse.schema import infer

GRAMMAR = """\
attr W = 30
attr D = 20
attr H = 40
terminal Wall, Window, Sill, Shop, Door, Cornice, Pier, Roof
Lot --> s(W, 0, D) extrude(H) comp(f) { front: Front | side: Side | top: Roof | bottom: NIL }
Front --> split(y) { 4.5: Ground | { ~3.2: Floor }* | 0.8: Cornice }
Side --> split(y) { 4.5: Floor | { ~3.2: Floor }* | 0.8: Cornice }
Ground --> split(x) { 1: Pier | 2.4: Door | { ~3: Shop | 0.6: Pier }* | 1: Pier }
Floor --> split(x) { 0.6: Pier | { ~3: Tile }* | 0.6: Pier }
Tile --> split(x) { ~0.8: Wall | 1.3: WinCol | ~0.8: Wall }
WinCol --> split(y) { 0.9: Wall | 0.1: Sill | 1.6: Window | ~0.6: Wall }
"""


def model_json(subfaces: int) -> tuple[str, int]:
    """The terminal list of GRAMMAR with its height and width scaled to about ``subfaces``."""
    base = bgr.derive(bgr.load(GRAMMAR)).terminals
    factor = math.sqrt(subfaces / len(base))
    attrs = {"W": round(30 * factor, 1), "D": round(20 * factor, 1), "H": round(40 * factor, 1)}
    result = bgr.derive(bgr.load(GRAMMAR), attrs=attrs)
    buffer = io.StringIO()
    write_json(result.terminals, buffer, seed=0, attrs=attrs)
    return buffer.getvalue(), len(result)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[5000, 20000])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print("subfaces  median s  best s  rules  grammar lines")
    for size in args.sizes:
        text, count = model_json(size)
        times = []
        for _ in range(args.repeats):
            start = time.perf_counter()
            module = infer(json.loads(text))
            grammar = bgr.format_module(module)
            times.append(time.perf_counter() - start)
        rules = sum(1 for item in module.items if type(item).__name__ == "Rule")
        print(
            f"{count:8,d}  {statistics.median(times):8.3f}  {min(times):6.3f}  {rules:5d}  "
            f"{grammar.count(chr(10)):5d}"
        )


if __name__ == "__main__":
    main()
