"""A CGA syntax tree -> a bgr syntax tree (``bgr.grammar.nodes``), and what could not be carried.

Two passes.  The first collects the file's names (rules with their arities, functions, attrs,
consts, imports), so that the second can tell a successor from an operation and an attr from a
function when it translates each rule.  Where bgr writes CGA's meaning otherwise, the
translation rewrites it:

- rules overloaded by arity (``Pipe(d, h, s)`` and ``Pipe(s)``) get one name each;
- a ``case`` or stochastic body nested in a branch becomes a rule of its own;
- an undefined successor or a leaf ``Name.`` becomes a declared ``terminal``, as CGA leaves it;
- an attr whose default reads the shape (``attr h = geometry.area / 10``: CGA evaluates it on the
  initial shape) gets a plain default and is ``set()`` to that expression when the start rule
  begins;
- a parameterless function (``tileW = a + b``) is a ``func tileW()``, called where it is named.

Everything else is dropped with a warning at its line and column (:attr:`Translator.warnings`).
"""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Callable

from lark import Token, Tree

from ..grammar import nodes as n
from ..grammar.annotations import SPECS
from ..grammar.errors import Diagnostic, source_line
from ..grammar.registry import (
    BUILTIN_NAMES,
    BUILTINS,
    KEYWORDS,
    OPERATIONS,
)
from . import media, overrides
from . import operations as ops
from .expressions import Expressions, dotted, pos, unquote
from .selectors import selectors
from .start import At, prepend_to_start, shape_attrs

EMPTY = "t"  # a step that changes nothing: a sequence CGA leaves empty keeps its shape as a leaf


def ascii_name(name: str) -> str:
    """A bgr name for a CGA one: CGA's names may hold any letter (``Façade``), bgr's are ASCII."""
    if name.isascii():
        return name
    text = unicodedata.normalize("NFKD", name).encode("ascii", "ignore").decode()
    text = re.sub(r"\W", "_", text)
    return text if text and not text[0].isdigit() else "_" + text


def _nothing() -> n.Sequence:
    return n.Sequence([n.Operation(EMPTY, [n.Number(0.0)] * 3)])


_PLAIN_BUILTINS = {k for k in BUILTIN_NAMES if "." not in k}
_ZERO_ARG_OPS = set(ops.SAME) | set(ops.DROPPED) | set(ops.PRIMITIVES) | {"NIL"}


