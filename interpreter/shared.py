"""What the lots of one run share: the grammar's compiled expressions and the engine's plans.

Every lot is derived by a fresh :class:`~bgr.interpreter.engine.Engine` (batch.derive_lot), and
each used to compile every expression it met and work out every operation's, successor's and
rule's plan again (Helsinki: 481 lots, 4-5 % of the derivation).  None of that depends on the
lot: a compiled expression reads an attr or a const through its module's ``values`` dict when
it runs, never when it is compiled, and a plan is made of compiled expressions and the
grammar's own nodes.  So the first lot's engine leaves them in the run's cache (batch's split
cache, whose keys are ids of the same grammar's nodes), and each later engine takes them over,
after writing its lot's attr and const values into the kept compilers' ``values``.

The kept compilers hold their compiled funcs in reference cycles (Engine.release):
:func:`forget` breaks them when the run, or the cache, ends.
"""

from __future__ import annotations

# the key of what share() keeps in the run's cache
SHARED = "engine.compiled"
# the engine's caches that are taken over with the compilers: each is keyed by ids of the
# grammar's nodes, and its entries are compiled expressions or the grammar's own values
_CACHES = (
    "compilers",
    "_exprs",
    "signatures",
    "binders",
    "defaults",
    "targets",
    "rule_locals",
    "uses_center",
    "constant_sizes",
    "_bindings",
)


def share(engine, cache: dict) -> None:
    """Make ``engine`` use the compiled expressions and plans kept in ``cache`` by the lots
    before it (or keep its own there, for the lots after it).  Call it before deriving."""
    kept = cache.get(SHARED)
    fresh = engine.compilers
    if kept is not None and kept["compilers"].keys() != fresh.keys():
        forget(cache)  # another grammar's: not expected in one run, but never mixed
        kept = None
    if kept is None:
        cache[SHARED] = {name: getattr(engine, name) for name in _CACHES}
        engine.shared = True
        return
    for key, compiler in fresh.items():  # this lot's attrs and consts, where kept code reads them
        values = kept["compilers"][key].values
        values.clear()
        values.update(compiler.values)
        compiler.funcs.clear()
    fresh.clear()  # the fresh compilers and their dict were a reference cycle
    for name in _CACHES:
        setattr(engine, name, kept[name])
    engine.shared = True  # its release() leaves them to the lots after it


def forget(cache: dict) -> None:
    """Drop what share() kept in ``cache``, breaking the compilers' reference cycles, so that
    nothing is left for the cyclic collector (tests/test_engine_release.py)."""
    kept = cache.pop(SHARED, None)
    if kept is None:
        return
    for compiler in kept["compilers"].values():
        compiler.funcs.clear()
    for name in _CACHES:
        kept[name].clear()
