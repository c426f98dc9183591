"""Level 0 without needless cuts: a building whose components are each of a
type of their own is put back whole.

Cutting a building into slabs pays where a slab repeats: its type's mesh is written once and
placed many times.  A slab that no other component equals is written once either way, and the cut
only costs: the triangles it crosses are clipped (Zurich's LoD2 tile: 5,141 input triangles, 7,820
in its components), and each slab is a mesh, a placement and a type of its own.  So at level 0 a
building with several components, none of whose types has another instance, is one component
again: its own triangles, uncut, in the box of its whole footprint.  A building whose slabs are all
footprints extruded keeps them (each is a line of operations, cheaper than one mesh).  Levels above
0 keep every cut: there the slabs are what the types share.
"""

from __future__ import annotations

import numpy as np

from .batch import _whole, fit_all
from .components import Component
from .model import CityObject
from .prisms import fit_prism
from .types import Types, base_types


def uncut_unique(
    objects: list[CityObject], comps: list[Component], types: Types, tolerance: float, grid: float
) -> tuple[list[Component], Types]:
    """Level 0's components with the buildings described in the module docstring put back whole
    (each where its lowest component was), and their level-0 types; ``comps`` and ``types`` as
    they are when no building is."""
    count = types.base_count[types.base_of]  # instances of each component's type
    members: dict[int, list[int]] = {}
    for i, comp in enumerate(comps):
        members.setdefault(comp.building, []).append(i)
    whole = [
        b
        for b, own in members.items()
        if len(own) > 1
        and bool(np.all(count[own] == 1))
        and not all(fit_prism(comps[i], tolerance) is not None for i in own)
    ]
    if not whole:
        return comps, types
    slabs = _whole([objects[b] for b in whole])
    fitted = fit_all(
        [(b, s) for b, s in zip(whole, slabs, strict=True) if s is not None], objects, grid
    )
    return whole_instead(comps, members, {c.building: c for c in fitted})


def whole_instead(
    comps: list[Component], members: dict[int, list[int]], instead: dict[int, Component]
) -> tuple[list[Component], Types]:
    """``comps`` with the components of each building of ``instead`` replaced by its one
    component there, where its lowest was; and their level-0 types."""
    out: list[Component] = []
    for i, comp in enumerate(comps):
        if comp.building not in instead:
            out.append(comp)
        elif i == members[comp.building][0]:
            out.append(instead[comp.building])
    return out, base_types(out)
