"""Transmission-error model benchmark: quasi-static and Newmark revolutions, numba vs NumPy, MC throughput.

Measured side by side in one process (the machine is shared and noisy: ratios are what counts,
absolute times are indicative).  One output revolution = z_b = 40 crank revolutions relative to
the carrier; at 36 positions per crank revolution that is 1440 static equilibria.

    python studies/benchmarks/bench_transmission.py [--quick]

Targets (issue 5): a quasi-static revolution ≤ 50 ms on one core; numba ≥ 20× the NumPy
implementation of the same equations; a 10 000-sample TE Monte Carlo < 5 min on 2 cores.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from rvtol.design import load_design
from rvtol.executors import make_executor
from rvtol.mc import evaluate
from rvtol.models.transmission import _kernels as K
from rvtol.models.transmission import layout as L
from rvtol.models.transmission.contacts import pin_cos_sin, static_table
from rvtol.models.transmission.model import TransmissionErrorModel
from rvtol.models.transmission.newmark import NewmarkSolver
from rvtol.models.transmission.quasistatic import QuasiStaticSolver
from rvtol.models.transmission.numpy_twin import ReferenceModel
from rvtol.sampling import sample
from rvtol.spec import load_spec

from _timing import best_of, print_table

ROOT = Path(__file__).resolve().parents[2]




def assembly_times(g, st, q, n=2000):
    """One force + tangent evaluation at a loaded state: numba kernel vs NumPy reference."""
    tab = static_table(g, st.err)
    coef, off = np.zeros((tab.n, 2, L.NZ)), np.zeros((tab.n, 2))
    prm, pcs = g.prm(), pin_cos_sin(g)
    F, fc, kt, Km = np.zeros(L.NDOF), np.zeros(tab.n), np.zeros((tab.n, 3)), np.zeros((L.NDOF, L.NDOF))

    def numba_once():
        for _ in range(n):
            K.update_table(0.3, 0.0, prm, st.err, st.pin_err, st.disc_h, pcs, coef, off)
            K.contact_forces(q, tab.kind, tab.idx, coef, off, tab.k0, tab.pw, tab.gap, tab.ser, tab.tab, F, fc, kt)
            K.tangent_matrix(tab.kind, tab.idx, coef, kt, Km)

    ref = ReferenceModel(g, st)
    m = max(20, n // 50)
    t_nb, _ = best_of(numba_once)
    t_np, _ = best_of(lambda: [ref.forces(0.3, q) for _ in range(m)])
    return t_nb / n, t_np / m


def main(quick: bool = False) -> None:
    design = load_design(ROOT / "data/designs/rv80e_te.toml")
    spec = load_spec(ROOT / "data/specs/rv80e_te.toml")
    model = TransmissionErrorModel(design, spec.names)
    g = model.geometry
    # a realistic reducer: the spec's sample with the median TE of a small batch
    S = sample(spec, 16, "lhs", 5)
    Y, _ = model.evaluate_with_status(S.values)
    x_med = S.values[np.argsort(Y[:, 0])[8]]
    cases = {"error-free": None, "spec sample (clearances, errors)": model.state(x_med)}
    rows = []
    for name, st in cases.items():
        solver = QuasiStaticSolver(g, st)
        solver.rotation()   # compile / warm
        t_qs, r = best_of(lambda: solver.rotation(per_crank_rev=36), repeat=3 if quick else 5)
        it = r.iterations.mean()
        rows.append((f"quasi-static revolution, numba, {name}", f"{t_qs * 1e3:.1f} ms",
                     f"1440 equilibria, {it:.2f} Newton it./position, {t_qs / 1440 * 1e6:.1f} µs/equilibrium "
                     f"(target ≤ 50 ms/rev)"))
        ref = ReferenceModel(g, st)
        npos = 60 if quick else 240
        th = solver.positions(36)[:npos]
        t_ref, _ = best_of(lambda: ref.rotation(th, -model.load_torque, r.q[0]), repeat=1)
        t_nb_part = t_qs * npos / 1440
        rows.append((f"quasi-static, NumPy reference, {name}", f"{t_ref / npos * 1440 * 1e3:.0f} ms",
                     f"per revolution (from {npos} positions); numba is {t_ref / t_nb_part:.0f}× faster "
                     "(target ≥ 20×)"))
        t_nb, t_np = assembly_times(g, solver.errors, r.q[len(r.q) // 3])
        rows.append((f"force + tangent evaluation, {name}", f"{t_nb * 1e6:.2f} µs",
                     f"NumPy {t_np * 1e6:.0f} µs: ratio {t_np / t_nb:.0f}×"))
    # Newmark
    nm = NewmarkSolver(g, cases["spec sample (clearances, errors)"])
    t_nm, rn = best_of(lambda: nm.run(), repeat=1)
    rows.append(("Newmark-β revolution at 15 rpm, spec sample", f"{t_nm:.2f} s",
                 f"{len(rn.te)} steps of {rn.time_step * 1e6:.0f} µs (lowest mode {rn.frequencies.min():.0f} Hz), "
                 f"{rn.iterations.mean():.2f} Newton it./step, {t_nm / len(rn.te) * 1e6:.1f} µs/step"))
    # Monte Carlo throughput
    n = 48 if quick else 160
    X = sample(spec, n, "lhs", 11).values
    evaluate(model, X[:2], progress=False)
    t_ser, _ = best_of(lambda: evaluate(model, X, progress=False), repeat=2)
    rows.append(("Monte Carlo, serial (1 core)", f"{n / t_ser:.1f} samples/s",
                 f"{t_ser / n * 1e3:.1f} ms/sample; 10 000 samples ≈ {1e4 * t_ser / n / 60:.1f} min"))
    rate = {}
    for w in (1, 2):
        with make_executor("process", w) as ex:
            evaluate(model, X[:2 * w], ex, chunk_size=1, progress=False)   # start and warm the pool
            t_w, _ = best_of(lambda: evaluate(model, X, ex, chunk_size=max(1, n // (8 * w)), progress=False),
                             repeat=2)  # best of 2: the first run in a fresh pool still warms the workers
        rate[w] = n / t_w
        extra = f"; speed-up {rate[2] / rate[1]:.2f}× vs 1 worker" if w == 2 else ""
        rows.append((f"Monte Carlo, process pool, {w} worker{'s' if w > 1 else ''}", f"{rate[w]:.1f} samples/s",
                     f"10 000 samples ≈ {1e4 / rate[w] / 60:.1f} min (target < 5 min on 2 cores){extra}"))
    print_table(rows, ("measurement", "value", "notes"))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="smaller sizes")
    main(ap.parse_args().quick)
