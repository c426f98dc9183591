"""Output files written as a run's lots are derived (``bgr derive`` on many lots).

A sink takes the lots' terminal tables one at a time (:meth:`Sink.add`) and drops them:

- **streamed**: ``.glb`` (the scene's parts and buffer spooled, :class:`.glb.Scene`),
  ``.city.jsonl`` (:class:`.cityjson.SequenceWriter`) and the terminal list ``.json``
  (:class:`.terminal_json.TerminalListWriter`) — memory does not grow with the number of lots;
- **gathered**: every other format (.gltf .obj .ply .stl .city.json, and a GLB grouped by
  label or not at all) needs the whole table at once; the lots are joined at the end and
  written by :func:`bgr.formats.write`.

Either way the file is the one writing the joined table would make, byte for byte, and it is
written atomically: a failure or an interrupt leaves nothing behind (:mod:`.atomic`).
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from bgr.interpreter.terminals import TerminalTable, concat

from . import check_writable, format_of, write
from .atomic import atomic_files, raise_if_terminated
from .cityjson import SequenceWriter
from .glb import Scene
from .terminal_json import TerminalListWriter

STREAMED = ("glb", "city.jsonl", "json")


def streams(path: str | Path, fmt: str | None = None, group_by: str = "lot") -> bool:
    """Whether :func:`open_sink` writes this output as lots come (else it gathers them)."""
    name = "json" if str(path) == "-" and not fmt else format_of(Path(str(path)), fmt)
    return name in STREAMED and (name != "glb" or group_by == "lot")


class Sink:
    """Where a run's lot tables go; counts what it was given.  ``streamed``: it does not keep
    them (so a run's budgets may hold per lot)."""

    streamed = True

    def __init__(self) -> None:
        self.terminals = 0
        self.triangles = 0

    def add(self, table: TerminalTable) -> None:
        check_writable(table, {})
        self.terminals += len(table)
        self.triangles += table.triangle_count()
        self.take(table)

    def take(self, table: TerminalTable) -> None:
        raise NotImplementedError

    def finish(self) -> None:
        """Complete the file (the context manager of :func:`open_sink` then renames it)."""


class _Glb(Sink):
    def __init__(self, stream, scene: Scene) -> None:
        super().__init__()
        self.stream, self.scene = stream, scene

    def take(self, table: TerminalTable) -> None:
        self.scene.add(table)

    def finish(self) -> None:
        raise_if_terminated()  # assembling the file takes a while: not after a SIGTERM
        self.scene.write_glb(self.stream)


class _Sequence(Sink):
    def __init__(self, writer: SequenceWriter, attrs: dict) -> None:
        super().__init__()
        self.writer, self.attrs = writer, attrs

    def take(self, table: TerminalTable) -> None:
        self.writer.add(table, self.attrs)


class _TerminalList(Sink):
    def __init__(self, writer: TerminalListWriter) -> None:
        super().__init__()
        self.writer = writer

    def take(self, table: TerminalTable) -> None:
        self.writer.add(table)

    def finish(self) -> None:
        self.writer.finish()


class _Gathered(Sink):
    """Every lot kept, joined and written at the end."""

    streamed = False

    def __init__(self, write_table) -> None:
        super().__init__()
        self.parts: list[TerminalTable] = []
        self.write_table = write_table

    def take(self, table: TerminalTable) -> None:
        self.parts.append(table)

    def finish(self) -> None:
        self.write_table(self.parts)


@contextlib.contextmanager
def open_sink(
    path: str | Path,
    *,
    seed: int,
    attrs: dict,
    fmt: str | None = None,
    site: dict | None = None,
    grammar: str = "",
    gltf: dict | None = None,
    lot_origins: np.ndarray | None = None,
) -> Iterator[Sink]:
    """A sink writing ``path`` (``"-"``: standard output, with ``fmt``) in the format of its
    extension, or ``fmt``.  ``site`` and ``grammar`` are what the run's tables carry;
    ``gltf`` the glTF options (``group_by``, ``instancing``); ``lot_origins`` (n, 3) the lots'
    origins, which place a GLB's root when the lots lie far from 0 (:func:`.glb.recentre`).

    The file is complete and in place when the ``with`` block ends without an error; on an
    error nothing is written.
    """
    check_writable(TerminalTable(), attrs)
    options = dict(gltf or {})
    group_by = options.get("group_by", "lot")
    to_stdout = str(path) == "-"
    name = format_of(Path(str(path)), fmt) if not to_stdout or fmt else "json"

    def gathered(parts: list[TerminalTable]) -> None:
        write(
            concat(parts, site=site, grammar=grammar),
            Path(str(path)),
            seed=seed,
            attrs=attrs,
            fmt=fmt or (name if to_stdout else None),
            gltf=options,
        )

    if not streams(path, name, group_by):
        sink: Sink = _Gathered(gathered)
        yield sink
        sink.finish()
        return
    if to_stdout:
        if name == "json":
            sink = _TerminalList(TerminalListWriter(sys.stdout.write, seed=seed, attrs=attrs))
            yield sink
            sink.finish()
            sys.stdout.flush()
            return
        sys.stdout.flush()
        with _streamed(
            sys.stdout.buffer, name, seed, attrs, site, grammar, options, None, lot_origins
        ) as sink:
            yield sink
        sys.stdout.buffer.flush()
        return
    target = Path(str(path))
    with atomic_files([target]) as (stream,):
        folder = str(target.parent)
        with _streamed(stream, name, seed, attrs, site, grammar, options, folder, lot_origins) as s:
            yield s


@contextlib.contextmanager
def _streamed(
    stream,
    name: str,
    seed: int,
    attrs: dict,
    site: dict | None,
    grammar: str,
    options: dict,
    folder: str | None,
    lot_origins: np.ndarray | None = None,
) -> Iterator[Sink]:
    """The streaming sink of format ``name`` on a binary stream; finished when the block ends
    without an error."""
    if name == "glb":
        from .glb import recentre_points

        shift = recentre_points(lot_origins) if lot_origins is not None else None
        with Scene(
            seed=seed,
            attrs=attrs,
            grammar=grammar,
            site=site,
            instancing=options.get("instancing", False),
            group_by="lot",
            shift=shift,
            folder=folder,
        ) as scene:
            sink: Sink = _Glb(stream, scene)
            yield sink
            sink.finish()
        return
    if name == "city.jsonl":
        sink = _Sequence(SequenceWriter(stream, site=site), attrs)
    else:
        sink = _TerminalList(
            TerminalListWriter(
                lambda text: stream.write(text.encode("utf-8")), seed=seed, attrs=attrs
            )
        )
    yield sink
    sink.finish()
