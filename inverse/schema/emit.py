"""Face, floor and model schemas of a :class:`Model`, written as a .bgr syntax tree.

* **Face schemas** (one rule per distinct subdivided cell): a cell's parts get symbols by the
  equality relation, the symbols are rewritten by Build-by-Number's pair rule
  (:mod:`.faces`), and the result becomes a ``split`` whose repeat groups are the starred pairs;
  fixed parts get absolute sizes, stretchable ones floating sizes.
* **Model schema**: a face's rows are its floors; the base, the bottom floor, the top floor and
  the roof trim do not repeat, the run of equal middle floors does.
* **Floor schemas**: a face of the target chooses among the source's face schemas by its corners
  (``comp.left``/``comp.right``: one of nine categories), then by the side it faces, then by
  width, then by the fewest occluded subfaces.

Deviations from the paper, each for a reason the docs give (docs/inverse-schema.md): columns are
equal when their labels *and* widths agree (so the schema re-creates its source exactly at the
source's size); a run of three or more equal columns, which the pair rule cannot express, repeats
as one symbol; every split is checked against the interpreter's split solver at the source size
and written without repeat groups if they would not give the source back.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass

from bgr.grammar import nodes as n
from bgr.grammar.safe_text import RESERVED, comment_text, identifier
from bgr.interpreter import split_solver as solver

from . import faces as fs
from .model import Cell, Face, Model

SIDES = ("front", "right", "back", "left")
_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_RESERVED = RESERVED


@dataclass(frozen=True)
class Run:
    """One column repeated: ``count`` equal columns from ``index`` on (our extension)."""

    index: int
    count: int


def _side(face: Face) -> str:
    """The comp selector a face had: the reader's, or by its outward normal (front is -z)."""
    if face.side in SIDES:
        return face.side
    from .terminals import side_of

    return side_of(face.normal)