class Translator:
    """Translate one parsed CGA file; ``assets`` and ``imports`` look files up beside it."""

    def __init__(
        self,
        tree: Tree,
        comments: list[n.Comment],
        text: str,
        path: str,
        assets,
        imports: Callable[[str, object], tuple[str, dict, dict] | None],
    ) -> None:
        self.tree, self.comments, self.text, self.path = tree, comments, text, path
        self.assets, self.resolve_import = assets, imports
        self.warnings: list[Diagnostic] = []
        self.expr_tr = Expressions(self)
        self.rules: dict[tuple[str, int], str] = {}
        self.arities: dict[str, set[int]] = {}
        self.funcs: dict[str, tuple[str, int]] = {}
        self.attrs: dict[str, str] = {}
        self.consts: dict[str, str] = {}
        self.arrays: set[str] = set()  # the CGA attrs and consts whose value is an array literal
        self.imports: dict[str, str | None] = {}
        # per import alias: (CGA rule, arity) -> its bgr name there (overrides.rules_of)
        self.import_rules: dict[str, dict[tuple[str, int], str]] = {}
        self.undefined: dict[tuple[str, int], str] = {}  # rules called but not defined here
        self.terminals: dict[str, str] = {}  # CGA leaf name -> bgr terminal
        self.taken: set[str] = set()
        self.params: dict[str, str] = {}
        self.rule_params: list[str] = []
        self.rule_name = ""
        self.extra: list[n.Rule] = []
        self.helpers = 0
        self.start: str | None = None
        self.seen_names: set = set()
        self.bindings: list[n.Operation] = []  # imports' attribute bindings, as set()s
        self.skipped: set[int] = set()  # items declared a second time

    # ---- diagnostics -----------------------------------------------------------------------
    def warn(self, meta, message: str, hint: str | None = None) -> None:
        if isinstance(meta, Tree):
            meta = meta.meta
        line = getattr(meta, "line", 0) or 0
        column = getattr(meta, "column", 0) or 0
        self.warnings.append(
            Diagnostic(
                self.path,
                line,
                column,
                message,
                hint,
                source_line(self.text, line),
                severity="warning",
            )
        )

    # ---- names -------------------------------------------------------------------------------
    def fresh(self, name: str, reserved=()) -> str:
        """``name``, or with ``_`` (then a number) added where bgr reserves it or it is taken."""
        name = ascii_name(name)
        base = name if name not in KEYWORDS and name not in reserved else name + "_"
        out, k = base, 1
        while out in self.taken:
            k += 1
            out = f"{base}{k}"
        self.taken.add(out)
        return out

    def collect(self) -> None:
        """Pass one: every name the file declares."""
        style = False
        for item in self.tree.children:
            kind = item.data
            if kind == "style_decl":
                style = True
            if style:
                continue
            if kind in ("rule", "func_decl", "attr_decl", "const_decl") and self.again(item):
                continue
            if kind == "rule" and "." not in str(item.children[0]):
                name, params = str(item.children[0]), _names(item.children[1])
                self.arities.setdefault(name, set()).add(len(params))
            elif kind == "func_decl" or (kind == "const_decl" and item.children[1] is not None):
                name = str(item.children[0])
                self.funcs[name] = (self.fresh(name, BUILTINS), len(_names(item.children[1])))
            elif kind == "attr_decl":
                self.attrs[str(item.children[0])] = self.fresh(
                    str(item.children[0]), _PLAIN_BUILTINS
                )
            elif kind == "const_decl":
                self.consts[str(item.children[0])] = self.fresh(
                    str(item.children[0]), _PLAIN_BUILTINS
                )
            if kind in ("attr_decl", "const_decl") and _is_array(item.children[-1]):
                self.arrays.add(str(item.children[0]))
        for name, arities in self.arities.items():
            for k, arity in enumerate(sorted(arities)):
                bgr = name if k == 0 else f"{name}_{arity}"
                self.rules[(name, arity)] = self.fresh(bgr, OPERATIONS)

    def again(self, item: Tree) -> bool:
        """Whether ``item`` declares again what an earlier one did (a rule of the same name and
        arity, a value or function of the same name): it is left out, with a warning."""
        name = str(item.children[0])
        key = (
            ("rule", name, len(_names(item.children[1])))
            if item.data == "rule"
            else ("value", name)
        )
        if key in self.seen_names:
            self.skipped.add(id(item))
            self.warn(item.meta, f"'{name}' is declared a second time; this one is left out")
            return True
        self.seen_names.add(key)
        return False

    def value(self, name: str, meta) -> n.Expr | None:
        if name in self.params:
            return n.Name(self.params[name])
        if name in self.attrs:
            return n.Name(self.attrs[name])
        if name in self.consts:
            return n.Name(self.consts[name])
        if name in self.funcs and self.funcs[name][1] == 0:
            return n.Call(self.funcs[name][0], [])
        alias, _, rest = name.partition(".")
        if rest and alias in self.imports:
            if self.imports[alias] is None:
                self.warn(meta, f"'{name}': its import was not translated; 0 stands in")
                return n.Number(0.0)
            return n.Name(f"{self.imports[alias]}.{rest}")
        return None

    def function(self, name: str, args: list[n.Expr], meta) -> n.Expr | None:
        if name in self.funcs:
            return n.Call(self.funcs[name][0], args)
        alias, _, rest = name.partition(".")
        if rest and alias in self.imports and self.imports[alias] is not None:
            return n.Call(f"{self.imports[alias]}.{rest}", args)
        return None

    def attr_name(self, name: str) -> str | None:
        return self.attrs.get(name)

    def expr(self, t) -> n.Expr:
        return self.expr_tr(t)

    def op_arg(self, t, symbols: bool = False):
        if isinstance(t, Tree) and t.data == "rel_arg":
            return n.Relative(self.expr(t.children[0]), pos=pos(t.meta))
        if isinstance(t, Tree) and t.data == "float_arg":
            return n.Relative(self.expr(t.children[0]), pos=pos(t.meta), floating=True)
        if isinstance(t, Tree) and t.data == "keyword_arg":
            self.warn(t.meta, f"named argument '{t.children[0]}' is read by position")
            return self.expr(t.children[1])
        if symbols:
            word = ops.is_symbol_arg(t, projection=True)
            if word is not None:
                return n.Name(word)
        return self.expr(t)

    # ---- the module ------------------------------------------------------------------------
    def module(self) -> n.Module:
        self.collect()
        items: list = [n.Version(1.0)]
        notes: list[n.Annotation] = []
        attrs: list[n.Attr] = []
        consts: list[n.Const] = []
        style = None
        for item in self.tree.children:
            kind = item.data
            if kind == "style_decl":
                style = item  # written as a grammar of its own (styles.py)
                continue
            if style is not None or id(item) in self.skipped:
                notes = []
                continue
            if kind == "annotation":
                note = self.annotation(item)
                if note is not None and any(a.name == note.name for a in notes):
                    self.warn(item.meta, f"@{note.name} is given twice; the second is left out")
                elif note is not None:
                    notes.append(note)
                continue
            if kind == "version_decl":
                items[0].pos = pos(item.meta)
            elif kind in ("import_named", "import_plain"):
                self.import_item(item, notes, items)
            elif kind == "attr_decl":
                name = str(item.children[0])
                attr = n.Attr(
                    self.attrs[name],
                    self.expr(item.children[1]),
                    pos=pos(item.meta),
                    annotations=[a for a in notes if _on_attr(a)],
                )
                self.drop_notes([a for a in notes if not _on_attr(a)], "an attr")
                items.append(attr)
                attrs.append(attr)
            elif kind == "const_decl" and item.children[1] is None:
                self.drop_notes(notes, "a const")
                name = str(item.children[0])
                const = n.Const(self.consts[name], self.expr(item.children[2]), pos=pos(item.meta))
                items.append(const)
                consts.append(const)
            elif kind in ("const_decl", "func_decl"):
                self.drop_notes(notes, "a function")
                items.append(self.func(item))
            elif kind == "rule" and "." in str(item.children[0]):
                found = overrides.override(self, item, notes)
                items += ([found] if found is not None else []) + self.extra
                self.extra = []
            elif kind == "rule":
                items.append(self.rule(item, notes))
                items += self.extra
                self.extra = []
            notes = []
        self.drop_notes(notes, "the end of the file")
        if self.bindings:  # after the attrs that read the shape (prepended next) are set
            items = prepend_to_start(self, items, self.bindings)
        items = shape_attrs(self, items, attrs, consts)
        if media.inserts(self):  # CGA's trim planes are on from the start; bgr's wait for this
            trim_on = n.Operation("set", [n.Name("trim.vertical"), n.Bool(True)])
            items = prepend_to_start(self, items, [trim_on])
        # the declarations bgr wants up front stand on the version's line, so that comments
        # keep their places around them
        head = items[0].pos if items[0].pos.line else n.Pos(1, 1, 1, 1)
        items[0].pos = head
        if self.terminals:
            items.insert(1, n.TerminalDecl(sorted(set(self.terminals.values())), pos=head))
        if self.start is not None:
            items.insert(1, n.Start(self.start, pos=head))
        for asset in reversed(self.assets.declared()):
            asset.pos = head
            items.insert(1, asset)
        return n.Module(items, path=self.path, comments=self.comments, source=self.text)

    def drop_notes(self, notes: list, what: str) -> None:
        for note in notes:
            self.warn(
                At(note.pos),
                f"annotation @{note.name} on {what} is "
                "left out (bgr keeps annotations on attrs and rules)",
            )

    def annotation(self, t: Tree) -> n.Annotation | None:
        name = str(t.children[1])
        args = [self.raw_arg(a) for a in (t.children[2].children if t.children[2] else [])]
        if name == "Range" and args and all(isinstance(a, n.String) for a in args):
            name = "Enum"  # CGA 2014's @Range of strings: a list of choices, later @Enum
        note = n.Annotation(name, args, pos=pos(t.meta))
        spec = SPECS.get(name)
        problem = spec.check(args) if spec is not None else None
        if problem is not None:
            self.warn(t.meta, f"@{name} {problem}; it is left out")
            return None
        return note

    def raw_arg(self, t):
        """An annotation's argument as written: names stay names (``@Hidden(Usage)``)."""
        if isinstance(t, Tree) and t.data == "keyword_arg":
            return n.Keyword(str(t.children[0]), self.raw_arg(t.children[1]))
        if isinstance(t, Tree) and t.data in ("name", "dotted"):
            return n.Name(dotted(t.children[0] if t.data == "name" else t))
        if isinstance(t, Tree) and t.data == "prefix" and str(t.children[0]) == "-":
            return n.Unary("-", self.raw_arg(t.children[1]))
        if isinstance(t, Tree) and t.data == "number":
            return n.Number(float(str(t.children[0])))
        if isinstance(t, Tree) and t.data == "string":
            return n.String(unquote(t.children[0]))
        if isinstance(t, Tree) and t.data in ("true", "false"):
            return n.Bool(t.data == "true")
        return self.expr(t)

    def import_item(self, t: Tree, notes: list, items: list) -> None:
        self.drop_notes(notes, "an import")
        if t.data == "import_plain":
            self.warn(
                t.meta,
                "an import without a name is not in bgr; it is left out",
                'name it: import name : "file.cga"',
            )
            return
        alias, target, args = str(t.children[0]), unquote(t.children[1]), t.children[2]
        bindings = args.children[0] if args is not None else None
        found = self.resolve_import(target, t.meta)
        if found is None:
            self.imports[alias] = None
            return
        bgr_path, their_attrs, self.import_rules[alias] = found
        name = self.fresh(alias, ("scope", "split", "comp", "stdlib"))
        self.imports[alias] = name
        items.append(n.Import(name, path=bgr_path, pos=pos(t.meta)))
        listed = list(bindings.children) if bindings is not None else []
        protected = {str(b.children[0]) for b in listed if len(b.children) == 1}
        for binding in listed:
            self.bind(name, binding, their_attrs)
        if args is not None and not listed:  # import x : "f.cga" (): every attr protected
            return
        # CGA propagates the importer's attrs to the imported file's of the same name, but
        # those the import lists (protected, or given a value)
        given = {str(b.children[0]) for b in listed}
        for attr in their_attrs:
            if attr in self.attrs and attr not in given | protected:
                value = n.Name(self.attrs[attr])
                target = n.Name(f"{name}.{their_attrs[attr]}")
                self.bindings.append(n.Operation("set", [target, value]))

    def bind(self, alias: str, binding: Tree, their_attrs: dict) -> None:
        """An import's attribute binding ``(height = Eave_Ht)``: ``set(alias.height, Eave_Ht)``
        when the start rule begins; ``(height)`` alone protects the imported file's attr from
        the importer's of that name (nothing to write)."""
        attr = str(binding.children[0])
        if attr not in their_attrs:
            self.warn(binding.meta, f"the imported file has no attr '{attr}'; binding left out")
            return
        if len(binding.children) == 1:
            return
        target = n.Name(f"{alias}.{their_attrs[attr]}")
        self.bindings.append(n.Operation("set", [target, self.expr(binding.children[1])]))

    def func(self, t: Tree) -> n.Func:
        name, params = str(t.children[0]), _names(t.children[1])
        self.params = dict(zip(params, self.params_of(params), strict=True))
        body = self.expr(t.children[2])
        self.params = {}
        return n.Func(self.funcs[name][0], list(self.params_of(params)), body, pos=pos(t.meta))

    def params_of(self, params: list[str]) -> list[str]:
        out = [ascii_name(p) for p in params]
        return [p if p not in KEYWORDS else p + "_" for p in out]

    # ---- rules -------------------------------------------------------------------------------
    def rule(self, t: Tree, notes: list) -> n.Rule:
        name, params = str(t.children[0]), _names(t.children[1])
        bgr_name = self.rules[(name, len(params))]
        self.rule_name = bgr_name
        self.rule_params = self.params_of(params)
        self.params = dict(zip(params, self.rule_params, strict=True))
        if any(a.name == "StartRule" for a in notes):
            if self.start is None and not params:
                self.start = bgr_name
            else:
                self.warn(
                    t.meta,
                    f"a second @StartRule ('{name}'); bgr starts at "
                    f"'{self.start}' unless you derive with --rule",
                )
        kept = [
            a
            for a in notes
            if not _on_attr(a) or a.name in ("Hidden", "Description", "Order", "Group")
        ]
        body = self.body(t.children[3])
        self.params = {}
        return n.Rule(
            bgr_name,
            list(self.rule_params),
            body,
            pos=pos(t.meta),
            annotations=[a for a in kept if _on_rule(a)],
        )

    def body(self, t) -> n.Body:
        if isinstance(t, Tree) and t.data == "cond":
            cases = [
                n.Case(self.expr(c.children[1]), self.branch(c.children[2]), pos=pos(c.meta))
                for c in t.children[:-1]
            ]
            cases.append(
                n.Case(None, self.branch(t.children[-1].children[1]), pos=pos(t.children[-1].meta))
            )
            return n.Conditional(cases, pos=pos(t.meta))
        if isinstance(t, Tree) and t.data == "stoch":
            choices = [
                n.Choice(self.expr(c.children[0]), self.branch(c.children[2]), pos=pos(c.meta))
                for c in t.children[:-1]
            ]
            choices.append(
                n.Choice(
                    None, self.branch(t.children[-1].children[1]), pos=pos(t.children[-1].meta)
                )
            )
            return n.Stochastic(choices, pos=pos(t.meta))
        return self.sequence_of(t.children if isinstance(t, Tree) else [t], pos(t.meta))

    def branch(self, t) -> n.Sequence:
        """A branch's steps; a branch that is itself a case or a stochastic choice becomes a rule
        of its own (bgr nests them only that way)."""
        if isinstance(t, Tree) and t.data in ("cond", "stoch"):
            return n.Sequence([self.helper(self.body(t), pos(t.meta))], pos=pos(t.meta))
        return self.sequence_of(t.children, pos(t.meta))

    def helper(self, body: n.Body, where: n.Pos) -> n.Successor:
        """A new rule with the current rule's parameters and ``body``; its successor."""
        self.helpers += 1
        name = self.fresh(f"{self.rule_name.replace('.', '_')}_{self.helpers}", OPERATIONS)
        self.extra.append(n.Rule(name, list(self.rule_params), body, pos=where))
        return n.Successor(name, [n.Name(p) for p in self.rule_params], pos=where)

    def sequence_of(self, steps: list, where: n.Pos = n.NOWHERE) -> n.Sequence:
        out = self.steps(list(steps))
        return n.Sequence(out, pos=where) if out else _nothing()

    def steps(self, trees: list) -> list:
        """CGA's NIL is a successor that makes nothing: the steps after it still run on the
        shape (``report(..) NIL report(..) NIL`` reports twice), which bgr's NIL would end, so
        a NIL with steps after it moves to the end of the sequence."""
        out: list = []
        deleted = None
        for k, t in enumerate(trees):
            rest = trees[k + 1 :]
            made, took_rest = self.step(t, rest)
            nils = [s for s in made if isinstance(s, n.Nil)]
            out += [s for s in made if not isinstance(s, n.Nil)]
            deleted = deleted or (nils[0] if nils else None)
            if took_rest:
                break
        return out + [deleted] if deleted is not None else out

    def step(self, t, rest: list) -> tuple[list, bool]:
        if isinstance(t, Token) and t.type == "NIL":
            return [n.Nil(pos=pos(t))], False
        if isinstance(t, Tree) and t.data == "nil":
            return [n.Nil(pos=pos(t.meta))], False
        if isinstance(t, Tree) and t.data == "push":
            inner = self.steps(list(t.children))
            return ([n.Push(inner, pos=pos(t.meta))] if inner else []), False
        if isinstance(t, Tree) and t.data == "leaf":
            return [self.leaf(str(t.children[0])[:-1], t.meta)], False
        if isinstance(t, Tree) and t.data == "successor":
            name = dotted(t.children[0])
            if name in self.arities or "." in name or name not in _ZERO_ARG_OPS:
                return [self.successor(name, [], t.meta)], False
            return ops.operation(self, name, [], None, t.meta, rest)
        # a call: a rule with arguments, or an operation
        name = dotted(t.children[0])
        args = list(t.children[1].children) if t.children[1] is not None else []
        block = t.children[2]
        if name in self.arities or (("." in name) and name.split(".")[0] in self.imports):
            return [self.successor(name, args, t.meta)], False
        return ops.operation(self, name, args, block, t.meta, rest)

    def successor(self, name: str, args: list, meta) -> n.Step:
        values = [self.expr(a) for a in args]
        if name in self.arities:
            bgr = self.rules.get((name, len(args)))
            if bgr is not None:
                return n.Successor(bgr, values, pos=pos(meta))
            self.warn(
                meta, f"no rule '{name}' takes {len(args)} arguments; the shape is left as a leaf"
            )
            return self.leaf(name, meta, quiet=True)
        alias, _, rest = name.partition(".")
        if rest and alias in self.imports:
            if self.imports[alias] is not None:
                return n.Successor(f"{self.imports[alias]}.{rest}", values, pos=pos(meta))
            return self.leaf(f"{alias}_{rest}", meta, quiet=True)
        if args:
            self.warn(meta, f"unknown rule or operation '{name}'; the shape is left as a leaf")
        return self.leaf(name.replace(".", "_"), meta, quiet=True)

    def leaf(self, name: str, meta, quiet: bool = False) -> n.Step:
        """A leaf shape named ``name`` (CGA's ``Name.``, or a successor without a rule)."""
        if name not in self.terminals:
            clash = name in self.arities
            self.terminals[name] = self.fresh(name + "Leaf" if clash else name, OPERATIONS)
        return n.Successor(self.terminals[name], [], pos=pos(meta))

    def block(self, t: Tree, kind: str) -> n.Block | None:
        """A block's entries; None when none of them could be translated."""
        entries = self.entries(t.children[1], kind)
        if not entries:
            return None
        return n.Block(entries, repeat=t.children[3] is not None, pos=pos(t.meta))

    def entries(self, t: Tree, kind: str) -> list:
        out: list = []
        named: set[str] = set()
        for e in t.children:
            if e.data == "plain_group":  # `{ ... }` without a star only groups its entries
                out += self.entries(e.children[1], kind)
                continue
            if e.data == "group":
                out.append(n.Group(self.entries(e.children[1], kind), pos=pos(e.meta)))
                continue
            key_tree, body = e.children
            size = {"key_abs": "abs", "key_rel": "rel", "key_float": "float"}[key_tree.data]
            whole = e.data == "keyed_whole" and kind in ("comp", "comp:f")  # bgr's `=`
            if e.data == "keyed_whole" and kind != "split" and not whole:
                self.warn(
                    e.meta,
                    "a '=' selector (all the parts as one shape) takes them one by one in bgr "
                    "outside comp(f)",
                )
            if kind == "split":
                out.append(
                    n.Entry(
                        size,
                        self.expr(key_tree.children[0]),
                        self.sequence_of(body.children, pos(body.meta)),
                        pos=pos(e.meta),
                    )
                )
                continue
            for key in self.selectors(key_tree.children[0], kind, e.meta, named):
                sequence = self.sequence_of(body.children, pos(body.meta))
                out.append(n.Entry("abs", key, sequence, pos=pos(e.meta), combine=whole))
        return out

    def selectors(self, t, kind: str, meta, named: set[str]) -> list:
        return selectors(self, t, kind, meta, named)


def _names(t) -> list[str]:
    return [] if t is None else [str(c) for c in t.children]


def _on_attr(note: n.Annotation) -> bool:
    spec = SPECS.get(note.name)
    return spec is None or "attr" in spec.targets


def _on_rule(note: n.Annotation) -> bool:
    spec = SPECS.get(note.name)
    return spec is None or "rule" in spec.targets


def _is_array(t) -> bool:
    """An array literal (``[1, 2, 3]``), which setback() reads as a distance per edge."""
    return isinstance(t, Tree) and t.data == "array"
