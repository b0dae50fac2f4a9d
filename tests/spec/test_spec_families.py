"""Drawing-level factor keys: part, feature, and FAMILY factors (multiplicity = N -> N iid copies)."""
import numpy as np
import pytest
from scipy import stats

from conftest import ROOT, write
from rvtol.errors import SpecError
from rvtol.sampling import sample
from rvtol.spec import load_spec, spec_from_table

FAMILY = {"name": "pins[k].diameter_in_lot", "unit": "um", "dist": "uniform", "lower": -1.0, "upper": 1.0,
          "part": "pins", "feature": "pin k diameter within its gauge lot", "multiplicity": 5}
PLAIN = {"name": "housing.pin_circle.radius", "unit": "um", "dist": "normal", "tolerance": 4.0,
         "part": "pin housing", "feature": "pin-groove circle ⌀153 js3", "group": "pin gear"}


def test_a_family_expands_to_n_named_copies_with_part_and_feature():
    spec = spec_from_table({"factor": [PLAIN, FAMILY]})
    assert spec.names == ("housing.pin_circle.radius",) + tuple(f"pins[{k}].diameter_in_lot" for k in range(1, 6))
    copies = spec.families()["pins[k].diameter_in_lot"]
    assert len(copies) == 5 and all(f.family == "pins[k].diameter_in_lot" for f in copies)
    assert {(f.part, f.feature, f.group, f.unit, f.dist.band) for f in copies} == \
        {("pins", "pin k diameter within its gauge lot", "pins", "um", (-1.0, 1.0))}
    plain = spec.factor("housing.pin_circle.radius")
    assert (plain.part, plain.group, plain.family) == ("pin housing", "pin gear", "")   # group given: kept
    frame = spec.to_frame()
    assert list(frame["factor"]) == list(spec.names)
    assert list(frame["part"]) == ["pin housing"] + ["pins"] * 5
    assert frame["feature"].iloc[0] == "pin-groove circle ⌀153 js3"
    fam = spec.to_frame(families=True)
    assert list(fam["factor"]) == ["housing.pin_circle.radius", "pins[k].diameter_in_lot"]
    assert list(fam["multiplicity"]) == ["", "×5"]


def test_the_copies_are_independent_and_identically_distributed():
    n = 4000
    spec = spec_from_table({"factor": [FAMILY]})
    X = sample(spec, n, "random", seed=7).display_values()
    for j in range(X.shape[1]):          # each copy: uniform on [-1, 1] (Kolmogorov–Smirnov at the 0.1 % level)
        assert stats.kstest(X[:, j], stats.uniform(-1.0, 2.0).cdf).pvalue > 1e-3
    r = np.corrcoef(X.T)[np.triu_indices(X.shape[1], 1)]
    assert np.abs(r).max() < 4.5 / np.sqrt(n)            # sd of r under independence is 1/√n


def test_the_product_table_expands_its_three_families():
    spec = load_spec(ROOT / "data/products/rv80e/tolerances.toml")
    fams = spec.families()
    # 159 tables + 3 end plays of the crank-support stacks (the shims' input, build.toml) + the output pilot's two
    # coordinates (the TE rig's order 1) + the three planets' clocking (issue 39): 167 tables, 284 factors
    assert len(spec) == 284 and sorted(fams) == ["housing.pin_groove[k].radial_residual",
                                                 "housing.pin_groove[k].tangential_residual",
                                                 "pins[k].diameter_in_lot"]
    assert all(len(v) == 40 for v in fams.values())
    assert len(spec.to_frame(families=True)) == 167
    assert all(f.part and f.feature and f.group == f.part for f in spec.factors)


@pytest.mark.parametrize("change, key, words", [
    ({"multiplicity": 0}, "factor[0].multiplicity", "must be >= 1"),
    ({"multiplicity": -3}, "factor[0].multiplicity", "must be >= 1"),
    ({"multiplicity": 2.5}, "factor[0].multiplicity", "expected an integer"),
    ({"multiplicity": "40"}, "factor[0].multiplicity", "expected an integer"),
    ({"name": "pins.diameter_in_lot"}, "factor[0].name", "[k] exactly once"),
    ({"name": "pins[k].groove[k].x"}, "factor[0].name", "[k] exactly once"),
    ({"multiplicity": None}, "factor[0].multiplicity", "needs 'multiplicity = N'"),
])
def test_a_bad_family_is_one_line_naming_file_and_key(tmp_path, change, key, words):
    f = {**FAMILY, **change}
    f = {k: v for k, v in f.items() if v is not None}
    lines = [f"{k} = {v!r}".replace("'", '"') for k, v in f.items()]
    p = write(tmp_path / "spec.toml", "[[factor]]\n" + "\n".join(lines) + "\n")
    with pytest.raises(SpecError) as exc:
        load_spec(p)
    assert (exc.value.file, exc.value.key) == (str(p), key) and words in exc.value.reason
    assert "\n" not in str(exc.value)


def test_a_copy_colliding_with_another_factor_is_named():
    with pytest.raises(SpecError) as exc:
        plain = {k: v for k, v in FAMILY.items() if k != "multiplicity"}
        spec_from_table({"factor": [{**FAMILY, "multiplicity": 3}, {**plain, "name": "pins[2].diameter_in_lot"}]})
    assert exc.value.key == "factor[1].name" and "duplicate factor name 'pins[2].diameter_in_lot'" in exc.value.reason
