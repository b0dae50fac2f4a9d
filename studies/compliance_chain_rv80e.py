"""RV-80E product: the figures of studies/compliance_chain.md — before (doc 000's rigid chain) and after (the
complete compliance chain) on the same product design.

    PYTHONPATH=$PWD python studies/compliance_chain_rv80e.py [--n 40] [--out studies/figures]

Prints markdown tables (nominal reducer, preload variants, per-element compliance, Monte Carlo with the drawing
tolerances mapped by studies/product_rv80e_mapping_check.py) and writes the figures (PNG) to ``--out``.
About 2 minutes on one core with --n 40 (plus the numba compilation on a first run).  Nothing is fitted; every
number comes from data/products/rv80e/design.toml and tolerances.toml.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import product_rv80e_mapping_check as pm  # noqa: E402  (the declared mapping of the drawing tolerances)

from rvtol.elements.reducer_chain import FAMILIES  # noqa: E402
from rvtol.models.stiffness.torsion_angle import ReducerStiffness  # noqa: E402
from rvtol.models.torsion_curve.beside_analytical_models import breakdown_at  # noqa: E402
from rvtol.models.torsion_curve.model import TorsionCurveModel  # noqa: E402
from rvtol.models.reducer_20dof.geometry import geometry_from_design  # noqa: E402
from rvtol.models.transmission_error.model import TransmissionErrorModel  # noqa: E402
from rvtol.models.transmission_error.orders import order_spectrum  # noqa: E402
from rvtol.sampling import sample  # noqa: E402

D = pm.D
T = D["reducer.rated_torque"]
ARCSEC, ARCMIN = 648000 / math.pi, 10800 / math.pi
NM_ARCMIN = math.pi / 10800 / 1e3
CAMS = tuple(f"delta_b[{j},{i}]" for j in (1, 2) for i in (1, 2, 3))
MEAN_CLEARANCES = dict(zip(CAMS + ("delta_pin",), [0.00136] * 6 + [0.0066]))   # mm: means (data/specs/rv80e_product_clearances.toml)


def geometries(design=D):
    return {"before": geometry_from_design(design, chain=False), "after": geometry_from_design(design)}


def metrics(c):
    m = c.metrics(3.0)
    return dict(rigidity=m.rigidity * NM_ARCMIN, lost_motion=m.lost_motion * ARCMIN, backlash=m.backlash * ARCMIN,
                angle_at_rated=m.angle_at_rated * ARCSEC)


def curve(g, values: dict | None = None):
    names = tuple(values) if values else ()
    model = TorsionCurveModel(g, names)
    return model.curve(np.array([values[n] for n in names]) if values else None)


def nominal_table(gs):
    print("\n### Nominal reducer (clearance-free; and at the mean clearances δ_b = 1.36 µm, δ_pin = 6.6 µm)\n")
    print("| case | chain | rigidity b/a (N·m/arcmin) | lost motion ±3 % (arcmin) | backlash (arcmin) | "
          "angle at +rated (arcsec) |")
    print("|---|---|---|---|---|---|")
    curves = {}
    for case, vals in (("clearance-free", None), ("mean clearances", MEAN_CLEARANCES)):
        for tag, g in gs.items():
            c = curve(g, vals)
            curves[case, tag] = c
            m = metrics(c)
            print(f"| {case} | {tag} | {m['rigidity']:.1f} | {m['lost_motion']:.3f} | {m['backlash']:.3f} | "
                  f"{m['angle_at_rated']:.1f} |")
    return curves


def preload_table():
    print("\n### Crank support pair: preload (clearance-free, chain on)\n")
    print("| preload (N) | rigidity b/a (N·m/arcmin) | lost motion ±3 % (arcmin) | pair share at rated (arcsec) |")
    print("|---|---|---|---|")
    for pre in (0.0, 500.0, 1000.0, 2000.0):
        g = geometry_from_design(D.with_values(**{"crank_support_bearing.preload": pre}))
        m = metrics(curve(g))
        bd = breakdown_at(g, T)
        print(f"| {pre:g} | {m['rigidity']:.1f} | {m['lost_motion']:.3f} | "
              f"{bd['crank_support_bearings'] * ARCSEC:.2f} |")


def breakdown_table(gs):
    print("\n### Output angle per element at 784 N·m (arcsec), clearance-free\n")
    rs = ReducerStiffness.from_design(D)
    mods = (D["cycloid.equidistance_modification"], D["cycloid.moved_distance_modification"])
    cols = {"20-DOF before": breakdown_at(gs["before"], T), "20-DOF after": breakdown_at(gs["after"], T),
            "doc 004 after": {k: float(v[0]) for k, v in rs.evaluate(T, *mods).families().items()}}
    lo = breakdown_at(gs["after"], 0.03 * T)
    print("| element | " + " | ".join(cols) + " | 20-DOF after at 3 % (arcsec per 3 % T × 33.3) |")
    print("|---|" + "---|" * (len(cols) + 1))
    for f, label in FAMILIES.items():
        vals = [f"{c[f] * ARCSEC:.2f}" if f in c else "—" for c in cols.values()]
        print(f"| {label} | " + " | ".join(vals) + f" | {lo.get(f, 0.0) * ARCSEC / 0.03:.2f} |")
    tot = [sum(c.values()) for c in cols.values()]
    print("| **total** | " + " | ".join(f"**{t * ARCSEC:.1f}**" for t in tot) + f" | {sum(lo.values()) * ARCSEC / 0.03:.1f} |")
    print("| T/θ (N·m/arcmin) | " + " | ".join(f"{T / t * NM_ARCMIN:.0f}" for t in tot) + " | |")
    return cols


def monte_carlo(gs, n):
    spec = pm.expanded_spec()
    v = pm.product_values(sample(spec, n, "random", seed=12002))
    d = pm.derived(v)
    te_models = {k: TransmissionErrorModel(g) for k, g in gs.items()}
    tc_models = {k: TorsionCurveModel(g) for k, g in gs.items()}
    out = {k: {"lost_motion": [], "rigidity": [], "backlash": [], "te_pp": []} for k in gs}
    results = {k: [] for k in gs}
    for row in range(n):
        st = pm.te_state(v, d, row)
        for k in gs:
            r, ext = te_models[k]._sweep(st)
            tc = tc_models[k]
            tc.state = lambda x, st=st: st
            c = tc.curve()
            if not (r.ok and ext.ok and c.ok):
                continue
            m = metrics(c)
            te = r.te * ARCSEC
            for key in ("lost_motion", "rigidity", "backlash"):
                out[k][key].append(m[key])
            out[k]["te_pp"].append(ext.pp * ARCSEC)
            results[k].append((row, r.theta_c, te))
    print(f"\n### Monte Carlo, drawing tolerances mapped (mapping.md), n = {n} (same samples before/after)\n")
    print("| quantity | chain | mean | sd | min | max |")
    print("|---|---|---|---|---|---|")
    for key, unit in (("rigidity", "N·m/arcmin"), ("lost_motion", "arcmin"), ("backlash", "arcmin"),
                      ("te_pp", "arcsec")):
        for k in gs:
            a = np.asarray(out[k][key])
            print(f"| {key} ({unit}) | {k} | {a.mean():.3f} | {a.std(ddof=1):.3f} | {a.min():.3f} | {a.max():.3f} |")
    return out, results


def spectra_table(results):
    """TE of the sample with the median TE p-p (after), before and after, and its largest orders."""
    pp = np.array([te.max() - te.min() for _, _, te in results["after"]])
    k = int(np.argsort(pp)[len(pp) // 2])
    row = results["after"][k][0]
    pick = {tag: next(x for x in results[tag] if x[0] == row) for tag in results}
    print(f"\n### TE of the median sample (row {row}): largest orders (arcsec)\n")
    print("| chain | TE p-p | " + " | ".join(f"order {o}" for o in (1, 2, 3, 39, 40, 78, 80, 120)) + " |")
    print("|---|---|" + "---|" * 8)
    for tag, (_, th, te) in pick.items():
        o, a = order_spectrum(te)
        print(f"| {tag} | {te.max() - te.min():.2f} | " + " | ".join(f"{a[i]:.3f}" for i in (1, 2, 3, 39, 40, 78, 80, 120))
              + " |")
    return pick


def figures(out_dir: Path, curves, cols, mc, pick):
    import matplotlib.pyplot as plt

    from rvtol.plotting.stiffness import plot_compliance_breakdown

    out_dir.mkdir(parents=True, exist_ok=True)
    fig, (ax, zx) = plt.subplots(1, 2, figsize=(10, 3.8))
    for (case, tag), c in curves.items():
        if case != "mean clearances":
            continue
        style = "-" if tag == "after" else "--"
        col = {"before": "#4C72B0", "after": "#DD8452"}[tag]
        lab = {"before": "before (doc 000's rigid chain)", "after": "after (compliance chain)"}[tag]
        ax.plot(c.torque_Nm, c.angle_arcmin, style, lw=1.2, label=lab, color=col)
        sel = np.abs(c.torque) <= 0.1 * c.rated
        zx.plot(c.torque_Nm[sel], c.angle_arcmin[sel], style + "o", ms=2, lw=1, label=lab, color=col)
    for a in (ax, zx):
        a.axvspan(-0.03 * T / 1e3, 0.03 * T / 1e3, color="0.6", alpha=0.2)
        a.set_xlabel("output torque [N·m]")
        a.set_ylabel("output torsion angle [arcmin]")
        a.legend(loc="best", fontsize=7)
    ax.set_title("hysteresis curve, RV-80E product, mean clearances")
    zx.set_title("within ±10 % rated (grey: ±3 %)")
    fig.savefig(out_dir / "compliance_chain_hysteresis.png", dpi=110, bbox_inches="tight")
    plt.close(fig)

    labels = [FAMILIES[f] for f in FAMILIES if any(f in c for c in cols.values())]
    series = {name: [c[f] * ARCSEC if f in c else np.nan for f in FAMILIES if any(f in cc for cc in cols.values())]
              for name, c in cols.items()}
    fig = plot_compliance_breakdown(labels, series)
    fig.savefig(out_dir / "compliance_chain_breakdown.png", dpi=110, bbox_inches="tight")
    plt.close(fig)

    fig, axs = plt.subplots(1, 3, figsize=(12, 3.4))
    for a, key, unit in zip(axs, ("lost_motion", "rigidity", "te_pp"), ("arcmin", "N·m/arcmin", "arcsec")):
        for tag in mc:
            a.hist(mc[tag][key], bins=12, alpha=0.6, label=tag, color={"before": "#4C72B0", "after": "#DD8452"}[tag])
        a.set_xlabel(f"{key.replace('_', ' ')} [{unit}]")
        a.legend(fontsize=7)
    axs[0].axvline(1.0, color="#C44E52", lw=1)
    fig.savefig(out_dir / "compliance_chain_monte_carlo.png", dpi=110, bbox_inches="tight")
    plt.close(fig)

    fig, (ax, sx) = plt.subplots(1, 2, figsize=(11, 3.6))
    color = {"before": "#4C72B0", "after": "#DD8452"}
    for tag, (_, th, te) in pick.items():
        ax.plot(np.degrees(th), te, lw=0.8, ls="-" if tag == "after" else "--", color=color[tag],
                label=f"{tag}: p-p {te.max() - te.min():.2f}″, mean {te.mean():.1f}″")
        o, amp = order_spectrum(te)
        sx.vlines(o[1:161] + (0.3 if tag == "after" else -0.3), 0, amp[1:161], lw=1.2, label=tag, color=color[tag])
    ax.set_xlabel("output angle [deg]")
    ax.set_ylabel("TE [arcsec]")
    ax.legend(fontsize=7)
    sx.set_xlabel("order [1/output revolution]")
    sx.set_ylabel("amplitude [arcsec]")
    sx.legend(fontsize=7)
    fig.savefig(out_dir / "compliance_chain_te.png", dpi=110, bbox_inches="tight")
    plt.close(fig)


def main(argv):
    n = int(argv[argv.index("--n") + 1]) if "--n" in argv else 40
    out = Path(argv[argv.index("--out") + 1]) if "--out" in argv else HERE / "figures"
    gs = geometries()
    curves = nominal_table(gs)
    preload_table()
    cols = breakdown_table(gs)
    mc, results = monte_carlo(gs, n)
    pick = spectra_table(results)
    figures(out, curves, cols, mc, pick)
    print(f"\nfigures: {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
