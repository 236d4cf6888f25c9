"""Scene parameters: nested frozen dataclasses, one declared domain per parameter, and
``--set key=value`` overrides.

Every leaf field of a parameter dataclass has a **domain**: its kind (float, int, bool, str,
a vector of floats), unit, bounds (open or closed), finiteness, tuple length, the choices of a
string, and what it costs (the element counts it multiplies). ``--set`` parsing, the one-line
error, ``interplay run SCENE --help-params`` and the scene's JSON schema are all made from it.

A field without a declaration still gets a domain from its type and default, so a new
scene's plain dataclass is checked unchanged: a float must be a finite number, an int a whole
number in the 32-bit range, a tuple keeps its default's length (``ANY_LENGTH``: any) and holds
finite numbers, a bool is yes/no. Richer declarations are opt-in through ``param``::

    radius: float = param(0.12, "m", gt=0.0, le=2.0, doc="the ball's radius")
    nu: int = param(30, "vertices", ge=2, le=400, cost="points")

(pydantic was tried for this and left out: on plain dataclasses it accepts NaN, inf, wrong
tuple lengths and 2**70 for an int unless each field carries its own annotated type, the
``--set`` syntax and the messages naming key, value, range and unit would still be ours, and
a cost or unit has no place in it; docs/robustness.md.)
"""
from __future__ import annotations

import dataclasses
import math
import types
import typing
from dataclasses import dataclass

from .errors import CostError, ParameterError

#: field metadata of a tuple parameter that may have any length
ANY_LENGTH = {"length": None}
#: the range of an int without declared bounds (numpy's int32: no silent overflow)
INT_RANGE = (-(2 ** 31), 2 ** 31 - 1)
#: longest string a str parameter may hold
MAX_STR = 4096
_KEEP = object()  # param(length=...) default: the default's length


def param(default, unit: str = "", *, gt=None, ge=None, lt=None, le=None, length=_KEEP,
          choices=None, cost=None, doc: str = "", check=None):
    """A dataclass field with a declared domain.

    unit: SI unit ("m", "kg/m^3", "-" for none); gt/ge/lt/le: open or closed bounds (each
    element of a vector); length: a vector's length (default: its default's; None: any; a
    tuple: any of those lengths); choices: the values a str may take; cost: what the value
    multiplies, "points", "columns", "particles" or (quantity, power), e.g. ("columns", 2)
    for cells along one side of a square grid; doc: one line for the parameter table; check:
    value -> None, raising ParameterError (without the key) for what bounds cannot say."""
    meta = {"unit": unit, "gt": gt, "ge": ge, "lt": lt, "le": le, "choices": choices,
            "cost": (cost, 1) if isinstance(cost, str) else cost, "doc": doc, "check": check}
    if length is not _KEEP:
        meta["length"] = length
    return dataclasses.field(default=default, metadata={"domain": meta})


