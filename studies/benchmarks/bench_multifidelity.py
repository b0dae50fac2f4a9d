"""Multi-fidelity Monte Carlo (rvtol.multifidelity) against plain Monte Carlo at the same budget (issue 40 item 3).

Two cases, each run side by side in one process:

* **closed form** — f₁ = exp(x), f₂ = 1 + x + x²/2, f₃ = 1 + x on x ~ U(0, 1), costs 1 : 0.01 : 0.001 (the
  estimator's own test case): the empirical variance of both estimators over R replications at one budget;
* **the RV-80E sign-off's lost motion** (quick and full sizes) — high fidelity: the 20-DOF torsion stage's lost
  motion; low fidelity: doc 001's statistical screening of the same reducer (the cheap model of the same
  quantity rvtol has), on the stages that reach each output (``CompositeModel.restricted``); the pilot gives
  their correlation and costs, the allocation the gain the theorem promises, and R replications the gain measured.

Printed per case: the pilot's correlation and cost ratio, the predicted variance ratio, the measured one and the
high-fidelity runs MFMC needs for the interval plain Monte Carlo gets from the budget.

    PYTHONPATH=.:studies/reproduction python studies/benchmarks/bench_multifidelity.py [--quick | --smoke]
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from _timing import add_size_options, by_size, print_table  # noqa: E402
from rvtol.multifidelity import allocation, estimate, pilot  # noqa: E402

FUNCTIONS = (np.exp, lambda x: 1 + x + x * x / 2, lambda x: 1 + x)


def closed_form(budget: float, reps: int) -> tuple:
    g = np.random.default_rng(1)
    x = g.random(2000)
    p = pilot(np.column_stack([f(x) for f in FUNCTIONS]), (1.0, 0.01, 0.001))
    a = allocation(p, budget)
    mf, mc = [], []
    for _ in range(reps):
        u = g.random(a.m[-1])
        mf.append(estimate([FUNCTIONS[k](u[: a.m[i]]) for i, k in enumerate(a.models)], a, p).value)
        mc.append(float(np.mean(FUNCTIONS[0](g.random(int(budget))))))
    return "closed form (exp, 2 Taylor models)", p, a, float(np.var(mf) / np.var(mc))


def signoff_lost_motion(budget: float, reps: int, n_pilot: int) -> tuple:
    from rvtol.sampling import sample
    from rvtol.study import load_study

    st = load_study(ROOT / "studies" / "rv80e_signoff.toml", analyses=False, progress=False, executor="serial")
    hf = st.model.restricted(["torsion.lost_motion"])
    lf = st.model.restricted(["screening.lost_motion"])
    X = sample(st.spec, n_pilot, "random", 11).values
    times = []
    cols = []
    for m in (hf, lf):
        m.evaluate_with_status(X[:2])
        t0 = time.perf_counter()
        cols.append(m.evaluate_with_status(X)[0][:, 0])
        times.append((time.perf_counter() - t0) / len(X))
    p = pilot(np.column_stack(cols), times)
    a = allocation(p, budget)
    stream = sample(st.spec, reps * (a.m[-1] + int(budget)), "random", 12).values
    mf, mc, at = [], [], 0
    for _ in range(reps):
        U = stream[at: at + a.m[-1]]
        at += a.m[-1]
        ys = [(hf if k == 0 else lf).evaluate_with_status(U[: a.m[i]])[0][:, 0] for i, k in enumerate(a.models)]
        mf.append(estimate(ys, a, p).value)
        mc.append(float(np.mean(hf.evaluate_with_status(stream[at: at + int(budget)])[0][:, 0])))
        at += int(budget)
    return "RV-80E lost motion (20-DOF torsion ← screening)", p, a, float(np.var(mf) / np.var(mc))


def main(size: str) -> None:
    rows = []
    cases = [closed_form(by_size(size, 20.0, 40.0, 40.0), by_size(size, 50, 2000, 4000))]
    if size != "smoke":
        cases.append(signoff_lost_motion(by_size(size, 0, 40.0, 100.0), by_size(size, 0, 10, 30),
                                         by_size(size, 0, 60, 200)))
    for name, p, a, measured in cases:
        rho = ", ".join(f"{r:.3f}" for r in p.rho[1:])
        cost = ", ".join(f"{c:.4f}" for c in p.cost[1:])
        rows.append((name, f"ρ {rho}; cost {cost}", f"models {a.models}, m {a.m}",
                     f"predicted {a.variance_ratio:.3f}, measured {measured:.3f}",
                     f"{1 / a.variance_ratio:.2f}× fewer high-fidelity runs (measured {1 / measured:.2f}×)"))
    print_table(rows, ("case", "pilot", "allocation", "variance MFMC / MC", "gain"))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_size_options(ap)
    main(ap.parse_args().size)
