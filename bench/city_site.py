"""Does an inferred city land where its input was?  (issue 29: the input's frame in the grammar)

    python bench/city_site.py [--levels] [FILE ...]   (default: every city of ../shared/data/cities)

For each input: ``bgr infer`` (level 0), then ``bgr derive`` of the grammar to OBJ, CityJSON
and GLB, each loaded back with no offset applied — OBJ and GLB by trimesh (the GLB through its
node transforms, turned from glTF's y up to z up), CityJSON by its ``transform`` — and measured
against the input with trimesh's ``closest_point`` (point to surface, both ways: the output's
vertices and surface samples to the input, the input's to the output).  OBJ inputs are read by
trimesh; CityJSON ones by bgr's reader (trimesh has none), put back in their own frame.

Prints two Markdown tables: the size of the grammar and of its one assets file against the
city's OBJ (its own OBJ file where one is shipped, else its triangles written as OBJ to the
millimetre); and the grammar's site line, and per output the symmetric Hausdorff distance
(metres) and the offset between the two bounding boxes' lowest corners.  ``--levels`` adds a
third: every level above 0, its size against the OBJ and against the input file (they differ
for CityJSON inputs), and its Chamfer distance to the input
(the mean of the two one-way mean distances, trimesh's ``closest_point``).
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import trimesh

ROOT = Path(__file__).resolve().parent.parent
CITIES = ROOT.parent / "shared" / "data" / "cities"
SAMPLES = 20_000


def bgr(*args: str) -> None:
    run = subprocess.run([sys.executable, "-m", "bgr", *args], capture_output=True, text=True)
    if run.returncode:
        raise SystemExit(f"bgr {' '.join(args)}: exit {run.returncode}\n{run.stderr}")


def lods_of(path: Path) -> list[str | None]:
    """The levels of detail of a CityJSON file whose objects have several (each measured on its
    own, ``bgr infer --lod``), else [None]: the file as bgr reads it by default."""
    if path.suffix != ".json":
        return [None]
    doc = json.loads(path.read_text())
    found = {
        str(g["lod"])
        for obj in doc.get("CityObjects", {}).values()
        for g in obj.get("geometry", [])
        if "lod" in g
    }
    return sorted(found) if len(found) > 1 else [None]


def read_input(path: Path, lod: str | None = None) -> trimesh.Trimesh:
    if path.suffix == ".obj":
        return trimesh.load(path, force="mesh", process=False)
    from bgr.inverse.city.read import read_city

    scene = read_city(str(path), lod=lod)
    parts = [(scene.to_input(o.vertices), o.faces) for o in scene.objects]
    return trimesh.util.concatenate([trimesh.Trimesh(v, f, process=False) for v, f in parts])


def read_output(path: Path) -> trimesh.Trimesh:
    if path.name.endswith(".city.json"):
        doc = json.loads(path.read_text())
        t = doc["transform"]
        vertices = np.array(doc["vertices"], dtype=np.float64) * t["scale"] + t["translate"]
        faces = []
        for obj in doc["CityObjects"].values():
            for geometry in obj.get("geometry", []):
                for surface in geometry["boundaries"]:
                    ring = surface[0]
                    faces += [[ring[0], ring[k], ring[k + 1]] for k in range(1, len(ring) - 1)]
        return trimesh.Trimesh(vertices, np.array(faces), process=False)
    mesh = trimesh.load(path, force="mesh", process=False)
    if path.suffix == ".glb":  # glTF is y up: (east, up, -north)
        v = mesh.vertices
        mesh = trimesh.Trimesh(np.column_stack([v[:, 0], -v[:, 2], v[:, 1]]), mesh.faces)
    return mesh


def distances(to: trimesh.Trimesh, source: trimesh.Trimesh) -> np.ndarray:
    points = np.vstack([source.vertices, trimesh.sample.sample_surface(source, SAMPLES, seed=1)[0]])
    _, distance, _ = trimesh.proximity.closest_point(to, points)
    return distance


def one_way(to: trimesh.Trimesh, source: trimesh.Trimesh) -> float:
    return float(distances(to, source).max())


def obj_bytes(path: Path, truth: trimesh.Trimesh, lod: str | None = None) -> int:
    """The size of the city as OBJ: its own OBJ file where ../shared/data has one, else its
    triangles (at ``lod``) written as OBJ to the millimetre (as the shipped OBJ files are)."""
    if path.suffix == ".obj":
        return path.stat().st_size
    beside = path.with_name(path.name.replace(".city.json", ".obj"))
    if beside.is_file() and lod is None:
        return beside.stat().st_size
    lines = [f"v {x:.3f} {y:.3f} {z:.3f}" for x, y, z in truth.vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in truth.faces]
    return len(("\n".join(lines) + "\n").encode())


def buildings_obj(path: Path, out: Path) -> bool:
    """The input's buildings alone (what bgr proceduralizes; roads, terrain and water are
    carried as they are) as OBJ, an ``o`` per building, to the millimetre in the input's frame;
    False when the input has nothing else."""
    from bgr.inverse.city.read import read_city

    scene = read_city(str(path))
    kept = [o for o in scene.objects if o.proceduralize]
    if len(kept) == len(scene.objects):
        return False
    lines, base = [], 1
    for o in kept:
        lines.append(f"o {o.name}")
        lines += [f"v {x:.3f} {y:.3f} {z:.3f}" for x, y, z in scene.to_input(o.vertices)]
        lines += [f"f {a + base} {b + base} {c + base}" for a, b, c in o.faces]
        base += len(o.vertices)
    out.write_text("\n".join(lines) + "\n")
    return True


def folder_bytes(folder: Path) -> int:
    return sum(p.stat().st_size for p in folder.iterdir()) if folder.is_dir() else 0


def levels(path: Path, truth: trimesh.Trimesh, obj: int, lod: str | None, name: str) -> list[str]:
    """Each level above 0: grammar + assets against the OBJ, and the Chamfer distance (mean of
    the two one-way mean distances) of its derived OBJ to the input, measured by trimesh."""
    rows, level, last = [], 1, 1
    while level <= last:
        with tempfile.TemporaryDirectory() as tmp:
            grammar = Path(tmp) / "city.bgr"
            pick = ["--lod", lod] if lod else []
            bgr(
                "infer",
                str(path),
                *pick,
                "--no-progress",
                "--level",
                str(level),
                "-o",
                str(grammar),
            )
            # the header says "(level L of M)": a level past M is M again
            found = re.search(r"\(level \d+ of (\d+)\)", grammar.read_text())
            last = int(found.group(1)) if found else level
            size = grammar.stat().st_size + folder_bytes(Path(tmp) / "city.assets")
            out = Path(tmp) / "out.obj"
            bgr("derive", str(grammar), "-o", str(out))
            mesh = read_output(out)
            chamfer = (distances(truth, mesh).mean() + distances(mesh, truth).mean()) / 2
            given = path.stat().st_size  # the input file, as the user has it
            rows.append(
                f"| {name} | {level} | {size:,} | {obj / size:.1f} | {given / size:.1f} | "
                f"{chamfer:.3f} |"
            )
        level += 1
    return rows


def main() -> None:
    flags = {a for a in sys.argv[1:] if a.startswith("--")}
    files = [Path(a) for a in sys.argv[1:] if not a.startswith("--")] or sorted(
        p for p in CITIES.iterdir() if p.suffix in (".obj", ".json")
    )
    rows, sizes, coarse = [], [], []
    for path, lod in [(p, lod) for p in files for lod in lods_of(p)]:
        name = path.name if lod is None else f"{path.name} (LoD {lod})"
        pick = ["--lod", lod] if lod else []
        truth = read_input(path, lod)
        obj = obj_bytes(path, truth, lod)
        with tempfile.TemporaryDirectory() as tmp:
            grammar = Path(tmp) / "city.bgr"
            bgr("infer", str(path), *pick, "--no-progress", "-o", str(grammar))
            assets = folder_bytes(Path(tmp) / "city.assets")
            text = grammar.stat().st_size
            size = path.stat().st_size
            sizes.append(
                f"| {name} | {size:,} | {obj:,} | {text:,} | {assets:,} | "
                f"{(text + assets) / obj:.2f} |"
            )
            site = next(
                (line for line in grammar.read_text().splitlines() if line.startswith("site ")),
                "(none)",
            )
            for ext in ("obj", "city.json", "glb"):
                out = Path(tmp) / f"out.{ext}"
                bgr("derive", str(grammar), "-o", str(out))
                mesh = read_output(out)
                distance = max(one_way(truth, mesh), one_way(mesh, truth))
                offset = float(np.abs(mesh.bounds[0] - truth.bounds[0]).max())
                rows.append(f"| {name} | `{site}` | .{ext} | {distance:.4f} | {offset:.4f} |")
        with tempfile.TemporaryDirectory() as tmp:
            alone = Path(tmp) / "buildings.obj"
            if lod is None and buildings_obj(path, alone):
                grammar = Path(tmp) / "city.bgr"
                bgr("infer", str(alone), "--no-progress", "-o", str(grammar))
                text, assets = grammar.stat().st_size, folder_bytes(Path(tmp) / "city.assets")
                alone_obj = alone.stat().st_size
                sizes.append(
                    f"| {path.name}, buildings only | | {alone_obj:,} | {text:,} | {assets:,} | "
                    f"{(text + assets) / alone_obj:.2f} |"
                )
        if "--levels" in flags:
            coarse += levels(path, truth, obj, lod, name)
    head = "| input | input bytes | OBJ bytes | grammar bytes | assets bytes |"
    print(head + " (grammar + assets) / OBJ |")
    print("|---|---|---|---|---|---|")
    print("\n".join(sizes) + "\n")
    print("| input | site line | output | Hausdorff (m) | lowest corner offset (m) |")
    print("|---|---|---|---|---|")
    print("\n".join(rows))
    if coarse:
        print(
            "\n| input | level | grammar + assets bytes | OBJ / that | input file / that "
            "| Chamfer (m) |"
        )
        print("|---|---|---|---|---|---|")
        print("\n".join(coarse))


if __name__ == "__main__":
    main()
