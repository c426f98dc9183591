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

from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as _version

from .grammar.checker import Grammar
from .grammar.errors import BgrCheckError, BgrError, BgrSyntaxError, Diagnostic
from .grammar.formatter import format_module, format_source
from .grammar.loader import load
from .grammar.parser import parse
from .interpreter.derive import Result, derive

try:
    __version__ = _version("bgr")
except PackageNotFoundError:  # pragma: no cover - running from a source tree without install
    __version__ = "0+unknown"

__all__ = [
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