class Emitter:
    def __init__(self, model: Model) -> None:
        self.model = model
        self.rules: list[n.Rule] = []
        self.by_key: dict[str, str] = {}
        self.labels: list[str] = []
        self.taken: set[str] = set()
        for cell in (f.root for f in model.faces()):
            for leaf in cell.leaves():
                if leaf.label and leaf.label not in self.labels:
                    self.labels.append(leaf.label)
        self.labels += [lbl for lbl in model.roof_labels if lbl not in self.labels]
        self.taken.update({"Lot"})
        # the scope axes a face's columns (x) and rows (y) are split along: a face from comp(f)
        # has x across and y up; a flat façade is the lot, whose rows run along another axis
        x_name, y_name = model.flat_axes or ("x", "y")
        self.axis_names = {"x": x_name, "y": y_name}
        # a label that is a plain name is a terminal of that name; any other ("shop-window",
        # "Lot", "split") gets a rule of a clean name that sets the label
        self.leaf: dict[str, str] = {}
        self.terminals: list[str] = []
        # a label with a colour is a rule that sets it (the terminal keeps the rule's name)
        colors = model.label_colors or {lbl: _default_color(lbl) for lbl in self.labels}
        self.colored: list[n.Rule] = []
        for label in self.labels:
            if _IDENT.fullmatch(label) and label not in self.taken and label not in _RESERVED:
                self.leaf[label] = label
                self.taken.add(label)
                if colors.get(label, _GREY) != _GREY:
                    self.colored.append(
                        n.Rule(
                            label, [], n.Sequence([n.Operation("color", [n.String(colors[label])])])
                        )
                    )
                else:
                    self.terminals.append(label)
        for label in self.labels:
            if label not in self.leaf:
                name = self.leaf[label] = self.fresh(label)
                steps = [n.Operation("label", [n.String(label)])]
                if colors.get(label, _GREY) != _GREY:
                    steps.insert(0, n.Operation("color", [n.String(colors[label])]))
                self.colored.append(n.Rule(name, [], n.Sequence(steps)))

    # ---- names ---------------------------------------------------------------------------
    def fresh(self, base: str) -> str:
        """A new rule name from input text (a label, a face's name): safe_text.identifier."""
        name = identifier(base, "Part", prefix="R", capital=True, taken=self.taken)
        self.taken.add(name)
        return name

    # ---- face schemas --------------------------------------------------------------------
    def target(self, cell: Cell) -> n.Sequence:
        """What a part becomes: its terminal label, NIL for a gap, or the rule of its schema."""
        if cell.is_leaf:
            return n.Sequence([n.Successor(self.leaf[cell.label])] if cell.label else [n.Nil()])
        return n.Sequence([n.Successor(self.rule_for(cell))])

    def rule_for(self, cell: Cell, name: str | None = None) -> str:
        key = cell.key()
        if key in self.by_key:
            return self.by_key[key]
        rule_name = self.by_key[key] = self.fresh(name or cell.label or _auto_name(cell))
        body = n.Sequence([self.split(cell, floors=name is not None)])
        self.rules.append(n.Rule(rule_name, [], body))
        return rule_name

    def entry(self, cell: Cell) -> n.Entry:
        kind = "abs" if cell.fixed else "float"
        return n.Entry(kind, n.Number(_clean(cell.size)), self.target(cell))

    def split(self, cell: Cell, floors: bool) -> n.Operation:
        parts = cell.parts
        keys = [f"{p.key()}@{round(p.size, 4)}{'!' if p.fixed else ''}" for p in parts]
        syms = fs.symbols(keys)
        items = (
            _model_rows(syms) if floors and cell.axis == "y" else _extend(fs.rewrite(syms), syms)
        )
        if any(isinstance(it, Run) for it in items):
            items = _expressible(items)
        else:  # the pair rule's own groups: faces.unroll also settles ties between equal groups
            items = fs.unroll(items, widths=[p.size for p in parts])
        entries = self.entries(items, parts)
        if not _reproduces(entries, parts, sum(p.size for p in parts)):
            entries = [self.entry(p) for p in parts]  # written out: exact, but it will not grow
        return n.Operation("split", [n.Name(self.axis_names[cell.axis])], n.Block(entries))

    def entries(self, items, parts: list[Cell]) -> list:
        out = []
        for it in items:
            if isinstance(it, fs.Sym):
                out.append(self.entry(parts[it.index]))
            elif isinstance(it, fs.Star):
                out.append(
                    n.Group([self.entry(parts[it.first_index]), self.entry(parts[it.second_index])])
                )
            else:
                out.append(n.Group([self.entry(parts[it.index])]))
        return out

    # ---- floor schemas -------------------------------------------------------------------
    def face_rules(self) -> dict[str, list[tuple[Face, str]]]:
        """One rule per distinct face schema; the faces that use each, by side."""
        by_side: dict[str, list[tuple[Face, str]]] = {s: [] for s in SIDES}
        for face in self.model.faces():
            if face.root.is_leaf:
                name = self.by_key.get(face.root.key())
                if name is None:
                    name = self.by_key[face.root.key()] = self.fresh(face.name + "Face")
                    self.rules.append(n.Rule(name, [], self.target(face.root)))
            else:
                name = self.rule_for(face.root, face.name)
            by_side[_side(face)].append((face, name))
        return by_side

    def chooser(self, side: str, by_side) -> n.Rule:
        """``FrontFacade --> case <corners>: ... | else: ...``: the floor schema's choice."""
        pool = [fr for s in SIDES for fr in by_side[s]]
        cases = []
        for left in ("outer", "inner", "flat"):
            for right in ("outer", "inner", "flat"):
                cond = _and(_corner_test("comp.left", left), _corner_test("comp.right", right))
                best = _ranked(pool, left, right)  # the corners first, then the side it faces
                best = [fn for fn in best if _side(fn[0]) == side] or best
                cases.append(n.Case(cond, n.Sequence([n.Successor(self.by_width(best))])))
        cases[-1] = n.Case(None, cases[-1].body)
        return n.Rule(self.fresh(side.capitalize() + "Facade"), [], _body(_merge(cases)))

    def by_width(self, ranked: list[tuple[Face, str]]) -> str:
        """A rule choosing by width among equally good faces (closest width, then fewest
        occluded subfaces), or the one face's schema."""
        names = _distinct(ranked)
        if len(names) == 1:
            return names[0][1]
        key = "|".join(f"{nm}@{round(f.width, 4)}" for f, nm in names)
        if key in self.by_key:
            return self.by_key[key]
        body = self.width_choice(names)
        if isinstance(body, n.Sequence):
            return body.steps[0].name
        rule_name = self.by_key[key] = self.fresh("ByWidth")
        self.rules.append(n.Rule(rule_name, [], body))
        return rule_name

    def width_choice(self, ranked: list[tuple[Face, str]]) -> n.Sequence | n.Conditional:
        """The body that picks the schema of the closest width (``case scope.sx < mid: ...``),
        among schemas of the same width the one with the fewest occluded subfaces; the one
        schema's successor when there is nothing to choose."""
        widths = []
        for face, name in sorted(_distinct(ranked), key=lambda fn: (fn[0].width, fn[0].occluded())):
            if not widths or face.width - widths[-1][0].width > 1e-6:
                widths.append((face, name))
        if len(widths) == 1:
            return n.Sequence([n.Successor(widths[0][1])])
        measure = n.Name("scope.s" + self.axis_names["x"])
        cases = []
        for (a, name), (b, _) in itertools.pairwise(widths):
            mid = (a.width + b.width) / 2
            cases.append(
                n.Case(
                    n.Binary("<", measure, n.Number(_clean(mid))), n.Sequence([n.Successor(name)])
                )
            )
        cases.append(n.Case(None, n.Sequence([n.Successor(widths[-1][1])])))
        return _body(_merge(cases))

    # ---- the whole grammar ---------------------------------------------------------------
    def module(self) -> n.Module:
        if self.model.flat_axes is not None:
            return self.flat_module()
        basis = self.model.sorted_blocks()[0]
        by_side = self.face_rules()
        choosers = {s: self.chooser(s, by_side) for s in SIDES}
        roof = self.model.roof_labels[0] if self.model.roof_labels else None
        # comp entries in the order the source's faces came out, so its terminal order comes back
        seen = [_side(f) for f in sorted(self.model.faces(), key=lambda f: f.order)]
        order = list(dict.fromkeys(seen + list(SIDES)))
        entries = [
            n.Entry("abs", n.Name(s), n.Sequence([n.Successor(choosers[s].name)])) for s in order
        ]
        entries.append(
            n.Entry(
                "abs",
                n.Name("top"),
                n.Sequence([n.Successor(self.leaf[roof])] if roof else [n.Nil()]),
            )
        )
        entries.append(n.Entry("abs", n.Name("bottom"), n.Sequence([n.Nil()])))
        lot = n.Rule(
            "Lot",
            [],
            n.Sequence(
                [
                    n.Operation("extrude", [n.Name("height")]),
                    n.Operation("comp", [n.Name("f")], n.Block(entries)),
                ]
            ),
        )
        head = [n.Version(1), n.Attr("height", n.Number(_clean(basis.height)))]
        if self.terminals:
            head.append(n.TerminalDecl(list(self.terminals)))
        faces = sum(len(b.faces) for b in self.model.blocks)
        leaves = sum(f.root.count() for f in self.model.faces())
        header = [
            f"# Inferred by bgr infer --kind schema from {self.source()}:",
            f"# {faces} faces, {leaves} subfaces; {len(self.rules)} schema rules. Derive it on a "
            "lot:",
            "#   bgr derive THIS.bgr --lot W,D|LOTS.geojson -o out.glb   (--set height=H)",
        ]
        if self.model.dropped:
            header.insert(
                2,
                f"# ({self.model.dropped} small faces on no mass, such as the sides of "
                "bays and dormers, are left out.)",
            )
        header += self.skipped_note()
        return _laid_out(header, [head, [lot], list(choosers.values()), self.rules, self.colored])

    def flat_module(self) -> n.Module:
        """The grammar of a flat model: the lot is the façade.  No extrude, no comp and no
        height: the lot rule splits the lot itself (its floors along the lot's axis that the
        source's rows ran along, ``split(z)`` for a lot split in x and z), and the lot's size is
        the façade's width and height.  Several distinct façades (one per lot of a GeoJSON
        source) are chosen among by width."""
        faces = self.model.faces()
        keys = list(dict.fromkeys(f.root.key() for f in faces))
        if len(keys) == 1:
            root = faces[0].root
            if root.is_leaf:
                body = self.target(root)
            else:
                self.by_key[root.key()] = "Lot"
                body = n.Sequence([self.split(root, floors=True)])
        else:
            body = self.width_choice([(f, self.flat_schema(f)) for f in faces])
        lot = n.Rule("Lot", [], body)
        head: list = [n.Version(1)]
        if self.terminals:
            head.append(n.TerminalDecl(list(self.terminals)))
        leaves = sum(f.root.count() for f in faces)
        x_name, y_name = self.axis_names["x"], self.axis_names["y"]
        plural = "s" if len(faces) != 1 else ""
        header = [
            f"# Inferred by bgr infer --kind schema from {self.source()}:",
            f"# {len(faces)} flat façade{plural}, {leaves} subfaces; {len(self.rules) + 1} schema "
            "rules. The lot is the façade:",
            f"# its columns run along the lot's {x_name}, its rows (floors) along its {y_name}. "
            "Derive it on a lot",
            "# as wide and as high as the façade:",
            "#   bgr derive THIS.bgr --lot W,H|LOTS.geojson -o out.glb",
        ]
        header += self.skipped_note()
        return _laid_out(header, [head, [lot], self.rules, self.colored])

    def flat_schema(self, face: Face) -> str:
        """The rule of one flat façade among several."""
        if not face.root.is_leaf:
            return self.rule_for(face.root, face.name)
        name = self.by_key.get(face.root.key())
        if name is None:
            name = self.by_key[face.root.key()] = self.fresh(face.name)
            self.rules.append(n.Rule(name, [], self.target(face.root)))
        return name

    def source(self) -> str:
        """The source's name as a comment can hold it (a file name is input: safe_text)."""
        return comment_text(self.model.source) if self.model.source else "a model"

    def skipped_note(self) -> list[str]:
        if not self.model.skipped:
            return []
        count = self.model.skipped
        return [
            f"# ({count} part{'s' if count != 1 else ''} of zero size (lines, faces without "
            f"area) {'are' if count != 1 else 'is'} left out.)"
        ]


