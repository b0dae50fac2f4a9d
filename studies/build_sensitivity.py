"""The RV-80E sign-off's verdict against the build's own rules (studies/build.md §4; issue 23 item 1).

The build (data/products/rv80e/build.toml) has three numbers that are rules, not physics: the smallest clearance
a pin set may leave (half the G2 gauge width), the smallest two-point clearance of a needle set (zero), and the
gauges' uncertainties; plus the shim step of the crank-support preload. Each is varied here on ONE common sample
of the sign-off's spec (common random numbers: the differences between rows are the rule's, not the sample's),
through the composed model restricted to the outputs the build reaches (stack-up, torsion curve, screening,
reducer stage; the TE sweep is left out): lost motion and backlash against 1 arcmin, the discs' fit in the pin
ring (margin ≥ 0), rigidity. The design's modification and crank-hole band stay as drawn in every row, so a
row's minimum also moves where in the supply the nominal demand lies. The preload's spread is computed for both
shim steps, with the clearance-free rigidity of the 20-DOF model at its extremes (its compliance chain is
tabulated at the design preload, so the per-sample preload does not reach the sign-off's rigidity).

    PYTHONPATH=. python studies/build_sensitivity.py          # ~3 min on 2 idle cores (n = 600)
"""
from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from rvtol import units
from rvtol.executors import make_executor
from rvtol.mc import Evaluator
from rvtol.models.torsion_curve.model import TorsionCurveModel
from rvtol.production.build import usage
from rvtol.sampling import sample
from rvtol.stats import proportion_lower_bound
from rvtol.study import load_study

ROOT = Path(__file__).resolve().parents[1]
N = int(sys.argv[1]) if len(sys.argv) > 1 else 600
SEED = 20261123
MARGINS = ["pin_ring.disc_1.margin", "pin_ring.disc_2.margin"]
OUTS = ["reducer.lost_motion", "reducer.backlash", *MARGINS, "torsion.torsional_rigidity", "build.pins.clearance"]


def with_fits(model, rules, **minimum_um):
    """The model with some fits' minimum clearance changed (µm; key = the fit's name with . as __)."""
    fits = tuple(replace(f, minimum=minimum_um[f.name.replace(".", "__")] * 1e-3)
                 if f.name.replace(".", "__") in minimum_um else f for f in rules.fits)
    return replace_build(model, replace(rules, fits=fits))


def replace_build(model, rules):
    from rvtol.models.composite.model import CompositeModel

    return CompositeModel(model.inputs, model.input_units, list(model.quantities), list(model.stages), rules,
                          model.build_outputs)


def trial_fit(st, rules, X):
    """X with the needles and shims as built and the pin set chosen by a TRIAL fit in the assembled reducer: the
    largest gauge with which both discs, where their cranks put them, keep the pins' minimum clearance in the pin
    ring — the per-pin fit margin of each disc ≥ minimum (stage pin_ring, mapping.md §6), read on the true parts (a
    trial, no gauge)."""
    from rvtol.production.selective import Classes

    drawn = st.model.without_build()
    env, _ = drawn.environment(X, set())
    changed, _ = rules.apply(env, len(X))
    Xb = X.copy()
    for name, v in changed.items():
        Xb[:, st.spec.index(name)] = v
    su = drawn.restricted(MARGINS)
    margin = su.evaluate(Xb).min(axis=1)                  # the tighter disc's margin with the build's pin set
    pins = next(f for f in rules.fits if f.name == "pins")
    lot = Xb[:, st.spec.index("pins.diameter_lot")]
    target = lot + margin - pins.minimum                  # the margin moves 1:1 with −δd (every g_k = δD_g/2 − δd − w_k)
    Xt = Xb.copy()
    Xt[:, st.spec.index("pins.diameter_lot")] = pins.sizes[Classes(np.append(pins.sizes, np.inf)).of(target)]
    return Xt


