"""Mutations of box hierarchies and captured models that keep them valid (bench/fuzz_inverse.py).

A byte flip or a number scaled by two almost always breaks what the readers check first (a child
inside its parent, parts that sum to their face), so 96 to 99 % of those mutants end as a clean
error before the analysis runs.  These mutators change the structure the way a real file
differs from the examples: a leaf split into slabs again and again (deep, wide hierarchies), a
subtree dropped, the whole model scaled or moved, boxes shrunk, behaviours and labels changed,
ids and labels made hostile (newlines, ``#``, quotes, ``-->``, 10,000 characters, each kept
unique), parts swapped or halved so that their sums still hold, and meshes pointed out of the
folder.  Each returns new bytes, or the input's own mutation by ``fallback`` when the file is no
longer the JSON it was.
"""

from __future__ import annotations

import json
import random
from collections.abc import Callable

HOSTILE_NAMES = (
    "a\nb", "rule\n-> evil", "# comment", '"quoted"', "'", "-->", "x" * 10_000, "é💥",
    "a b", "attr evil = 1", "import \"x.bgr\"", "\t", "-", "0", "",
)  # fmt: skip
HOSTILE_MESHES = ("../../../etc/passwd", "/dev/zero", "parts/missing.obj", "parts", "a\nb.obj")
SCALES = (1e-3, 0.1, 0.5, 3, 10, 1000)


def _nodes(node: dict) -> list[dict]:
    """Every box of a hierarchy, depth first."""
    out = [node]
    for child in node.get("children", []):
        out.extend(_nodes(child))
    return out


def _split_leaf(rng: random.Random, box: dict, serial: int) -> None:
    """Cut a box into 2 to 6 equal slabs along one axis: its children, so it stays valid."""
    axis = rng.randrange(3)
    lo, hi = box["min"][axis], box["max"][axis]
    count = rng.choice((2, 2, 3, 6))
    children = []
    for k in range(count):
        child_min, child_max = list(box["min"]), list(box["max"])
        child_min[axis] = lo + (hi - lo) * k / count
        child_max[axis] = lo + (hi - lo) * (k + 1) / count
        behavior = {a: rng.choice("SFR") for a in "xyz"}
        children.append(
            {
                "id": f"s{serial}-{k}",
                "min": child_min,
                "max": child_max,
                "behavior": behavior,
                "children": [],
            }  # fmt: skip
        )
    box["children"] = children


def _changed(rng: random.Random, data: bytes, fallback: Callable, change: Callable) -> bytes:
    """``change`` applied to the parsed document, or ``fallback``'s mutation when the file is
    not the JSON it was (an earlier mutation of the same case broke it)."""
    try:
        doc = json.loads(data)
        change(rng, doc)
        return json.dumps(doc).encode()
    except (ValueError, ArithmeticError, RecursionError, LookupError, TypeError, AttributeError):
        return fallback(rng, data)


def mutate_boxes(rng: random.Random, data: bytes, fallback: Callable) -> bytes:
    """One valid-preserving change to a box hierarchy (see the module)."""
    return _changed(rng, data, fallback, _change_boxes)


def mutate_captured(rng: random.Random, data: bytes, fallback: Callable) -> bytes:
    """One valid-preserving change to a captured model (see the module)."""
    return _changed(rng, data, fallback, _change_captured)


