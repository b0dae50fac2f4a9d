"""What the sensitivity sections say: their prose and the layout of each result as report blocks.

One function per analysis kind, ``layout(result, options, plan) -> list of blocks`` (:mod:`rvtol.blocks`:
Text, Table, Figure; ``plan``: the analysis' :class:`~rvtol.sensitivity.analyses.SensitivityPlan`); the analyses (:mod:`rvtol.sensitivity.analyses`) name them, the generic report
(:meth:`rvtol.analysis.Analysis.report`) puts the blocks into a section.
"""
from __future__ import annotations

import pandas as pd

from ..blocks import Figure, Table, Text, figure_png
from ..units import label
from . import global_ as gs

LOCAL = ("Each factor in turn takes five equally spaced values spanning ±{percent:g} % of its nominal (zero nominals: "
         "±{percent:g} % of the tolerance half-band unless an absolute step is given), the others stay at nominal. S "
         "is the five-point central derivative at the nominal; the one-sided five-point stencils give S at the low "
         "and high end of the interval (their spread shows non-linearity). The tornado chart shows S × (tolerance "
         "limit − nominal) for each factor.")

CURVE = ("Five-point central derivative at magnitude e ({how}, the others at nominal; the five points span "
         "±{percent:g} % of e). The shaded band spans the one-sided derivatives at the interval ends.")

CONTRIBUTIONS = ("Linearisation at the nominal point with the five-point gradient: % contribution to variance = "
                 "(S_i σ_i)² / Σ (S_j σ_j)²; RSS σ = √(Sᵀ C S); worst case = every factor at the tolerance limit that "
                 "pushes the output the same way. Beside it, the Monte Carlo figures, and the one-at-a-time table with "
                 "the model evaluated at each factor's low limit, median and high limit.")

#: the explanation of each global method (key: the result's ``method``)
EXPLAIN = {
    "sobol": ("Variance-based indices (Saltelli scheme on a scrambled Sobol' sequence, each factor sampled from its "
              "own distribution): S1 = share of the output variance due to the factor alone, ST = including its "
              "interactions, S2 = pair interactions; CIs by bootstrap."),
    "morris": ("Morris trajectories on each factor's tolerance band in probability (P0.135…P99.865 for ±3σ): μ* = "
               "mean |elementary effect| (importance), σ = their spread (non-linearity or interaction), in the "
               "output's unit."),
    "fast": "Extended FAST (search curves through each factor's distribution): S1 and ST.",
    "rbd_fast": ("RBD-FAST first-order indices from a random sample (no extra evaluations when it reuses the Monte "
                 "Carlo sample)."),
    "delta": ("Borgonovo's δ: the expected shift of the whole output distribution when a factor is known (0: none, "
              "1: all); valid with correlated inputs. S1 is estimated from the same data."),
    "given_data": ("First-order indices S1 = V[E(Y|X_i)]/V[Y] from the Monte Carlo samples themselves, with no further "
                   "model run: the correlation ratio of the output on each factor over equal-count classes of the "
                   "factor, with Kelley's correction of its noise bias (Plischke, Borgonovo & Smith 2013); CIs by "
                   "bootstrap of the samples. Total indices cannot be read from given data: the pce analysis (a "
                   "surrogate fitted on the same samples) or the Saltelli route (sobol) gives them."),
    "pce": ("Sobol indices S1, ST (and S2) read from the coefficients of a sparse polynomial chaos expansion fitted on "
            "the Monte Carlo samples (no further model run; Sudret 2008, Blatman & Sudret 2011). The expansion is "
            "validated by leave-one-out and on held-out samples: below the stated Q² its indices are withheld (their "
            "error could exceed their interval by up to 1 − Q²). CIs by bootstrap of the samples, given the selected "
            "terms."),
}