def table_row(label, Y, status, model):
    ok = status == 0
    col = lambda o: units.from_base(Y[:, model.output_index(o)], model.output(o).shown_unit)  # noqa: E731
    lm, bl = col("reducer.lost_motion"), col("reducer.backlash")
    m1, m2 = (col(o) for o in MARGINS)
    fits = lambda y, lo, hi: int(((y >= lo) & (y <= hi) & ok).sum())  # noqa: E731
    n = len(ok)
    row = {"case": label, "failed": int((~ok).sum()),
           "LM mean (′)": np.nanmean(lm), "LM P99 (′)": np.nanpercentile(lm, 99),
           "LM ≤ 1′": fits(lm, -np.inf, 1.0) / n, "LM ≤ 1′ (95 % lower bound)": proportion_lower_bound(fits(lm, -np.inf, 1.0), n, 0.95),
           "backlash ≤ 1′": fits(bl, -np.inf, 1.0) / n,
           "pin ring 1 ≥ 0": fits(m1, 0.0, np.inf) / n, "pin ring 2 ≥ 0": fits(m2, 0.0, np.inf) / n,
           "rigidity mean": np.nanmean(col("torsion.torsional_rigidity"))}
    if "build.pins.clearance" in model.output_names:
        row["pin clearance mean (µm)"] = np.nanmean(col("build.pins.clearance"))
    return row


def main():
    st = load_study(ROOT / "studies/rv80e_signoff.toml", n=N, progress=False)
    rules = st.build
    base = st.model.restricted(OUTS)
    X = sample(st.spec, N, "lhs", seed=SEED).values
    gauges = [j for j, n in enumerate(st.spec.names) if n.startswith("gauge.")]
    needles = {f.name.replace(".", "__"): None for f in rules.fits if f.name.startswith("needles.")}
    cases = [("as drawn (no build; the new drawing)", base.without_build(), X),
             ("as built (build.toml)", base, X)]
    for m in (0.0, 0.5, 2.0):
        cases.append((f"pins: minimum {m:g} µm (design 1)", with_fits(base, rules, pins=m), X))
    for m in (1.0, 2.0):
        cases.append((f"needles: minimum {m:g} µm (design 0)", with_fits(base, rules, **dict.fromkeys(needles, m)), X))
    for f in (0.0, 2.0):
        Xg = X.copy()
        Xg[:, gauges] *= f
        cases.append((f"gauges: u × {f:g}", base, Xg))
    cases.append(("pins by trial fit in the assembled reducer (pin-ring margin ≥ 1 µm)", base.without_build(),
                  trial_fit(st, rules, X)))
    import pandas as pd

    rows = []
    with make_executor("process") as ex:
        ev = Evaluator(ex)
        for label, model, Xc in cases:
            r = ev(model, Xc, label)
            rows.append(table_row(label, r.Y, r.status, model))
            print(pd.DataFrame([rows[-1]]).to_string(index=False, float_format=lambda v: f"{v:.3g}"), flush=True)
    print()
    print(pd.DataFrame(rows).to_string(index=False, float_format=lambda v: f"{v:.3g}"))

    # the crank-support preload: spread for shim steps of 5 and 10 µm, clearance-free rigidity at its extremes
    env, _ = st.model.without_build().environment(X, set())
    print()
    for step in (5.0, 10.0):
        shims = tuple(s.with_step(step * 1e-3) for s in rules.shims)
        u = usage(replace(rules, shims=shims), env, N)
        print(f"shim step {step:g} µm:")
        print(u[u["quantity"] == "preload (N)"].to_string(index=False, float_format=lambda v: f"{v:.4g}"))
        pre = np.concatenate([s.choose(env, N).preload for s in shims])
        lo, hi = np.percentile(pre, [0.135, 99.865])
        for label, p in (("P0.135", lo), ("design", 1000.0), ("P99.865", hi)):
            d = st.design.with_values(**{"crank_support_bearing.preload": float(p)})
            c = TorsionCurveModel(d, ()).curve().metrics(3.0)
            print(f"  preload {label} {p:7.1f} N: clearance-free rigidity "
                  f"{units.from_base(c.rigidity, 'N*m/arcmin'):.1f} N·m/arcmin, lost motion "
                  f"{units.from_base(c.lost_motion, 'arcmin'):.4f}′")


if __name__ == "__main__":
    main()
