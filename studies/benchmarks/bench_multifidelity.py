"""Multi-fidelity Monte Carlo (rvtol.multifidelity) against plain Monte Carlo at equal interval width (issue 40 item 3).

Cases, each run side by side in one process:

* **closed form** — f₁ = exp(x), f₂ = 1 + x + x²/2, f₃ = 1 + x on x ~ U(0, 1), costs 1 : 0.01 : 0.001 (the
  estimator's own test case): the empirical variance of both estimators over R replications at one budget;
* **the RV-80E sign-off** (studies/rv80e_signoff.toml) — high fidelity: the 20-DOF outputs the sign-off judges,
  ``reducer.lost_motion`` (torsion curve + first-stage play) and ``te.te_pp``, each on the stages that reach it
  (``CompositeModel.restricted``).  Low fidelity: a ridge surrogate (``fit_surrogate``) trained on ``n_train``
  independent 20-DOF runs, on cheap features the same composition computes without the 20-DOF solver —
  lost motion: the outputs of its two cheap stages, ``pin_ring`` (the discs' rigid fit in the pin ring: margin and
  tightest clearance) and ``screening`` (doc 001: lost motion and its three stages); TE: the 20-DOF model's own
  inputs as built (``stage_inputs("te")``: stack-up, mapping and build, no solve).  The lost motion a second time
  with the same composition's torsion curve solved without friction between the two (:func:`frictionless`: run on
  the training inputs too, for the pilot).  Per output and statistic (mean, standard deviation, a yield) the
  allocation that matches the interval plain Monte Carlo gets from the sign-off's n = 1500 runs, the estimation
  run on fresh inputs, and its measured interval: the plain runs that interval needs (σ̂²/se², σ̂² from every
  20-DOF run made) against what MFMC spent in 20-DOF runs, its training and every model's runs by their measured
  cost.  An estimation that would cost more than ``max_cost`` 20-DOF runs (or where the allocation drops the
  surrogate: MFMC is then plain Monte Carlo plus the wasted training) is not run; its row gives the prediction.
  The correlations are measured twice: on the training runs (the surrogate's out of fold) and on fresh runs.
* ``--full`` adds the first-order Taylor model from the five-point derivatives at the nominal (the sign-off's
  sensitivity_matrix computes them, 4·276 + 1 runs, so in a sign-off run they are already paid): its correlation
  with each output on 100 runs it has not seen.

The yields are at limits inside the distributions (lost motion ≤ 0.6′, TE ≤ 20″, each ≈ 0.9): at the sign-off's
limits (1′, 60″) a few hundred runs see no failure and the yield is a tail question (bench_tail.py).  Timings are
per run on one core; the machine's load average is printed before and after.

    PYTHONPATH=.:studies/reproduction python studies/benchmarks/bench_multifidelity.py [--quick | --smoke]
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from _timing import add_size_options, by_size, print_table  # noqa: E402
from rvtol.multifidelity import (allocation, estimate, fit_surrogate, fluctuation,  # noqa: E402
                                 for_plain_runs, inside, pilot)

FUNCTIONS = (np.exp, lambda x: 1 + x + x * x / 2, lambda x: 1 + x)
#: the sign-off's Monte Carlo size: MFMC is asked for the interval plain Monte Carlo gets from it
SIGNOFF_N = 1500
#: output, its yield's upper limit (display unit), the stages whose outputs are the lost motion's features
LOST_MOTION = ("reducer.lost_motion", 0.6)
TE = ("te.te_pp", 20.0)
CHEAP_STAGES = ("pin_ring", "screening")
#: at least this many 20-DOF runs in an estimation: its interval's variance is estimated from them
MIN_HIGH = 10


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
    rho = ", ".join(f"{r:.3f}" for r in p.rho[1:])
    cost = ", ".join(f"{c:.4f}" for c in p.cost[1:])
    measured = float(np.var(mf) / np.var(mc))
    return ("closed form (exp, 2 Taylor models)", f"ρ {rho}; cost {cost}", f"models {a.models}, m {a.m}",
            f"predicted {a.variance_ratio:.3f}, measured {measured:.3f}",
            f"{1 / a.variance_ratio:.2f}× fewer high-fidelity runs (measured {1 / measured:.2f}×)")


class SignOff:
    """The RV-80E sign-off's model: its outputs (the high fidelity), the same composition with a frictionless torsion
    curve, and the cheap features."""

    def __init__(self):
        from rvtol.study import load_study

        self.study = load_study(ROOT / "studies" / "rv80e_signoff.toml", analyses=False, progress=False,
                                executor="serial")
        model = self.study.model
        self._cheap = model.restricted([o.name for o in model.outputs if o.name.split(".")[0] in CHEAP_STAGES])
        self.features = {LOST_MOTION[0]: self._cheap.evaluate, TE[0]: lambda X: model.stage_inputs("te", X)}
        self.frictionless = frictionless(model)

    def inputs(self, n: int, seed: int) -> np.ndarray:
        from rvtol.sampling import sample

        return sample(self.study.spec, n, "random", seed).values

    def run(self, output: str, X: np.ndarray, friction: bool = True) -> np.ndarray:
        """The output in its display unit on the rows of X; a failed row stops the benchmark (dropping it would
        break the nested samples)."""
        m = (self.study.model if friction else self.frictionless).restricted([output])
        Y, status = m.evaluate_with_status(X)
        if np.any(status != 0):
            raise RuntimeError(f"{output}: {int(np.sum(status != 0))} failed runs")
        return np.asarray(m.output(output).to_display(Y[:, 0]), dtype=float)


def frictionless(model):
    """``model`` with its torsion curves solved without the design's Coulomb friction: the lost motion reads the
    mid-points of the loop, where friction cancels to first order (rvtol.models.torsion_curve.model), at a third of the
    cost — a low fidelity of the same quantity from the 20-DOF model itself."""
    from dataclasses import replace

    from rvtol.models.composite.model import CompositeModel
    from rvtol.models.torsion_curve.model import TorsionCurveModel

    def without(m):
        return TorsionCurveModel(m.geometry, m.inputs, percent=m.percent, points=m.points, torque=m.torque,
                                 harmonic=m.factors.harmonic, friction=False, **m.solver_options)

    stages = [replace(st, model=without(st.model)) if st.kind == "torsion_curve" else st for st in model.stages]
    return CompositeModel(model.inputs, model.input_units, list(model.quantities), stages, model.build,
                          model.build_outputs, model.constants)


def timed(f, *args, **kw):
    """(f's result, seconds it took)."""
    t0 = time.perf_counter()
    out = f(*args, **kw)
    return out, time.perf_counter() - t0


def signoff_case(so: SignOff, output: str, upper: float, with_frictionless: bool, n_plain: int, n_train: int,
                 n_check: int, max_cost: int, seeds: tuple[int, int]) -> list:
    """The rows of one output: per statistic the correlations, the allocation for plain Monte Carlo's interval with
    ``n_plain`` runs and — where it costs at most ``max_cost`` 20-DOF runs — the estimate, its measured interval and
    the 20-DOF cost against plain Monte Carlo's for that interval, training and pilot included."""
    features = so.features[output]
    X = so.inputs(n_train, seeds[0])
    so.run(output, X[:2]), features(X[:2])           # compiled kernels loaded before the clock starts
    y, t_hf = timed(so.run, output, X)
    F, t_lf = timed(features, X)
    s = fit_surrogate(F, y, folds=min(10, n_train // 2))
    names, costs = ["20-DOF", "surrogate"], [1.0, t_lf / t_hf]
    runs = [lambda U: so.run(output, U), lambda U: s.predict(features(U))]
    others = ()
    if with_frictionless:
        so.run(output, X[:2], friction=False)
        y_nf, t_nf = timed(so.run, output, X, friction=False)
        others = ((y_nf, t_nf / t_hf),)
        names.insert(1, "frictionless")
        costs.insert(1, t_nf / t_hf)
        runs.insert(1, lambda U: so.run(output, U, friction=False))
    fixed = n_train * sum(costs)                      # the training runs (the pilot's) of every model
    unit = "′" if "lost_motion" in output else "″"
    plans = []
    for label, statistic, limits in (("mean", "mean", None), ("std", "variance", None),
                                     (f"yield ≤ {upper:g}{unit}", "mean", (-math.inf, upper))):
        try:
            p = s.pilot(costs[-1], statistic, limits, others)
        except ValueError as e:                       # a yield the training runs never miss
            plans.append((label, statistic, limits, None, str(e)))
            continue
        plans.append((label, statistic, limits, p, for_plain_runs(p, n_plain, MIN_HIGH)))
    run = [a for *_, p, a in plans if p is not None and len(a.models) > 1 and _cost(a, costs) <= max_cost]
    m = [max([a.m[a.models.index(k)] for a in run if k in a.models] + [n_check]) for k in range(len(runs))]
    U = so.inputs(max(m), seeds[1])                   # fresh inputs: nested prefixes of one stream
    out = [f(U[:mk]) for f, mk in zip(runs, m)]
    timing = ", ".join(f"{n} {1e3 * c * t_hf / n_train:.1f} ms" for n, c in zip(names, costs))
    rows = [(f"{output}: {timing} per run; training {n_train} runs", "", "", "", "", "")]
    for label, statistic, limits, p, a in plans:
        if p is None:
            rows.append((f"  {label}", "—", "—", f"not estimated: {a}", "—", "—"))
            continue
        quantities = [_quantity(v, limits, k == len(runs) - 1, s) for k, v in enumerate(out)]
        fresh = pilot(np.column_stack([q[: min(m)] for q in quantities]), costs, statistic).rho[1:]
        rho = " / ".join(f"{names[k]} {_r(p.rho[k])}, {_r(fresh[k - 1])}" for k in range(1, len(runs)))
        spent = fixed + _cost(a, costs)
        allotted = ", ".join(f"{names[k]} {a.m[i]}" for i, k in enumerate(a.models))
        allotted += "".join(f" ({names[k]} dropped: {why})" for k, why in a.dropped)
        predicted = f"predicted {n_plain / spent:.2f}×, {1 / a.variance_ratio:.2f}× as n → ∞"
        if a not in run:
            why = "plain Monte Carlo" if len(a.models) == 1 else f"costs {_cost(a, costs):.0f} > {max_cost}: not run"
            rows.append((f"  {label}", rho, f"{allotted} — {why}", "—", f"{n_plain} / {spent:.0f}", predicted))
            continue
        e = estimate([quantities[k][: a.m[i]] for i, k in enumerate(a.models)], a, statistic=statistic)
        # plain Monte Carlo's runs for this se: σ² of the statistic's quantity from every 20-DOF run made (training
        # and estimation: the m₁ alone can be few)
        made = np.concatenate([_quantity(y, limits, False, s), quantities[0][: a.m[0]]])
        plain = float(np.var(fluctuation(made, statistic), ddof=1)) / e.se ** 2
        e = e.square_root() if statistic == "variance" else e
        same = _plain_half_width(quantities[0][: a.m[0]], statistic)
        shown = f"{e.value:.4g} ± {1.96 * e.se:.2g} (plain, same {a.m[0]} runs: ± {same:.2g})"
        rows.append((f"  {label}", rho, allotted, shown, f"{plain:.0f} / {spent:.0f}", f"{plain / spent:.2f}× ({predicted})"))
    return rows


def _r(rho: float) -> str:
    """A correlation to 3 decimals, or 5 where it is that close to 1."""
    return f"{rho:.5f}" if abs(rho) > 0.999 else f"{rho:.3f}"


def _cost(a, costs) -> float:
    """The estimation's cost in high-fidelity runs."""
    return float(sum(costs[k] * mk for k, mk in zip(a.models, a.m)))


def _quantity(values, limits, surrogate: bool, s):
    """What the statistic averages: the runs, or within the yield's limits the indicator (the surrogate's chance)."""
    if limits is None:
        return values
    return s.within(values, *limits) if surrogate else inside(values, *limits)


def _plain_half_width(y, statistic) -> float:
    """95 % half-width of plain Monte Carlo on the runs ``y`` (the standard deviation's by the delta method)."""
    se = float(np.std(fluctuation(y, statistic), ddof=1)) / math.sqrt(len(y))
    return 1.96 * (se / (2.0 * float(np.std(y, ddof=1))) if statistic == "variance" else se)


def taylor_rows(so: SignOff, seeds: int, n: int) -> list:
    """The first-order Taylor model from the five-point derivatives at the nominal: its correlation with each output
    on ``n`` runs it has not seen."""
    from rvtol.sensitivity.local import five_point

    spec, model = so.study.spec, so.study.model
    outputs = [LOST_MOTION[0], TE[0]]
    (res, t) = timed(five_point, model.restricted(outputs), spec)
    X = so.inputs(n, seeds)
    x0 = spec.nominal_base()
    rows = []
    for o in outputs:
        grad = np.nan_to_num(res.gradient(o, [f.name for f in spec.factors]))
        y = so.run(o, X)
        rho = float(np.corrcoef(y, (X - x0) @ grad)[0, 1])
        rows.append((f"{o}: first order at the nominal ({4 * len(x0) + 1} runs, {t:.0f} s)", f"{rho:.3f}",
                     f"{1 / (1 - rho ** 2):.2f}× at most (1/(1 − ρ²), were it free)"))
    return rows


def main(size: str) -> None:
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    rows = [closed_form(by_size(size, 20.0, 40.0, 40.0), by_size(size, 50, 2000, 4000))]
    print_table(rows, ("case", "pilot", "allocation", "variance MFMC / MC", "gain"))
    so = SignOff()
    n_plain = by_size(size, 60, SIGNOFF_N, SIGNOFF_N)
    sizes = {"n_plain": n_plain, "n_train": by_size(size, 10, 50, 50), "n_check": by_size(size, 5, 40, 100),
             "max_cost": by_size(size, 43, 800, 800)}
    rows = []
    for (output, upper), friction, seeds in ((LOST_MOTION, False, (21, 22)), (LOST_MOTION, True, (21, 22)),
                                             (TE, False, (31, 32))):
        rows += signoff_case(so, output, upper, friction, seeds=seeds, **sizes)
    print(f"\nRV-80E sign-off: MFMC for the interval plain Monte Carlo gets from n = {n_plain} (95 %); ρ of each low "
          "fidelity with the 20-DOF (the statistic's quantity: runs, centred squares, indicator), on the training runs "
          "(the surrogate out of fold), then on fresh runs; cost in 20-DOF runs, training and pilot included")
    print_table(rows, ("output: statistic", "ρ", "runs", "estimate ± 95 %", "cost: plain / MFMC",
                       "gain at equal width"))
    if size == "full":
        print()
        print_table(taylor_rows(so, 41, 100), ("Taylor model (derivatives already paid in a sign-off run)", "ρ",
                                                  "gain"))
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_size_options(ap)
    main(ap.parse_args().size)
