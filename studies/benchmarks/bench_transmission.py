"""Transmission-error model benchmark: the 20-DOF solver before and after issue 15, numba vs NumPy, MC throughput.

Measured side by side in one process (the machine is shared and noisy: ratios are what counts, absolute
times are indicative; CPU time, best of several interleaved runs).  "Before" is the kernels of the commit
issue 15 started from (:mod:`_baseline`), run on the same reducers; "NumPy" is the twin
(``tests/numpy_twin.py``).  One output revolution = z_b = 40 crank revolutions
relative to the carrier; at 36 positions per crank revolution that is 1440 static equilibria.

Δθ_er after issue 24 is the curve's, refined between the positions (:mod:`rvtol.models.transmission_error.extremes`);
"before" is the sampled one of the baseline.  The Monte Carlo rows compare before, after at the study's 36
positions per crank revolution and after at :data:`COARSE` (the same Δθ_er within the refinement's tolerance); the
extremes rows check the refinement against a dense reference on spec samples.

Arithmetic limit: the flops of one Newton iteration counted from the contact table at a converged state
(table update, two force evaluations — the step and its check —, one tangent assembly, the Cholesky
factor of 20×20 and two triangular solves; :func:`flops`) at this core's scalar multiply-add rate
(:func:`_machine.scalar_flop_rate`).  One iteration per equilibrium is what a perfect predictor would
leave; the printed fraction is limit / measured.

    python studies/benchmarks/bench_transmission.py [--quick | --smoke]
"""
from __future__ import annotations

import argparse
import functools
import sys
import time
from pathlib import Path

import numpy as np

import _baseline
from _machine import scalar_flop_rate
from _timing import add_size_options, by_size, print_table
from rvtol.design import load_design
from rvtol.executors import make_executor
from rvtol.mc import evaluate
from rvtol.models.reducer_20dof import _kernels as K
from rvtol.models.reducer_20dof import layout as L
from rvtol.models.reducer_20dof.contacts import pin_cos_sin
from rvtol.models.transmission_error.extremes import KAPPA, TOL_TE, te_extremes
from rvtol.models.transmission_error.model import TransmissionErrorModel
from rvtol.models.reducer_20dof.newmark import NewmarkSolver
from rvtol.models.reducer_20dof.quasistatic import QuasiStaticSolver
from rvtol.sampling import sample
from rvtol.spec import load_spec

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests"))     # the test oracle numpy_twin.py
from numpy_twin import ReferenceModel  # noqa: E402
ARCSEC = np.pi / 180 / 3600

#: positions per crank revolution of the coarser Monte Carlo sweep (Δθ_er refined between them)
COARSE = 12
# flop counts of the pieces (multiply, add = 1; fused multiply-add = 2; sqrt, divide, pow, sin/cos counted as 1)
PIN_UPDATE, PIN_UPDATE_DISC_ERRORS, OTHER_UPDATE = 32, 84, 300
LAW, RADIAL_LAW = 10, 25


def cpu_best(f, repeat: int):
    """(best CPU time of ``repeat`` calls, last result)."""
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.process_time()
        out = f()
        best = min(best, time.process_time() - t0)
    return best, out


def interleaved(fa, fb, repeat: int):
    """Best CPU times of ``fa`` and ``fb`` called alternately ``repeat`` times, and their last results."""
    ta = tb = float("inf")
    ra = rb = None
    for _ in range(repeat):
        t, ra = cpu_best(fa, 1)
        ta = min(ta, t)
        t, rb = cpu_best(fb, 1)
        tb = min(tb, t)
    return ta, tb, ra, rb


