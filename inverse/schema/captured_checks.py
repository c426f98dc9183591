"""The first two checks of a captured-model JSON: the JSON itself, and its JSON Schema.

Stage 1 (:func:`parse`, :func:`_check_json`): finite numbers, no key given twice, not nested
absurdly deep, not too many values.  Stage 2 (:func:`_check_schema`): the JSON Schema of
:mod:`.captured_schema`, each validator error turned into diagnostics that name the offending
element by its JSON path and say what is expected.  The helpers that word those diagnostics
(``_diag``, ``_where``, ``_join``, ``_num``...) are here too; the meaning checks of
:mod:`.captured_reader` and :mod:`.captured_faces` use them.
"""

from __future__ import annotations

import json
import math
import re

from bgr.grammar.errors import BgrError, Diagnostic, suggest

from .captured_schema import MAX_NESTING, MAX_VALUES, SCHEMA

# ---- errors -----------------------------------------------------------------------------------


def _diag(path: str, where: str, message: str, hint: str | None = None) -> Diagnostic:
    text = f"{where}: {message}" if where else message
    return Diagnostic(path, 0, 0, text, hint)


def _error(path: str, where: str, message: str, hint: str | None = None) -> BgrError:
    return BgrError(_diag(path, where, message, hint))


def _where(parts) -> str:
    """``blocks[0].faces.front[1]`` from a JSON path (keys and indices)."""
    out = ""
    for p in parts:
        if isinstance(p, int):
            out += f"[{p}]"
        elif re.match(r"^[A-Za-z_][A-Za-z0-9_]*$", p):
            out += f".{p}" if out else p
        else:
            out += f"[{_show(p)}]"  # a 10,000-character key is cut
    return out


def _join(where: str, key) -> str:
    return _where([key]) if not where else where + _where(["_", key])[1:]


def _show(value) -> str:
    try:
        text = json.dumps(value, ensure_ascii=False)
    except (TypeError, ValueError):
        text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _num(x: float) -> str:
    return format(x, ".12g")


_KIND = {
    dict: "an object",
    list: "an array",
    str: "a string",
    bool: "a boolean",
    type(None): "null",
    int: "a number",
    float: "a number",
}


def _kind(value) -> str:
    return _KIND.get(type(value), type(value).__name__)


# ---- stage 1: the JSON itself -------------------------------------------------------------------


class _Object(dict):
    """A JSON object that remembers the keys given more than once."""

    duplicates: tuple = ()


def _pairs(pairs):
    obj = _Object(pairs)
    if len(obj) != len(pairs):
        seen, dups = set(), []
        for k, _ in pairs:
            if k in seen and k not in dups:
                dups.append(k)
            seen.add(k)
        obj.duplicates = tuple(dups)
    return obj


def _constant(name: str):
    raise ValueError(f"{name} is not a JSON number")


def parse(text: str, path: str = "<captured>"):
    """The JSON value of a captured-model text; syntax errors point at their line and column."""
    try:
        return json.loads(text, object_pairs_hook=_pairs, parse_constant=_constant)
    except json.JSONDecodeError as exc:
        lines = text.split("\n")
        line = lines[exc.lineno - 1] if 0 < exc.lineno <= len(lines) else None
        raise BgrError(
            Diagnostic(
                path,
                exc.lineno,
                exc.colno,
                f"not valid JSON: {exc.msg}",
                'a captured model is a JSON object: {"bgr_captured": 1, "blocks": [...]}',
                source_line=line,
            )
        ) from None
    except ValueError as exc:  # NaN, Infinity; integers too long to convert
        raise _error(path, "", f"not valid JSON: {exc}") from None
    except RecursionError:
        raise _error(
            path, "", f"the JSON is nested too deeply (more than {MAX_NESTING} levels)"
        ) from None


def _check_json(data, path: str) -> list[Diagnostic]:
    """Stage 1, without recursion: JSON types only, finite numbers, no duplicate keys, bounded
    nesting (so that the schema validator and the builder cannot run out of stack)."""
    out: list[Diagnostic] = []
    stack = [(data, "", 1)]
    count = 0
    while stack:
        value, where, depth = stack.pop()
        count += 1
        if count > MAX_VALUES:  # before the schema validator's time grows with it
            return [_too_many(path)]
        if depth > MAX_NESTING:
            out.append(_diag(path, where, f"nested too deeply (more than {MAX_NESTING} levels)"))
            continue
        if isinstance(value, dict):
            for key in getattr(value, "duplicates", ()):
                out.append(
                    _diag(
                        path,
                        _join(where, key),
                        "given twice in one object",
                        "JSON keeps only the last one; remove the other",
                    )
                )
            items = []
            for key, item in value.items():
                if not isinstance(key, str):
                    out.append(_diag(path, where, f"has a key that is not a string: {key!r}"))
                    continue
                items.append((item, _join(where, key), depth + 1))
            stack.extend(reversed(items))
        elif isinstance(value, list):
            stack.extend(
                reversed([(item, _join(where, i), depth + 1) for i, item in enumerate(value)])
            )
        elif isinstance(value, float):
            if not math.isfinite(value):
                out.append(_diag(path, where, f"{value} is not a JSON number"))
        elif isinstance(value, int) and not isinstance(value, bool):
            if abs(value) > 10**300:
                out.append(_diag(path, where, "a number too large to be a length or a coordinate"))
        elif not isinstance(value, (str, bool)) and value is not None:
            out.append(_diag(path, where, f"{type(value).__name__} is not a JSON value"))
    return out


