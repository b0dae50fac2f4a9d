"""Regenerate the SYNTHETIC measured curves in data/measurements/ (issue 12, item 4).

They are made by the 20-DOF model of data/designs/rv80e_te.toml with the known parameters below plus
seeded normal noise (tests/synthetic_curves.py); they are NOT measurements of any reducer.  The
calibration study (studies/calibration_rv80e_synthetic.toml) and tests/models/test_calibration.py fit them
and check that the fit finds these values within its intervals.

    PYTHONPATH=. python studies/calibration_synthetic_data.py        # a few seconds
"""
import sys
from pathlib import Path

from rvtol import units
from rvtol.design import load_design

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))   # the test oracle synthetic_curves.py
from synthetic_curves import synthetic_measurement, write_synthetic_csv  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
DESIGN = ROOT / "data/designs/rv80e_te.toml"
OUT = ROOT / "data/measurements"
SEED = 20120412

#: the "true" reducer: 25 % more compliant than doc 000's Table 2 everywhere, 3 µm of needle-bearing
#: clearance, 5 µm of crank cam eccentricity error and 3 µm of pin tooth-space error (Table 3 patterns)
TRUTH = {"compliance.all": 1.25, "clearance.crank_bearing": 3.0, "factor.E_c": 5.0, "factor.R_pin": 3.0}
CURVES = {
    # file: (kind, points, sigma [arcsec], offset [arcsec], seed key)
    "synthetic_rv80e_torsion_curve.csv": ("torsion", 40, 0.5, 7.0, 1),
    "synthetic_rv80e_te.csv": ("transmission_error", 360, 0.2, -20.0, 2),
}


def main() -> None:
    design = load_design(DESIGN)
    arcsec = float(units.to_base(1.0, "arcsec"))
    truth = ", ".join(f"{k} = {v:g}" for k, v in TRUTH.items())
    for name, (kind, points, sigma, offset, key) in CURVES.items():
        m = synthetic_measurement(design, kind, TRUTH, sigma=sigma * arcsec, seed=SEED + key, points=points,
                                  offset=offset * arcsec, name=Path(name).stem)
        what = ("torsion curve, input locked, output torque 0 -> +784 -> -784 -> 0 N*m in 40 steps per quarter"
                if kind == "torsion" else "TE curve over one output revolution under 3 % of rated torque (23.52 N*m)")
        write_synthetic_csv(OUT / name, m, [
            f"{what}; model: {DESIGN.relative_to(ROOT)} (doc 000's 20-DOF RV-80E)",
            f"true parameters: {truth} (um for clearances and factors); angle offset {offset:g} arcsec",
            f"noise: independent normal, sigma = {sigma:g} arcsec, seed {SEED + key} (sub-stream calibration_noise)",
            "regenerate: PYTHONPATH=. python studies/calibration_synthetic_data.py"])
        print(f"wrote {OUT / name} ({m.n} points)")


if __name__ == "__main__":
    main()
