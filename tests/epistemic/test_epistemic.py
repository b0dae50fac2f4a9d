"""The epistemic band (issue 39 item 2): a prediction over the design's estimated numbers within their stated
ranges, beside the tolerance scatter, and the first-order indices of those numbers — on a cantilever whose
deflection δ = F L³ / (3 E π d⁴/64) has every moment in closed form."""
import math

import numpy as np
import pytest

from rvtol.design import design_from_table
from rvtol.epistemic import design_inputs, epistemic_band
from rvtol.errors import InputError, SpecError
from rvtol.model import FunctionModel, Quantity
from rvtol.spec import spec_from_table

DESIGN = design_from_table({
    "design": {"name": "cantilever"},
    "beam": {
        "E": {"value": 206, "unit": "GPa", "source": "s", "status": "estimate", "range": [200, 212], "basis": "steel"},
        "d": {"value": 10, "unit": "mm", "source": "s", "status": "estimate", "range": [8, 12], "step": 1,
              "basis": "whole millimetres"},
        "L": {"value": 100, "unit": "mm", "source": "s", "status": "estimate", "range": [95, 105], "basis": "b"},
        "ends": {"value": 2, "unit": "1", "source": "document", "status": "document"},
    }}, file="beam.toml")
SPEC = spec_from_table({"factor": [{"name": "F", "unit": "N", "dist": "uniform", "lower": 90.0, "upper": 110.0}]})


def deflection(F, E, d, L):
    return F * L ** 3 / (3.0 * E * math.pi * d ** 4 / 64.0)


def maker(values, fail_below=None):
    d = DESIGN.with_values(**values)
    if fail_below is not None and d["beam.d"] < fail_below:
        raise SpecError("too thin for the clamp", key="beam.d")
    E, dd, L = d["beam.E"], d["beam.d"], d["beam.L"]
    model = FunctionModel(lambda X: deflection(X[:, 0], E, dd, L)[:, None], ["F"],
                          [Quantity("tip", "mm", "um")], ["N"])
    return model, SPEC


def test_the_band_lies_within_the_ranges_corners_and_covers_them():
    res = epistemic_band(DESIGN, maker, ["tip"], n=64, seed=3)
    E, d, L = DESIGN["beam.E"], DESIGN["beam.d"], DESIGN["beam.L"]
    assert res.nominal[0] == pytest.approx(1e3 * deflection(100.0, E, d, L), rel=1e-12)   # µm, nominal F = 100 N
    lo = 1e3 * deflection(100.0, 212e3, 12.0, 95.0)
    hi = 1e3 * deflection(100.0, 200e3, 8.0, 105.0)
    b = res.band("tip")
    assert lo <= b["epistemic min"] <= b["epistemic low"] < b["epistemic median"] < b["epistemic high"] \
        <= b["epistemic max"] <= hi
    assert b["epistemic max"] > 0.7 * hi and b["epistemic min"] < 1.3 * lo          # d ∈ {8, 12} both drawn
    assert set(np.unique(res.values[:, 1])) == {8.0, 9.0, 10.0, 11.0, 12.0}          # the grid, nothing between
    assert "ends" not in [i.name for i in res.inputs]


def test_first_order_indices_against_the_closed_form_variance_decomposition():
    """δ = c L³ E⁻¹ d⁻⁴ with independent inputs: E(δ|d) = c E[L³] E[E⁻¹] d⁻⁴, so S1_d = Var(d⁻⁴) E[L³]² E[E⁻¹]² / V
    (and alike for E, L), V from the moments of uniforms (d over its five grid points)."""
    res = epistemic_band(DESIGN, maker, ["tip"], n=256, seed=7, num_resamples=100)

    def mom(p, lo, hi):                      # E[x^p] of a uniform on [lo, hi]
        return (hi ** (p + 1) - lo ** (p + 1)) / ((p + 1) * (hi - lo)) if p != -1 else math.log(hi / lo) / (hi - lo)

    grid = np.arange(8.0, 13.0)
    m = {"E": (mom(-1, 200, 212), mom(-2, 200, 212)), "L": (mom(3, 95, 105), mom(6, 95, 105)),
         "d": (np.mean(grid ** -4.0), np.mean(grid ** -8.0))}
    V = np.prod([v[1] for v in m.values()]) - np.prod([v[0] for v in m.values()]) ** 2
    for name, (m1, m2) in m.items():
        others = np.prod([v[0] for k, v in m.items() if k != name]) ** 2
        want = (m2 - m1 ** 2) * others / V
        row = res.sensitivity.set_index("factor").loc[f"beam.{name}"]
        assert row["S1"] == pytest.approx(want, abs=0.08), name
    assert res.drivers("tip", 1)["factor"][0] == "beam.d"


