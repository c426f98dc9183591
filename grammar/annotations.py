"""Annotations: CityEngine CGA's ``@Name(args)`` lines above an attr or a rule.

In CGA, annotations "do not affect the semantics of a rule and thus have no influence on the
model generation"; they tell an editor how to present an attribute (a slider's range, a list of
choices, a group, an order, a colour picker) or a rule (the start rule, a description).  bgr
reads them the same way: the derivation never looks at them, the checker holds them to CGA's
documented forms (:data:`SPECS`), and :func:`attr_metadata` hands them to tools (the preview's
sliders, the CGA import) as plain values.

An annotation bgr does not know is kept and reported as a warning, not an error: CGA files carry
annotations of newer CityEngine releases, and none of them changes what a grammar derives.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from . import nodes as n
from .errors import Diagnostic, source_line

ATTR, RULE = "attr", "rule"


@dataclass(frozen=True)
class Spec:
    """One annotation: what it may stand above, its form as CGA's reference writes it, and
    a check of its arguments that returns a problem's text (None when they are right)."""

    targets: tuple[str, ...]
    form: str
    check: Callable[[list], str | None]


def _literal(e) -> object:
    """The value of a literal argument (a number, maybe negative, a string, true or false);
    ``_NOT`` for anything else."""
    if isinstance(e, n.Number):
        return e.value
    if isinstance(e, n.Unary) and e.op == "-" and isinstance(e.operand, n.Number):
        return -e.operand.value
    if isinstance(e, (n.String, n.Bool)):
        return e.value
    return _NOT


_NOT = object()


def _split(args: list) -> tuple[list, dict]:
    return [a for a in args if not isinstance(a, n.Keyword)], {
        a.name: a.value for a in args if isinstance(a, n.Keyword)
    }


def _none(args: list) -> str | None:
    return "takes no arguments" if args else None


def _one_string(args: list) -> str | None:
    if len(args) != 1 or not isinstance(args[0], n.String):
        return "takes one string"
    return None


def _strings(args: list) -> str | None:
    if not all(isinstance(a, n.String) for a in args):
        return "takes strings only"
    return None


def _order(args: list) -> str | None:
    if len(args) != 1 or not isinstance(_literal(args[0]), float):
        return "takes one number"
    return None


def _group(args: list) -> str | None:
    names = args[:-1] if args and not isinstance(args[-1], n.String) else args
    if not names or not all(isinstance(a, n.String) for a in names):
        return "takes one or more group names (strings), then optionally an order (a number)"
    if len(names) < len(args) and not isinstance(_literal(args[-1]), float):
        return "ends with an order, a number"
    return None


def _restricted(named: dict) -> str | None:
    if "restricted" in named and not isinstance(_literal(named["restricted"]), bool):
        return "restricted is true or false"
    return None


def _range(args: list) -> str | None:
    plain, named = _split(args)
    if plain:  # the older form, @Range(min, max)
        values = [v for v in map(_literal, plain) if isinstance(v, float)]
        if named or len(plain) != 2 or len(values) != 2:
            return "takes min = NUMBER, max = NUMBER (and stepsize, restricted), or two numbers"
        low, high = values
    elif set(named) <= {"min", "max", "stepsize", "restricted"}:
        literal = {k: _literal(v) for k, v in named.items() if k != "restricted"}
        if not all(isinstance(v, float) for v in literal.values()):
            return "min, max and stepsize are numbers"
        numbers: dict[str, float] = {k: v for k, v in literal.items() if isinstance(v, float)}
        if numbers.get("stepsize", 0.0) < 0:
            return "stepsize is 0 (none) or more"
        low, high = numbers.get("min", float("-inf")), numbers.get("max", float("inf"))
        if (problem := _restricted(named)) is not None:
            return problem
    else:  # the oldest form, @Range(Low = 0, Mid = 1): named choices
        if any(_literal(v) is _NOT for v in named.values()):
            return "a named choice's value is a number, a string or true/false"
        return None
    if low > high:
        return f"has its min ({low:g}) above its max ({high:g})"
    return None