@dataclass(frozen=True)
class Domain:
    """The domain of one parameter (see the module docstring). key: its dotted name."""
    key: str
    kind: str  # float | int | bool | str | vector | other (not settable from text)
    default: object
    unit: str = ""
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    optional: bool = False
    length: object = None  # vector: int, None (any) or a tuple of allowed lengths
    choices: tuple | None = None
    cost: tuple | None = None
    doc: str = ""
    check: typing.Callable | None = None

    # --- text ----------------------------------------------------------------------------
    def bounds_text(self) -> str:
        """'> 0 and <= 2' style bounds, '' when unbounded."""
        parts = []
        if self.lo is not None:
            parts.append(f"{'>' if self.lo_open else '>='} {_num(self.lo)}")
        if self.hi is not None:
            parts.append(f"{'<' if self.hi_open else '<='} {_num(self.hi)}")
        return " and ".join(parts)

    def range_text(self) -> str:
        """What the parameter accepts, in words, with its unit."""
        unit = f" {self.unit}" if self.unit and self.unit != "-" else ""
        b = self.bounds_text()
        if self.kind == "bool":
            text = "true or false"
        elif self.kind == "str":
            text = ("one of " + ", ".join(repr(c) for c in self.choices) if self.choices
                    else "a text")
        elif self.kind == "other":
            text = "set in Python only"
        elif self.kind == "vector":
            n = ("any number of" if self.length is None else
                 " or ".join(str(k) for k in self.length) if isinstance(self.length, tuple)
                 else str(self.length))
            text = f"{n} comma-separated finite numbers{' each ' + b if b else ''}{unit}"
        else:
            what = "a whole number" if self.kind == "int" else "a finite number"
            text = f"{what} {b}{unit}" if b else f"{what}{unit}"
        return text + (" (or none)" if self.optional and self.default is not None else "")

    def _fail(self, shown, why: str = ""):
        raise ParameterError(f"{self.key}={shown}: {why or 'out of range'}; {self.key} must "
                             f"be {self.range_text()}")

    # --- parsing and checking --------------------------------------------------------------
    def parse(self, text: str):
        """The value of ``--set key=text``, checked; ParameterError naming key, value, range
        and unit."""
        if len(text) > MAX_STR:
            self._fail(text[:40] + "...", f"{len(text)} characters is too long")
        low = text.strip().lower()
        if self.optional and low in ("none", "auto"):
            return None
        if self.kind == "other":
            self._fail(text[:40], "this parameter cannot be set from the command line")
        if self.kind == "bool":
            if low in ("1", "true", "yes", "on"):
                return True
            if low in ("0", "false", "no", "off"):
                return False
            self._fail(text, "not true or false")
        if self.kind == "str":
            return self.validate(text, text)
        if self.kind == "vector":
            items = text.replace("(", "").replace(")", "").split(",")
            items = [] if items == [""] else items
            return self.validate(tuple(self._number(v, text, float) for v in items), text)
        return self.validate(self._number(text, text, int if self.kind == "int" else float),
                             text)

    def _number(self, item: str, whole: str, typ):
        item = item.strip()
        try:
            if typ is int:
                return int(item, 10)
            return float(item)
        except ValueError:
            self._fail(whole, f"{item!r} is not {'a whole number' if typ is int else 'a number'}")

    def validate(self, value, shown=None):
        """``value`` checked against the domain (a Python value, e.g. a default or what the
        API was given); returns it (ints as int, vectors as tuples of float)."""
        shown = _show(value) if shown is None else shown
        if value is None:
            if self.optional:
                return None
            self._fail(shown, "a value is required")
        if self.kind == "other":
            return value
        if self.kind == "bool":
            if not isinstance(value, bool):
                self._fail(shown, "not true or false")
            return value
        if self.kind == "str":
            if not isinstance(value, str):
                self._fail(shown, "not a text")
            if "\x00" in value or len(value) > MAX_STR:
                self._fail(shown, "not a plain text")
            if self.choices is not None and value not in self.choices:
                self._fail(shown, "not one of the choices")
            self._custom(value, shown)
            return value
        if self.kind == "vector":
            if not isinstance(value, (tuple, list)):
                self._fail(shown, "not a list of numbers")
            n = len(value)
            ok = (self.length is None or (n in self.length if isinstance(self.length, tuple)
                                          else n == self.length))
            if not ok:
                self._fail(shown, f"{n} numbers given")
            out = []
            for v in value:
                out.append(self._scalar(v, shown, float))
            value = tuple(out)
            self._custom(value, shown)
            return value
        value = self._scalar(value, shown, int if self.kind == "int" else float)
        self._custom(value, shown)
        return value

    def _scalar(self, v, shown, typ):
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            self._fail(shown, "not a number")
        if typ is int:
            if isinstance(v, float):
                if not v.is_integer():
                    self._fail(shown, "not a whole number")
                v = int(v)
            lo = self.lo if self.lo is not None else INT_RANGE[0]
            hi = self.hi if self.hi is not None else INT_RANGE[1]
            if v < lo or v > hi or (self.lo_open and v == lo) or (self.hi_open and v == hi):
                self._fail(shown)
            return int(v)
        v = float(v)  # an int too large for a float raises OverflowError: caught by callers
        if not math.isfinite(v):
            self._fail(shown, "not finite")
        if self.lo is not None and (v < self.lo or (self.lo_open and v == self.lo)):
            self._fail(shown)
        if self.hi is not None and (v > self.hi or (self.hi_open and v == self.hi)):
            self._fail(shown)
        return v

    def _custom(self, value, shown):
        if self.check is not None:
            try:
                self.check(value)
            except ParameterError as e:
                raise ParameterError(f"{self.key}={shown}: {e}") from None

    # --- descriptions -----------------------------------------------------------------------
    def schema(self) -> dict:
        """This parameter as a JSON Schema (draft 2020-12) fragment; x-unit and x-cost carry
        what JSON Schema has no word for."""
        num = {"type": "integer" if self.kind == "int" else "number"}
        if self.kind == "int":
            lo = self.lo if self.lo is not None else INT_RANGE[0]
            hi = self.hi if self.hi is not None else INT_RANGE[1]
            num.update({"minimum": lo, "maximum": hi})
        else:
            if self.lo is not None:
                num["exclusiveMinimum" if self.lo_open else "minimum"] = self.lo
            if self.hi is not None:
                num["exclusiveMaximum" if self.hi_open else "maximum"] = self.hi
        if self.kind in ("float", "int"):
            s = num
        elif self.kind == "bool":
            s = {"type": "boolean"}
        elif self.kind == "other":
            s = {}
        elif self.kind == "str":
            s = {"type": "string", "maxLength": MAX_STR}
            if self.choices:
                s["enum"] = list(self.choices)
        else:
            s = {"type": "array", "items": num}
            if isinstance(self.length, int):
                s.update(minItems=self.length, maxItems=self.length)
            elif isinstance(self.length, tuple):
                s.update(minItems=min(self.length), maxItems=max(self.length))
        if self.optional:
            s = {"anyOf": [s, {"type": "null"}]}
        if self.kind != "other":
            s["default"] = list(self.default) if isinstance(self.default, tuple) \
                else self.default
        if self.unit:
            s["x-unit"] = self.unit
        if self.cost:
            s["x-cost"] = f"{self.cost[0]}" + (f"^{self.cost[1]}" if self.cost[1] != 1 else "")
        if self.doc:
            s["description"] = self.doc
        return s


