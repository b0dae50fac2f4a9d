"""Stack-up benchmark: deviation-chain composition throughput, fused numba kernel vs NumPy matmul chain.

One core, one process, side by side (the machines are shared and noisy: compare the ratios).

* chain composition throughput: deviation vectors E[n, m, 6] → T = Π T(E_i) → extracted deviation,
  counted as n·m 4×4 compositions (each includes building T(E_i) from its six numbers; deviation
  angles ~1e-3 rad, as in tolerance chains, where the kernel's sine/cosine polynomial is shortest);
* the same program run by the fused numba kernel (3×4 affine products, no temporaries) and by
  batched NumPy 4×4 matmuls; and NumPy matmul of pre-built matrices (composition alone);
* the RV crank-chain Model (11 deviation slots, 49 operations) with either backend.

    python studies/benchmarks/bench_stackup.py [--quick | --smoke]
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from rvtol.models.stackup import transforms as tr
from rvtol.models.stackup.program import chain_program, run_numba, run_numpy

from _timing import add_size_options, best_time, by_size, print_table

ROOT = Path(__file__).resolve().parents[2]




def main(size: str = "full") -> None:
    n, m = by_size(size, 2000, 200_000, 1_000_000), 8
    g = np.random.default_rng(0)
    E = np.ascontiguousarray(np.concatenate([g.normal(0, 0.01, (n, m, 3)), g.normal(0, 1e-3, (n, m, 3))], axis=2))
    p = chain_program(m)
    run_numba(p, E[:10])  # compile / load the cache outside the timing
    rows = []
    for mode in ("exact", "small"):
        t_nb = best_time(lambda: run_numba(p, E, mode))
        t_np = best_time(lambda: run_numpy(p, E, mode), repeat=2)
        rows.append((f"fused numba chain ({mode}), build + compose + extract", f"{n * m / t_nb / 1e6:.1f} M/s",
                     "target ≥ 20 M/s per core"))
        rows.append((f"NumPy matmul chain ({mode}), same program", f"{n * m / t_np / 1e6:.1f} M/s",
                     f"numba / NumPy = {t_np / t_nb:.1f}× (target ≥ 1.5×)"))
    Eb = E.copy()
    Eb[..., 3:] *= 50.0  # angles ~0.05 rad: past the short sine/cosine polynomial
    t_big = best_time(lambda: run_numba(p, Eb, "exact"))
    rows.append(("fused numba chain (exact), angles ~0.05 rad", f"{n * m / t_big / 1e6:.1f} M/s",
                 "longer sine/cosine polynomial"))
    Ts = tr.exact(E[: n // 4])
    t_mm = best_time(lambda: tr.compose(Ts))
    rows.append(("NumPy matmul of pre-built 4×4 matrices (composition only)", f"{n // 4 * (m - 1) / t_mm / 1e6:.1f} M/s",
                 "reference: no building, no extraction"))

    from rvtol.design import load_design
    from rvtol.sampling import sample
    from rvtol.spec import load_spec
    from rvtol.models.stackup.graph import load_assembly
    from rvtol.models.stackup.model import StackupModel

    asm = load_assembly(ROOT / "data/assemblies/rv_crank_chain.toml", load_design(ROOT / "data/designs/rv80e_te.toml"))
    spec = load_spec(ROOT / "data/specs/stackup_rv_crank_chain.toml")
    X = sample(spec, by_size(size, 1000, 50_000, 200_000), "random", seed=1).values
    mods = {b: StackupModel(asm, "carrier_first", spec.names, backend=b) for b in ("numba", "numpy")}
    mods["numba"].evaluate(X[:10])
    t = {b: best_time(lambda b=b: mods[b].evaluate(X), repeat=2) for b in mods}
    k = len(mods["numba"].program.ops)
    rows.append(("RV crank-chain Model, numba backend", f"{len(X) / t['numba'] / 1e3:.0f} k samples/s",
                 f"{k} operations per sample"))
    rows.append(("RV crank-chain Model, NumPy backend", f"{len(X) / t['numpy'] / 1e3:.0f} k samples/s",
                 f"numba / NumPy = {t['numpy'] / t['numba']:.1f}×"))
    print_table(rows, ("measurement (1 core)", "value", "ratio / target"))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    add_size_options(ap)
    main(ap.parse_args().size)
