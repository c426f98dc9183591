"""The Markdown reference of the standard library, generated from its doc comments.

    python -m bgr.grammar.stdlib_reference > docs/stdlib.md

Every public rule of ``stdlib/*.bgr`` is listed with its summary, its parameters (with their
defaults, as the formatter prints them) and a thumbnail; ``docs/make_gallery.py`` renders the
thumbnails with ``bgr render``.  A test keeps docs/stdlib.md equal to this output.
"""

from __future__ import annotations

from .docstrings import module_header, rule_docs
from .formatter import format_expr
from .loader import _stdlib_dir
from .parser import parse

# The modules in the order the reference shows them, with how thumbnails are made.
MODULES = ("mass", "facade", "window", "roof", "palette", "textured")
TITLES = {
    "mass": "Building masses (`stdlib.mass`)",
    "facade": "Façades (`stdlib.facade`)",
    "window": "Windows and entrances (`stdlib.window`)",
    "roof": "Roof assemblies (`stdlib.roof`)",
    "palette": "Colours (`stdlib.palette`)",
    "textured": "Textured surfaces (`stdlib.textured`)",
}

EXAMPLE = """\
import stdlib.mass as mass
import stdlib.facade as fac
import stdlib.window as win

Lot --> mass.{mass}(facade = Upper, front = Street)
Upper --> fac.{upper}(window = win.Arched, tile_w = 3.5)
Street --> fac.{street}(window = win.Arched, ground = win.Shop)
"""


def thumbnail_path(module: str, rule: str) -> str:
    """Where docs/make_gallery.py writes a rule's thumbnail, relative to docs/."""
    return f"img/stdlib/{module}/{rule}.png"


def public_rules(module_name: str):
    """(module tree, [(rule, RuleDoc or None)]) of a stdlib module's public rules, in file order."""
    path = _stdlib_dir() / f"{module_name}.bgr"
    tree = parse(path.read_text(encoding="utf-8"), str(path))
    docs = rule_docs(tree)
    return tree, [(r, docs.get(r.name)) for r in tree.rules() if not r.name.startswith("_")]


def _signature(rule) -> str:
    parts = []
    for i, p in enumerate(rule.params):
        d = rule.default(i)
        parts.append(p if d is None else f"{p} = {format_expr(d)}")
    return f"{rule.name}({', '.join(parts)})" if parts else rule.name


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def stdlib_markdown(example: dict[str, str] | None = None) -> str:
    """docs/stdlib.md.  ``example`` names the rules of the composition example."""
    example = example or {"mass": "LHip", "upper": "Grid", "street": "Shopfront"}
    out = [
        "# The standard library",
        "",
        "Generated from the doc comments of `stdlib/*.bgr` by `python -m "
        "bgr.grammar.stdlib_reference`;",
        "thumbnails by `python docs/make_gallery.py`. Do not edit.",
        "",
        "The standard library is a set of `.bgr` modules bundled with bgr. A grammar imports them",
        "with `import stdlib.NAME as alias` and applies their rules like its own. Every rule takes",
        "parameters with defaults ([defaults and keyword "
        "arguments](language.md#defaults-keyword-arguments-and-rules-as-parameters)),",
        "so `fac.Grid` and `fac.Grid(tile_w = 4, window = win.Arched)` both work, and the parts",
        "of a mass or a façade (its façades, windows, doors, roof) are rules handed over as",
        "parameters: plug in your own rule anywhere a stdlib part goes. The families follow",
        "Nishida et al. 2018 (*Procedural modeling of a building from a single image*): 30 masses",
        "(Figure 3), 16 façades (Figure 5) and 31 windows and entrances (Figure 6), plus roof",
        "assemblies, a colour palette and textured surfaces (the images bgr ships).",
        "",
        "A building from the library in a few lines:",
        "",
        "```bgr",
        EXAMPLE.format(**example).rstrip(),
        "```",
        "",
        "What each module's rules receive:",
        "",
        "- **masses** receive the lot (a flat footprint); `facade` is applied to every side face,"
        " `front` to the street face, `roof` to the top;",
        "- **façades** receive a vertical face from `comp(f)` and split it into floors and tiles;",
        "- **windows and entrances** receive the opening rectangle a façade leaves for them;",
        "- **roof assemblies** receive the top face of a mass;",
        "- **textured surfaces** receive a face whose caller set up a projection"
        " (`setupProjection(0, scope.xy, ~2, ~1.2)`).",
        "",
        "![contact sheet of the standard library](img/stdlib/contact_sheet.png)",
        "",
    ]
    for name in MODULES:
        tree, rules = public_rules(name)
        out += [f"## {TITLES[name]}", ""]
        header = module_header(tree)
        if header:
            out += [header, ""]
        if not rules:
            consts = [item for item in tree.items if type(item).__name__ == "Const"]
            out += ["| const | value |", "|---|---|"]
            out += [f"| `{name}.{c.name}` | `{format_expr(c.value)}` |" for c in consts]
            out.append("")
            continue
        out += ["| | rule |", "|---|---|"]
        for rule, doc in rules:
            summary = doc.summary if doc else ""
            params = "".join(
                f"<br>`{p}`: {_cell(text)}" for p, text in (doc.params.items() if doc else [])
            )
            image = f"![{rule.name}]({thumbnail_path(name, rule.name)})"
            out.append(f"| {image} | `{_cell(_signature(rule))}`<br>{_cell(summary)}{params} |")
        out.append("")
    return "\n".join(out)


if __name__ == "__main__":
    print(stdlib_markdown(), end="")