MATRIX = ("Rows: drawing tolerances (the coordinates of one callout and the copies of a per-part family are one "
          "tolerance); columns: outputs. Left: the five-point (±{percent:g} %) linearised share of each output's "
          "variance, (S_i σ_i)² / Σ (correlation ignored), for every tolerance — {n_five_point} model runs. Right: "
          "Sobol total indices (Saltelli, n = {n}, {n_sobol} model runs) of {n_top} tolerances — each output's largest "
          "in turn (its largest five-point share; for an output the linearisation cannot see, a magnitude whose "
          "derivative vanishes at the nominal{by_mc}, its largest first-order index from the Monte Carlo samples) — "
          "the others as one group: the total index includes interactions and the non-linearity the linear share "
          "misses.")


def notes(items) -> list[Text]:
    return [Text("Note: " + n) for n in items]


# --------------------------------------------------------------------------- local
def local(res, o, p) -> list:
    blocks = [Text(LOCAL.format(percent=o.percent))]
    for out in p.outputs:
        blocks += [Table(res.table(out), f"Five-point sensitivities of {out} (sign: + the output grows with the "
                                         "factor)", "{:.4g}"),
                   Figure(figure_png(res.plot(out)), f"Tornado chart of {out} from the local sensitivities")]
    return blocks + notes(res.notes)


def curve(res, o, p) -> list:
    how = "every listed factor set to e at once" if o.together else "one factor at a time set to e"
    blocks = [Text(CURVE.format(how=how, percent=o.percent))]
    for out in p.outputs:
        d = res.frame[res.frame["output"] == out]
        table = d.pivot_table(index="magnitude", columns="factor", values="S", sort=False).reset_index()
        table = table.rename(columns={"magnitude": f"e [{label(d['magnitude_unit'].iloc[0])}]"})
        table.columns = [c if i == 0 else f"S {c} [{d[d['factor'] == c]['S_unit'].iloc[0]}]"
                         for i, c in enumerate(table.columns)]
        blocks += [Table(table, f"Sensitivity of {out} against the magnitude e"),
                   Figure(figure_png(res.plot(out)), f"Sensitivity curves of {out}")]
    return blocks + notes(res.notes)


def contributions(res, o, p) -> list:
    blocks = [Text(CONTRIBUTIONS)]
    stats = res.mc_statistics
    for out in res.outputs:
        pred = res.predictions[out]
        u = label(pred.unit)
        s = stats.loc[out] if stats is not None else pd.Series(dtype=float)
        comp = pd.DataFrame([
            {"figure": "mean", "linearised": pred.mean, "Monte Carlo": s.get("mean")},
            {"figure": "standard deviation", "linearised": pred.std, "Monte Carlo": s.get("std")},
            {"figure": "low end (RSS: mean − 3σ; MC: P0.135)", "linearised": pred.mean - 3 * pred.std,
             "Monte Carlo": s.get("P0.135")},
            {"figure": "high end (RSS: mean + 3σ; MC: P99.865)", "linearised": pred.mean + 3 * pred.std,
             "Monte Carlo": s.get("P99.865")},
            {"figure": "worst case low", "linearised": pred.worst_low, "Monte Carlo": s.get("min")},
            {"figure": "worst case high", "linearised": pred.worst_high, "Monte Carlo": s.get("max")},
        ])
        comp.columns = ["figure", f"linearised [{u}]", f"Monte Carlo [{u}]"]
        f = pred.frame
        contrib = pd.DataFrame({
            "factor": f["factor"], "S": f["S"], "unit of S": f["S_unit"],
            "σ": [f"{v:.4g} {label(fu)}" for v, fu in zip(f["sigma"], f["factor_unit"])],
            f"S·σ [{u}]": f["S_sigma"], "% of variance": f["variance_pct"],
            f"Δ at low limit [{u}]": f["dy_low"], f"Δ at high limit [{u}]": f["dy_high"],
        }).sort_values("% of variance", ascending=False)
        h = res.high_low.frame[res.high_low.frame["output"] == out]
        ht = pd.DataFrame({
            "factor": h["factor"],
            "low / median / high": [f"{a:.4g} / {b:.4g} / {c:.4g} {label(fu)}"
                                    for a, b, c, fu in zip(h["low"], h["median"], h["high"], h["factor_unit"])],
            f"{out} at low [{u}]": h["y_low"], f"at median [{u}]": h["y_median"],
            f"at high [{u}]": h["y_high"], f"swing [{u}]": h["swing"],
        }).sort_values(f"swing [{u}]", ascending=False)
        blocks += [
            Table(comp, f"{out}: linearised predictions beside the Monte Carlo (MC worst-case rows: sample min/max)"),
            Table(contrib, f"{out}: linearised contributions"),
            Figure(figure_png(pred.plot()), f"{out}: % contribution to variance"),
            Table(ht, f"{out}: high/low/median (one factor at a time, the others at nominal = "
                      f"{h['y_nominal'].iloc[0]:.4g} {u})"),
            Figure(figure_png(res.high_low.plot(out)), f"{out}: high/low swing (model evaluated)"),
            *notes(pred.notes),
        ]
    return blocks