def flops(solver: QuasiStaticSolver, theta_c: float, q: np.ndarray, dynamic: bool = False) -> int:
    """Flops of one Newton iteration at the converged state ``q`` (module notes)."""
    g, e, t = solver.g, solver.errors, solver.table
    coef, off = np.zeros((t.n, 2, L.NZ)), np.zeros((t.n, 2))
    K.update_table(theta_c, 0.0, g.prm(), e.err, e.pin_err, e.disc_h, pin_cos_sin(g), coef, off)
    F, fc, kt = np.zeros(L.NDOF), np.zeros(t.n), np.zeros((t.n, 3))
    K.contact_forces(q, t.kind, t.idx, coef, off, t.k0, t.pw, t.gap, t.ser, t.tab, F, fc, kt)
    nnz = (t.idx >= 0).sum(axis=2)                     # [nc, 2] entries per row of G
    radial = t.kind == L.RADIAL
    loaded = fc != 0.0
    rows = np.where(radial, nnz[:, 0] + nnz[:, 1], nnz[:, 0])
    forces = int((2 * rows).sum() + (loaded * (2 * rows + np.where(radial, RADIAL_LAW, LAW))).sum())
    tangent = int(np.where(radial, 2 * (nnz[:, 0] + nnz[:, 1]) ** 2, 2 * nnz[:, 0] ** 2)[loaded].sum())
    n = L.NDOF
    chol = n ** 3 // 3 + n * (n - 1) // 2 + n + 2 * n * n
    has_disc = bool(np.any(e.disc_h))
    update = OTHER_UPDATE + L.N_DISC * g.z_b * (PIN_UPDATE + (PIN_UPDATE_DISC_ERRORS if has_disc else 0))
    dyn = 2 * (2 * n * n) + n * n // 2 if dynamic else 0     # D·Δ in both force evaluations, D added to K
    return update + 2 * forces + tangent + chol + 10 * n + dyn


