"""Global sensitivity at a fraction of the Monte Carlo: Saltelli Sobol vs PCE and given data on the MC samples.

For each case the same process measures, side by side (the machines are shared and noisy):

* **Saltelli** (SALib Sobol, first and total order): its n·(k+2) model runs and its analysis;
* the **Monte Carlo** a study runs anyway (n_MC runs, LHS), then on those samples, with no
  further model run: the **PCE** surrogate (S1, ST, S2, validation, bootstrap intervals),
  the **given-data** first-order indices and **delta** on its default subsample (2 000 rows).

Reported: model runs, wall time, time as a ratio to Saltelli and to the Monte Carlo, and the
agreement of the indices with Saltelli's (share of factors whose difference lies within the
combined interval √(c_a² + c_b²), plus the PCE's bias bound).  Cases:

1. Ishigami (k = 3, cheap): indices also against the closed form;
2. a moderately expensive synthetic reducer model (k = 8, Newton solves over 1 440 positions × 20
   loads per run, ~5 ms): the cost of each route relative to the Monte Carlo;
3. optionally (``--te-samples DIR``) a saved study report: the fits on its ``samples.parquet``,
   compared with the Saltelli indices in its ``summary.json`` (e.g. the TE study, 10 000 runs).

    python studies/benchmarks/bench_gsa.py [--quick | --smoke] [--te-samples reports/transmission_error_rv80e]
"""
from __future__ import annotations

import argparse
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from rvtol import units
from rvtol.mc import evaluate
from rvtol.model import FunctionModel, Model, Quantity
from rvtol.sampling import SampleSet, sample
from rvtol.sensitivity import sobol
from rvtol.sensitivity.given_data import DELTA_DEFAULT_N, delta_given, given_data
from rvtol.sensitivity.surrogate import pce
from rvtol.spec import load_spec, spec_from_table

from _timing import add_size_options, best_of, by_size, print_table


# --------------------------------------------------------------------------- models
def ishigami(X):
    return (np.sin(X[:, 0]) + 7.0 * np.sin(X[:, 1]) ** 2 + 0.1 * X[:, 2] ** 4 * np.sin(X[:, 0]))[:, None]


def ishigami_case():
    spec = spec_from_table({"factor": [{"name": f"x{i + 1}", "unit": "1", "dist": "uniform",
                                        "lower": -math.pi, "upper": math.pi} for i in range(3)]})
    a, b, pi = 7.0, 0.1, math.pi
    V = a**2 / 8 + b * pi**4 / 5 + b**2 * pi**8 / 18 + 0.5
    V1, V2, V13 = 0.5 * (1 + b * pi**4 / 5) ** 2, a**2 / 8, b**2 * pi**8 * (1 / 18 - 1 / 50)
    exact = pd.DataFrame({"S1": np.array([V1, V2, 0.0]) / V, "ST": np.array([V1 + V13, V2, V13]) / V},
                         index=spec.names)
    return FunctionModel(ishigami, spec.names, ["y"]), spec, exact


class SyntheticReducer(Model):
    """A moderately expensive stand-in for a reducer model (k = 8, ~5 ms per run), solved row by row.

    Per run: the error excitation e(θ) = Σ eccentricity components · cos/sin(mθ) over
    ``positions`` angles; at each of ``load_steps`` loads F a stiffening contact
    k·d + 0.02·d³ = F + e(θ) is solved by Newton at every angle (the clearance b softens k);
    the output is the RMS deflection ripple in µm, averaged over the load sweep.  Smooth in its
    inputs, with interactions (the clearance and the cubic term couple the errors).
    """

    def __init__(self, positions: int = 1440, load_steps: int = 20):
        self.inputs = ("ex1", "ey1", "ex2", "ey2", "b", "k_err", "f_err", "r")
        self.input_units = ("mm",) * 8
        self.outputs = (Quantity("defl_rms", "mm", "um"),)
        self.theta = np.linspace(0.0, 2 * np.pi, positions, endpoint=False)
        self.loads = np.linspace(0.5, 3.0, load_steps)[:, None]

    def evaluate(self, X):
        X = self.check_input(X) * 1e3  # µm
        th, out = self.theta, np.empty(len(X))
        c1, s1, c2, s2, c3 = np.cos(th), np.sin(th), np.cos(2 * th), np.sin(2 * th), np.cos(3 * th)
        for i, (ex1, ey1, ex2, ey2, b, ke, fe, r) in enumerate(X):   # one "solve" per run
            e = ex1 * c1 + ey1 * s1 + ex2 * c2 + ey2 * s2 + 0.3 * r * c3
            k = (1.0 + 0.05 * ke) / (1.0 + 0.1 * b)
            rhs = self.loads * (1.0 + 0.05 * fe) + e[None, :]
            d = np.zeros_like(rhs)
            for _ in range(8):  # Newton on k·d + 0.02·d³ = rhs, every load and angle at once
                d -= (k * d + 0.02 * d**3 - rhs) / (k + 0.06 * d**2)
            out[i] = np.mean(np.sqrt(np.mean((d - d.mean(axis=1, keepdims=True)) ** 2, axis=1)))
        return out[:, None] * 1e-3


