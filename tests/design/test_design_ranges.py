"""What is known of a design number (issue 39 item 2): status, plausible range and its basis, step, computed
numbers that follow others — read and checked by the design loader; the RV-80E product carries a range for every
estimate."""
import math
import re
import tomllib

import numpy as np
import pytest

from rvtol.design import STATUSES, design_from_table, load_design
from rvtol.errors import SpecError

from conftest import ROOT

PRODUCT = ROOT / "data/products/rv80e/design.toml"


def design(**params):
    """A design table from ``key = {...}`` entries (group.key)."""
    data = {"design": {"name": "t"}}
    for k, v in params.items():
        group, key = k.split("__")
        data.setdefault(group, {})[key] = v
    return design_from_table(data, file="d.toml")


def test_range_basis_step_and_status_are_read_in_the_values_unit():
    d = design(a__x={"value": 26, "unit": "mm", "source": "s", "status": "estimate", "range": [24, 28],
                     "basis": "why"},
               a__n={"value": 4, "unit": "mm", "source": "s", "status": "estimate", "range": [3, 5], "step": 0.5,
                     "basis": "ISO sizes"},
               a__k={"value": 2, "unit": "um", "source": "s", "status": "estimate", "range": [1, 3], "basis": "b"},
               a__e={"value": 7, "unit": "mm", "source": "doc", "status": "document"})
    p = d.param("a.x")
    assert (p.status, p.range, p.basis) == ("estimate", (24.0, 28.0), "why")
    assert d.param("a.k").base_range == pytest.approx((0.001, 0.003))
    assert [q.name for q in d.uncertain()] == ["a.x", "a.n", "a.k"]
    assert d.param("a.n").step == 0.5 and d.param("a.e").range is None
    assert set(d.ranges_frame()["parameter"]) == {"a.x", "a.n", "a.k"}


@pytest.mark.parametrize("entry, key, msg", [
    ({"value": 30, "range": [24, 28], "basis": "b"}, "a.x.range", "outside its range"),
    ({"value": 26, "range": [28, 24], "basis": "b"}, "a.x.range", "low < high"),
    ({"value": 26, "range": [24], "basis": "b"}, "a.x.range", "expected 2 numbers"),
    ({"value": 26, "range": [24, 28]}, "a.x.basis", "needs its basis"),
    ({"value": 26, "status": "estimate"}, "a.x.range", "plausible range"),
    ({"value": 26, "status": "guess"}, "a.x.status", "expected one of"),
    ({"value": 26.3, "range": [24, 28], "step": 0.5, "basis": "b"}, "a.x.step", "lo \\+ k·step"),
    ({"value": 26, "step": 1}, "a.x.step", "needs the range"),
    ({"value": "X", "range": [0, 1], "basis": "b"}, "a.x.range", "single number"),
    ({"formula": "a.y + 1", "status": "estimate"}, "a.x.status", "computed"),
    ({"formula": "a.y + 1", "range": [24, 28], "basis": "b"}, "a.x.range", "give their ranges"),
])
def test_bad_ranges_and_statuses_name_their_key(entry, key, msg):
    with pytest.raises(SpecError, match=msg) as e:
        design(a__x={"unit": "mm", "source": "s", **entry}, a__y={"value": 25, "unit": "mm", "source": "s"})
    assert e.value.key == key and e.value.file == "d.toml"


def test_a_computed_number_is_its_formula_and_follows_a_variant():
    base = dict(a__e={"value": 26, "unit": "mm", "source": "s", "status": "estimate", "range": [24, 28], "basis": "b"},
                a__d={"value": 4, "unit": "mm", "source": "s", "status": "estimate", "range": [3, 5], "basis": "b"},
                a__p={"value": 1.3, "unit": "1", "source": "s", "status": "estimate", "range": [1.1, 1.5], "basis": "b"},
                a__hole={"formula": "a.e + 2 * a.d", "unit": "mm", "source": "s"},
                a__n={"formula": "pi * (a.e + a.d) / (a.p * a.d)", "unit": "1", "source": "s", "step": 1},
                a__web={"formula": "(a.hole - 28) / 2", "unit": "mm", "source": "s", "status": "computed"})
    d = design(**base)
    assert [p.name for p in d.uncertain()] == ["a.e", "a.d", "a.p"]
    assert d.param("a.hole").status == "computed"                       # a formula's number is computed
    # hand computation: hole 26 + 8 = 34, rollers round(π·30/(1.3·4)) = round(18.12) = 18, web (34 − 28)/2 = 3
    assert d["a.hole"] == 34.0 and d["a.n"] == 18.0 and d["a.web"] == 3.0
    v = d.with_values(**{"a.e": 28.0, "a.d": 3.0})
    # hole 28 + 6 = 34, rollers round(π·31/(1.3·3)) = round(24.97) = 25, web (34 − 28)/2 = 3
    assert v["a.hole"] == 34.0 and v["a.n"] == 25.0 and v["a.web"] == 3.0
    v = d.with_values(**{"a.d": 5.0})
    assert v["a.hole"] == 36.0 and v["a.n"] == round(math.pi * 31 / 6.5) and v["a.web"] == 4.0
    assert d.with_values(**{"a.hole": 35.0})["a.hole"] == 35.0          # given itself: kept
    with pytest.raises(SpecError, match="cycle"):
        design(a__x={"formula": "a.y", "unit": "1", "source": "s"}, a__y={"formula": "a.x", "unit": "1", "source": "s"})
    with pytest.raises(SpecError, match="unknown design number 'a.q'") as e:
        design(a__x={"formula": "a.q", "unit": "1", "source": "s"})
    assert e.value.key == "a.x.formula"


def test_every_estimate_of_the_rv80e_product_has_a_range_and_its_basis():
    """Every number whose source or note calls it an estimate states what is known of it: an estimate with its
    plausible range and basis, a computed number (from other numbers), or a design choice."""
    raw = tomllib.loads(PRODUCT.read_text())
    d = load_design(PRODUCT)
    said_estimate = []
    for group, table in raw.items():
        for key, entry in (table.items() if group != "design" else ()):
            if isinstance(entry, dict) and ("value" in entry or "formula" in entry) and re.search(
                    r"\bestimate", entry.get("source", "") + " " + entry.get("note", "")[:9], re.I):
                said_estimate.append(f"{group}.{key}")
    assert len(said_estimate) > 40
    for name in said_estimate:
        p = d.param(name)
        assert p.status in STATUSES, name
        if p.status == "estimate":
            assert p.range is not None and p.basis.strip(), name
    for p in d.uncertain():
        assert p.range[0] <= p.value <= p.range[1] and p.basis
    # the carrier's centre bore follows the wall beside the cup seats (issue 39: was ⌀40, a 0.94-mm wall)
    wall = d.value("crank_bearing.centre_radius", "mm") - 21.0 - d.value("carrier.bore_diameter", "mm") / 2
    assert wall == pytest.approx(d.value("carrier.bore_ligament", "mm"), abs=1e-9) and wall >= 3.0


def test_the_compliant_corner_is_the_end_of_each_range_it_changes():
    """data/products/rv80e/compliant_corner.toml writes only ends of the base's stated ranges (a bound of what the
    estimates admit, studies/epistemic_band.md §6): a range moved in design.toml must move the corner with it."""
    corner = load_design(PRODUCT.parent / "compliant_corner.toml")
    base = load_design(PRODUCT)
    changed = [k for k, p in corner.params.items() if p.file and p.file.endswith("compliant_corner.toml")]
    assert len(changed) > 20
    for k in changed:
        lo, hi = base.param(k).range
        assert corner.param(k).value in (lo, hi), k
