"""Coverage of the per-serial update on synthetic reducers with a known truth (issue 41; studies/production.md §8).

A small non-linear reducer model of five factors (one of them, the housing, measured on every unit with u = 0.2 µm)
and four outputs: two read on the end-of-line rig (u_obs = 0.3 µm each), two not.  Per unit the truth is drawn
from the unit's own prior (its measured housing ± u, the rest from the spec), the rig's readings are the truth
plus a normal error of u_obs, and rvtol.production.per_serial updates the unit with its defaults (2 hidden
factors and the directions of the other three, 4 ensembles × 32 walkers × 1000 steps; or update = "outputs").  Printed: per output and nominal level, the
fraction of units whose central posterior interval holds the truth (with its 95 % Clopper–Pearson interval), the
prior's for comparison, the median ratio of the posterior to the prior interval width, and the time per serial.

    PYTHONPATH=. python studies/per_serial_coverage.py [UNITS [factors|outputs]]   # 200 units: ~10 min / ~5 s
"""
from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy import stats

from rvtol.mc import Evaluator
from rvtol.model import FunctionModel, Quantity
from rvtol.production import FamilySource, load_measured_units
from rvtol.production.per_serial import EndOfLine, update_serials
from rvtol.production.per_unit import unit_values
from rvtol.spec import spec_from_table
from rvtol.stats import proportion_ci

SPEC = spec_from_table({"factor": [
    {"name": "crank.a", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 1.0},
    {"name": "disc.b", "unit": "um", "dist": "normal", "mean": 1.0, "sigma": 1.0},
    {"name": "disc.c", "unit": "um", "dist": "uniform", "lower": -2.0, "upper": 2.0},
    {"name": "pins.d", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 0.5},
    {"name": "housing.e", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 1.0},
]})
OUTPUTS = ("lost motion (read)", "rigidity (read)", "TE (not read)", "other (not read)")
U_OBS = np.array([0.3, 0.3])
LEVELS = (0.5, 0.8, 0.9, 0.95)


def reducer(X):
    a, b, c, d, e = (X[:, j] * 1e3 for j in range(5))          # µm
    return np.column_stack([a + 0.5 * b + 0.1 * a ** 2, b - 0.7 * c + 0.2 * e, a + b + c + 0.6 * d,
                            0.5 * a * b + e + d])


def main(n_units: int = 200, seed: int = 20261129, update: str = "factors") -> None:
    rng = np.random.default_rng(seed)
    folder = Path(tempfile.mkdtemp())
    rows = "\n".join(f"H{i}, {rng.normal(0, 1):.4f}" for i in range(n_units))
    (folder / "housings.csv").write_text(f"serial, e [um]\nuncertainty, 0.2\n{rows}\n", encoding="utf-8")
    (folder / "kits.csv").write_text("reducer, housing\n" + "\n".join(f"R{i}, H{i}" for i in range(n_units)) + "\n",
                                     encoding="utf-8")
    units = load_measured_units(SPEC, folder / "kits.csv", [FamilySource(folder / "housings.csv", ("housing",))])
    model = FunctionModel(reducer, SPEC.names, [Quantity(q, "um") for q in OUTPUTS], ["mm"] * 5)
    truth = np.array([model.evaluate(unit_values(SPEC, units, i, stats.norm.cdf(rng.standard_normal((1, 5)))))[0]
                      for i in range(n_units)])
    obs = truth[:, :2] + U_OBS * rng.standard_normal((n_units, 2))
    eol = EndOfLine("synthetic", "", OUTPUTS[:2], ("um", "um"), tuple(units.units), tuple(range(n_units)), obs, U_OBS)
    t0 = time.perf_counter()
    res = update_serials(model, SPEC, units, eol, 210, evaluator=Evaluator(), seed=seed, update=update)
    seconds = (time.perf_counter() - t0) / n_units
    print(f"{n_units} synthetic reducers, update = {update!r}: {seconds:.3f} s per serial (the update alone "
          f"{np.mean([u.seconds for u in res.updates.values()]):.3f} s)")
    print("| output | nominal | posterior coverage [95 % CI] | prior coverage | median width posterior/prior |")
    print("|---|---|---|---|---|")
    for j, q in enumerate(OUTPUTS):
        for level in LEVELS:
            a = (1 - level) / 2
            cov = {}
            width = []
            for w, p in (("prior", res.prior), ("posterior", res.posterior)):
                lo, hi = np.quantile(p.Y[:, :, j], [a, 1 - a], axis=1)
                cov[w] = int(np.sum((lo <= truth[:, j]) & (truth[:, j] <= hi)))
                width.append(hi - lo)
            ci = proportion_ci(cov["posterior"], n_units, 0.95)
            print(f"| {q} | {level:.0%} | {cov['posterior'] / n_units:.3f} [{ci[0]:.3f}, {ci[1]:.3f}] | "
                  f"{cov['prior'] / n_units:.3f} | {np.median(width[1] / width[0]):.2f} |")
    print("\nThe 95 % intervals of the first three units, prior → posterior (µm), and the truth:")
    print("| unit | output | prior | posterior | truth |")
    print("|---|---|---|---|---|")
    for i in range(min(3, n_units)):
        for j, q in enumerate(OUTPUTS):
            (plo, phi), (qlo, qhi) = (np.quantile(p.Y[i, :, j], [0.025, 0.975]) for p in (res.prior, res.posterior))
            print(f"| R{i} | {q} | [{plo:.2f}, {phi:.2f}] (width {phi - plo:.2f}) | [{qlo:.2f}, {qhi:.2f}] "
                  f"(width {qhi - qlo:.2f}) | {truth[i, j]:.2f} |")
    diag = res.update_frame()
    if update == "factors":
        print(f"converged: {int((diag['converged'] == 'yes').sum())} of {n_units}; R-hat max "
              f"{diag['R-hat max'].max():.4f}; ESS min {diag['ESS min'].min():.0f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 200, update=sys.argv[2] if len(sys.argv) > 2 else "factors")