def test_tolerance_band_and_designs_by_units():
    res = epistemic_band(DESIGN, maker, ["tip"], n=16, seed=1, tolerance_samples=40)
    b = res.band("tip")
    nom = res.nominal[0]
    # F uniform 90…110 N: the design's units lie within ±10 % of the nominal deflection, and cover most of it
    assert 0.9 * nom <= b["tolerance low"] < 0.93 * nom and 1.07 * nom < b["tolerance high"] <= 1.1 * nom
    assert b["combined low"] <= b["epistemic low"] and b["combined high"] >= b["epistemic high"]
    assert res.Y_tol.shape == (16, 40, 1)
    f = res.to_frame()
    assert list(f["output"]) == ["tip"] and f["designs"][0] == 16 and "beam.d" in f["largest drivers (S1)"][0]


def test_a_design_that_cannot_be_built_is_listed_and_left_out():
    res = epistemic_band(DESIGN, lambda v: maker(v, fail_below=9.0), ["tip"], n=20, seed=2)
    bad = res.values[:, 1] < 9.0
    assert bad.any() and list(~res.ok) == list(bad)
    assert all("too thin" in r for r in res.failures()["reason"])
    assert np.isnan(res.Y[bad]).all() and np.isfinite(res.Y[~bad]).all()
    assert "gave no prediction" in res.notes[0]


def test_bad_requests_are_refused():
    with pytest.raises(InputError, match="no range"):
        design_inputs(DESIGN, ["beam.ends"])
    with pytest.raises(InputError, match="not a number"):
        design_inputs(DESIGN, ["beam.q"])
    with pytest.raises(InputError, match="unknown output"):
        epistemic_band(DESIGN, maker, ["tipp"], n=8)
    with pytest.raises(InputError, match="n must be"):
        epistemic_band(DESIGN, maker, ["tip"], n=2)


def test_a_driver_is_listed_only_where_the_designs_resolve_it():
    """The tip deflection does not read E's neighbours below: with 16 designs over the three numbers and eight dummy
    numbers the tip never reads, the given-data index of a dummy is noise about 0 (its interval reaches 0) — only
    the diameter (S1 ≈ 0.8 by the closed form above) is listed; an output that reads no estimate lists none."""
    rows = {"E": (206, "GPa", [200, 212]), "d": (10, "mm", [8, 12]), "L": (100, "mm", [95, 105])}
    rows.update({f"x{i}": (1.0, "1", [0.0, 2.0]) for i in range(8)})
    table = {"design": {"name": "cantilever+"}}
    table["beam"] = {k: {"value": v, "unit": u, "source": "s", "status": "estimate", "range": r, "basis": "b"}
                     for k, (v, u, r) in rows.items()}
    design = design_from_table(table, file="beam.toml")

    def make(values):
        d = design.with_values(**values)
        E, dd, L = d["beam.E"], d["beam.d"], d["beam.L"]
        return FunctionModel(lambda X: np.column_stack([deflection(X[:, 0], E, dd, L), 0.0 * X[:, 0] + 1.0]),
                             ["F"], [Quantity("tip", "mm", "um"), Quantity("flat", "mm", "um")], ["N"]), SPEC

    res = epistemic_band(design, make, ["tip", "flat"], n=32, seed=2, num_resamples=200)
    s = res.sensitivity.set_index(["output", "factor"])
    dummies = [f"beam.x{i}" for i in range(8)]
    assert (s.loc[[("tip", x) for x in dummies], "S1_low"] <= 0.0).all()          # each dummy's interval reaches 0
    assert list(res.drivers("tip")["factor"]) == ["beam.d"]
    assert res.drivers_text("tip").startswith("beam.d (")
    assert res.drivers_text("flat").startswith("none resolved by 32 designs")
