"""The files around a CGA rule file: its assets, its imports, and the .bgr files written.

CityEngine finds a rule's assets in its project's ``assets/`` folder (a rule package keeps
``rules/`` and ``assets/`` side by side) and reads paths starting with ``/`` from the workspace
root.  :class:`Assets` looks in the same places around the CGA file; what it finds is named
relative to the .bgr file being written, what it does not find is a warning, and the geometry
becomes a box filling the asset's scope (``i(cube)``), a texture is left out.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..grammar import nodes as n
from ..grammar.errors import BgrError, Diagnostic
from ..grammar.loader import decode
from ..grammar.paths import read_input
from ..grammar.registry import KEYWORDS, PRIMITIVES
from .lookup import find
from .parse import parse_lenient
from .styles import style_blocks, style_module
from .translate import Translator, ascii_name

READABLE_MESHES = (".obj", ".glb", ".gltf", ".ply", ".stl", ".off")
READABLE_IMAGES = (".png", ".jpg", ".jpeg")
_BUILTIN = {"cube": "cube", "cylinder": "cylinder", "sphere": "sphere", "quad": "quad"}


@dataclass
class Assets:
    """The assets and textures one CGA file names, as the .bgr file in ``out_dir`` reaches them."""

    folder: Path
    out_dir: Path
    decls: dict[str, n.Asset] = field(default_factory=dict)
    outside: set[Path] = field(default_factory=set)
    warned: set[str] = field(default_factory=set)

    def once(self, warn, meta, text: str, message: str, hint: str | None = None) -> None:
        """Each missing file is reported once, where the file first names it."""
        if text not in self.warned:
            self.warned.add(text)
            warn(meta, message, hint)

    def relative(self, found: Path) -> str:
        rel = Path(os.path.relpath(found.resolve(), self.out_dir.resolve())).as_posix()
        if rel.startswith("../"):
            self.outside.add(found.resolve().parent)
        return rel

    def geometry(self, text: str, meta, warn) -> n.Expr:
        if text.startswith("builtin:"):
            kind = text.split(":")[1]
            if kind in _BUILTIN:
                return n.Name(_BUILTIN[kind])
            warn(meta, f"built-in asset '{text}' is not in bgr; a box stands in")
            return n.Name("cube")
        found = find(text, self.folder)
        if found is None:
            self.once(
                warn,
                meta,
                text,
                f"asset '{text}' was not found beside the file; a box of its scope stands in",
                "put the rule package's assets/ folder beside the rules/ folder",
            )
            return n.Name("cube")
        if found.suffix.lower() not in READABLE_MESHES:
            self.once(
                warn,
                meta,
                text,
                f"asset '{text}' is a {found.suffix} file, which bgr cannot read; a box stands in",
                "convert it to OBJ, glTF, PLY or STL",
            )
            return n.Name("cube")
        if text not in self.decls:
            taken = {a.name for a in self.decls.values()}
            base = re.sub(r"\W", "_", found.stem) or "asset"
            if base[0].isdigit() or base in PRIMITIVES or base in KEYWORDS:
                base = "a_" + base
            name, k = base, 1
            while name in taken:
                k += 1
                name = f"{base}{k}"
            self.decls[text] = n.Asset(name, self.relative(found))
        return n.Name(self.decls[text].name)

    def texture(self, text: str, meta, warn) -> n.Expr | None:
        if text == "":
            return n.String("")
        found = find(text, self.folder)
        if found is None:
            self.once(
                warn, meta, text, f"texture '{text}' was not found beside the file; it is left out"
            )
            return None
        if found.suffix.lower() not in READABLE_IMAGES:
            self.once(
                warn,
                meta,
                text,
                f"texture '{text}' is a {found.suffix} file; bgr reads "
                "PNG and JPEG, so it is left out",
            )
            return None
        return n.String(self.relative(found))

    def texture_prefix(self, images: set[str]) -> str | None:
        """The folder every image the file names is found under, relative to the output (a
        computed path is that folder + the path); None when one is missing or unreadable."""
        prefixes = set()
        for text in images:
            found = find(text, self.folder)
            if found is None or found.suffix.lower() not in READABLE_IMAGES:
                return None
            rel = self.relative(found)
            tail = text.lstrip("/")
            if not rel.endswith(tail):
                return None
            prefixes.add(rel[: len(rel) - len(tail)])
        return prefixes.pop() if len(prefixes) == 1 else None

    def declared(self) -> list[n.Asset]:
        return list(self.decls.values())


def read_cga(path: Path) -> str:
    """A .cga file's text; other files are refused unread (an error quotes what it reads)."""
    shown = str(path)
    if path.suffix.lower() != ".cga":
        raise BgrError(
            Diagnostic(
                shown,
                0,
                0,
                "not a .cga file: CGA rules are read from .cga files only",
                "rename it to end in .cga",
            )
        )
    try:
        data = read_input(path, "CGA file")
    except FileNotFoundError:
        raise BgrError(Diagnostic(shown, 0, 0, "no such file", "check the path")) from None
    except IsADirectoryError:
        raise BgrError(Diagnostic(shown, 0, 0, "is a folder, not a .cga file")) from None
    except OSError as e:
        raise BgrError(
            Diagnostic(shown, 0, 0, f"cannot read the file: {e.strerror or e}")
        ) from None
    return decode(data, shown)


