"""Benchmark: parse and check a generated 5,000-line grammar (the size of an inferred city grammar).

    python bench/parse_check.py [--lines 5000] [--repeat 5]

Prints the timings of parsing alone and of ``bgr.load`` (parse + resolve + check) as the median
and best of several runs, each in a fresh grammar text of the requested size.  Target (issue 2):
under 2 s for 5,000 lines.
"""

from __future__ import annotations

import argparse
import platform
import random
import statistics
import time

import bgr
from bgr.grammar.parser import parse


def generate(lines: int = 5000, seed: int = 0) -> str:
    """A valid grammar of at least ``lines`` lines: whole buildings of 11 varied lines each."""
    rng = random.Random(seed)
    out = [
        "version 1",
        "attr height = 18",
        "const floor_h = 3.2",
        "func storeys(h) = floor(h / floor_h)",
        "terminal Glass, Frame",
        "",
    ]
    i = 0
    while len(out) < lines:
        out += [
            f"# building {i}",
            f"Lot{i} --> extrude(height * {rng.uniform(0.5, 2):.3f}) comp(f) "
            f"{{ top: Roof{i} | front: Front{i} | side: Facade{i} }}",
            f'Roof{i} --> roof(hip, {rng.randint(20, 45)}, 0.4) color("#8a4b3c")',
            f"Front{i} --> split(y) "
            f"{{ 4: Shop{i} | {{ ~floor_h: Floor{i}(split.index) }}* | 1: Cornice{i} }}",
            f"Facade{i} --> split(y) {{ ~floor_h: Floor{i}(split.index) }}*",
            f"Floor{i}(k) --> split(x) {{ 1: Wall{i} | {{ ~3: Tile{i}(k) }}* | 1: Wall{i} }}",
            f"Tile{i}(k) --> case k == 0: Wall{i} | case scope.sx < 1.2: Wall{i} | else: split(x) "
            f"{{ ~1: Wall{i} | 1.5: Win{i} | ~1: Wall{i} }}",
            f"Win{i} --> 60%: [ t(0, 0, -0.2) i(cube) Glass ] Frame | 30%: s('1, '0.8, 0) Glass | "
            "else: NIL",
            f"Shop{i} --> split(x) "
            f"{{ 0.5: Wall{i} | {{ ~4: offset(-0.2) {{ inside: Glass | border: Frame }} }}* "
            f"| 0.5: Wall{i} }}",
            f"Cornice{i} --> extrude(0.3 + rand(0, 0.2)) color(0.8, 0.8, 0.7)",
            f'Wall{i} --> color("#d8d0c0")',
        ]
        i += 1
    return "\n".join(out) + "\n"


def timed(fn, *args) -> float:
    start = time.perf_counter()
    fn(*args)
    return time.perf_counter() - start


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lines", type=int, default=5000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    parse("A --> B\n")  # build the LALR tables once, as a long-running process would
    text = generate(args.lines)
    n_lines, n_tokens = (
        len(text.splitlines()),
        sum(1 for _ in __import__("re").finditer(r"\S+", text)),
    )
    parse_times = [timed(parse, text) for _ in range(args.repeat)]
    load_times = [timed(bgr.load, text) for _ in range(args.repeat)]
    print(
        f"machine: {platform.processor() or platform.machine()}, Python "
        f"{platform.python_version()}, "
        f"bgr {bgr.__version__}"
    )
    print(f"input: {n_lines} lines, {len(text)} characters, ~{n_tokens} words")
    print(
        f"parse only:           median {statistics.median(parse_times):.3f} s, best "
        f"{min(parse_times):.3f} s"
    )
    print(
        f"load (parse + check): median {statistics.median(load_times):.3f} s, best "
        f"{min(load_times):.3f} s"
    )
    print(f"lines per second (load, median): {n_lines / statistics.median(load_times):,.0f}")
    print("target: under 2 s ->", "met" if statistics.median(load_times) < 2.0 else "NOT met")


if __name__ == "__main__":
    main()