@functools.lru_cache
def reducers(size: str):
    """(name, geometry, error state, load torque) of the benchmark's reducers (smoke: doc 000's design alone, the
    product's FE seats take seconds to build)."""
    out = []
    spec = load_spec(ROOT / "data/specs/rv80e_te.toml")
    designs = (("RV-80E doc 000 design", "data/designs/rv80e_te.toml"),
               ("RV-80E product (compliance chain)", "data/products/rv80e/design.toml"))
    for label, path in designs[:by_size(size, 1, 2, 2)]:
        model = TransmissionErrorModel(load_design(ROOT / path), spec.names)
        if not out:
            out.append(("error-free", model, None))
        S = sample(spec, by_size(size, 2, 8, 16), "lhs", 5)
        Y, _ = model.evaluate_with_status(S.values)
        out.append((f"spec sample, {label}", model, model.state(S.values[np.argsort(Y[:, 0])[len(Y) // 2]])))
    return out


def solver_rows(size: str, base, rate: float) -> list:
    rows = []
    rep = by_size(size, 1, 3, 7)
    for name, model, st in reducers(size):
        g = model.geometry
        new = QuasiStaticSolver(g, st)
        pcr = model.per_crank_rev
        th = new.positions(pcr)
        T = -model.load_torque
        new.sweep(th[:3], T)
        if base is not None:
            old = _baseline.BaselineSolver(g, st)
            old.sweep(th[:3], T)
            t_old, t_new, r_old, r_new = interleaved(lambda: old.sweep(th, T), lambda: new.rotation(-T, pcr), rep)
        else:
            t_new, r_new = cpu_best(lambda: new.rotation(-T, pcr), rep)
        npos = th.size
        it = r_new.iterations.mean()
        f = flops(new, th[npos // 3], r_new.q[npos // 3])
        limit = f / rate
        note = (f"{npos} equilibria, {it:.2f} Newton it./position, {t_new / npos * 1e6:.1f} µs/equilibrium; "
                f"arithmetic limit {limit * 1e6:.2f} µs ({f} flops): {limit / (t_new / npos):.1%} of it, "
                f"{limit * it / (t_new / npos):.0%} per iteration")
        rows.append((f"quasi-static revolution, {name}", f"{t_new * 1e3:.1f} ms", note))
        if base is not None:
            d = np.max(np.abs(r_old.te - r_new.te)) / ARCSEC
            rows.append((f"  before (commit {_baseline.BASELINE_REV})", f"{t_old * 1e3:.1f} ms",
                         f"{r_old.iterations.mean():.2f} it./position; after/before speed-up {t_old / t_new:.2f}×; "
                         f"max |ΔTE| {d:.1e}″"))
        if st is not None and name.startswith("spec sample, RV-80E doc"):
            ref = ReferenceModel(g, st)
            m = by_size(size, 4, 20, 60)
            t_ref, _ = cpu_best(lambda: ref.rotation(th[:m], T, r_new.q[0]), 1)
            rows.append(("  NumPy twin (same equations)", f"{t_ref / m * npos * 1e3:.0f} ms",
                         f"per revolution (from {m} positions); numba is {t_ref / m * npos / t_new:.0f}× faster"))
    return rows


def newmark_rows(size: str, base, rate: float) -> list:
    name, model, st = reducers("smoke" if size == "smoke" else "quick")[1]
    g = model.geometry
    new = NewmarkSolver(g, st, settle_periods=by_size(size, 1.0, 5.0, 50.0))
    new.run()                                   # compile / load the kernels outside the timing
    rows = []
    if base is not None:
        old = _baseline.BaselineNewmark(g, st, settle_periods=new.settle_periods)
        old.run()
        t_old, t_new, r_old, r_new = interleaved(old.run, new.run, by_size(size, 1, 2, 3))
    else:
        t_new, r_new = cpu_best(new.run, 2)
    n = len(r_new.te)
    it = r_new.iterations.mean()
    f = flops(new.static, float(r_new.theta_c[n // 3]), r_new.q[n // 3], dynamic=True)
    limit = f / rate
    rows.append(("Newmark-β revolution at 15 rpm, " + name, f"{t_new:.2f} s",
                 f"{n} steps of {r_new.time_step * 1e6:.0f} µs (lowest mode {r_new.frequencies.min():.0f} Hz), "
                 f"{it:.2f} Newton it./step, {t_new / n * 1e6:.1f} µs/step; arithmetic limit "
                 f"{limit * 1e6:.2f} µs: {limit / (t_new / n):.1%} of it, {limit * it / (t_new / n):.0%} per iteration"))
    if base is not None:
        d = np.max(np.abs(r_old.te - r_new.te)) / ARCSEC
        rows.append((f"  before (commit {_baseline.BASELINE_REV})", f"{t_old:.2f} s",
                     f"{t_old / n * 1e6:.1f} µs/step, {r_old.iterations.mean():.2f} it./step; speed-up "
                     f"{t_old / t_new:.2f}×; max |ΔTE| {d:.1e}″ (both run once before timing: issue 15's 198 µs/step "
                     "timed the first call, numba's compilation included)"))
    return rows


def mc_rows(size: str, base) -> list:
    """Monte Carlo throughput of the TE study's model: before (the baseline kernels, Δθ_er of the 36 positions
    per crank revolution), after (36 positions, Δθ_er of the curve refined between them, :mod:`.extremes`) and
    after at :data:`COARSE` positions per crank revolution (the same Δθ_er within the refinement's tolerance; the
    other outputs are the coarser sweep's), side by side on the same samples."""
    design = load_design(ROOT / "data/designs/rv80e_te.toml")
    spec = load_spec(ROOT / "data/specs/rv80e_te.toml")
    model = TransmissionErrorModel(design, spec.names)
    models = {"after": model,
              f"after, {COARSE} per crank rev": TransmissionErrorModel(design, spec.names, per_crank_rev=COARSE)}
    if base is not None:
        models = {"before": _baseline.BaselineTEModel.of(model), **models}
    n = by_size(size, 4, 48, 160)
    X = sample(spec, n, "lhs", 11).values
    rows = []
    for label, m in models.items():
        m.evaluate(X[:2])
    t, Y = {}, {}
    for _ in range(2):
        for label, m in models.items():
            t0 = time.process_time()
            ev = evaluate(m, X, progress=False)
            t[label] = min(t.get(label, np.inf), time.process_time() - t0)
            assert ev.ok.all()
            Y[label] = ev.Y
    ratio = (lambda label: f"; {t['before'] / t[label]:.2f}× before" if "before" in t and label != "before" else "")
    for label in models:
        rows.append((f"Monte Carlo, 1 core, {label}", f"{n / t[label]:.1f} samples/s",
                     f"{t[label] / n * 1e3:.1f} ms/sample (CPU time){ratio(label)}"))
    coarse = f"after, {COARSE} per crank rev"
    d = np.abs(Y[coarse] - Y["after"])
    rows.append((f"  Δθ_er at {COARSE} vs 36 per crank rev (both refined)", f"{d[:, 0].max() / ARCSEC:.1e}″",
                 f"largest |difference| over the {n} samples (refinement tolerance {TOL_TE / ARCSEC:.0e}″ per "
                 f"extreme, plus the solver's); the sweep's own outputs differ: mean TE by up to "
                 f"{d[:, 1].max() / ARCSEC:.3f}″, largest pin force {d[:, 2].max():.1f} N, bearing force "
                 f"{d[:, 3].max():.1f} N, mean loaded pins {d[:, 5].max():.2f}"))
    if "before" in Y:
        d = (Y["after"][:, 0] - Y["before"][:, 0]) / ARCSEC
        rows.append(("  Δθ_er after − before (36 per crank rev)", f"{d.mean():.3f}″",
                     f"mean; {d.min():.1e} … {d.max():.3f}″: the curve's extremes against the positions'"))
    with make_executor("process", 2) as ex:
        for label, m in models.items():
            evaluate(m, X[:4], ex, chunk_size=1, progress=False)      # start and warm the pool
        wall = {}
        for _ in range(2):
            for label, m in models.items():
                t0 = time.perf_counter()
                evaluate(m, X, ex, chunk_size=max(1, n // 16), progress=False)
                wall[label] = min(wall.get(label, np.inf), time.perf_counter() - t0)
    rate = {label: n / wall[label] for label in models}
    for label in models:
        extra = (f"; {rate[label] / rate['before']:.2f}× the throughput before (target ≥ 3×)"
                 if label != "before" and "before" in rate else "")
        rows.append((f"Monte Carlo, process pool, 2 workers, {label}", f"{rate[label]:.1f} samples/s",
                     f"10 000 samples ≈ {1e4 / rate[label] / 60:.1f} min (wall time){extra}"))
    return rows


def extremes_rows(size: str) -> list:
    """The refined extremes from the study's and coarser sweeps against a dense reference (288 positions per
    crank revolution, refined with a wider slope bound, κ = 4), and what the refinement costs; also with the
    band-limited bound κ = π/2, cheaper and not sound for a kink inside an interval (:mod:`.extremes`)."""
    design = load_design(ROOT / "data/designs/rv80e_te.toml")
    spec = load_spec(ROOT / "data/specs/rv80e_te.toml")
    model = TransmissionErrorModel(design, spec.names)
    T = model.load_torque
    n = by_size(size, 2, 24, 100)
    X = sample(spec, n, "lhs", 23).values
    cases = [(36, KAPPA), (18, KAPPA), (COARSE, KAPPA), (36, np.pi / 2), (COARSE, np.pi / 2)]
    worst, evals, iters, secs, sweeps = ({c: 0.0 for c in cases}, {c: 0 for c in cases}, {c: 0 for c in cases},
                                         {c: 0.0 for c in cases}, {c: 0.0 for c in cases})
    sampled = []
    for x in X:
        solver = QuasiStaticSolver(model.geometry, model.state(x))
        ref = te_extremes(solver, solver.rotation(T, 288), kappa=4.0)
        assert ref.ok
        for p in sorted({p for p, _ in cases}, reverse=True):
            t0 = time.process_time()
            sweep = solver.rotation(T, p)
            t_sweep = time.process_time() - t0
            if p == 36:
                sampled.append(ref.pp - np.ptp(sweep.te))
            for c in [c for c in cases if c[0] == p]:
                t0 = time.process_time()
                e = te_extremes(solver, sweep, kappa=c[1])
                secs[c] += time.process_time() - t0
                sweeps[c] += t_sweep
                assert e.ok
                worst[c] = max(worst[c], ref.te_max - e.te_max, e.te_min - ref.te_min)
                evals[c] += e.evaluations
                iters[c] += e.iterations
    rows = []
    for c in cases:
        p, kappa = c
        rows.append((f"TE extremes refined from {p} per crank rev, κ = {kappa:.3g}", f"{worst[c] / ARCSEC:.1e}″",
                     f"largest shortfall against the dense reference over {n} spec samples; {evals[c] / n:.0f} "
                     f"equilibria per sample ({iters[c] / evals[c]:.2f} Newton it. each): {secs[c] / n * 1e3:.2f} ms "
                     f"after a sweep of {sweeps[c] / n * 1e3:.2f} ms (CPU time)"))
    sampled = np.array(sampled) / ARCSEC
    rows.append(("  Δθ_er of the 36 positions themselves", f"{sampled.mean():.3f}″",
                 f"mean shortfall against the curve's (largest {sampled.max():.3f}″)"))
    return rows


def main(size: str = "full") -> list:
    base = _baseline.kernels()
    rate = scalar_flop_rate()
    rows = [("scalar multiply-add rate of this core", f"{rate / 1e9:.2f} GFlop/s",
             "the reference of the arithmetic limits (independent FMA chains)")]
    if base is None:
        rows.append(("before", "—", f"git revision {_baseline.BASELINE_REV} not available: no before rows"))
    rows += solver_rows(size, base, rate)
    rows += newmark_rows(size, base, rate)
    rows += extremes_rows(size)
    rows += mc_rows(size, base)
    print_table(rows, ("measurement", "value", "notes"))
    return rows


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_size_options(ap)
    main(ap.parse_args().size)