@dataclass
class Imported:
    """The result of one import: each .bgr file to write with its text, and the warnings."""

    outputs: dict[Path, str] = field(default_factory=dict)
    warnings: list[Diagnostic] = field(default_factory=list)
    attrs: dict[Path, dict[str, str]] = field(default_factory=dict)  # CGA name -> bgr name
    # per output: (CGA rule, arity) -> bgr rule, what an importer's overrides name
    rules: dict[Path, dict[tuple[str, int], str]] = field(default_factory=dict)


def translate_file(source: Path, output: Path) -> Imported:
    """Translate ``source`` (and the CGA files it imports) into ``output`` (and beside it)."""
    from ..grammar.formatter import format_module
    from . import overrides

    result = Imported()
    busy: list[Path] = []

    def one(src: Path, out: Path) -> None:
        text = read_cga(src)
        tree, comments, unread = parse_lenient(text, str(src))
        result.warnings += unread
        assets = Assets(src.parent, out.parent)
        busy.append(src.resolve())

        def resolve_import(target: str, meta) -> tuple[str, dict, dict] | None:
            found = find(target, src.parent)
            line, column = getattr(meta, "line", 0), getattr(meta, "column", 0)
            if found is None:
                result.warnings.append(
                    Diagnostic(
                        str(src),
                        line,
                        column,
                        f"imported file '{target}' was not found; rules "
                        "taken from it are left as leaves",
                        "put it beside the file (or its project folder above it)",
                        severity="warning",
                    )
                )
                return None
            if found.resolve() in busy:
                result.warnings.append(
                    Diagnostic(
                        str(src),
                        line,
                        column,
                        f"'{target}' imports itself (a cycle); left out",
                        severity="warning",
                    )
                )
                return None
            target_out = out.parent / (found.stem + ".bgr")
            k = 1
            while target_out in result.outputs or target_out.resolve() == out.resolve():
                k += 1
                target_out = out.parent / f"{found.stem}_{k}.bgr"
            try:
                one(found, target_out)
            except BgrError as e:
                result.warnings += [
                    Diagnostic(**{**d.__dict__, "severity": "warning"}) for d in e.diagnostics
                ]
                return None
            return target_out.name, result.attrs[target_out], result.rules[target_out]

        tr = Translator(tree, comments, text, str(src), assets, resolve_import)
        module = tr.module()
        busy.pop()
        if assets.outside:
            folders = ", ".join(sorted(str(p) for p in assets.outside))
            tr.warnings.append(
                Diagnostic(
                    str(src),
                    0,
                    0,
                    f"its assets are outside {out.parent}: derive with --allow-path for {folders}",
                    severity="warning",
                )
            )
        result.outputs[out] = format_module(module)
        result.attrs[out] = dict(tr.attrs)
        result.rules[out] = overrides.rules_of(tr)
        rules = module.rules()
        for decl, items in style_blocks(tree):
            if not rules:
                tr.warn(decl.meta, f"style '{decl.children[0]}': the file has no rules to run")
                continue
            start = tr.start or rules[0].name
            styled = style_module(tr, decl, items, out.name, start)
            styled_out = out.with_name(f"{out.stem}.{ascii_name(str(decl.children[0]))}.bgr")
            result.outputs[styled_out] = format_module(styled)
        result.warnings += tr.warnings

    one(source, output)
    return result
