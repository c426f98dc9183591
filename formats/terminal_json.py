"""The terminal list (LANGUAGE.md section 11): what exact tests read.

One terminal per line, keys in the order the language reference shows, floats as Python's ``repr``
(shortest text that reads back to the same double), so a round trip through ``json.loads`` is exact.
"""

from __future__ import annotations

import json
import tempfile
from collections.abc import Callable
from typing import BinaryIO, TextIO

import numpy as np

from bgr.grammar.errors import BgrError
from bgr.grammar.parser import no_gc
from bgr.interpreter.surfaces import Surface, set_values, values_of
from bgr.interpreter.terminals import TerminalTable, lot_tables

from .meshes import srgb8


def plain(value):
    """json's fallback for numpy values (and tuples) in attrs."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (tuple, set, frozenset)):
        return list(value)
    raise TypeError(f"{type(value).__name__} is not JSON data")


_ENCODER = json.JSONEncoder(ensure_ascii=False, allow_nan=False, default=plain)


def _dumps(value) -> str:
    try:
        return _ENCODER.encode(value)
    except (TypeError, ValueError) as exc:
        raise BgrError(f"cannot write the terminal list as JSON: {exc}") from exc


def terminal_dicts(table: TerminalTable) -> list[dict]:
    """The ``terminals`` array as Python data, in table order."""
    table.freeze()
    with no_gc():
        # adding 0.0 turns -0.0 into 0.0: same value, tidier text
        origin = (table.origin + 0.0).tolist()
        axes = (table.axes + 0.0).tolist()
        size = (table.size + 0.0).tolist()
        rgb = srgb8(table).astype(np.int64)  # rounded as terminals.color_hex rounds
        colours = [f"#{v:06x}" for v in ((rgb[:, 0] << 16) | (rgb[:, 1] << 8) | rgb[:, 2]).tolist()]
        rows = [
            {
                "label": label,
                "rule": rule,
                "path": path,
                "origin": o,
                "axes": a,
                "size": sz,
                "color": c,
                "material": material,
                "geometry": geometry,
            }
            for label, rule, path, o, a, sz, c, material, geometry in zip(
                table.label,
                table.rule,
                table.path,
                origin,
                axes,
                size,
                colours,
                table.material,
                table.geometry_names(),
                strict=True,
            )
        ]
    for row in rows:  # set(material.opacity, ...) and the others: the name, and the values
        material = row["material"]
        if isinstance(material, Surface):
            row["material"] = material.name
            row["surface"] = set_values(values_of(material))
    return rows


# what the terminal list says of each lot: its frame (the inverse modules read a face's side in
# it) and its name; the glTF and CityJSON files carry the attrs and feature properties too
LOT_KEYS = ("path", "name", "origin", "axes", "size")


def dumps(table: TerminalTable, *, seed: int, attrs: dict) -> str:
    """The whole document as text (ends with a newline)."""
    pieces: list[str] = []
    writer = TerminalListWriter(pieces.append, seed=seed, attrs=attrs)
    for part in lot_tables(table):
        writer.add(part)
    writer.finish()
    return "".join(pieces)


class TerminalListWriter:
    """The terminal list written as lots come: the head and each lot's terminals at once, the
    ``lots`` array (which follows the terminals) kept in a spool until :meth:`finish`.  Writing
    a table's lots one by one gives the text writing the whole table gives."""

    def __init__(self, write: Callable[[str], object], *, seed: int, attrs: dict) -> None:
        self.write = write
        self.rows = 0
        # the lots' text: in memory up to a few megabytes, then in a temporary file
        self.lots = tempfile.SpooledTemporaryFile(  # noqa: SIM115 - closed by finish()
            max_size=1 << 20, mode="w+", encoding="utf-8"
        )
        self.n_lots = 0
        write(
            f'{{\n  "bgr": 1,\n  "seed": {_dumps(seed)},\n  "attrs": {_dumps(attrs)},\n'
            '  "terminals": ['
        )

    def add(self, table: TerminalTable) -> None:
        with no_gc():
            rows = terminal_dicts(table)
            if rows:
                self.write(
                    (",\n" if self.rows else "\n") + ",\n".join(["    " + _dumps(t) for t in rows])
                )
                self.rows += len(rows)
            for lot in table.lots:
                text = "    " + _dumps({k: lot[k] for k in LOT_KEYS if k in lot})
                self.lots.write((",\n" if self.n_lots else "") + text)
                self.n_lots += 1

    def finish(self) -> None:
        self.write("\n  ]" if self.rows else "]")
        if self.n_lots:
            self.write(',\n  "lots": [\n')
            self.lots.seek(0)
            while chunk := self.lots.read(1 << 20):
                self.write(chunk)
            self.write("\n  ]\n}\n")
        else:
            self.write("\n}\n")
        self.lots.close()


def write_json(table: TerminalTable, stream: TextIO, *, seed: int, attrs: dict) -> None:
    """Write the terminal list to a text stream (``sys.stdout`` for ``-o -``)."""
    stream.write(dumps(table, seed=seed, attrs=attrs))


def write_json_bytes(table: TerminalTable, stream: BinaryIO, *, seed: int, attrs: dict) -> None:
    """Write the terminal list, UTF-8 encoded, to a binary stream."""
    stream.write(dumps(table, seed=seed, attrs=attrs).encode("utf-8"))
