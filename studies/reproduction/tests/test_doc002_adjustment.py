"""Doc 002's mapping of the assembly's key characteristics onto the 20-DOF transmission-error model."""
import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rvtol_reproduction", reason="the reproduction wing is not installed "
                                                  "(python -m pip install -e studies/reproduction)")

from rvtol.models.adjustment import AdjustedAssemblyModel
from rvtol.plugin import TransmissionErrorModel, load_assembly, load_design
from rvtol_reproduction.doc002_adjustment import CRANK_ANGLES, te_against_q, te_inputs, te_values

ROOT = Path(__file__).resolve().parents[3]   # the repository


def test_te_mapping_by_hand():
    """KC1 tilted by δ: crank 1 moves by (0, −δL); disc 1 moves relative to it by (0, +δL) (KC2 = 0)."""
    d, L = 1e-3, 6.0
    v = dict(zip(te_inputs(), te_values({"KC1": d, "KC2": 0.0, "KC3": 0.0, "KC4": 0.0}, L)))
    assert v["E_ca[1]"] == pytest.approx(d * L) and v["beta_ca[1]"] == pytest.approx(-math.pi / 2)
    for h in (1, 2, 3):  # the same carrier-frame vector seen from each hole's radial direction
        assert v[f"E_h[1,{h}]"] == pytest.approx(d * L)
        assert v[f"beta_h[1,{h}]"] == pytest.approx(math.pi / 2 - CRANK_ANGLES[h - 1])
    assert v["E_ca[2]"] == 0.0 and v["E_h[2,1]"] == 0.0
    # a gear tilted with its crank (δ_gear = δ_crank) sits exactly on it
    v = dict(zip(te_inputs(), te_values({"KC1": 0.0, "KC2": 0.0, "KC3": d, "KC4": d}, L)))
    assert v["E_h[2,1]"] == 0.0 and v["E_ca[2]"] == pytest.approx(d * L)


def test_te_of_the_mapped_example_scales_with_the_lever_arm():
    """Small offsets: TE is kinematic, proportional to L; at Q = ∞ the mapped reducer is error-free."""
    te = TransmissionErrorModel(load_design(ROOT / "data/designs/rv80e_te.toml"), inputs=te_inputs())
    m = AdjustedAssemblyModel(load_assembly(ROOT / "data/assemblies/bx40e_2d.toml"))
    w = np.array([-1.6, 5.3, 5.8, 3.2]) * 1e-3
    a = te_against_q(m, te, w, [5.0, math.inf], 3.0)
    b = te_against_q(m, te, w, [5.0, math.inf], 6.0)
    free = te.evaluate(np.zeros((1, len(te.inputs))))[0, te.output_index("te_pp")]
    assert b["te_pp [arcsec]"][0] == pytest.approx(2 * a["te_pp [arcsec]"][0], rel=0.02)
    assert a["te_pp [arcsec]"][1] == pytest.approx(free * 206264.806, rel=1e-6)
