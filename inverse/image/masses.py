"""The 30 building masses of ``stdlib/mass.bgr`` as parametric shapes the photograph stage fits
(Nishida et al. 2018, section 4.1): each family's free parameters with the ranges it is trained
and fitted within, the grammar that derives a mass from them, and its triangles.

A parameter is written into the grammar as an ``attr`` (so that the grammar ``bgr infer`` writes
can be edited like any other) and passed to the stdlib rule through an expression: most are
metres or fractions as the rule takes them; ``size`` is a fraction of the footprint's smaller
side, and a height marked ``of`` another is a fraction of it, which keeps every sample a valid
building whatever the other parameters are.  Parameters left out (a tower's number of sides, a
spire's pitch) keep the rule's defaults.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np

FOOTPRINT = (("w", 6.0, 24.0), ("d", 5.0, 18.0))
METRIC = frozenset({"w", "d", "h", "h1", "h2", "setback"})  # in metres: scaled with the mass
PITCH = ("pitch", 20.0, 50.0)


@dataclass(frozen=True)
class Param:
    """One free parameter: its attr name, range, and the expression the stdlib rule receives."""

    name: str
    low: float
    high: float
    argument: str = ""  # the rule's parameter it sets (its own name when empty)
    expression: str = ""  # what is passed, in terms of the attrs (the attr itself when empty)

    @property
    def target(self) -> str:
        return self.argument or self.name


@dataclass(frozen=True)
class Family:
    """One mass rule of stdlib.mass and the parameters fitted to a photograph."""

    rule: str
    params: tuple[Param, ...]

    @property
    def names(self) -> list[str]:
        return [p.name for p in self.params]

    @property
    def low(self) -> np.ndarray:
        return np.array([p.low for p in self.params])

    @property
    def high(self) -> np.ndarray:
        return np.array([p.high for p in self.params])

    def values(self, unit: np.ndarray) -> dict[str, float]:
        """Parameter values (metres, fractions, degrees) from their [0, 1] coordinates."""
        real = self.low + np.clip(unit, 0, 1) * (self.high - self.low)
        return {p.name: float(v) for p, v in zip(self.params, real, strict=True)}

    def unit(self, values: dict[str, float]) -> np.ndarray:
        real = np.array([values[p.name] for p in self.params])
        return (real - self.low) / (self.high - self.low)

    def call(self, wall: str = "Wall") -> str:
        """The stdlib call with every free parameter passed from its attr."""
        args = [f"{p.target} = {p.expression or p.name}" for p in self.params]
        return f"mass.{self.rule}({', '.join(args)}, facade = {wall})"


def _p(name: str, low: float, high: float, argument: str = "", expression: str = "") -> Param:
    return Param(name, low, high, argument, expression)


def _family(rule: str, *params: Param, pitch: bool = False, footprint: bool = True) -> Family:
    head = tuple(_p(*p) for p in FOOTPRINT) if footprint else ()
    tail = (_p(*PITCH),) if pitch else ()
    return Family(rule, head + params + tail)


_SIZE = "size_f * min(w, d)"
FAMILIES: tuple[Family, ...] = (
    # row 1: single stacks, flat roofs
    _family("Block", _p("h", 3.6, 24)),
    _family("LBlock", _p("a", 0.25, 0.6), _p("b", 0.3, 0.7), _p("h", 3.6, 18)),
    _family("UBlock", _p("a", 0.2, 0.4), _p("b", 0.3, 0.6), _p("h", 3.6, 18)),
    _family("TBlock", _p("a", 0.25, 0.6), _p("b", 0.3, 0.6), _p("h", 3.6, 18)),
    _family("RoundTower", _p("w", 4.8, 18), _p("h", 4.8, 27), footprint=False),
    _family("CrossBlock", _p("a", 0.25, 0.6), _p("b", 0.25, 0.6), _p("h", 3.6, 18)),
    # row 2: pitched roofs
    _family("GableHouse", _p("h", 2.5, 8), pitch=True),
    _family("LHip", _p("a", 0.25, 0.6), _p("b", 0.3, 0.7), _p("h", 2.5, 8), pitch=True),
    _family("UMansard", _p("a", 0.2, 0.4), _p("b", 0.3, 0.6), _p("h", 2.4, 10.8), pitch=True),
    _family("TGambrel", _p("a", 0.25, 0.6), _p("b", 0.3, 0.6), _p("h", 2.5, 8), pitch=True),
    _family("ConeTower", _p("w", 3.6, 15), _p("h", 3.6, 18), _p("pitch", 30, 70), footprint=False),
    _family("CrossGable", _p("a", 0.25, 0.6), _p("b", 0.25, 0.6), _p("h", 2.5, 8), pitch=True),
    # rows 3 and 4: two stacks
    _family(
        "PodiumSlab",
        _p("h1", 2.5, 6),
        _p("h2", 3.6, 24),
        _p("inset_f", 0.03, 0.2, "inset", "inset_f * min(w, d)"),
    ),
    _family(
        "PodiumTower", _p("h1", 2.5, 6), _p("size_f", 0.3, 0.7, "size", _SIZE), _p("h2", 6, 42)
    ),
    _family(
        "SideBySide",
        _p("split_at", 0.3, 0.7, "split"),
        _p("h1", 4.8, 21.6),
        _p("h2_f", 0.3, 0.85, "h2", "h2_f * h1"),
    ),
    _family("StepBack", _p("split_at", 0.25, 0.6, "split"), _p("h1", 2.5, 7), _p("h2", 5.4, 21.6)),
    _family(
        "RearAnnex",
        _p("split_at", 0.4, 0.75, "split"),
        _p("annex", 0.3, 0.9),
        _p("h1", 2.4, 7.2),
        _p("h2_f", 0.3, 0.8, "h2", "h2_f * h1"),
        pitch=True,
    ),
    _family(
        "SideWing",
        _p("split_at", 0.4, 0.75, "split"),
        _p("wing", 0.4, 1.0),
        _p("h1", 2.4, 7.2),
        _p("h2_f", 0.5, 1.0, "h2", "h2_f * h1"),
        pitch=True,
    ),
    _family("CornerTower", _p("size_f", 0.25, 0.5, "size", _SIZE), _p("h1", 3, 9.6), pitch=True),
    _family("Steeple", _p("h1", 3, 9.6), _p("pitch", 25, 50)),
    _family(
        "PodiumRound", _p("h1", 2.5, 6), _p("size_f", 0.4, 0.8, "size", _SIZE), _p("h2", 3.6, 30)
    ),
    _family(
        "BarnLeanTo",
        _p("split_at", 0.5, 0.85, "split"),
        _p("h1", 2.5, 6),
        _p("h2_f", 0.4, 0.8, "h2", "h2_f * h1"),
        pitch=True,
    ),
    _family("LTower", _p("a", 0.3, 0.6), _p("b", 0.3, 0.7), _p("h1", 2.5, 8), _p("h2", 7.2, 36)),
    _family("ShopHouse", _p("h1", 2.5, 4.5), _p("setback", 0.6, 2.4), _p("h2", 2.4, 6), pitch=True),
    # row 5: three stacks
    _family(
        "WeddingCake",
        _p("h1", 3, 12),
        _p("h2_f", 0.5, 1.0, "h2", "h2_f * h1"),
        _p("h3_f", 0.3, 0.8, "h3", "h3_f * h1"),
        _p("inset_f", 0.03, 0.15, "inset", "inset_f * min(w, d)"),
    ),
    _family(
        "TowerCrown",
        _p("h1", 2.5, 6),
        _p("size_f", 0.35, 0.65, "size", _SIZE),
        _p("h2", 7.2, 36),
        _p("crown", 0.5, 0.9),
        _p("h3_f", 0.3, 0.8, "h3", f"h3_f * {_SIZE}"),
        pitch=True,
    ),
    _family(
        "Terraced",
        _p("h1", 2.5, 7),
        _p("h2_f", 1.3, 2.2, "h2", "h2_f * h1"),
        _p("h3_f", 2.0, 3.2, "h3", "h3_f * h1"),
    ),
    _family(
        "CentralWings",
        _p("centre", 0.25, 0.5),
        _p("wing", 0.5, 0.95),
        _p("h1", 3, 8.4),
        _p("h2_f", 1.1, 1.8, "h2", "h2_f * h1"),
        pitch=True,
    ),
    _family(
        "RoundTiers",
        _p("h1", 2.5, 7),
        _p("size_f", 0.5, 0.9, "size", _SIZE),
        _p("h2_f", 0.3, 0.8, "h2", f"h2_f * {_SIZE}"),
        _p("lantern", 0.4, 0.7),
        _p("h3_f", 0.2, 0.6, "h3", f"h3_f * {_SIZE}"),
        pitch=True,
    ),
    _family(
        "TwinTowers",
        _p("h1", 2.5, 6),
        _p("size_f", 0.25, 0.45, "size", _SIZE),
        _p("h2", 4.8, 42),
        _p("h3_f", 0.5, 1.0, "h3", "h3_f * h2"),
    ),
)
BY_RULE = {f.rule: f for f in FAMILIES}
MAX_PARAMS = max(len(f.params) for f in FAMILIES)


def attr_lines(family: Family, values: dict[str, float], digits: int = 2) -> list[str]:
    """``attr`` lines of a family's parameters, for the grammar the photograph stage writes."""
    return [f"attr {p.name} = {round(values[p.name], digits):g}" for p in family.params]


