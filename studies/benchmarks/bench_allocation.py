"""Adjustment and allocation benchmark: the fast paths against the straightforward ones.

Measured side by side in one process (shared, noisy machines), reported as ratios:

1. the Monte Carlo constraint's candidate sampling: affine rescaling of one fixed design
   (``MonteCarloConstraint.samples``) against the spine path ``spec.scaled`` + ``to_factors``
   (re-freezing every scipy distribution per candidate);
2. the adjusted assembly's row-by-row products: ``np.einsum`` against broadcast-multiply-and-sum,
   and the model's closed-loop linear map against the step-by-step simulation (Kalman + LQR);
3. one GA generation on the BX40E 3-D problem (40 candidates × n samples) and where its time goes.

    python studies/benchmarks/bench_allocation.py [--quick | --smoke]
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from rvtol.models.adjustment import AdjustedAssemblyModel, load_assembly
from rvtol.allocation.cost import load_costs
from rvtol.allocation.problem import AllocationProblem, MonteCarloConstraint, expand_requirements
from rvtol.sampling import rng, to_factors
from rvtol.spec import Requirement, load_spec

from _timing import add_size_options, best_time, by_size, print_table

ROOT = Path(__file__).resolve().parents[2]




def problem() -> AllocationProblem:
    spec = load_spec(ROOT / "data/specs/bx40e_assembly_3d.toml")
    model = AdjustedAssemblyModel(load_assembly(ROOT / "data/assemblies/bx40e_3d.toml"), spec.names)
    curve = load_costs(ROOT / "data/costs/bx40e_angular.toml")["ground_axis"]
    names = [n for n in spec.names if n.startswith("dtheta")]
    reqs = expand_requirements([Requirement("delta_*", -1.0, 1.0, "arcmin", min_cpk=1.0)], model)
    return AllocationProblem(model, spec, names, [curve] * len(names), reqs)


def main(size: str = "full") -> None:
    n = by_size(size, 20, 1000, 4000)
    p = problem()
    mc = MonteCarloConstraint(p, n, "lhs", 1)
    T = p.t0 * rng(2).uniform(0.05, 0.5, size=(40, len(p.factors)))
    rows = []
    t_fast = best_time(lambda: [mc.samples(t) for t in T])
    t_spine = best_time(lambda: [to_factors(p.spec_at(t), mc.U) for t in T])
    err = max(np.max(np.abs(mc.samples(t) - to_factors(p.spec_at(t), mc.U))) for t in T[:3])
    rows.append(("candidate samples, 40 × n (affine vs spec.scaled + to_factors)",
                 f"{t_fast * 1e3:.1f} ms vs {t_spine * 1e3:.1f} ms", f"{t_spine / t_fast:.1f}× faster, max diff {err:.1e}"))

    X = rng(3).normal(size=(40 * n, 12))
    M = rng(4).normal(size=(12, 12))
    t_es = best_time(lambda: np.einsum("nc,rc->nr", X, M))
    t_bc = best_time(lambda: (X[:, None, :] * M[None]).sum(-1))
    rows.append((f"row-by-row products, {40 * n} rows × 12×12 (einsum vs broadcast-sum)",
                 f"{t_es * 1e3:.1f} ms vs {t_bc * 1e3:.1f} ms", f"{t_bc / t_es:.1f}× faster"))

    Xs = np.vstack([mc.samples(t) for t in T])
    t_model = best_time(lambda: p.model.evaluate(Xs))
    t_sim = best_time(lambda: p.model.simulate(Xs))
    rows.append((f"adjusted assembly, {len(Xs)} rows (closed-loop map vs step-by-step simulate)",
                 f"{t_model * 1e3:.0f} ms vs {t_sim * 1e3:.0f} ms", f"{t_sim / t_model:.1f}× faster"))
    t_gen = best_time(lambda: mc.violation(T), repeat=2)
    rows.append((f"one GA generation (40 candidates × n = {n}): model share",
                 f"{t_model * 1e3:.0f} ms of {t_gen * 1e3:.0f} ms", f"{100 * t_model / t_gen:.0f} % in the model"))
    print_table(rows)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_size_options(ap)
    main(ap.parse_args().size)