def _num(x) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


def _show(value) -> str:
    if isinstance(value, (tuple, list)):
        return ",".join(_num(v) if isinstance(v, (int, float)) else repr(v) for v in value)
    return _num(value) if isinstance(value, (int, float)) and not isinstance(value, bool) \
        else repr(value)


def _unwrap(typ):
    """(base type, optional) of a field's type hint."""
    origin = typing.get_origin(typ)
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(typ) if a is not type(None)]
        return args[0], len(args) < len(typing.get_args(typ))
    return typ, False


def domain_of(cls, f: dataclasses.Field, default, key: str) -> Domain:
    """The domain of field ``f`` of parameter dataclass ``cls`` (default: its value in the
    enclosing default instance), from its type hint, its default and its declaration."""
    typ, optional = _unwrap(typing.get_type_hints(cls)[f.name])
    base = typing.get_origin(typ) or typ
    meta = dict(f.metadata.get("domain", {}))
    if "length" in f.metadata:  # ANY_LENGTH
        meta.setdefault("length", f.metadata["length"])
    if base is bool:
        kind = "bool"
    elif base is int:
        kind = "int"
    elif base is float:
        kind = "float"
    elif base is str:
        kind = "str"
    elif base is tuple:
        kind = "vector"
    else:  # a list, a mapping, a callable: kept as given, not settable with --set
        kind = "other"
    length = meta.get("length", len(default) if isinstance(default, tuple) else None)
    lo = hi = None
    lo_open = hi_open = False
    if meta.get("gt") is not None:
        lo, lo_open = meta["gt"], True
    elif meta.get("ge") is not None:
        lo = meta["ge"]
    if meta.get("lt") is not None:
        hi, hi_open = meta["lt"], True
    elif meta.get("le") is not None:
        hi = meta["le"]
    choices = meta.get("choices")
    return Domain(key, kind, default, meta.get("unit", ""), lo, hi, lo_open, hi_open,
                  optional or default is None, length, tuple(choices) if choices else None,
                  meta.get("cost"), meta.get("doc", ""), meta.get("check"))