def grammar_text(family: Family, values: dict[str, float] | None = None) -> str:
    """A grammar whose start rule ``Lot`` derives the family's mass with plain walls (what its
    silhouette needs), its parameters as attrs."""
    values = values or family.values(np.full(len(family.params), 0.5))
    return "\n".join(
        [
            "version 1",
            "import stdlib.mass as mass",
            "terminal Wall, Side",
            *attr_lines(family, values, digits=6),
            f"Lot --> {family.call('Side')}",
            "",
        ]
    )


@cache
def _grammar(rule: str):
    import bgr

    return bgr.load(grammar_text(BY_RULE[rule]))


def _derive(family: Family, values: dict[str, float]):
    from bgr.interpreter.derive import derive

    w, d = _footprint(family, values)
    return derive(_grammar(family.rule), attrs=dict(values), lot=(w, d)).terminals


def triangles(family: Family, values: dict[str, float]) -> np.ndarray:
    """(n, 3, 3) world triangles of the mass (metres, y up), its footprint centred on the
    origin and its street face toward -z."""
    from bgr.interpreter.terminals import world_vertices

    w, d = _footprint(family, values)
    table = _derive(family, values)
    parts = []
    ids = np.asarray(table.mesh)
    for mesh_id in np.unique(ids):
        rows = np.flatnonzero(ids == mesh_id)
        mesh = table.library.meshes[mesh_id]
        world = world_vertices(table, rows, mesh)  # (rows, V, 3)
        parts.append(world[:, mesh.faces].reshape(-1, 3, 3))
    tris = np.concatenate(parts) if parts else np.zeros((0, 3, 3))
    return tris - np.array([w / 2, 0.0, d / 2])


def side_faces(family: Family, values: dict[str, float]) -> list[tuple[np.ndarray, ...]]:
    """(origin, axes (3, 3) whose rows are the face's x, y and outward normal, size) of every
    side face of the mass that receives the façade, in :func:`triangles`' frame."""
    w, d = _footprint(family, values)
    table = _derive(family, values)
    shift = np.array([w / 2, 0.0, d / 2])
    return [
        (np.asarray(table.origin[i]) - shift, np.asarray(table.axes[i]), np.asarray(table.size[i]))
        for i, label in enumerate(table.label)
        if label == "Side"
    ]


def _footprint(family: Family, values: dict[str, float]) -> tuple[float, float]:
    w = values.get("w", 20.0)
    return w, values.get("d", w)
