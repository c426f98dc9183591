"""A derivation's engine is freed when the derivation ends, not left to the cyclic collector
(issue 27: after a style sheet's derivation 55,000 objects waited for it, 0.1 s of a 1 s
restyle, and a full collection over a loaded sheet took 0.25 s)."""

from __future__ import annotations

import gc
import weakref

import bgr
from bgr.interpreter import engine as engine_module

GRAMMAR = """version 1
attr floors = 3
const h = 3
start Lot
terminal Window, Wall
Lot --> extrude(floors * h) comp(f) { side: Facade | all: Wall }
Facade --> split(y) { ~h: Floor }*
Floor --> split(x) { ~1: Wall | 1.2: Win(0.5 + split.index * 0) | ~1: Wall }*
Win(inset) --> s('1, '1 - inset / 2, '1) Window
"""


def test_no_engine_outlives_its_derivation(monkeypatch):
    engines: list[weakref.ref] = []
    init = engine_module.Engine.__init__

    def recording(self, *args, **kwargs):
        engines.append(weakref.ref(self))
        init(self, *args, **kwargs)

    monkeypatch.setattr(engine_module.Engine, "__init__", recording)
    bgr.derive(GRAMMAR, lot=(12.0, 8.0))  # imports and first-use caches out of the way
    engines.clear()
    gc.collect()
    gc.disable()  # only reference counting frees anything below
    try:
        result = bgr.derive(GRAMMAR, lot=(12.0, 8.0))
        assert len(result.terminals) > 20
        assert len(engines) == 2  # the attrs' engine and the lot's
        assert [ref() for ref in engines] == [None, None]
        # nor their compiled expressions (closures in reference cycles with their compilers)
        assert gc.collect() == 0
    finally:
        gc.enable()