def _change_boxes(rng: random.Random, doc: dict) -> None:
    boxes = _nodes(doc["root"])
    roll = rng.random()
    if roll < 0.3:  # split leaves, repeatedly: deeper and wider hierarchies
        for serial in range(rng.choice((1, 3, 10, 40))):
            leaves = [b for b in _nodes(doc["root"]) if not b.get("children")]
            _split_leaf(rng, rng.choice(leaves), serial)
    elif roll < 0.4 and len(boxes) > 1:  # a subtree dropped
        parent = rng.choice([b for b in boxes if b.get("children")])
        parent["children"].pop(rng.randrange(len(parent["children"])))
    elif roll < 0.5:  # the whole model scaled or moved
        scale, shift = rng.choice(SCALES), rng.uniform(-1e4, 1e4) * rng.choice((0, 1))
        for box in boxes:
            box["min"] = [v * scale + shift for v in box["min"]]
            box["max"] = [v * scale + shift for v in box["max"]]
    elif roll < 0.6:  # a leaf shrunk towards its centre
        leaf = rng.choice([b for b in boxes if not b.get("children")])
        factor = rng.choice((0.999, 0.5, 1e-3))
        centre = [(a + b) / 2 for a, b in zip(leaf["min"], leaf["max"], strict=True)]
        leaf["min"] = [c + (a - c) * factor for a, c in zip(leaf["min"], centre, strict=True)]
        leaf["max"] = [c + (b - c) * factor for b, c in zip(leaf["max"], centre, strict=True)]
    elif roll < 0.7:  # behaviours changed
        for box in rng.sample(boxes, min(len(boxes), rng.choice((1, 5, 50)))):
            box["behavior"] = {a: rng.choice("SFR") for a in "xyz"}
    elif roll < 0.85:  # hostile ids, still unique
        for k, box in enumerate(rng.sample(boxes, min(len(boxes), rng.choice((1, 3, 20))))):
            box["id"] = f"{rng.choice(HOSTILE_NAMES)}{k}"
    elif roll < 0.92:  # children in another order
        for box in boxes:
            rng.shuffle(box.get("children", []))
    else:  # a mesh out of the folder, at a device, missing
        rng.choice(boxes)["mesh"] = rng.choice(HOSTILE_MESHES)


def _splits(node, out: list[list]) -> list[list]:
    """Every ``parts`` list of a captured model (a split's parts sum to their face)."""
    if isinstance(node, dict):
        if isinstance(node.get("parts"), list) and node["parts"]:
            out.append(node["parts"])
        for value in node.values():
            _splits(value, out)
    elif isinstance(node, list):
        for value in node:
            _splits(value, out)
    return out


def _change_captured(rng: random.Random, doc: dict) -> None:
    splits = _splits(doc["blocks"], [])
    if not splits:
        raise ValueError("no split to change")
    roll = rng.random()
    if roll < 0.35:  # a leaf part halved, again and again: the sums still hold
        for _ in range(rng.choice((1, 3, 10, 60))):
            parts = rng.choice(_splits(doc["blocks"], []))
            k = rng.randrange(len(parts))
            part = parts[k]
            if (
                isinstance(part, dict)
                and "parts" not in part
                and isinstance(part.get("size"), float | int)
            ):
                half = dict(part, size=part["size"] / 2)
                parts[k : k + 1] = [half, json.loads(json.dumps(half))]
    elif roll < 0.55:  # parts in another order
        for parts in rng.sample(splits, min(len(splits), rng.choice((1, 5, 100)))):
            rng.shuffle(parts)
    elif roll < 0.8:  # hostile labels, and their fixed flags
        labels = doc.setdefault("labels", {})
        for parts in rng.sample(splits, min(len(splits), rng.choice((1, 5, 30)))):
            part = rng.choice(parts)
            if isinstance(part, dict) and isinstance(labels, dict):
                part["label"] = rng.choice(HOSTILE_NAMES) + str(rng.randrange(4))
                labels[part["label"]] = {"fixed": rng.random() < 0.5}
    elif roll < 0.9:  # floors in another order
        for block in doc["blocks"]:
            if isinstance(block, dict) and isinstance(block.get("floors"), list):
                rng.shuffle(block["floors"])
    else:  # a hostile model or block name
        target = rng.choice([doc, *[b for b in doc["blocks"] if isinstance(b, dict)]])
        target["name" if target is doc else "id"] = rng.choice(HOSTILE_NAMES)