def synthetic_case():
    spec = spec_from_table({"factor": [
        {"name": "ex1", "unit": "um", "dist": "normal", "mean": 0.0, "tolerance": 6.0},
        {"name": "ey1", "unit": "um", "dist": "normal", "mean": 0.0, "tolerance": 6.0},
        {"name": "ex2", "unit": "um", "dist": "normal", "mean": 0.0, "tolerance": 3.0},
        {"name": "ey2", "unit": "um", "dist": "normal", "mean": 0.0, "tolerance": 3.0},
        {"name": "b", "unit": "um", "dist": "truncnorm", "mean": 3.0, "tolerance": 2.0},
        {"name": "k_err", "unit": "um", "dist": "uniform", "lower": -2.0, "upper": 2.0},
        {"name": "f_err", "unit": "um", "dist": "triangular", "lower": -3.0, "upper": 3.0},
        {"name": "r", "unit": "um", "dist": "rayleigh", "tolerance": 4.0}]})
    return SyntheticReducer(), spec


# --------------------------------------------------------------------------- helpers
def agreement(a: pd.DataFrame, b: pd.DataFrame, col: str, extra: float = 0.0) -> str:
    """Share of factors whose two estimates differ by at most √(c_a² + c_b²) (+ extra)."""
    ok = np.abs(a[col] - b[col]) <= np.hypot(a[f"{col}_conf"], b[f"{col}_conf"]) + extra
    return f"{int(ok.sum())}/{len(ok)}"


def display_Y(model, X):
    ev = evaluate(model, X, progress=False)
    return np.column_stack([q.to_display(ev.Y[:, j]) for j, q in enumerate(model.outputs)])