def domains(params, prefix: str = "") -> list[Domain]:
    """Every leaf parameter's Domain, in declaration order, with dotted keys."""
    out = []
    for f in dataclasses.fields(params):
        v = getattr(params, f.name)
        if dataclasses.is_dataclass(v):
            out += domains(v, f"{prefix}{f.name}.")
        else:
            out.append(domain_of(type(params), f, v, prefix + f.name))
    return out


def keys(params) -> list[str]:
    """Every settable dotted key of a nested parameter dataclass."""
    return [d.key for d in domains(params)]


def _unknown(key, params, prefix=""):
    return ParameterError(f"{key}: unknown parameter; valid keys: "
                          f"{', '.join(prefix + k for k in keys(params))}")


def override(params, key: str, value, prefix: str = ""):
    """A copy of ``params`` with the dotted ``key`` set to ``value`` (a string is parsed by the
    field's domain, anything else validated by it). Unknown keys raise ParameterError listing
    the valid ones. prefix: the groups above ``params`` (for messages naming the whole key)."""
    head, _, rest = key.partition(".")
    fields = {f.name: f for f in dataclasses.fields(params)}
    if head not in fields:
        raise _unknown(prefix + key, params, prefix)
    current = getattr(params, head)
    if dataclasses.is_dataclass(current):
        if not rest:
            raise ParameterError(f"{prefix}{key}: {head} is a group; set one of its fields, "
                                 f"e.g. {prefix}{head}.{keys(current)[0]}")
        new = override(current, rest, value, f"{prefix}{head}.")
    else:
        if rest:
            raise _unknown(prefix + key, params, prefix)
        d = domain_of(type(params), fields[head], current, prefix + key)
        try:
            new = d.parse(value) if isinstance(value, str) else d.validate(value)
        except OverflowError:
            raise ParameterError(f"{prefix}{key}={_show(value)}: too large; {prefix}{key} "
                                 f"must be {d.range_text()}") from None
    try:
        return dataclasses.replace(params, **{head: new})
    except ParameterError as e:  # a group's own check of how its fields go together
        raise ParameterError(f"{prefix}{key}={_show(value) if not isinstance(value, str) else value}"
                             f": {e}") from None


def apply(params, assignments: dict):
    """Apply several overrides {dotted key: value}."""
    for k, v in assignments.items():
        params = override(params, k, v)
    return params


def validate(params, prefix: str = "", trusted=()) -> list[str]:
    """Check every leaf of ``params`` against its domain (values given through the Python API
    or as defaults): ParameterError on the first that is out of its domain. For the keys in
    ``trusted`` (the defaults nobody set) a field's own ``check`` (a file that must exist) is
    not an error: its message is returned, so the caller can report it as a warning."""
    notes = []
    for d in domains(params, prefix):
        value = d.default
        try:
            if d.key in trusted and d.check is not None:
                try:
                    d.check(value)
                except ParameterError as e:
                    notes.append(f"{d.key}={_show(value)} (the default): {e}")
                d = dataclasses.replace(d, check=None)
            d.validate(value)
        except OverflowError:
            raise ParameterError(f"{d.key}={_show(value)}: too large; {d.key} must be "
                                 f"{d.range_text()}") from None
    return notes


def zero_or_at_least(lo: float):
    """A check: 0 (meaning automatic) or at least ``lo``."""
    def check(v):
        if v != 0 and v < lo:
            raise ParameterError(f"0 (automatic) or at least {lo:g}")
    return check


def intervals(v):
    """A check: a vector of (lo, hi) pairs, each with lo < hi (an area x0, x1, y0, y1)."""
    if len(v) % 2 or any(a >= b for a, b in zip(v[::2], v[1::2])):
        raise ParameterError("each pair must be (low, high) with low < high")