def _enum(args: list) -> str | None:
    plain, named = _split(args)
    if set(named) - {"restricted", "valuesAttr"}:
        return "takes values, then optionally restricted = true|false"
    if "valuesAttr" in named:
        if plain or not isinstance(named["valuesAttr"], n.Name):
            return "valuesAttr = NAME names the attr that holds the values, and nothing else"
    elif not plain or any(_literal(a) is _NOT for a in plain):
        return "takes its values: numbers, strings or true/false"
    return _restricted(named)


def _hidden(args: list) -> str | None:
    if not all(isinstance(a, n.Name) for a in args):
        return "takes nothing, or the names of attributes to hide"
    return None


def _out(args: list) -> str | None:
    plain, named = _split(args)
    value = named.get("granularity")
    if plain or set(named) != {"granularity"} or not isinstance(value, n.Name):
        return "takes granularity = separatedShapes|combinedShape"
    if value.name not in ("separatedShapes", "combinedShape"):
        return "granularity is separatedShapes or combinedShape"
    return None


def _location(args: list) -> str | None:
    if len(args) != 2 or not all(isinstance(_literal(a), float) for a in args):
        return "takes two numbers (x, y)"
    return None


def _any(args: list) -> str | None:
    return None


BOTH = (ATTR, RULE)
SPECS: dict[str, Spec] = {
    "Angle": Spec((ATTR,), "@Angle", _none),
    "Color": Spec((ATTR,), "@Color", _none),
    "Description": Spec(BOTH, '@Description("text")', _one_string),
    "Directory": Spec((ATTR,), "@Directory", _none),
    "DisplayName": Spec((ATTR,), '@DisplayName("name")', _one_string),
    "Distance": Spec((ATTR,), "@Distance", _none),
    "Enum": Spec((ATTR,), "@Enum(value_1, ..., restricted = true)", _enum),
    "File": Spec((ATTR,), '@File or @File("ext_1", ...)', _strings),
    "Group": Spec(BOTH, '@Group("level_1", ..., order)', _group),
    "Handle": Spec((ATTR,), "@Handle(handle parameters)", _any),
    "Hidden": Spec(BOTH, "@Hidden or @Hidden(attr_1, ...)", _hidden),
    "InLine": Spec((RULE,), "@InLine", _none),
    "InMesh": Spec((RULE,), "@InMesh", _none),
    "InPoint": Spec((RULE,), "@InPoint", _none),
    "InPointCloud": Spec((RULE,), "@InPointCloud", _none),
    "InPolygon": Spec((RULE,), "@InPolygon", _none),
    "Location": Spec(BOTH, "@Location(x, y)", _location),
    "MaterialFile": Spec((ATTR,), "@MaterialFile", _none),
    "Order": Spec(BOTH, "@Order(order)", _order),
    "Out": Spec((RULE,), "@Out(granularity = separatedShapes|combinedShape)", _out),
    "Percent": Spec((ATTR,), "@Percent", _none),
    "Range": Spec((ATTR,), "@Range(min = a, max = b, stepsize = 0, restricted = true)", _range),
    "StartRule": Spec((RULE,), "@StartRule", _none),
}


def _annotated(module: n.Module):
    """(item, its kind) for every attr and rule of ``module`` that has annotations."""
    for item in module.items:
        if isinstance(item, (n.Attr, n.Rule)) and item.annotations:
            yield item, ATTR if isinstance(item, n.Attr) else RULE


def _diagnostic(path: str, source: str, note: n.Annotation, message: str, hint, severity):
    pos = note.pos
    length = pos.end_column - pos.column if pos.end_line == pos.line else 1
    return Diagnostic(
        path, pos.line, pos.column, message, hint, source_line(source, pos.line), max(length, 1),
        severity=severity,
    )  # fmt: skip


def annotation_errors(path: str, module: n.Module) -> list[Diagnostic]:
    """Annotations of a known name in the wrong place, with the wrong arguments, or twice."""
    out = []
    for item, kind in _annotated(module):
        seen: set[str] = set()
        for note in item.annotations:
            spec = SPECS.get(note.name)
            if spec is None:
                continue
            problem = None
            if note.name in seen:
                problem = f"@{note.name} is given twice for {kind} '{item.name}'"
            elif kind not in spec.targets:
                problem = f"@{note.name} annotates {' or '.join(spec.targets)}s, not {kind}s"
            elif (text := spec.check(note.args)) is not None:
                problem = f"@{note.name} {text}"
            seen.add(note.name)
            if problem is not None:
                hint = f"CGA writes it {spec.form}"
                out.append(_diagnostic(path, module.source, note, problem, hint, "error"))
    return out