def run_case(name, model, spec, n_base, n_mc, exact=None, delta_too=True):
    """Rows for one model: Saltelli, the MC, then PCE / given data / delta on the MC samples.

    With ``exact`` (a cheap analytic function) the costs are compared with Saltelli only (the
    Monte Carlo of a closed form costs nothing) and the indices with the closed form.
    """
    rows = []
    of_mc = (lambda t: "") if exact is not None else (lambda t: f", {t / t_mc:.1%} of the MC")
    k = len(spec)
    t_sal, sal = best_of(lambda: sobol(model, spec, n=n_base, second_order=False, seed=1), repeat=1)
    s = sample(spec, n_mc, "lhs", 2)
    t_mc, Y = best_of(lambda: display_Y(model, s.values), repeat=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t_pce, p = best_of(lambda: pce(model, spec, s, Y, seed=3, on_poor_fit="warn"), repeat=1)
    t_gd, g = best_of(lambda: given_data(model, spec, s, Y, seed=4), repeat=1)
    v = p.validation.iloc[0]
    sf, pf, gf = (r.frame.set_index("factor") for r in (sal, p, g))
    n_sal = sal.n_evaluations
    rows.append((f"{name}: Saltelli Sobol, n = {n_base} (k = {k})", f"{n_sal} runs",
                 f"{t_sal:.2f} s = 1 (reference)" + ("" if exact is not None else f"; {t_sal / t_mc:.0%} of the MC")))
    rows.append((f"{name}: Monte Carlo (done anyway)", f"{n_mc} runs",
                 f"{t_mc:.2f} s; runs {n_mc / n_sal:.2f}× Saltelli's"))
    rows.append((f"{name}: PCE on the MC samples", "0 runs",
                 f"{t_pce:.2f} s = {t_pce / t_sal:.3f}× Saltelli{of_mc(t_pce)}; "
                 f"Q² LOO {v['Q2_loo']:.4f}, hold-out {v['Q2_holdout']:.4f}, {v['n_terms']} terms, "
                 f"{'reliable' if v['reliable'] else 'NOT reliable (withheld by default)'}"))
    rows.append((f"{name}: given-data S1 on the MC samples", "0 runs",
                 f"{t_gd:.2f} s = {t_gd / t_sal:.3f}× Saltelli{of_mc(t_gd)}"))
    if delta_too:
        t_d, _ = best_of(lambda: delta_given(model, spec, s, Y, seed=5), repeat=1)
        rows.append((f"{name}: delta on a subsample of min(n, {DELTA_DEFAULT_N})", "0 runs",
                     f"{t_d:.2f} s = {t_d / t_sal:.3f}× Saltelli{of_mc(t_d)}"))
    b = v["bias_bound"]
    rows.append((f"{name}: agreement with Saltelli (within √(c²+c²))", "",
                 f"PCE S1 {agreement(pf, sf, 'S1', b)}, ST {agreement(pf, sf, 'ST', b)}; "
                 f"given-data S1 {agreement(gf, sf, 'S1')}; interval half-widths max: Saltelli "
                 f"{sf[['S1_conf', 'ST_conf']].max().max():.3f}, PCE {pf[['S1_conf', 'ST_conf']].max().max():.4f}, "
                 f"given data {gf['S1_conf'].max():.3f}"))
    if exact is not None:
        err = lambda f, c: float(np.max(np.abs(f[c] - exact[c])))  # noqa: E731
        rows.append((f"{name}: max |index − closed form|", "",
                     f"Saltelli S1 {err(sf, 'S1'):.4f} ST {err(sf, 'ST'):.4f}; PCE S1 {err(pf, 'S1'):.5f} "
                     f"ST {err(pf, 'ST'):.5f}; given data S1 {err(gf, 'S1'):.4f}"))
    return rows


def study_case(folder: Path, output: str, spec_path: Path):
    """Fits on a saved study's Monte Carlo sample, against the Saltelli indices in its summary."""
    spec = load_spec(spec_path)
    d = pd.read_parquet(folder / "samples.parquet")
    cols = {c.split(" [")[0]: c for c in d.columns}
    X = np.column_stack([units.to_base(d[cols[f.name]].to_numpy(), f.unit) for f in spec.factors])
    s = SampleSet(X, spec.names, spec.units, "given", None)
    ycol = cols[output]
    Y = d[[ycol]].to_numpy()
    unit = ycol.split("[")[1].rstrip("]")
    model = FunctionModel(lambda X: np.full((len(X), 1), np.nan), spec.names, [Quantity(output, unit)],
                          input_units=[units.base_unit(u) for u in spec.units])
    summ = json.loads((folder / "summary.json").read_text())["analyses"]
    sal = next(v for v in summ.values() if isinstance(v, dict) and v.get("method") == "sobol")
    sf = pd.DataFrame(sal["indices"]).query("output == @output").set_index("factor")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t_pce, p = best_of(lambda: pce(model, spec, s, Y, seed=3, on_poor_fit="warn"), repeat=1)
    t_gd, g = best_of(lambda: given_data(model, spec, s, Y, seed=4), repeat=1)
    t_d, _ = best_of(lambda: delta_given(model, spec, s, Y, seed=5), repeat=1)
    v = p.validation.iloc[0]
    pf, gf = p.frame.set_index("factor"), g.frame.set_index("factor")
    name = folder.name
    return [
        (f"{name}: saved Monte Carlo / Saltelli runs", f"{len(d)} / {sal['n_evaluations']}", "runs already made"),
        (f"{name}: PCE on the MC samples", "0 runs",
         f"{t_pce:.1f} s; Q² LOO {v['Q2_loo']:.3f}, hold-out {v['Q2_holdout']:.3f}, {v['n_terms']} terms: "
         f"{'reliable' if v['reliable'] else 'NOT reliable (withheld by default)'}"),
        (f"{name}: given-data S1", "0 runs",
         f"{t_gd:.1f} s; agrees with Saltelli S1 for {agreement(gf, sf, 'S1')} factors; half-widths "
         f"≤ {gf['S1_conf'].max():.3f} (Saltelli ≤ {sf['S1_conf'].max():.3f})"),
        (f"{name}: delta on {DELTA_DEFAULT_N} of the samples", "0 runs", f"{t_d:.1f} s (serial)"),
        (f"{name}: PCE vs Saltelli (with bias bound {v['bias_bound']:.2f})", "",
         f"S1 {agreement(pf, sf, 'S1', v['bias_bound'])}, ST {agreement(pf, sf, 'ST', v['bias_bound'])}"),
    ]


def main(size: str = "full", te: str | None = None, te_output: str = "te_pp", te_spec: str | None = None) -> None:
    rows = []
    model, spec, exact = ishigami_case()
    n = by_size(size, 128, 512, 1024)
    rows += run_case("Ishigami", model, spec, n_base=n, n_mc=n, exact=exact, delta_too=size == "full")
    model, spec = synthetic_case()
    rows += run_case("synthetic reducer", model, spec, n_base=by_size(size, 16, 128, 256),
                     n_mc=by_size(size, 128, 1000, 2000))
    if te:
        folder = Path(te)
        rows += study_case(folder, te_output, Path(te_spec or "data/specs/rv80e_te.toml"))
    print_table(rows, ("measure", "model runs", "time and ratios"))


if __name__ == "__main__":
    from threadpoolctl import threadpool_limits

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_size_options(ap)
    ap.add_argument("--te-samples", metavar="DIR", help="a saved study report folder (samples.parquet, summary.json)")
    ap.add_argument("--te-output", default="te_pp", help="output to analyse in that report (default te_pp)")
    ap.add_argument("--te-spec", help="the study's spec file (default data/specs/rv80e_te.toml)")
    a = ap.parse_args()
    with threadpool_limits(1):  # one BLAS thread, as in the executor's workers
        main(a.size, a.te_samples, a.te_output, a.te_spec)
