"""Declarative options: an array of tables handed on as Params (rvtol.options, type ``list[Params]``)."""
from dataclasses import dataclass

import pytest

from rvtol.errors import InputError
from rvtol.options import describe, option, read_options
from rvtol.params import Params


@dataclass
class Tables:
    domain: list[Params] = option([], "the tables", min_length=2)


def test_an_array_of_tables_is_handed_on_as_located_params():
    p = Params({"domain": [{"kind": "plane", "t": 1.0}, {"kind": "cylinder"}]}, file="s.toml", key="analysis[3]")
    o = read_options(Tables, p)
    assert [t.key for t in o.domain] == ["analysis[3].domain[0]", "analysis[3].domain[1]"]
    assert o.domain[0].str("kind") == "plane" and o.domain[1].str("kind") == "cylinder"
    with pytest.raises(InputError) as e:           # the code that reads a table reports its own keys, located
        o.domain[0].float("t", max=0.5)
    assert (e.value.file, e.value.key) == ("s.toml", "analysis[3].domain[0].t")
    assert describe(Tables)[0].type == "array of tables"


def test_too_few_tables_or_not_tables_are_errors():
    with pytest.raises(InputError, match=r"at least 2 \[\[analysis\[0\]\.domain\]\] tables") as e:
        read_options(Tables, Params({"domain": [{"kind": "plane"}]}, file="s.toml", key="analysis[0]"))
    assert e.value.key == "analysis[0].domain"
    with pytest.raises(InputError, match="expected an array of tables"):
        read_options(Tables, Params({"domain": [1, 2]}, file="s.toml", key="analysis[0]"))
    assert read_options(Tables, Params({}, file="s.toml")).domain == []        # absent: the default