# --- descriptions -----------------------------------------------------------------------------
def table(params) -> list[tuple[str, str, str, str, str]]:
    """(key, unit, default, range, description) of every parameter, for --help-params."""
    rows = []
    for d in domains(params):
        default = "none" if d.default is None else _show(d.default)
        rows.append((d.key, d.unit or "", default, d.range_text(), d.doc))
    return rows


def json_schema(params, title: str = "") -> dict:
    """The parameters as a JSON Schema (draft 2020-12): nested objects, one property per
    field, no other properties."""
    def build(p, prefix):
        props = {}
        for f in dataclasses.fields(p):
            v = getattr(p, f.name)
            if dataclasses.is_dataclass(v):
                props[f.name] = build(v, f"{prefix}{f.name}.")
            else:
                props[f.name] = domain_of(type(p), f, v, prefix + f.name).schema()
        return {"type": "object", "properties": props, "additionalProperties": False}

    doc = {"$schema": "https://json-schema.org/draft/2020-12/schema",
           "title": title or type(params).__name__, **build(params, "")}
    return doc


# --- what the parameters cost -------------------------------------------------------------------
#: bytes of memory per element, over everything a step keeps (state, springs, solver
#: matrices, output frames of a short run): a spring-mass point with its ~6 springs and the
#: implicit solver's 3x3 blocks ~2 kB; a water column with its 8 pipes and lids ~0.5 kB; a
#: spray particle ~0.1 kB (measured order of magnitude, docs/robustness.md)
BYTES = {"points": 2048, "columns": 512, "particles": 128}
#: the most of each element a run may ask for without --force (the default scenes ask for
#: 156 to ~3,000 points, 16,000 columns, 6,000 particles)
BUDGET = {"points": 200_000, "columns": 1_100_000, "particles": 1_000_000}


def cost(params, prefix: str = "") -> dict:
    """What the parameters ask for: {quantity: [(group key, count, "a x b")]}: within a group
    the fields declaring the same cost multiply (a flag's nu x nv points)."""
    out: dict = {}
    groups: dict = {}
    for d in domains(params, prefix):
        if d.cost is None or d.default is None:
            continue
        quantity, power = d.cost
        group = d.key.rpartition(".")[0]
        n, why = groups.get((group, quantity), (1, []))
        groups[(group, quantity)] = (n * float(d.default) ** power,
                                     why + [f"{d.key} {_show(d.default)}"
                                            + (f"^{power}" if power != 1 else "")])
    for (group, quantity), (n, why) in groups.items():
        out.setdefault(quantity, []).append((group, n, " x ".join(why)))
    return out


def check_cost(params, scene: str, force: bool = False, default=None) -> dict:
    """Refuse, before anything is allocated, parameters that ask for more elements than
    BUDGET (CostError with the estimate and how to proceed) unless ``force``. Returns
    {quantity: total} (and "bytes")."""
    totals = {}
    for quantity, items in cost(params).items():
        total = sum(n for _, n, _ in items)
        totals[quantity] = total
        if total > BUDGET.get(quantity, math.inf) and not force:
            big = max(items, key=lambda it: it[1])
            normal = ""
            if default is not None:
                base = sum(n for _, n, _ in cost(default).get(quantity, []))
                normal = f" (the default {scene} run: {base:,.0f})"
            raise CostError(f"{scene}: the parameters ask for {total:.3g} {quantity}{normal}, "
                            f"about {_bytes(total * BYTES.get(quantity, 0))}, over the budget "
                            f"of {BUDGET[quantity]:,} {quantity}; the most from {big[0]} "
                            f"({big[2]}); lower it, or pass --force to go on anyway")
    totals["bytes"] = sum(BYTES.get(q, 0) * n for q, n in totals.items())
    return totals


def _bytes(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB", "PB"):
        if n < 1024 or unit == "PB":
            return f"{n:.3g} {unit}"
        n /= 1024.0
    return f"{n:.3g} PB"
