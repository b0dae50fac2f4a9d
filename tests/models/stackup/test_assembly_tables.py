"""The stack-up's assembly file read by its declared schemas (rvtol.models.stackup.assembly_tables, issue 38 item 1):
a length is a number, { value, unit } or a dimension's name alike; the keys a deviation's (a domain's) kind does not
take, a dimension both written and the design's, are one located error; rvtol kinds lists every key."""
import math
import tomllib

import pytest

from rvtol.errors import InputError
from rvtol.models.stackup.domain_check import domain_from_table
from rvtol.models.stackup.graph import assembly_from_table
from rvtol.options import describe
from rvtol.params import Params
from rvtol.registry import table_options

from conftest import ROOT

TWO_PARTS = """
[assembly]
name = "two"
ground = "housing"
[dimensions]
h = {{ value = 2, unit = "cm", source = "test" }}
turn = {{ value = 90, unit = "deg", source = "test" }}
[[part]]
name = "housing"
[[part.feature]]
name = "floor"
datum = true
[[part.feature]]
name = "seat"
{seat}
[[part.feature.deviation]]
name = "d"
{deviation}
[[part]]
name = "A"
[[part.feature]]
name = "bottom"
datum = true
[[fit]]
name = "f"
base = "housing.seat"
mate = "A.bottom"
[[sequence]]
name = "s"
steps = [{{ part = "A", by = "f" }}]
"""
DOF = 'kind = "dof"\ndofs = ["w"]'


def load(seat="z = 20", deviation=DOF, dimensions=None):
    text = TWO_PARTS.format(seat=seat, deviation=deviation)
    if dimensions is not None:
        text = text.replace('turn = { value = 90, unit = "deg", source = "test" }', dimensions)
    return assembly_from_table(tomllib.loads(text), file="a.toml")


def refused(key, reason, **kw):
    with pytest.raises(InputError, match=reason) as e:
        load(**kw)
    assert (e.value.file, e.value.key) == ("a.toml", key)


@pytest.mark.parametrize("seat", ["z = 20", 'z = { value = 2, unit = "cm" }', 'z = "h"', 'z = "-h"'])
def test_a_length_is_a_number_a_quantity_or_a_dimension(seat):
    z = load(seat=seat).features["housing.seat"].frame[2, 3]
    assert z == pytest.approx(-20.0 if '"-h"' in seat else 20.0)


def test_an_angle_named_by_a_dimension_turns_the_origin():
    frame = load(seat='radius = "h"\nangle = "turn"').features["housing.seat"].frame
    assert frame[:3, 3] == pytest.approx([20.0 * math.cos(math.pi / 2), 20.0, 0.0], abs=1e-12)


@pytest.mark.parametrize("deviation,key,reason", [
    ('kind = "axis"\nlength = 10\ndofs = ["w"]', "dofs", "kind 'axis' takes no 'dofs'"),
    (DOF + "\nlength = 10", "length", "kind 'dof' takes no 'length'"),
    ('kind = "plane"\nwidth = 10', "width", "give zone too"),
    ('kind = "plane"\nzone = 0.01\nlength = 10', "width", "missing required key"),
    ('kind = "axis"', "length", "missing required key"),
    ('kind = "dof"', "dofs", "missing required key"),
    ('kind = "axis"\nlength = "-h"', "length", "must be > 0"),
    ('kind = "axis"\nlength = "hh"', "length", "unknown dimension 'hh'"),
])
def test_a_deviation_takes_the_keys_of_its_kind(deviation, key, reason):
    refused(f"part[0].feature[1].deviation[0].{key}", reason, deviation=deviation)


def test_a_dimension_is_written_or_the_designs_not_both():
    refused("dimensions.turn.value", "not both",
            dimensions='turn = { value = 90, unit = "deg", design = "x.y", source = "test" }')
    refused("dimensions.turn.unit", "missing required key", dimensions='turn = { value = 90, source = "test" }')


def test_a_fixed_fit_takes_no_clearance_keys_and_a_clearance_fit_needs_its_hole():
    text = TWO_PARTS.format(seat="z = 20", deviation=DOF)
    for extra, key, reason in (('float = "uniform"', "float", "only a clearance fit"),
                               ("clearance = 0.01\nlength = 5", "hole", "missing required key")):
        with pytest.raises(InputError, match=reason) as e:
            assembly_from_table(tomllib.loads(text.replace('mate = "A.bottom"', 'mate = "A.bottom"\n' + extra)),
                                file="a.toml")
        assert e.value.key == f"fit[0].{key}"


@pytest.mark.parametrize("table,key,reason", [
    ({"kind": "cylinder", "t": 0.01, "length": 5, "width": 3}, "width", "kind 'cylinder' takes no 'width'"),
    ({"kind": "plane", "t1": 0.0, "t2": 0.01, "length": 5}, "width", "missing required key"),
    ({"kind": "clearance", "clearance": 0.01, "length": 5, "hole": 1}, "hole", "expected a table"),
])
def test_a_domain_takes_the_keys_of_its_kind(table, key, reason):
    with pytest.raises(InputError, match=reason) as e:
        domain_from_table(Params(table, file="s.toml", key="analysis[1].domain[0]"))
    assert (e.value.file, e.value.key) == ("s.toml", f"analysis[1].domain[0].{key}")


def test_rvtol_kinds_lists_the_files_keys_as_written():
    keys = {name: [o.key for o in describe(table_options(name))]
            for name in ("assembly", "dimension", "part", "feature", "deviation", "assembly_fit", "sequence", "kc",
                         "domain")}
    assert keys["assembly_fit"] == ["name", "base", "mate", "type", "clearance", "length", "hole", "float",
                                    "description"]
    assert keys["sequence"] == ["name", "description", "steps", "steps[].part", "steps[].by"]
    assert {"radius", "angle", "x", "y", "z", "rotation", "size", "form", "deviation"} <= set(keys["feature"])


ASSEMBLY_TABLES = {"assembly": "assembly", "part": "part", "fit": "assembly_fit", "sequence": "sequence", "kc": "kc"}


@pytest.mark.parametrize("file", ["data/assemblies/rv_crank_chain.toml", "data/assemblies/shaft_hole_doc003.toml",
                                  "data/products/rv80e/assembly.toml"])
def test_every_key_of_the_assembly_files_is_declared(file):
    """rvtol kinds lists every key the repository's assembly files write, in every table and sub-table."""
    data = tomllib.loads((ROOT / file).read_text(encoding="utf-8"))

    def declared(name):
        return {o.key for o in describe(table_options(name))}

    for entry in data.get("dimensions", {}).values():
        assert set(entry) <= declared("dimension")
    for table, name in ASSEMBLY_TABLES.items():
        for t in data[table] if isinstance(data[table], list) else [data[table]]:
            assert set(t) <= declared(name), (table, set(t) - declared(name))
    for feature in (f for p in data["part"] for f in p.get("feature", [])):
        assert set(feature) <= declared("feature")
        for term in feature.get("deviation", []):
            assert set(term) <= declared("deviation")
