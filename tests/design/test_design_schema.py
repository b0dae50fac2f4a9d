"""A design file is read by its declared schema (issue 38 item 1): the ``[design]`` head (:class:`DesignHead`) and
each number (:class:`DesignEntry`) are options classes, listed by ``rvtol kinds design`` / ``design_parameter``
and fed invalid values by the common test (tests/options/test_options_invalid_values.py); the loader's
cross-key checks stay in ``DesignEntry.complete``."""
import pytest

from rvtol.cli import main
from rvtol.design import DesignEntry, DesignHead, design_from_table, load_design
from rvtol.errors import SpecError
from rvtol.options import describe
from rvtol.registry import table_options

from conftest import ROOT

HEAD_KEYS = ["name", "description", "source", "extends"]
ENTRY_KEYS = ["value", "formula", "unit", "source", "note", "status", "basis", "range", "step"]


def test_the_design_files_keys_are_declared_and_listed(capsys):
    assert table_options("design") is DesignHead and table_options("design_parameter") is DesignEntry
    assert [o.key for o in describe(DesignHead)] == HEAD_KEYS
    assert [o.key for o in describe(DesignEntry)] == ENTRY_KEYS
    assert main(["kinds", "design_parameter"]) == 0
    listed = capsys.readouterr().out
    assert all(f"  {k} (" in listed for k in ENTRY_KEYS) and "one of 'document', 'computed', 'choice'" in listed


def test_every_key_of_every_shipped_design_is_a_declared_one():
    """The product's design, its variant and the data/designs files load, and hold no key the schema lacks."""
    import tomllib

    files = [ROOT / "data/products/rv80e/design.toml", ROOT / "data/products/rv80e_153/design.toml",
             *sorted((ROOT / "data/designs").glob("*.toml"))]
    seen = set()

    def entries(table):
        for v in table.values():
            if isinstance(v, dict):
                if "value" in v or "formula" in v:
                    seen.update(v)
                else:
                    entries(v)

    for f in files:
        d = load_design(f)
        assert d.params and d.name
        raw = tomllib.loads(f.read_text())
        assert set(raw["design"]) <= set(HEAD_KEYS)
        entries({k: v for k, v in raw.items() if k != "design"})
    assert {"value", "formula", "unit", "source", "note", "status", "range", "basis", "step"} <= seen <= set(ENTRY_KEYS)


def test_an_unknown_key_of_a_number_lists_every_declared_key():
    """A misspelt key is named with the keys a number takes: all of them (the hand reader listed only those it had
    read before, without formula)."""
    with pytest.raises(SpecError) as e:
        design_from_table({"design": {"name": "t"}, "a": {"x": {"value": 1, "source": "s", "colour": "red"}}},
                          file="d.toml")
    assert (e.value.file, e.value.key) == ("d.toml", "a.x.colour")
    assert e.value.reason == f"unknown key (known here: {', '.join(sorted(ENTRY_KEYS))})"


@pytest.mark.parametrize("entry, key, reason", [
    ({"value": True, "source": "s"}, "a.x.value", "expected a number or an array or a string"),
    ({"value": [1, "two"], "source": "s"}, "a.x.value[1]", "expected a number, got the string 'two'"),
    ({"value": 1, "unit": "blorps", "source": "s"}, "a.x.unit", "blorps"),
    ({"value": 1}, "a.x.source", "missing required key"),
    ({"value": 1, "source": "s", "step": 0}, "a.x.step", "must be > 0"),
    ({"value": 1, "source": "s", "range": [0, "2"], "basis": "b"}, "a.x.range[1]", "expected a number"),
    ({"formula": 3, "source": "s"}, "a.x.formula", "expected a string"),
])
def test_a_bad_value_of_a_number_is_one_error_naming_file_and_key(entry, key, reason):
    with pytest.raises(SpecError) as e:
        design_from_table({"design": {"name": "t"}, "a": {"x": entry}}, file="d.toml")
    assert (e.value.file, e.value.key) == ("d.toml", key) and reason in e.value.reason, e.value


def test_a_head_is_read_by_its_schema(tmp_path):
    with pytest.raises(SpecError) as e:
        design_from_table({"design": {"name": "t", "descripton": "x"}, "a": {"x": {"value": 1, "source": "s"}}},
                          file="d.toml")
    assert (e.value.key, e.value.reason) == ("design.descripton", "unknown key (did you mean 'description'?)")
    with pytest.raises(SpecError) as e:
        design_from_table({"design": {"name": 7}, "a": {"x": {"value": 1, "source": "s"}}}, file="d.toml")
    assert (e.value.key, e.value.reason) == ("design.name", "expected a string, got int")
    with pytest.raises(SpecError) as e:       # a variant is read from its file, its base relative to that file
        design_from_table({"design": {"name": "t", "extends": "b.toml"}, "a": {"x": {"value": 1, "source": "s"}}},
                          file="d.toml")
    assert e.value.key == "design.extends"