def annotation_warnings(path: str, module: n.Module) -> list[Diagnostic]:
    """Unknown annotations (kept as metadata), and an attr whose default a restricted @Range
    or @Enum would not let an editor choose."""
    out = []
    for item, _ in _annotated(module):
        for note in item.annotations:
            if note.name not in SPECS:
                out.append(
                    _diagnostic(
                        path,
                        module.source,
                        note,
                        f"unknown annotation @{note.name}: kept as metadata, no effect",
                        f"CityEngine's annotations: {', '.join('@' + k for k in SPECS)}",
                        "warning",
                    )
                )
        if isinstance(item, n.Attr):
            info = _info(item)
            problem = _outside(info)
            if problem is not None:
                note = next(a for a in item.annotations if a.name in ("Range", "Enum"))
                out.append(_diagnostic(path, module.source, note, problem, None, "warning"))
    return out


def _outside(info: dict) -> str | None:
    """Whether a literal default lies outside the attr's restricted range or choices."""
    default = info.get("default")
    bounds = info.get("range")
    if isinstance(default, float) and bounds and bounds.get("restricted", True):
        low, high = bounds.get("min"), bounds.get("max")
        if (low is not None and default < low) or (high is not None and default > high):
            return f"the default {default:g} is outside @Range({low:g}, {high:g})"
    choices: dict = info.get("enum") or {}
    restricted = "values" in choices and choices.get("restricted", True)
    if restricted and default is not None and default not in choices["values"]:
        return f"the default {default!r} is not one of the @Enum values"
    return None


def _info(attr: n.Attr) -> dict:
    """An attr's annotations as plain values (see :func:`attr_metadata`)."""
    value = _literal(attr.value)
    info: dict = {"default": None if value is _NOT else value}
    for note in attr.annotations:
        plain, named = _split(note.args)
        key = note.name[0].lower() + note.name[1:]
        if note.name == "Range":
            if plain:
                info["range"] = {"min": _literal(plain[0]), "max": _literal(plain[1])}
            elif set(named) <= {"min", "max", "stepsize", "restricted"}:
                info["range"] = {k: _literal(v) for k, v in named.items()}
            else:  # named choices, the oldest form
                values = [_literal(v) for v in named.values()]
                info["enum"] = {"values": values, "labels": list(named)}
        elif note.name == "Enum":
            choices: dict = {k: _literal(v) for k, v in named.items() if k == "restricted"}
            if "valuesAttr" in named and isinstance(named["valuesAttr"], n.Name):
                choices["valuesAttr"] = named["valuesAttr"].name
            else:
                choices["values"] = [_literal(a) for a in plain]
            info["enum"] = choices
        elif note.name == "Group":
            last = _literal(plain[-1]) if plain else _NOT
            if isinstance(last, float):
                info["group"], info["groupOrder"] = [_literal(a) for a in plain[:-1]], last
            else:
                info["group"] = [_literal(a) for a in plain]
        elif note.name in ("Description", "DisplayName", "Order"):
            info[key] = _literal(plain[0]) if plain else None
        elif note.name == "File":
            info["file"] = [_literal(a) for a in plain]
        else:  # a flag (@Hidden, @Color, @Angle...) or an annotation kept as it is
            info[key] = [_literal(a) for a in note.args] if note.args else True
    return info


def attr_metadata(grammar) -> dict[str, dict]:
    """Each attr of a loaded grammar (``bgr.load``), in declaration order, with its literal
    default (None where the default is an expression) and its annotations as plain values:
    ``range`` ({min, max, stepsize, restricted}), ``enum`` ({values, restricted} or
    {valuesAttr}), ``group`` (names) and ``groupOrder``, ``order``, ``description``,
    ``displayName``, ``file`` (extensions), and ``True`` for each flag (``hidden``, ``color``,
    ``angle``, ``distance``, ``percent``, ``directory``...)."""
    return {name: _info(attr) for name, attr in grammar.attrs.items()}