# ---- symbol strings ----------------------------------------------------------------------------

_GREY = "#cccccc"  # the interpreter's default colour: nothing to write
_COMMON = {
    "window": "#3b4a5a",
    "glass": "#3b4a5a",
    "door": "#5a3a28",
    "entrance": "#5a3a28",
    "brick": "#9c4a35",
    "wall": "#d8c8a8",
    "plinth": "#8c8a84",
    "base": "#8c8a84",
    "trim": "#e4ddd0",
    "cornice": "#e4ddd0",
    "sill": "#e4ddd0",
    "pier": "#c9b99b",
    "pilaster": "#c9b99b",
    "roof": "#6b6b6b",
    "shop": "#4a6a7a",
    "sign": "#2f4f4f",
    "fascia": "#2f4f4f",
    "step": "#a9a9a4",
}


def _default_color(label: str) -> str:
    """A preview colour for a label from a model that has none (a captured model): common
    architectural words get their usual colour, others a stable muted one from the name."""
    low = label.lower()
    for word, color in _COMMON.items():
        if word in low:
            return color
    h = sum((i + 1) * ord(c) for i, c in enumerate(label))
    return f"#{0x90 + h % 0x40:02x}{0x90 + (h // 7) % 0x40:02x}{0x90 + (h // 49) % 0x40:02x}"


