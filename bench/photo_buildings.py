"""``bgr infer --kind image`` end to end on the three street photographs of
``../shared/data/facades/photos`` with the outlines drawn in ``bench/photos/`` (issue 28's third
acceptance point).

    python bench/photo_buildings.py [--photos DIR] [--previews docs/images]

For each photograph: the command's wall time, that the grammar derives (and its triangles), the
silhouette IoU of the rendered model with the outline, the mass family, the floors and the
scale; the previews go to ``--previews`` as ``photo-<name>.png``.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PHOTOS = ROOT.parent / "shared" / "data" / "facades" / "photos"
NAMES = ("building", "leuvenA", "leuvenB")


def run(photo: Path, outline: Path, out: Path, preview: Path) -> tuple[float, str]:
    start = time.perf_counter()
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "bgr",
            "infer",
            str(photo),
            "--kind",
            "image",
            "--silhouette",
            str(outline),
            "-o",
            str(out),
            "--preview",
            str(preview),
        ],
        capture_output=True,
        text=True,
    )
    seconds = time.perf_counter() - start
    if done.returncode:
        raise SystemExit(f"{photo.name}: exit {done.returncode}\n{done.stderr}")
    return seconds, done.stderr


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--photos", default=str(PHOTOS))
    parser.add_argument("--previews", default=str(ROOT / "docs" / "images"))
    args = parser.parse_args()
    import bgr

    for name in NAMES:
        photo = Path(args.photos) / f"{name}.jpg"
        if not photo.exists():
            print(f"{name}: {photo} is missing, skipped")
            continue
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / f"{name}.bgr"
            preview = Path(args.previews) / f"photo-{name}.png"
            seconds, log = run(photo, ROOT / "bench" / "photos" / f"{name}.json", out, preview)
            result = bgr.derive(out)
            lines = [line.removeprefix("bgr infer: ") for line in log.splitlines()]
            summary = "; ".join(
                line for line in lines if line.startswith(("mass:", "façade:", "preview"))
            )
            print(
                f"{name}: {seconds:.1f} s, derives {len(result.mesh.faces):,} triangles; {summary}"
            )


if __name__ == "__main__":
    main()