def _too_many(path: str) -> Diagnostic:
    return _diag(
        path,
        "",
        f"the captured model holds more than {MAX_VALUES:,} JSON values",
        "infer each building from a file of its own (docs/limits.md)",
    )


# ---- stage 2: the JSON Schema -------------------------------------------------------------------

_VALIDATOR = None


def _validator():
    global _VALIDATOR
    if _VALIDATOR is None:
        try:
            from jsonschema import Draft202012Validator
        except ImportError:  # pragma: no cover - a declared dependency
            raise BgrError(
                Diagnostic(
                    "",
                    0,
                    0,
                    "reading a captured model needs the jsonschema package",
                    "pip install jsonschema",
                )
            ) from None
        _VALIDATOR = Draft202012Validator(SCHEMA)
    return _VALIDATOR


def _resolve(schema: dict) -> dict:
    ref = schema.get("$ref", "")
    return SCHEMA["$defs"].get(ref.rsplit("/", 1)[-1], schema) if ref else schema


def _expected(schema: dict) -> str:
    """What a schema asks for, in words."""
    if "description" in schema:
        return schema["description"]
    return "a valid value"


def _schema_diagnostics(error, path: str) -> list[Diagnostic]:
    """One jsonschema error as diagnostics that name the offending element and what is expected."""
    parts = list(error.absolute_path)
    where = _where(parts)
    schema = error.schema if isinstance(error.schema, dict) else {}
    kind, value, instance = error.validator, error.validator_value, error.instance
    hint = schema.get("description")
    if "propertyNames" in error.relative_schema_path:
        return [_diag(path, _join(where, instance), "not a valid label", hint)]
    if kind == "required":
        out = []
        for key in value:
            if not isinstance(instance, dict) or key in instance:
                continue
            if key == "label" and "description" not in schema:  # the subface's if/then
                what = "a leaf subface (one without split and parts) needs a label"
            elif key in schema.get("properties", {}):
                what = _expected(_resolve(schema["properties"][key]))
            elif "description" in schema:  # a part of a split: its size
                what = schema["description"]
            else:  # a shape's own key (sides, footprint)
                what = _expected(SCHEMA["$defs"]["block"]["properties"].get(key, {}))
            out.append(_diag(path, _join(where, key), "missing", what))
        return out
    if kind == "additionalProperties" and isinstance(instance, dict):
        known = list(schema.get("properties", {}))
        out = []
        for key in instance:
            if key not in known:
                hint = suggest(key, known) or (
                    "expected one of: " + ", ".join(known) if known else None
                )
                out.append(_diag(path, _join(where, key), "unknown key", hint))
        return out
    if kind == "dependentRequired" and isinstance(instance, dict):
        out = []
        for key, needs in value.items():
            if key in instance:
                for other in needs:
                    if other not in instance:
                        out.append(
                            _diag(
                                path,
                                _join(where, other),
                                f'missing: a subface with "{key}" needs "{other}"',
                                _expected(SCHEMA["$defs"]["subface"]),
                            )
                        )
        return out
    if kind == "type":
        types = value if isinstance(value, list) else [value]
        words = " or ".join(
            {
                "object": "an object",
                "array": "an array",
                "string": "a string",
                "number": "a number",
                "integer": "an integer",
                "boolean": "true or false",
                "null": "null",
            }.get(t, t)
            for t in types
        )
        return [
            _diag(path, where, f"expected {words}, got {_kind(instance)} {_show(instance)}", hint)
        ]
    if kind == "enum":
        return [
            _diag(
                path, where, f"{_show(instance)} is not one of {', '.join(map(str, value))}", hint
            )
        ]
    if kind == "const":
        return [_diag(path, where, f"expected {_show(value)}, got {_show(instance)}", hint)]
    if kind in ("exclusiveMinimum", "minimum", "maximum", "exclusiveMaximum"):
        word = {
            "exclusiveMinimum": "greater than",
            "minimum": "at least",
            "maximum": "at most",
            "exclusiveMaximum": "less than",
        }[kind]
        return [_diag(path, where, f"must be {word} {_num(value)}, got {_show(instance)}", hint)]
    if kind in ("minItems", "maxItems"):
        n = len(instance) if isinstance(instance, list) else 0
        if schema.get("minItems") == schema.get("maxItems"):
            need = f"exactly {value}"
        else:
            need = f"at least {value}" if kind == "minItems" else f"at most {value}"
        return [_diag(path, where, f"has {n} item{'s' * (n != 1)}, expected {need}", hint)]
    if kind == "minLength":
        return [_diag(path, where, "must not be empty", hint)]
    if kind == "pattern":
        return [_diag(path, where, f"{_show(instance)} is not an identifier", hint)]
    return [_diag(path, where, error.message, hint)]  # pragma: no cover - every keyword above


def _check_schema(data, path: str) -> list[Diagnostic]:
    errors = sorted(
        _validator().iter_errors(data),
        key=lambda e: (
            [(0, p) if isinstance(p, int) else (1, p) for p in e.absolute_path],
            str(e.validator),
        ),
    )
    out: list[Diagnostic] = []
    seen = set()
    for error in errors:
        for d in _schema_diagnostics(error, path):
            if d.message not in seen:
                seen.add(d.message)
                out.append(d)
    return out
