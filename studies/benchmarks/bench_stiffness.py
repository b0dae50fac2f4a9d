"""Torsional-stiffness benchmark: time per torsion-angle evaluation (doc 004) and per hysteresis curve (20-DOF).

Measured side by side in one process (the machines are shared and noisy); ratios are what counts:

* torsion-angle model (NumPy, vectorised over samples): one row alone, and per row in a batch
  of 1000 (the batch/one-row ratio is the vectorisation gain);
* hysteresis curve (0 → +T → −T → 0, 20 steps per quarter, 83 equilibria): the numba sweep
  against the NumPy reference implementation of the same 20-DOF equations (warm-started Newton),
  for a clearance-free reducer and one with 2 µm crank-bearing and pin clearances.

    python studies/benchmarks/bench_stiffness.py [--quick | --smoke]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from rvtol.design import load_design
from rvtol.models.stiffness.torsion_angle import ReducerStiffness
from rvtol.models.torsion_curve.model import TorsionCurveModel, torque_schedule
from rvtol.models.torsion_curve.model import CAMS

from _timing import add_size_options, best_time, by_size, print_table

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests"))     # the test oracle numpy_twin.py
from numpy_twin import ReferenceModel  # noqa: E402




def reference_curve(model: TorsionCurveModel, x) -> np.ndarray:
    """The same torque schedule solved with the NumPy reference model (warm-started Newton per point)."""
    ref = ReferenceModel(model.geometry, model.state(x))
    torque, _ = torque_schedule(model.torque, model.points, model.percent)
    q = np.zeros(20)
    out = np.empty(torque.size)
    for k, tau in enumerate(torque):
        q = ref.rotation([0.0], tau, q, tol_f=model.solver_options["tol_f"], maxit=200)[0]
        out[k] = q[19]
    return out


def main(size: str = "full") -> None:
    rows = []
    d = load_design(ROOT / "data/designs/rv80e_stiffness.toml")
    rs = ReducerStiffness.from_design(d)
    mods = (d["cycloid.equidistance_modification"], d["cycloid.moved_distance_modification"])
    n = by_size(size, 10, 200, 1000)
    rng = np.random.default_rng(0)
    errs = rng.normal(0.0, 0.0015, (n, 2))
    t_one = best_time(lambda: rs.evaluate(784e3, *mods, pin_circle_error=errs[:1, 0], pin_radius_error=errs[:1, 1]))
    t_batch = best_time(lambda: rs.evaluate(784e3, *mods, pin_circle_error=errs[:, 0], pin_radius_error=errs[:, 1]))
    rows.append(("torsion angle θ1..θ5, one row", f"{t_one * 1e3:.2f} ms", "reference"))
    rows.append((f"torsion angle θ1..θ5, per row in a batch of {n}", f"{t_batch / n * 1e6:.0f} µs",
                 f"{t_one / (t_batch / n):.0f}× faster per row than one row alone"))

    te = load_design(ROOT / "data/designs/rv80e_te.toml")
    m = TorsionCurveModel(te, CAMS + ("delta_pin",))
    for label, x in (("clearance-free", np.zeros(7)), ("2 µm clearances", np.full(7, 0.002))):
        m.curve(x)                                            # compile / warm the numba kernels
        t_nb = best_time(lambda: m.curve(x), repeat=by_size(size, 1, 5, 5))
        t_np = best_time(lambda: reference_curve(m, x), repeat=by_size(size, 1, 1, 2))
        c = m.curve(x)
        loaded = c.torque != 0.0          # at exactly zero torque the equilibrium inside the clearances is not unique
        diff = np.abs(reference_curve(m, x) - c.angle)[loaded].max() / np.abs(c.angle).max()
        rows.append((f"hysteresis curve, numba sweep ({label})", f"{t_nb * 1e3:.2f} ms", "reference"))
        rows.append((f"hysteresis curve, NumPy reference ({label})", f"{t_np * 1e3:.0f} ms",
                     f"{t_np / t_nb:.0f}× the numba time; curves agree to {diff:.1e} (relative, τ ≠ 0)"))

    print_table(rows, ("measurement", "time", "ratio"))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_size_options(ap)
    main(ap.parse_args().size)
