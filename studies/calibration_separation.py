"""Which measurements separate the needle-bearing compliance from the pin-contact compliance?

A synthetic reducer (data/designs/rv80e_te.toml) is built with different scales on the two families
(cycloid–crank bearing × 1.4, cycloid–pin × 0.8), 3 µm of needle-bearing clearance, E_c = 5 µm and
R_pin = 3 µm. It is "measured" as a torsion curve (σ 0.5″), a TE curve at 3 % of rated torque and a TE
curve at 30 % (σ 0.2″), and the fit is repeated on combinations of these curves. For each fit the
script prints both scales with their standard errors, their correlation ρ, the largest condition index
η and the identifiability verdict. The table is in studies/calibration.md.

    PYTHONPATH=. python studies/calibration_separation.py      # about a minute on a shared machine
"""
import sys
from pathlib import Path

import numpy as np

from rvtol import units
from rvtol.design import load_design
from rvtol.models.calibration import calibrate

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))   # the test oracle synthetic_curves.py
from synthetic_curves import synthetic_measurement  # noqa: E402

D = load_design("data/designs/rv80e_te.toml")
AS = float(units.to_base(1.0, "arcsec"))
T = float(D["reducer.rated_torque"])
TRUTH = {"compliance.turning_arm_bearings": 1.4, "compliance.cycloid_pin": 0.8,
         "clearance.crank_bearing": 3.0, "factor.E_c": 5.0, "factor.R_pin": 3.0}


def main() -> None:
    tc = synthetic_measurement(D, "torsion", TRUTH, sigma=0.5 * AS, seed=11, points=40, offset=7 * AS, name="tc")
    te3 = synthetic_measurement(D, "transmission_error", TRUTH, sigma=0.2 * AS, seed=12, points=360,
                                offset=-20 * AS, name="te3")
    te30 = synthetic_measurement(D, "transmission_error", TRUTH, sigma=0.2 * AS, seed=13, points=360,
                                 offset=-20 * AS, name="te30", load_torque=0.3 * T)
    names = list(TRUTH)
    cases = [("torsion curve, E_c and R_pin known", [tc], names[:3], {"E_c": 5e-3, "R_pin": 3e-3}),
             ("TE 3 %", [te3], names, None),
             ("torsion + TE 3 %", [tc, te3], names, None),
             ("torsion + TE 3 % + TE 30 %", [tc, te3, te30], names, None),
             ("TE 3 % + TE 30 %", [te3, te30], names, None)]
    print("| measurements | needle bearing (1.4) | pin contact (0.8) | ρ | η_max | separable |")
    print("|---|---|---|---|---|---|")
    for label, ms, ps, fixed in cases:
        f = calibrate(D, ms, ps, fixed_factors=fixed).fit
        i, j = f.names.index(names[0]), f.names.index(names[1])
        print(f"| {label} | {f.x[i]:.3f} ± {f.se[i]:.3f} | {f.x[j]:.3f} ± {f.se[j]:.3f} | {f.corr[i, j]:+.3f} | "
              f"{np.nanmax(f.identifiability.condition_indices):.1f} | {'yes' if f.identifiability.ok else 'no'} |")


if __name__ == "__main__":
    main()
