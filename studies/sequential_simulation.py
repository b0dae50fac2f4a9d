"""Sequential sign-off by simulation: the wrong-PASS rate under repeated looks and the samples a decision costs.

Many simulated runs of one yield requirement (0.9973 at 95 % one-sided, α = 0.05), each drawing batches of
``BATCH`` samples up to ``MAX_N`` and looking after every batch, under three rules:

* **sequential** — rvtol's anytime-valid rule (:mod:`rvtol.sequential`): PASS when the mixture evidence for
  yield > 0.9973 reaches 1/α, FAIL when the evidence for a non-conforming share > 0.0027 does;
* **naive** — stop the first time the fixed-n Clopper–Pearson bound crosses (PASS when the lower bound ≥ 0.9973,
  FAIL when the upper bound < 0.9973), i.e. the fixed-n verdict looked at after every batch;
* **fixed n** — one look at a planned n: the n at which the fixed-n rule passes with 90 % probability at that
  true yield (found by the exact binomial power), and rvtol's ``n_to_demonstrate`` (the n whose bound would reach
  the requirement if the estimate held exactly: a coin-flip plan, ≈ 50 % power).

Writes ``studies/figures/sequential_error_rate.png``, ``studies/figures/sequential_sample_size.png`` and prints the
tables of ``studies/sequential.md``.  Run: ``PYTHONPATH=. python studies/sequential_simulation.py`` (≈ 1 min).
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
from scipy import stats

from rvtol import sequential as sq
from rvtol.stats import n_for_yield

P0, ALPHA, BATCH, MAX_N, RUNS, SEED = 0.9973, 0.05, 500, 100_000, 4000, 20261129
TUNE_N = 1500            # the study's n that the mixture is tuned to (the main sign-off's n)
YIELDS = (0.995, 0.9973, 0.9985, 0.999, 0.9995, 0.99999)
FIG = Path(__file__).resolve().parent / "figures"


def per_pair(f, s, n):
    """``f(s, n)`` on the distinct (successes, n) pairs only."""
    s, n = np.broadcast_arrays(s, n)
    pairs, back = np.unique(np.stack([s.ravel(), n.ravel()]), axis=1, return_inverse=True)
    return f(pairs[0], pairs[1])[back.ravel()].reshape(s.shape)


def cumulative(p, runs, looks, seed):
    g = np.random.default_rng(seed)
    return np.cumsum(g.binomial(BATCH, p, size=(runs, looks)), axis=1), BATCH * np.arange(1, looks + 1)


def decisions(s, n, tune_n=TUNE_N):
    """(passes, fails) at every look of every run, for the sequential and the naive rule."""
    seq_pass = per_pair(lambda k, m: sq.evidence_reached(k, m, P0, ALPHA, tune_n), s, n)
    seq_fail = per_pair(lambda k, m: sq.evidence_reached(m - k, m, 1 - P0, ALPHA, tune_n), s, n)
    cp_lo = per_pair(lambda k, m: np.where(k > 0, stats.beta.ppf(ALPHA, k, m - k + 1), 0.0), s, n)
    cp_hi = per_pair(lambda k, m: np.where(k < m, stats.beta.ppf(1 - ALPHA, k + 1, m - k), 1.0), s, n)
    return (seq_pass, seq_fail), (cp_lo >= P0, cp_hi < P0)


def first_stop(passes, fails):
    """Per run: the look (0-based) it stops at (the last one when it never decides) and its outcome."""
    decided = passes | fails
    any_ = decided.any(axis=1)
    at = np.where(any_, decided.argmax(axis=1), decided.shape[1] - 1)
    rows = np.arange(len(at))
    outcome = np.where(~any_, "undecided", np.where(passes[rows, at], "PASS", "FAIL"))
    return at, outcome


def fixed_n_for_power(p, power=0.9, step=BATCH):
    """The smallest n (a multiple of ``step``) at which the one-look Clopper–Pearson rule passes with probability
    ``power`` at the true yield ``p`` (exact binomial), or None beyond 2·10⁶."""
    for n in range(step, 2_000_001, step):
        k = n - np.arange(0, n // 50 + 2)                    # conforming counts, from n down
        ok = np.where(k > 0, stats.beta.ppf(ALPHA, np.maximum(k, 1), n - k + 1), 0.0) >= P0
        if not ok[0]:
            continue
        k_min = k[ok].min()                                   # the fewest conforming that still pass
        if stats.binom.sf(k_min - 1, n, p) >= power:
            return n
    return None


def main() -> int:
    looks = MAX_N // BATCH
    rows, error_curve = [], {}
    for i, p in enumerate(YIELDS):
        s, n = cumulative(p, RUNS, looks, SEED + i)
        (sp, sf), (npass, nfail) = decisions(s, n)
        row = {"p": p}
        for name, (a, b) in (("sequential", (sp, sf)), ("naive", (npass, nfail))):
            at, out = first_stop(a, b)
            used = n[at]
            row[name] = {"pass": (out == "PASS").mean(), "fail": (out == "FAIL").mean(),
                         "undecided": (out == "undecided").mean(), "mean_n": used.mean(),
                         "median_n": float(np.median(used)), "p90_n": float(np.quantile(used, 0.9))}
        row["fixed_90"] = fixed_n_for_power(p) if p > P0 else None
        row["fixed_estimate"] = n_for_yield(p, P0, 1 - ALPHA) if p > P0 else None
        rows.append(row)
        if p == P0:           # the wrong-PASS rate within the first K looks
            for K in (1, 2, 5, 10, 20, 50, 100, 200):
                error_curve[K] = (sp[:, :K].any(axis=1).mean(), npass[:, :K].any(axis=1).mean())
    mc = 3 * math.sqrt(ALPHA * (1 - ALPHA) / RUNS)
    print(f"yield requirement {P0} at {1 - ALPHA:.0%} one-sided; batches of {BATCH} to {MAX_N}, {RUNS} runs per "
          f"true yield; mixture tuned to n = {TUNE_N}; 3 Monte Carlo standard errors at alpha: ±{mc:.4f}\n")
    print("wrong PASS at the true yield 0.9973 within the first K looks (K batches of 500):")
    print("| looks K | sequential | naive (fixed-n bound at every look) |\n|---:|---:|---:|")
    for K, (a, b) in error_curve.items():
        print(f"| {K} | {a:.4f} | {b:.4f} |")
    print("\n| true yield | rule | P(PASS) | P(FAIL) | P(undecided at 100 000) | mean n | median n | 90 % n |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        for name in ("sequential", "naive"):
            d = r[name]
            print(f"| {r['p']} | {name} | {d['pass']:.4f} | {d['fail']:.4f} | {d['undecided']:.4f} | "
                  f"{d['mean_n']:,.0f} | {d['median_n']:,.0f} | {d['p90_n']:,.0f} |")
    print("\n| true yield | fixed n, 90 % power | rvtol's n_to_demonstrate (estimate held: ≈ 50 % power) |")
    print("|---:|---:|---:|")
    for r in rows:
        if r["fixed_90"] is not None or r["fixed_estimate"] is not None:
            print(f"| {r['p']} | {r['fixed_90'] or '> 2 000 000':,} | {r['fixed_estimate']:,} |")
    tune = {}
    s, n = cumulative(0.999, RUNS, looks, SEED + 99)
    for t in (500, 1500, 5000, 20000):
        (sp, sf), _ = decisions(s, n, t)
        at, out = first_stop(sp, sf)
        tune[t] = (n[at].mean(), (out == "PASS").mean())
    print("\nthe mixture's tuning at the true yield 0.999: | tune_n | mean n | P(PASS) |")
    for t, (m, pp) in tune.items():
        print(f"| {t} | {m:,.0f} | {pp:.4f} |")
    _figures(error_curve, rows, mc)
    return 0


def _figures(error_curve, rows, mc):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    FIG.mkdir(exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 3.6))
    K = list(error_curve)
    ax.plot(K, [error_curve[k][1] for k in K], "o-", label="naive: stop when the fixed-n bound crosses")
    ax.plot(K, [error_curve[k][0] for k in K], "s-", label="sequential (rvtol): anytime-valid evidence")
    ax.axhline(ALPHA, color="k", lw=0.8)
    ax.axhspan(ALPHA - mc, ALPHA + mc, color="0.85", label="α = 0.05 ± 3 Monte Carlo SE")
    ax.set_xscale("log")
    ax.set_xlabel("looks (one after every 500 samples)")
    ax.set_ylabel("wrong PASS rate at yield = 0.9973")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(FIG / "sequential_error_rate.png", dpi=120)
    fig, ax = plt.subplots(figsize=(6, 3.6))
    good = [r for r in rows if r["p"] > P0]
    x = [1 - r["p"] for r in good]
    ax.plot(x, [r["sequential"]["mean_n"] for r in good], "s-", label="sequential: mean n at the stop")
    ax.plot(x, [r["fixed_90"] for r in good], "o--", label="fixed n with 90 % power")
    ax.plot(x, [r["fixed_estimate"] for r in good], "^:", label="rvtol's n_to_demonstrate (≈ 50 % power)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("true non-conforming share 1 − yield (requirement: 0.0027)")
    ax.set_ylabel("samples")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(FIG / "sequential_sample_size.png", dpi=120)


if __name__ == "__main__":
    sys.exit(main())
