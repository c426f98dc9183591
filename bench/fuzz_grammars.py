"""The long run of the hostile-mutation grammar fuzzing, with progress and a count of failures.

``pytest tests/test_fuzz.py -k hostile_mutations --fuzz-cases N`` stops at the first failure and
prints nothing until it ends.  This script draws the same cases (the ``hostile_mutations``
strategy of tests/test_fuzz.py) and runs each through the same ``derive_and_write`` (load, fmt,
a bounded derive, GLB/OBJ/JSON writers, a 10 s limit per case), but keeps going after a failure,
saves each failing grammar to ``OUT/failures/``, and prints a progress line every ``--every``
cases.  The property is the test's: success or one ``BgrError``; anything else, and any case
over 10 s, is a failure.  Results go in docs/fuzzing.md.

    python bench/fuzz_grammars.py --cases 50000 --seed 1 --out /tmp/fuzz1
"""

from __future__ import annotations

import argparse
import json
import resource
import sys
import tempfile
import time
import traceback
import warnings
from pathlib import Path

from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import seed as hypothesis_seed

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

import test_fuzz  # noqa: E402  (the strategy and the case runner live with the test)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=1000, help="cases to run (default 1000)")
    parser.add_argument("--seed", type=int, default=0, help="hypothesis seed (default 0)")
    parser.add_argument("--every", type=int, default=500, help="progress line every N cases")
    parser.add_argument("--out", type=Path, default=None, help="where failures and summary go")
    args = parser.parse_args(argv)
    out = args.out or Path(tempfile.mkdtemp(prefix="bgr-fuzz-"))
    (out / "failures").mkdir(parents=True, exist_ok=True)

    stats = {"cases": 0, "failures": 0, "max_case_s": 0.0, "slowest": ""}
    start = time.perf_counter()

    @settings(
        max_examples=args.cases,
        deadline=None,
        database=None,
        phases=[Phase.generate],  # no shrinking: a failure is saved as drawn, and the run goes on
        suppress_health_check=list(HealthCheck),
    )
    @hypothesis_seed(args.seed)
    @given(test_fuzz.hostile_mutations())
    def run(case: tuple[Path, str]) -> None:
        path, text = case
        t0 = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                with tempfile.TemporaryDirectory() as tmp:
                    test_fuzz.derive_and_write(text, path.with_name("fuzz.bgr"), Path(tmp))
        except Exception as e:  # the property broken: record it and go on
            stats["failures"] += 1
            name = f"{stats['failures']:04d}-{type(e).__name__}"
            (out / "failures" / f"{name}.bgr").write_text(text, encoding="utf-8")
            (out / "failures" / f"{name}.txt").write_text(
                f"{path.name}\n{traceback.format_exc()}", encoding="utf-8"
            )
        seconds = time.perf_counter() - t0
        stats["cases"] += 1
        if seconds > stats["max_case_s"]:
            stats["max_case_s"], stats["slowest"] = seconds, path.name
        if stats["cases"] % args.every == 0:
            report(stats, start)

    run()
    report(stats, start)
    stats["seconds"] = round(time.perf_counter() - start, 1)
    stats["peak_mb"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
    stats["seed"] = args.seed
    (out / "summary.json").write_text(json.dumps(stats, indent=2) + "\n", encoding="utf-8")
    print(json.dumps(stats), flush=True)
    return 1 if stats["failures"] else 0


def report(stats: dict, start: float) -> None:
    elapsed = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(
        f"{stats['cases']} cases, {stats['failures']} failures, slowest case "
        f"{stats['max_case_s']:.2f} s ({stats['slowest']}), {elapsed:.0f} s, {peak:.0f} MB",
        flush=True,
    )


if __name__ == "__main__":
    sys.exit(main())
