"""Build-by-Number's design schemas (face, floor, model), inferred from a subdivided, labelled
building and written as a .bgr grammar:

    from bgr.inverse.schema import infer
    module = infer("terminals.json")          # or a captured-model JSON, or a .bgr to derive
    text = bgr.format_module(module)

The pipeline: a reader (:mod:`.terminals` for ``bgr derive -o x.json`` output, :mod:`.captured`
for captured-model JSON) builds a :class:`.model.Model` of subdivided faces; :mod:`.faces` is the
paper's rewrite algorithm on symbol strings; :mod:`.emit` turns the model into rules.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable
from pathlib import Path

from bgr.grammar import nodes as n
from bgr.grammar.errors import BgrError, Diagnostic
from bgr.grammar.paths import read_input

from .model import Model

__all__ = ["Model", "check_derives", "infer", "read_model", "source_lot"]


def read_model(
    source,
    *,
    fixed: dict[str, bool] | None = None,
    seed: int = 0,
    lot=None,
    allow_paths: Iterable[str | os.PathLike] = (),
) -> Model:
    """The Model of ``source``: a terminal-list or captured-model JSON path (or its parsed
    dict), a .bgr path (derived with ``seed`` and ``lot`` first, loaded with ``allow_paths`` as
    :func:`bgr.load`), or a ``bgr.Result``."""
    from .terminals import model_from_terminals

    if hasattr(source, "terminals") and hasattr(source, "attrs"):  # a bgr.Result
        import io

        from bgr.formats import write_json

        buffer = io.StringIO()
        write_json(source.terminals, buffer, seed=0, attrs={})
        return model_from_terminals(json.loads(buffer.getvalue()), "<derived>", fixed)
    if isinstance(source, dict):
        return _from_dict(source, "<data>", fixed)
    path = Path(os.fspath(source))
    shown = str(source)
    if path.suffix.lower() == ".bgr":
        from bgr.grammar.loader import load
        from bgr.interpreter.derive import derive

        grammar = load(path, allow_paths=allow_paths)
        model = read_model(derive(grammar, seed=seed, lot=lot), fixed=fixed)
        model.source = shown
        return model
    try:
        data = read_input(path, "input file")
        text = data.decode("utf-8")
    except FileNotFoundError:
        raise BgrError(
            Diagnostic(
                shown,
                0,
                0,
                "no such file",
                "give a terminal list (bgr derive -o x.json), a captured-model .json or a .bgr",
            )
        ) from None
    except UnicodeDecodeError:
        from ..inputs import not_text

        raise not_text(shown, data[: 1 << 16]) from None
    except OSError as exc:
        raise BgrError(Diagnostic(shown, 0, 0, f"cannot read the file: {exc}")) from None
    from .captured import parse  # strict JSON: line and column, duplicate keys, no NaN

    return _from_dict(parse(text, shown), shown, fixed)


def _from_dict(data, shown: str, fixed) -> Model:
    from .terminals import model_from_terminals

    if isinstance(data, dict) and "terminals" in data:
        return model_from_terminals(data, shown, fixed)
    if isinstance(data, dict) and ("bgr_captured" in data or "blocks" in data):
        from .captured import model_from_captured

        return model_from_captured(data, shown, fixed)
    raise BgrError(
        Diagnostic(
            shown,
            0,
            0,
            "neither a terminal list nor a captured model",
            "a terminal list has a 'terminals' list (bgr derive -o x.json); a captured "
            "model has 'bgr_captured' and 'blocks' (docs/inverse-schema.md)",
        )
    )


def infer(
    source,
    *,
    fixed: dict[str, bool] | None = None,
    seed: int = 0,
    lot=None,
    allow_paths: Iterable[str | os.PathLike] = (),
) -> n.Module:
    """The style grammar of ``source`` (see :func:`read_model`) as a syntax tree.

    The grammar is derived once on the source's own size before it is returned (see
    :func:`check_derives`): a grammar that cannot derive is never handed out to be written."""
    from .emit import Emitter

    model = read_model(source, fixed=fixed, seed=seed, lot=lot, allow_paths=allow_paths)
    module = Emitter(model).module()
    check_derives(module, model)
    return module


def source_lot(model: Model) -> tuple[float, float]:
    """The rectangle lot (width, depth) that re-creates the model's basis block: its extent in
    plan, or for a flat model the façade's own width and height; 20 m where a side is 0 (a lone
    face has no depth)."""
    block = model.sorted_blocks()[0]
    return tuple(v if v > 1e-6 else 20.0 for v in (block.width, block.depth))


def check_derives(module: n.Module, model: Model) -> None:
    """Derive the inferred grammar on the source's size; a grammar that does not check or
    derive (an error, or a failure inside the geometry code) is a bug of the inference, and
    becomes one BgrError naming the source rather than a file that fails later."""
    from bgr.grammar.formatter import format_module
    from bgr.grammar.loader import load
    from bgr.interpreter.derive import derive

    try:
        derive(load(format_module(module), path="<inferred>"), lot=source_lot(model))
    except Exception as exc:  # any failure at all: such a grammar must not be written
        detail = exc.message if isinstance(exc, BgrError) else f"{type(exc).__name__}: {exc}"
        raise BgrError(
            Diagnostic(
                model.source or "<model>",
                0,
                0,
                f"the inferred grammar does not derive on the source's size: {detail}",
                "nothing was written; this is a bug in bgr infer, please report it with the input",
            )
        ) from None
