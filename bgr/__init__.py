"""bgr: a building-grammar toolkit.

The public Python API::

    import bgr
    grammar = bgr.load("house.bgr")        # parse, resolve imports, check; raises bgr.BgrError
    text = bgr.format_source(open("house.bgr").read())   # canonical layout, comments kept
    result = bgr.derive(grammar, seed=3)     # terminals as a table; result.save("house.glb")

Every bad value, in a file or an argument, is a :class:`BgrError` with a located message
(docs/cli.md, "Values from outside", gives the ranges).  Only text that is not text at all,
``load(None)`` or ``format_source(5)``, is a ``TypeError``: a programmer's error, not a user's.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .grammar.annotations import attr_metadata
    from .grammar.checker import Grammar
    from .grammar.errors import BgrCheckError, BgrError, BgrSyntaxError, Diagnostic
    from .grammar.formatter import format_module, format_source
    from .grammar.loader import load
    from .grammar.parser import parse
    from .interpreter.derive import Result, derive

# The API is imported when first used, not with the package: ``bgr --version`` and a command
# that needs only the parser start without the interpreter, numpy and trimesh.
_WHERE = {
    "attr_metadata": ".grammar.annotations",
    "Grammar": ".grammar.checker",
    "BgrError": ".grammar.errors",
    "BgrCheckError": ".grammar.errors",
    "BgrSyntaxError": ".grammar.errors",
    "Diagnostic": ".grammar.errors",
    "format_module": ".grammar.formatter",
    "format_source": ".grammar.formatter",
    "load": ".grammar.loader",
    "parse": ".grammar.parser",
    "Result": ".interpreter.derive",
    "derive": ".interpreter.derive",
}
# the package's folders, as attributes: ``import bgr; bgr.formats.meshes``
_PACKAGES = {"formats", "grammar", "interpreter", "inverse", "render", "stdlib"}


def version() -> str:
    """The installed package's version ("0+unknown" in a source tree without install)."""
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as installed

    try:
        return installed("bgr")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree without install
        return "0+unknown"


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        value = getattr(import_module(_WHERE[name], __name__), name)
    elif name in _PACKAGES:
        value = import_module(f".{name}", __name__)
    elif name == "__version__":
        value = version()
    else:
        raise AttributeError(f"module 'bgr' has no attribute {name!r}")
    globals()[name] = value
    return value


__all__ = [
    "attr_metadata",
    "load",
    "derive",
    "Result",
    "parse",
    "format_source",
    "format_module",
    "Grammar",
    "BgrError",
    "BgrSyntaxError",
    "BgrCheckError",
    "Diagnostic",
    "__version__",
]
