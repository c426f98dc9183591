"""``bgr retarget BOXES.json --size W,H,D``: structure-preserving retargeting of a box
hierarchy (inverse/boxes; the work is in its command.py)."""

from __future__ import annotations

from .common import add_allow_path, whole
from .options import add_memory_option, under_ceiling


def add_parser(commands) -> None:
    retarget = commands.add_parser(
        "retarget",
        help="resize a box hierarchy, replicating, scaling and fixing its boxes",
        description="Structure-preserving retargeting of a box hierarchy (docs/inverse-boxes.md): "
        "resize it to --size one axis at a time, R boxes replicated or deleted, S boxes "
        "scaled, F boxes kept, alignments kept where they can be. Writes the retargeted boxes "
        "(.json, itself a valid input) or a model with each box's mesh fitted (.glb .gltf .obj "
        ".ply .stl .city.json; a cube for a leaf without one).",
    )
    retarget.add_argument("input", metavar="BOXES.json", help="the box hierarchy")
    retarget.add_argument(
        "--size", required=True, metavar="W,H,D", help="the new size in metres: x, y (up), z"
    )
    retarget.add_argument(
        "--order",
        default="xyz",
        metavar="AXES",
        help="the axes in the order they are retargeted (default xyz); the order changes the "
        "result, e.g. yx against xy",
    )
    retarget.add_argument(
        "-o", "--output", metavar="OUT", help="OUT.json or a model file (default: JSON on stdout)"
    )
    retarget.add_argument(
        "--max-boxes",
        type=whole,
        default=200_000,
        metavar="N",
        help="refuse an input or a result of more than N boxes (default 200000: about 1 GB "
        "and 10 s)",
    )
    add_memory_option(retarget)
    add_allow_path(
        retarget,
        "also let box meshes be read from under DIR (repeatable); by default they must "
        "stay in the boxes file's folder",
    )


def run(args) -> int:
    from ..inverse.boxes.command import run_retarget

    return under_ceiling(args, "retarget", "ask a smaller size, or give fewer boxes", run_retarget)
