"""--set overrides of nested frozen parameter dataclasses."""
from dataclasses import dataclass, field

import pytest

from interplay import params as P
from interplay.errors import ParameterError


@dataclass(frozen=True)
class Inner:
    k: float = 1.0
    on: bool = True
    where: tuple = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Outer:
    inner: Inner = field(default_factory=Inner)
    dt: float | None = None
    n: int = 3
    name: str = "a"


def test_values_are_converted_to_the_field_type():
    p = P.apply(Outer(), {"inner.k": "2.5", "inner.on": "false", "inner.where": "1,2,3",
                          "n": "7", "name": "b", "dt": "1e-3"})
    assert p == Outer(Inner(2.5, False, (1.0, 2.0, 3.0)), 1e-3, 7, "b")
    assert P.apply(Outer(dt=1.0), {"dt": "auto"}).dt is None


def test_keys_lists_every_leaf():
    assert P.keys(Outer()) == ["inner.k", "inner.on", "inner.where", "dt", "n", "name"]


@pytest.mark.parametrize("key,value,message", [
    ("inner.x", "1", "unknown parameter; valid keys: inner.k"),
    ("inner", "1", "is a group"),
    ("n.m", "1", "unknown parameter"),
    ("n", "1.5", "not a whole number; n must be a whole number"),
    ("inner.on", "maybe", "inner.on=maybe: not true or false"),
    ("dt", "soon", "dt=soon: .soon. is not a number; dt must be a finite number"),
])
def test_bad_overrides_say_what_is_wrong(key, value, message):
    with pytest.raises(ParameterError, match=message):
        P.apply(Outer(), {key: value})


def test_a_field_of_another_type_is_kept_but_not_settable():
    @dataclass(frozen=True)
    class WithList:
        names: list = field(default_factory=list)
    assert P.table(WithList())[0][3] == "set in Python only"
    with pytest.raises(ParameterError, match="cannot be set from the command line"):
        P.apply(WithList(), {"names": "a,b"})
