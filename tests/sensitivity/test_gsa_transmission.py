"""Global sensitivity of the 20-DOF TE model from its Monte Carlo sample against the Saltelli route (issue 15).

Five factors of the TE study's spec (data/specs/rv80e_te.toml), 8 positions per crank revolution (320
equilibria per reducer: the indices of this cheaper model, the same physics), one output te_pp.  Two
independent routes: SALib Saltelli (n = 64 → 448 runs) and, on 512 Monte Carlo runs with no further model
run, the given-data first-order indices and a polynomial chaos surrogate.  The difference of two
independent estimates lies within √(c_a² + c_b²) (+ the surrogate's bias bound), each half-width at the
Bonferroni level of the family of comparisons (tests/gsa_reference.py).
"""

import numpy as np
import pytest

from rvtol.design import load_design
from rvtol.mc import run_monte_carlo
from rvtol.models.transmission_error.model import TransmissionErrorModel
from rvtol.sensitivity import sobol
from rvtol.sensitivity.given_data import given_data
from rvtol.sensitivity.surrogate import pce
from rvtol.spec import load_spec

from gsa_reference import bonferroni

from conftest import ROOT

FACTORS = ["E_c[1,1]", "beta_c[1,1]", "delta_b[1,1]", "E_h", "R_pin"]


@pytest.fixture(scope="module")
def case():
    full = load_spec(ROOT / "data/specs/rv80e_te.toml")
    spec = full.with_factors([full.factor(n) for n in FACTORS])
    model = TransmissionErrorModel(load_design(ROOT / "data/designs/rv80e_te.toml"), spec.names, per_crank_rev=8)
    return model, spec


def test_te_indices_from_the_monte_carlo_agree_with_saltelli(case):
    model, spec = case
    conf = bonferroni(3 * len(FACTORS))
    sal = sobol(model, spec, n=64, outputs=["te_pp"], second_order=False, seed=21, confidence=conf)
    mc = run_monte_carlo(model, spec, 512, "lhs", seed=22, progress=False)
    assert mc.ok.all() and sal.n_failed == 0
    given = given_data(model, spec, mc.samples, mc.Y, outputs=["te_pp"], seed=23, num_resamples=100,
                       confidence=conf)
    sur = pce(model, spec, mc.samples, mc.Y, outputs=["te_pp"], seed=24, num_resamples=50, confidence=conf,
              max_degree=6, second_order=False)
    s, g, p = (r.frame.set_index("factor").loc[FACTORS] for r in (sal, given, sur))
    assert given.n_evaluations == sur.n_evaluations == 0
    tol = np.hypot(s["S1_conf"], g["S1_conf"])
    assert (np.abs(s["S1"] - g["S1"]) <= tol).all(), (s, g)
    v = sur.validation.iloc[0]
    assert v["reliable"], v                             # te_pp of this five-factor model is smooth enough
    for col in ("S1", "ST"):
        tol = np.hypot(s[f"{col}_conf"], p[f"{col}_conf"]) + v["bias_bound"]
        assert (np.abs(s[col] - p[col]) <= tol).all(), (col, s, p)
    # not a vacuous agreement: one factor dominates and every route says so
    assert s["S1"].idxmax() == g["S1"].idxmax() == p["ST"].idxmax() == "R_pin" and g.loc["R_pin", "S1"] > 0.8