# --------------------------------------------------------------------------- global
def index_table(res, output: str) -> pd.DataFrame:
    d = res.for_output(output)
    out = pd.DataFrame({"factor": d["factor"]})
    if res.method == "morris":
        u = label(d["unit"].iloc[0])
        out[f"μ* [{u}]"] = d["mu_star"]
        out[f"μ* CI ± [{u}]"] = d["mu_star_conf"]
        out[f"μ [{u}]"] = d["mu"]
        out[f"σ [{u}]"] = d["sigma"]
        return out.sort_values(f"μ* [{u}]", ascending=False)
    for col, conf in gs.INDEX_COLUMNS[res.method]:
        out[col] = d[col]
        out[f"{col} CI ±"] = d[conf]
    return out.sort_values(gs.INDEX_COLUMNS[res.method][-1][0], ascending=False)


def global_indices(res, o, p) -> list:
    blocks = [Text(EXPLAIN[res.method] + f" {res.n_evaluations} model evaluations"
                   + (f" ({res.n_failed} failed)" if res.n_failed else "") + ".")]
    for out in p.outputs:
        blocks.append(Table(index_table(res, out), f"{gs.TITLES[res.method]} of {out} (CI: {res.confidence:.0%})"))
        if res.second_order is not None:
            s2 = res.second_order[res.second_order["output"] == out].drop(columns="output")
            s2 = s2.reindex(s2["S2"].abs().sort_values(ascending=False).index).head(15)
            blocks.append(Table(s2.rename(columns={"S2_conf": "S2 CI ±"}),
                                f"Second-order Sobol indices of {out} (largest 15 pairs)"))
        blocks.append(Figure(figure_png(res.plot(out)), f"{gs.TITLES[res.method]} of {out}"))
    return blocks + notes(res.notes)


PCE_VALIDATION = ("output", "reliable", "Q2_loo", "Q2_holdout", "rel_rmse_holdout", "bias_bound", "degree", "n_terms",
                  "n_candidates", "n_samples", "n_holdout")


def pce(res, o, p) -> list:
    blocks = global_indices(res, o, p)
    v = res.validation
    cols = [c for c in PCE_VALIDATION if c in v.columns]
    blocks.insert(1, Table(v[cols], f"Validation of the surrogate (indices withheld below Q² = {o.min_q2:g})"))
    return blocks


# --------------------------------------------------------------------------- cross-model matrix
def matrix(res, o, p) -> list:
    intro = MATRIX.format(percent=res.percent, n_five_point=res.n_five_point, n=res.n, n_sobol=res.n_sobol,
                          n_top=len(res.top), by_mc=f" ({', '.join(res.ranked_by_mc)})" if res.ranked_by_mc else "")
    return [
        Text(intro),
        Figure(figure_png(res.plot("share")), "Cross-model sensitivity: five-point linearised variance share (drawing "
                                              "tolerance × output)"),
        Figure(figure_png(res.plot("total")), "Cross-model sensitivity: Sobol total index of the top tolerances (their "
                                              "interactions included)"),
        Table(res.total_table(), f"Sobol total indices with their {100 * res.confidence:.0f} % bootstrap half-widths"),
        Table(res.share.loc[res.shown].reset_index(names="drawing tolerance"),
              "Five-point linearised variance shares (the largest tolerances)", "{:.3f}"),
        *notes(res.notes),
    ]
