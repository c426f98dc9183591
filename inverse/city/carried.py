"""The city objects that are not buildings (roads, land use, water, vegetation, terrain): carried
through unchanged, one mesh and one rule for each kind of them.

Level 0 must derive the whole input back, so these objects are kept as they are.  Delft's tile has
410 of them; written as a mesh, an asset line, a rule and a placement each they were half its
grammar and most of its assets file (glTF spends some 300 bytes of JSON a mesh).  So the objects
of one kind (the CityJSON type; "object" for formats without types) are one mesh at their own
coordinates, each object's triangles one run of it in input order, and the node holding it lists
the objects' ids and where each one's triangles start (``extras.objects``: ``[[id, first], ...]``),
so that nothing of the input is lost but the split into files of its own.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bgr.grammar.safe_text import comment_text

from . import emit, tree
from .components import grid_mesh
from .container import Mesh, reordered
from .model import CityScene


@dataclass
class Carried:
    """One kind of carried objects: its terminal, its placement (its lowest corner) and the
    objects, each (id, vertices relative to that corner, triangles)."""

    terminal: emit.Terminal
    placement: tree.Placement
    parts: list[tuple[str, np.ndarray, np.ndarray]]

    def mesh(self, digits: int, compress: bool = True) -> Mesh:
        """The kind's mesh on the grammar's grid (``digits`` decimals), its objects one after
        another, with the node's ``extras`` naming them and where each begins; ``compress``:
        each object's triangles in the order meshoptimizer's codecs like (:func:`.reordered`;
        the container keeps the order, so each object stays one run)."""
        verts, faces, starts, count = [], [], [], 0
        for name, v, f in self.parts:
            v, f = grid_mesh(v, f, digits)
            if compress and len(f):
                v, f = reordered(v, f)
            starts.append([name, sum(len(x) for x in faces)])
            verts.append(v)
            faces.append(f + count)
            count += len(v)
        return Mesh(
            self.terminal.asset,
            np.concatenate(verts),
            np.concatenate(faces),
            extras={"objects": starts},
            keep_order=True,
        )

    @property
    def vertices(self) -> np.ndarray:
        return np.concatenate([v for _, v, _ in self.parts])

    @property
    def faces(self) -> np.ndarray:
        offsets = np.cumsum([0] + [len(v) for _, v, _ in self.parts])
        return np.concatenate([f + offsets[k] for k, (_, _, f) in enumerate(self.parts)])


def carry(scene: CityScene, path: str, colour_of) -> list[Carried]:
    """The carried objects of ``scene`` by kind, kinds in order of first appearance; ``path``:
    the assets file as the grammar names it; ``colour_of(colors)``: a kind's colour."""
    kinds: dict[str, list] = {}
    for obj in scene.objects:
        if not obj.proceduralize and len(obj.faces):
            kinds.setdefault(obj.kind, []).append(obj)
    out = []
    for k, (kind, objects) in enumerate(kinds.items(), start=1):
        low = np.min([o.vertices.min(axis=0) for o in objects], axis=0)
        high = np.max([o.vertices.max(axis=0) for o in objects], axis=0)
        colours = [o.colors for o in objects]
        colour = colour_of(np.concatenate(colours)) if all(c is not None for c in colours) else None
        what = (
            f"{comment_text(kind, 60)}: {len(objects)} objects, carried as they are (their ids "
            "in the mesh node's extras)"
            if len(objects) > 1
            else f"{comment_text(kind, 60)} {comment_text(objects[0].name)}, carried as it is"
        )
        term = emit.Terminal(f"Object{k}", f"object{k}", f"{path}#object{k}", colour, what)
        parts = [(o.name, o.vertices - low, o.faces) for o in objects]
        out.append(Carried(term, tree.Placement(term.name, 0.0, low, high - low), parts))
    return out