def _auto_name(cell: Cell) -> str:
    """A name from the labels inside an unnamed cell: its most telling leaf (a fixed one, else
    the first) and its shape: ``WindowColumn`` for a y split, ``WindowRow`` for an x split."""
    leaves = [leaf for leaf in cell.leaves() if leaf.label]
    key = next((leaf for leaf in leaves if leaf.fixed), leaves[0] if leaves else None)
    base = key.label if key is not None else "Empty"
    return base[:1].upper() + base[1:] + ("Column" if cell.axis == "y" else "Row")


def _extend(items, syms):
    """Our one addition to the pair rule: a run of three or more equal plain columns (which no
    pair can express: AA is never a pair) repeats as one column."""
    out, i = [], 0
    while i < len(items):
        it = items[i]
        if isinstance(it, fs.Sym):
            j = i
            while (
                j + 1 < len(items)
                and isinstance(items[j + 1], fs.Sym)
                and syms[items[j + 1].index] == syms[it.index]
            ):
                j += 1
            if j - i + 1 >= 3:
                out.append(Run(it.index, j - i + 1))
                i = j + 1
                continue
        out.append(it)
        i += 1
    return out


def _model_rows(syms):
    """A face's floors (the model schema): the longest run of equal rows repeats — the middle
    floors; base, bottom floor, top floor and roof trim around it stay single.  Without a run of
    two or more, the pair rule decides."""
    best, i = (0, 0), 0
    while i < len(syms):
        j = i
        while j + 1 < len(syms) and syms[j + 1] == syms[i]:
            j += 1
        if j - i + 1 > best[1]:
            best = (i, j - i + 1)
        i = j + 1
    start, length = best
    if length < 2:
        return _extend(fs.rewrite(syms), syms)
    return (
        [fs.Sym(k) for k in range(start)]
        + [Run(start, length)]
        + [fs.Sym(k) for k in range(start + length, len(syms))]
    )


