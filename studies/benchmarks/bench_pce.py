"""PCE Sobol indices of the Sobol' G-function (8 factors, a = 0, 1, 4.5, 9, 99, 99, 99, 99), side by side in one
process: time and the largest error of S1 and ST against the closed form (Sobol' 1993), with the stated bound
(the interval half-width + the surrogate's bias bound 1 − Q²).

* rvtol OMP, BLAS threads as the machine gives them (the code before issue 25);
* rvtol OMP, BLAS limited to one thread inside the PCE (issue 25: the small factorisations of the bootstrap
  and the selection no longer fight over threads);
* the same with OMP's candidate scan in float64 alone (before issue 24's float32 scan; the selection must be the
  same, so the indices are too);
* OpenTURNS functional chaos with LARS and the corrected leave-one-out (``method="lars"``), the candidate set
  capped at degree ``--ot-degree`` (its LARS grows about as P³ on this machine: 229 candidates on 1 024 samples
  took 40 s), so it finishes;
* scikit-learn's ``lars_path`` on the degree-10 candidate set (one path, the selection step only).

    python studies/benchmarks/bench_pce.py [--quick | --smoke] [--n 4096] [--ot-degree 3]
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from _timing import add_size_options, by_size, print_table

from rvtol.sensitivity import surrogate as S
from rvtol.sensitivity.surrogate import fit as surrogate_fit, indices as surrogate_indices

A = np.array([0, 1, 4.5, 9, 99, 99, 99, 99.0])


def g_function(U):
    return np.prod((np.abs(4 * U - 2) + A) / (1 + A), axis=1)


def reference():
    Vi = 1 / (3 * (1 + A) ** 2)
    V = np.prod(1 + Vi) - 1
    return Vi / V, Vi * np.array([np.prod(np.delete(1 + Vi, i)) for i in range(len(A))]) / V


def float64_scan(Psi, Psi32, r, norms, avail):
    """OMP's candidate scan before the float32 one: every correlation in float64."""
    c = np.abs(Psi.T @ r) / norms
    c[~avail] = -1.0
    return int(np.argmax(c))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_size_options(ap)
    ap.add_argument("--n", type=int, default=None, help="samples (default 4096; --quick 1024, --smoke 256)")
    ap.add_argument("--ot-degree", type=int, default=None, help="OpenTURNS' candidate degree cap (default 3; --smoke 2)")
    args = ap.parse_args()
    args.n = args.n or by_size(args.size, 256, 1024, 4096)
    args.ot_degree = args.ot_degree or by_size(args.size, 2, 3, 3)
    rng = np.random.default_rng(20261127)
    U = rng.random((args.n, len(A)))
    y = g_function(U)
    S1, ST = reference()
    rows = []

    def record(name, fn):
        t0 = time.perf_counter()
        r = fn()
        dt = time.perf_counter() - t0
        e1, eT = np.abs(r.S1 - S1).max(), np.abs(r.ST - ST).max()
        bound = r.validation["bias_bound"] + max(r.S1_conf.max(), r.ST_conf.max())
        rows.append((name, f"{dt:.1f} s", f"max |ΔS1| {e1:.4f}, |ΔST| {eT:.4f}; bound {bound:.4f}; "
                                          f"Q² hold-out {r.validation['Q2_holdout']:.4f}; {r.validation['n_terms']} "
                                          f"terms; {'inside' if max(e1, eT) <= bound else 'OUTSIDE'}"))
        return dt

    t_before = record("rvtol OMP, BLAS threads free (before)",
                      lambda: surrogate_indices._pce_indices(U, y, "legendre", holdout=0.2, ci="bootstrap",
                                                             num_resamples=100, confidence=0.95, min_q2=0.95, seed=1))
    t_after = record("rvtol OMP, one BLAS thread (after)", lambda: S.pce_indices(U, y, "legendre", seed=1))
    rows.append(("  ratio before/after", f"{t_before / t_after:.2f}×", "same process, same data"))
    scan = surrogate_fit._most_correlated
    surrogate_fit._most_correlated = float64_scan
    try:
        t64 = record("rvtol OMP, one BLAS thread, float64 scan (before the float32 scan)",
                     lambda: S.pce_indices(U, y, "legendre", seed=1))
    finally:
        surrogate_fit._most_correlated = scan
    rows.append(("  ratio float64 scan / float32 scan", f"{t64 / t_after:.2f}×", "same process, same data"))
    record(f"OpenTURNS LARS, degree ≤ {args.ot_degree}",
           lambda: S.pce_indices(U, y, "legendre", seed=1, method="lars", max_degree=args.ot_degree))
    record(f"rvtol OMP, degree ≤ {args.ot_degree} (the same candidates)",
           lambda: S.pce_indices(U, y, "legendre", seed=1, method="omp", max_degree=args.ot_degree))
    from sklearn.linear_model import lars_path

    G = S.germ(U, ["legendre"] * len(A))
    Psi = S.design_matrix(G, ["legendre"] * len(A), S.multi_indices(len(A), 10, S.Q_NORM))
    t0 = time.perf_counter()
    X = Psi[:, 1:] - Psi[:, 1:].mean(axis=0)
    lars_path(X, y - y.mean(), method="lar", max_iter=400, return_path=False)
    rows.append((f"scikit-learn lars_path, degree 10 ({Psi.shape[1]} candidates), selection only",
                 f"{time.perf_counter() - t0:.1f} s", "one path of 400 steps (the OMP path's length)"))
    print_table(rows, ("G-function, 8 factors, n = %d" % args.n, "time", "accuracy"))


if __name__ == "__main__":
    main()
