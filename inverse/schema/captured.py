"""Read a captured-model JSON (a building written by hand) into a :class:`Model`.

A captured model is Build-by-Number's model specification (section 3.1) as a file: a scene graph
of blocks (box, cylinder, prism) with transforms and attachments, each block cut into floors, and
each face of each floor subdivided into rows and columns of labelled subfaces.  The format is
documented in ``docs/inverse-schema.md`` ("Captured-model JSON"); its JSON Schema is
:data:`SCHEMA` (from :mod:`.captured_schema`), and ``docs/captured-model.schema.json`` is that
schema written out
(``python -m bgr.inverse.schema.captured > docs/captured-model.schema.json``; a test keeps them
equal).

Reading goes in three stages, each reporting every problem it finds as a :class:`BgrError` whose
diagnostics name the offending element by its JSON path (``blocks[0].faces.front[1].size``):

1. the JSON itself: finite numbers, no key given twice, not nested absurdly deep;
2. the JSON Schema (:data:`SCHEMA`): keys, types, ranges;
3. the meaning: ids unique, parents known and acyclic, floors summing to the block's height,
   subface sizes summing to their cell, attachments naming real faces that touch.

Then the faces are built in world coordinates and :func:`link_faces` sets their corners, as the
terminal-list reader (:mod:`.terminals`) does.

This module puts the stages together (:func:`model_from_captured`, :func:`load_captured`) and
prints the schema when run; the stages are in :mod:`.captured_checks` (1 and 2),
:mod:`.captured_reader` (3: the scene graph and the floors) and :mod:`.captured_faces` (3: the
faces, their subfaces and attachments), the blocks' geometry in :mod:`.captured_geometry`.
"""

from __future__ import annotations

import sys
from pathlib import Path

from bgr.grammar.errors import BgrError
from bgr.grammar.paths import read_input

from .captured_checks import _check_json, _check_schema, _error, parse
from .captured_faces import _attachments, _faces_of
from .captured_reader import _Reader
from .captured_schema import (
    BOX_FACES,
    BOX_RING,
    FORMAT_VERSION,
    GEOM_TOL,
    IDENTIFIER,
    MAX_LENGTH,
    MAX_NESTING,
    MAX_VALUES,
    PLAIN,
    SCHEMA,
    TOL,
    schema_text,
)
from .corners import link_faces
from .model import Block, Model

__all__ = [
    "BOX_FACES",
    "BOX_RING",
    "FORMAT_VERSION",
    "GEOM_TOL",
    "IDENTIFIER",
    "MAX_LENGTH",
    "MAX_NESTING",
    "MAX_VALUES",
    "PLAIN",
    "SCHEMA",
    "TOL",
    "load_captured",
    "main",
    "model_from_captured",
    "parse",
    "schema_text",
]


def model_from_captured(
    data, path: str = "<captured>", fixed: dict[str, bool] | None = None
) -> Model:
    """The Model of a parsed captured-model JSON.  ``fixed`` overrides the file's ``labels``.

    Every problem raises :class:`BgrError`, its diagnostics naming the element by JSON path."""
    diags = _check_json(data, path)
    if diags:
        raise BgrError(diags)
    try:
        diags = _check_schema(data, path)
    except RecursionError:  # pragma: no cover - MAX_NESTING keeps the validator shallow
        raise _error(path, "", "the captured model is nested too deeply to validate") from None
    if diags:
        raise BgrError(diags)
    reader = _Reader(data, path, fixed)
    ids = reader.check_blocks()
    reader.raise_if_failed()
    blocks = data["blocks"]
    frames = reader.frames(ids)
    built = [_faces_of(reader, b, i, frames[i]) for i, b in enumerate(blocks)]
    roofs = []
    for i, b in enumerate(blocks):
        if "roof" in b:
            reader.use_label(b["roof"], f"blocks[{i}].roof")
            if b["roof"] not in roofs:
                roofs.append(b["roof"])
    reader.raise_if_failed()
    by_name = [dict(faces) for faces in built]
    hidden, start_covered = _attachments(reader, blocks, by_name, ids)
    reader.raise_if_failed()
    kept = [[f for _, f in faces if id(f) not in hidden] for faces in built]
    all_faces = [f for faces in kept for f in faces]
    if not all_faces:
        raise _error(path, "blocks", "every face is hidden by an attachment: nothing to infer from")
    # link_faces joins a face to the first face that starts where it ends: one whose start an
    # attached block hides goes last, so that a wall running on past the attachment wins
    link_faces(
        [f for f in all_faces if id(f) not in start_covered]
        + [f for f in all_faces if id(f) in start_covered]
    )
    model_blocks = []
    for b, faces, ring in zip(blocks, kept, built, strict=True):
        w, h, d = (float(v) for v in b["size"])
        plan = [(f.origin[0], f.origin[2]) for _, f in ring]  # every face, hidden ones too
        model_blocks.append(Block(b["id"], faces, w, d, h, b["shape"], footprint=plan))
    labels = list(reader.used) + [lbl for lbl in reader.fixed if lbl not in reader.used]
    labels_fixed = {lbl: reader.is_fixed(lbl) for lbl in labels}
    return Model(model_blocks, source=path, labels_fixed=labels_fixed, roof_labels=roofs)


def load_captured(path: str | Path, fixed: dict[str, bool] | None = None) -> Model:
    """Read and check a captured-model JSON file: see :func:`model_from_captured`."""
    shown = str(path)
    try:
        text = read_input(path, "captured model").decode("utf-8")
    except FileNotFoundError:
        raise _error(shown, "", "no such file") from None
    except IsADirectoryError:
        raise _error(shown, "", "is a directory, not a captured-model JSON file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise _error(shown, "", f"cannot read the captured model: {exc}") from None
    return model_from_captured(parse(text, shown), shown, fixed)


def main(argv: list[str] | None = None) -> int:
    """``python -m bgr.inverse.schema.captured``: print the JSON Schema (the docs' copy)."""
    sys.stdout.write(schema_text())
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
