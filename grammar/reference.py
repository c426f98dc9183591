"""The Markdown reference of operations and built-ins, generated from the registry.

    python -m bgr.grammar.reference > docs/operations.md

A test keeps docs/operations.md equal to this output.
"""

from __future__ import annotations

from .registry import (
    BUILTIN_NAMES,
    BUILTINS,
    COMP_SELECTORS,
    FOOTPRINT_KINDS,
    OPERATIONS,
    PRIMITIVES,
    ROOF_KINDS,
)


def _cell(text: str) -> str:
    """Table cells cannot hold a bare '|', not even inside backticks."""
    return text.replace("|", "\\|")


def reference_markdown() -> str:
    """The operation and function reference, generated from this registry (docs/operations.md)."""
    out = [
        "# Operations and built-in functions",
        "",
        "Generated from `grammar/registry.py` by `python -m bgr.grammar.reference`; do not edit.",
        "",
    ]
    families = [
        "transforms",
        "splits",
        "components",
        "roofs",
        "inserts",
        "appearance",
        "attributes",
        "reports",
        "texturing",
    ]
    for family in families:
        out += [
            f"## {family.capitalize()}",
            "",
            "| operation | meaning | example |",
            "|---|---|---|",
        ]
        for op in OPERATIONS.values():
            if op.family == family:
                out.append(f"| `{_cell(op.usage())}` | {_cell(op.doc)} | `{_cell(op.example)}` |")
        out.append("")
    out += ["## Built-in functions", "", "| function | meaning |", "|---|---|"]
    for b in BUILTINS.values():
        out.append(f"| `{b.usage}` | {b.doc[0].upper() + b.doc[1:]} |")
    out += ["", "## Built-in names", "", "| name | meaning |", "|---|---|"]
    for name, doc in BUILTIN_NAMES.items():
        out.append(f"| `{name}` | {doc} |")
    out += [
        "",
        "Symbols: roof kinds "
        + ", ".join(f"`{k}`" for k in ROOF_KINDS)
        + "; footprints "
        + ", ".join(f"`{k}`" for k in FOOTPRINT_KINDS)
        + "; primitives "
        + ", ".join(f"`{p}`" for p in PRIMITIVES)
        + "; component selectors "
        + ", ".join(f"`{s}`" for s in COMP_SELECTORS)
        + ", `face(i)`; offset selectors `inside`, `border`.",
        "",
    ]
    return "\n".join(out)


if __name__ == "__main__":
    print(reference_markdown(), end="")
