"""Final KC angles of the 2-D BX40E assembly -> error inputs of the 20-DOF transmission-error model.

Doc 002 simulates TE "for different Q values" without saying how its final
KC errors enter the dynamic model; rvtol's mapping (stated in the report):

* the TE model is the RV-80E of doc 000 (``rvtol.models.transmission``; the
  only RV geometry with a TE model here) standing in for the BX40E;
* doc 002's 2-D angles are tilts about the datum x axis (perpendicular to the
  reducer axis z).  A tilt δ moves an axis point at axial distance L from the
  tilt pivot by ``(0, −δ·L)`` in the carrier frame; ``L`` (``lever_arm``) is
  the distance from the pivot to the cycloid discs' mid-planes;
* crankshaft KC1 / KC3 -> carrier crank-hole position error of RV-80E cranks
  1 / 2 (``E_ca[i]``, ``beta_ca[i]``: offset |δ|·L, direction relative to the
  crank's radial direction φ_i = 0°, 120°); crank 3 stays exact;
* cycloid gear KC2 / KC4 -> disc 1 / 2 displaced relative to its cranks by
  the gear's own tilt relative to its crank, (δ_gear − δ_crank)·L, applied to
  all three crank holes of the disc (``E_h[j,i]``, ``beta_h[j,i]``);
* every other error of the TE model is zero, so at Q = ∞ the TE is that of
  an error-free reducer (doc 002's 12.5 arcsec floor comes from error
  sources it does not describe).
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

#: the mapping in plain words, for the report
MAPPING = (
    "The RV-80E transmission-error model of doc 000 stands in for the BX40E (doc 002 gives no BX40E "
    "geometry). Doc 002's 2-D angles are read as tilts about the datum x axis, perpendicular to the reducer "
    "axis: a tilt δ moves an axis point at axial distance L from the tilt pivot by (0, −δ·L) in the carrier "
    "frame. Crankshaft KC1 / KC3 become carrier crank-hole position errors of RV-80E cranks 1 / 2 (E_ca, "
    "β_ca; crank 3 exact); cycloid gear KC2 / KC4 displace disc 1 / 2 relative to its cranks by the gear's "
    "own tilt relative to its crank, (δ_gear − δ_crank)·L, on all three crank holes (E_h, β_h). Every other "
    "error of the TE model is zero, so at Q = ∞ the reducer is error-free (doc 002's 12.5 arcsec floor comes "
    "from error sources it does not describe). TE is computed quasi-statically over one output revolution "
    "at 3 % of rated torque.")

CRANK_ANGLES = (0.0, 2.0 * math.pi / 3.0, 4.0 * math.pi / 3.0)
#: doc 002 chain -> (KC of the crankshaft, KC of the cycloid gear, RV-80E crank index, disc index)
CHAINS = (("KC1", "KC2", 1, 1), ("KC3", "KC4", 2, 2))


def te_inputs() -> list[str]:
    names = []
    for _, _, i, j in CHAINS:
        names += [f"E_ca[{i}]", f"beta_ca[{i}]"]
        for h in (1, 2, 3):
            names += [f"E_h[{j},{h}]", f"beta_h[{j},{h}]"]
    return names


def _polar(offset_y: float, ref_angle: float) -> tuple[float, float]:
    """Magnitude and angle (relative to ``ref_angle``) of the carrier-frame offset ``(0, offset_y)``."""
    mag = abs(offset_y)
    ang = (math.pi / 2 if offset_y >= 0 else -math.pi / 2) - ref_angle
    return mag, ang


def te_values(final: dict[str, float], lever_arm: float) -> np.ndarray:
    """TE factor values (mm, rad) in :func:`te_inputs` order from final KC angles (rad) and L (mm)."""
    vals = []
    for kc_crank, kc_gear, i, j in CHAINS:
        vals += _polar(-final[kc_crank] * lever_arm, CRANK_ANGLES[i - 1])
        rel = -(final[kc_gear] - final[kc_crank]) * lever_arm
        for h in (1, 2, 3):
            vals += _polar(rel, CRANK_ANGLES[h - 1])
    return np.array(vals, float)


def te_against_q(model, te_model, w: np.ndarray, weights, lever_arm: float) -> pd.DataFrame:
    """TE peak-to-peak and the largest pin force of the example assembly at each accuracy weight Q."""
    from .. import units

    names = model.description.observation_names()
    X = []
    for q in weights:
        run = model.with_accuracy(q).adjuster.simulate(w)
        X.append(te_values(dict(zip(names, run.final[0])), lever_arm))
    Y, status = te_model.evaluate_with_status(np.array(X))
    return pd.DataFrame({
        "Q": list(weights),
        "Q shown": ["∞" if math.isinf(q) else f"{q:g}" for q in weights],
        "te_pp [arcsec]": units.from_base(Y[:, te_model.output_index("te_pp")], "arcsec"),
        "pin_force_max [N]": Y[:, te_model.output_index("pin_force_max")],
        "status": [te_model.status_reasons.get(int(s), "?") if s else "ok" for s in status],
    })