def _expressible(items):
    """Pull repetitions out of groups until all counts are k or k + 1, the only counts the
    application rule can give, so the source size comes back (cf. faces.unroll)."""
    counts = [it.count for it in items if not isinstance(it, fs.Sym)]
    if fs.counts_expressible(counts):
        return items
    k = min(counts)
    out = []
    for it in items:
        if isinstance(it, fs.Sym):
            out.append(it)
            continue
        keep = min(it.count, k + 1)
        extra = it.count - keep
        if isinstance(it, fs.Star):
            out.append(fs.Star(it.first_index, it.second_index, keep))
            out += [fs.Sym(it.first_index), fs.Sym(it.second_index)] * extra
        else:
            out.append(Run(it.index, keep))
            out += [fs.Sym(it.index)] * extra
    return out


def _reproduces(entries, parts: list[Cell], length: float) -> bool:
    """Does the split solver lay these entries out at the source length exactly as the source?"""

    def item(e):
        if isinstance(e, n.Group):
            return solver.Repeat(tuple(item(x) for x in e.entries))
        return solver.Piece(e.kind, e.key.value)

    placed = solver.solve([item(e) for e in entries], length)
    if len(placed) != len(parts):
        return False
    return all(abs(p.size - c.size) < 1e-7 for p, c in zip(placed, parts, strict=True))


# ---- floor-schema choice -------------------------------------------------------------------


def _distinct(ranked: list[tuple[Face, str]]) -> list[tuple[Face, str]]:
    """The first face of each schema name, in order."""
    out: dict[str, Face] = {}
    for face, name in ranked:
        out.setdefault(name, face)
    return [(face, name) for name, face in out.items()]


def _corner_test(name: str, kind: str):
    if kind == "outer":
        return n.Binary(">", n.Name(name), n.Number(1))
    if kind == "inner":
        return n.Binary("<", n.Name(name), n.Number(-1))
    return n.Binary(
        "and", n.Binary(">=", n.Name(name), n.Number(-1)), n.Binary("<=", n.Name(name), n.Number(1))
    )


def _and(a, b):
    return n.Binary("and", a, b)


def _ranked(pool, left: str, right: str):
    """The faces of ``pool`` that best fit a face with these corners: most matching corners
    (a free edge counts as an outer corner); ties are settled by width later."""

    def score(face: Face) -> int:
        fl = "outer" if face.left == "free" else face.left
        fr = "outer" if face.right == "free" else face.right
        return (fl == left) + (fr == right)

    top = max(score(f) for f, _ in pool)
    return [(f, name) for f, name in pool if score(f) == top]


def _merge(cases: list[n.Case]) -> list[n.Case]:
    """Drop cases that lead where the final else does, and fold equal neighbours with 'or'."""
    last = cases[-1]
    target = last.body.steps[0].name
    kept = [c for c in cases[:-1] if c.body.steps[0].name != target]
    merged: list[n.Case] = []
    for c in kept:
        if merged and merged[-1].body.steps[0].name == c.body.steps[0].name:
            merged[-1] = n.Case(n.Binary("or", merged[-1].cond, c.cond), merged[-1].body)
        else:
            merged.append(c)
    return merged + [last]


def _body(cases: list[n.Case]):
    """A conditional body, or the one sequence when nothing is left to choose."""
    return n.Conditional(cases) if len(cases) > 1 else cases[0].body


def _clean(x: float) -> float:
    """Sizes as written: rounded to 1e-9 m so that 2.9999999999999996 reads 3."""
    r = round(x, 9)
    return r if abs(r - x) < 1e-9 else x


def _laid_out(header: list[str], groups: list[list]) -> n.Module:
    """A module whose layout the formatter keeps: the header comment, then the groups of items
    with a blank line between groups (positions and a stand-in source tell it where lines are)."""
    items, comments, lines = [], [], []
    for text in header:
        lines.append(text)
        comments.append(n.Comment(text, len(lines), 1, True))
    for group in groups:
        if not group:
            continue
        lines.append("")
        for item in group:
            lines.append("x")
            item.pos = n.Pos(len(lines), 1, len(lines), 2)
            items.append(item)
    return n.Module(items, comments=comments, source="\n".join(lines) + "\n")
