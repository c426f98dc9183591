"""The public derivation API: ``bgr.derive(grammar, seed=, attrs=, lot=)``."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from bgr.grammar.checker import Grammar
from bgr.grammar.errors import BgrError
from bgr.grammar.loader import load

from .engine import DEFAULT_MAX_DEPTH, DEFAULT_MAX_SHAPES, Engine
from .lots import DEFAULT_LOT, Lot, parse_lot_option, rectangle
from .randomness import child_hash, name_hash, root_hash
from .terminals import TerminalTable


@dataclass
class Result:
    """What a derivation made: the terminal table, and ways to turn it into meshes and files."""

    terminals: TerminalTable
    seed: int
    attrs: dict

    def __len__(self) -> int:
        return len(self.terminals)

    @property
    def mesh(self):
        """One ``trimesh.Trimesh`` of every terminal, with face colours."""
        from .writers import to_trimesh

        return to_trimesh(self.terminals)

    def save(self, path: str | os.PathLike, fmt: str | None = None) -> None:
        """Write by extension (.glb .gltf .obj .ply .stl .json), atomically."""
        from .writers import write

        write(self.terminals, Path(path), seed=self.seed, attrs=self.attrs, fmt=fmt)


def derive(
    grammar: Grammar | str | os.PathLike,
    seed: int = 0,
    attrs: dict | None = None,
    lot: str | tuple[float, float] | list[Lot] | None = None,
    *,
    max_depth: int = DEFAULT_MAX_DEPTH,
    max_shapes: int = DEFAULT_MAX_SHAPES,
    start: str | None = None,
) -> Result:
    """Derive a grammar on one lot or several.

    ``grammar`` is a checked :class:`bgr.Grammar` or anything :func:`bgr.load` takes.  ``lot`` is
    ``(width, depth)``, ``"W,D"``, a GeoJSON path, or a list of lots; the default is 20 x 20 m.
    Each GeoJSON feature's properties override attrs of the same name for its building.
    """
    if not isinstance(grammar, Grammar):
        grammar = load(grammar)
    if isinstance(seed, bool) or not isinstance(seed, int):
        raise BgrError(f"the seed must be a whole number, got {seed!r}")
    lots = _lots(lot)
    attrs = dict(attrs or {})
    table = TerminalTable()
    shared_cache: dict = {}
    for i, each in enumerate(lots):
        overrides = dict(attrs)
        overrides.update(
            {
                k: v
                for k, v in each.properties.items()
                if k in grammar.attrs and isinstance(v, (int, float, str, bool)) and v is not None
            }
        )
        engine = Engine(grammar, seed, overrides, max_depth, max_shapes, lot_index=i)
        engine.table = table
        engine.split_cache = shared_cache
        shape = each.shape.copy()
        engine.derive(shape, start, index=i, several=len(lots) > 1)
        lot_shape = each.shape  # its frame: the inverse modules read a face's side in it
        name = start or grammar.start
        table.lots.append(
            {
                "path": f"{name}.{i}" if len(lots) > 1 else name,
                "origin": list(lot_shape.origin),
                "axes": [list(a) for a in lot_shape.axes],
                "size": list(lot_shape.size),
            }
        )
    values = Engine(grammar, seed, attrs, max_depth, max_shapes).attrs if lots else attrs
    return Result(table.freeze(), seed, values)


def _lots(lot) -> list[Lot]:
    if lot is None:
        return [rectangle(*DEFAULT_LOT)]
    if (
        isinstance(lot, (tuple, list))
        and len(lot) == 2
        and all(isinstance(v, (int, float)) for v in lot)
    ):
        return [rectangle(float(lot[0]), float(lot[1]))]
    if isinstance(lot, (str, os.PathLike)):
        return parse_lot_option(str(lot))
    if isinstance(lot, Lot):
        return [lot]
    return list(lot)


__all__ = ["derive", "Result", "child_hash", "name_hash", "root_hash"]
