"""Scene parameters as nested frozen dataclasses, and ``--set key=value`` overrides.

A tuple parameter keeps the length of its default unless its field says otherwise
(``metadata={"length": None}``: any length, e.g. one value per ball)."""
from __future__ import annotations

import dataclasses
import typing

from .errors import ParameterError

#: field metadata of a tuple parameter that may have any length
ANY_LENGTH = {"length": None}


def _convert(owner_key: str, text, typ, length=None):
    """``text`` as a value of type ``typ``; a tuple must have ``length`` numbers (None: any)."""
    if not isinstance(text, str):
        return text
    origin = typing.get_origin(typ)
    args = typing.get_args(typ)
    if type(None) in args:  # Optional: "none" (or "auto") selects None, else the other type
        if text.strip().lower() in ("none", "auto"):
            return None
        others = [a for a in args if a is not type(None)]
        return _convert(owner_key, text, others[0], length)
    try:
        if typ is bool:
            low = text.strip().lower()
            if low in ("1", "true", "yes", "on"):
                return True
            if low in ("0", "false", "no", "off"):
                return False
            raise ValueError
        if typ is int:
            return int(text)
        if typ is float:
            return float(text)
        if typ is str:
            return text
        if origin is tuple or typ is tuple:
            values = tuple(float(v) for v in text.replace("(", "").replace(")", "").split(","))
            if length is None or len(values) == length:
                return values
            raise ParameterError(f"--set {owner_key}={text}: expected {length} numbers, "
                                 f"got {len(values)}")
    except ParameterError:
        raise
    except ValueError:
        pass
    else:
        raise ParameterError(f"--set {owner_key}: cannot set a value of type "
                             f"{getattr(typ, '__name__', typ)}")
    name = getattr(typ, "__name__", str(typ))
    raise ParameterError(f"--set {owner_key}={text}: expected a {name} value")


def keys(params) -> list[str]:
    """Every settable dotted key of a nested parameter dataclass."""
    out = []
    for f in dataclasses.fields(params):
        v = getattr(params, f.name)
        if dataclasses.is_dataclass(v):
            out += [f"{f.name}.{k}" for k in keys(v)]
        else:
            out.append(f.name)
    return out


def override(params, key: str, value, prefix: str = ""):
    """A copy of ``params`` with the dotted ``key`` set to ``value`` (a string is converted to
    the field's type). Unknown keys raise ParameterError listing the valid ones. prefix: the
    groups above ``params`` (for messages naming the whole key)."""
    head, _, rest = key.partition(".")
    hints = typing.get_type_hints(type(params))
    names = {f.name for f in dataclasses.fields(params)}
    if head not in names:
        raise ParameterError(f"--set {key}: unknown parameter; valid keys: {', '.join(keys(params))}")
    current = getattr(params, head)
    if dataclasses.is_dataclass(current):
        if not rest:
            raise ParameterError(f"--set {key}: {head} is a group; set one of its fields, "
                                 f"e.g. {keys(params)[0]}")
        try:
            new = override(current, rest, value, f"{prefix}{head}.")
        except ParameterError as e:
            if "unknown parameter" in str(e):
                raise ParameterError(f"--set {key}: unknown parameter; valid keys: "
                                     f"{', '.join(keys(params))}") from None
            raise
    else:
        if rest:
            raise ParameterError(f"--set {key}: unknown parameter; valid keys: "
                                 f"{', '.join(keys(params))}")
        fld = next(f for f in dataclasses.fields(params) if f.name == head)
        length = fld.metadata.get("length", len(current) if isinstance(current, tuple) else None)
        new = _convert(prefix + key, value, hints[head], length)
    return dataclasses.replace(params, **{head: new})


def apply(params, assignments: dict):
    """Apply several overrides {dotted key: value}."""
    for k, v in assignments.items():
        params = override(params, k, v)
    return params
