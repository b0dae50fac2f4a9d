"""The sections every study report has: verdict, inputs, results, convergence, failures."""
from __future__ import annotations

from functools import partial

import numpy as np
import pandas as pd

from ..model import model_label
from ..precision import requirements_scale, shown
from ..units import label
from ..blocks import RunTable, Section, Table


def correlated_pairs(names, corr) -> pd.DataFrame:
    """One row per correlated pair of factors (ρ ≠ 0 off the diagonal) — not the k × k matrix, which for the
    sign-off's 304 factors is 92 416 cells holding 14 pairs."""
    corr = np.asarray(corr, float)
    i, j = np.nonzero(np.triu(corr, 1))
    return pd.DataFrame({"factor": [names[a] for a in i], "with": [names[b] for b in j], "ρ": corr[i, j]})


def _fmt_ci(v, lo, hi, fmt="{:.4g}") -> str:
    """``v [lo, hi]``; ``fmt`` a format string or a function (:func:`rvtol.precision.shown` with a scale)."""
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return "—"
    form = fmt if callable(fmt) else fmt.format
    s = form(v)
    if lo is None and hi is None:
        return s
    f = lambda x: "…" if x is None or not np.isfinite(x) else form(x)  # noqa: E731
    return f"{s} [{f(lo)}, {f(hi)}]"


def verdict_section(result) -> Section:
    from ..verdict import EXPLORATORY, describe_bound

    mc = result.mc
    sec = Section("verdict", "Verdict")
    verdicts = mc.verdicts()
    if not verdicts:
        if result.verdict == EXPLORATORY:
            sec.add_text("EXPLORATORY: this study declares that it checks no requirement ([study] exploratory = "
                         "true); it describes, it signs nothing off.")
        else:
            sec.add_text("NO REQUIREMENTS: this study checks no requirement, so nothing is demonstrated and the run "
                         "does not pass a gate (exit code 4). Add [[requirement]] tables to gate on yield or Cpk, "
                         "or declare [study] exploratory = true if the study only describes.")
        return sec
    rows = []
    stat_asked = any(v.statistic is not None for v in verdicts)
    for v in verdicts:
        r, y, c = v.requirement, v.yield_, v.capability
        lims = " … ".join(x for x in (f"{r.lower:g}" if r.lower is not None else "−∞",
                                      f"{r.upper:g}" if r.upper is not None else "+∞"))
        need = []
        if r.min_yield is not None:
            need.append(f"yield ≥ {r.min_yield:g}" + (" (default)" if r.yield_defaulted else ""))
        if r.min_cpk is not None:
            need.append(f"Cpk ≥ {r.min_cpk:g}" + (" (percentile, ISO 22514-2)" if r.cpk_method == "percentile"
                                                   else " (normal theory)"))
        if r.statistic is not None:
            need.append(f"the {r.statistic} within the limits")
        stat = v.statistic is not None
        row = {
            "requirement": r.label,
            "limits": f"[{lims}] {label(r.unit)}",
            "needs": " and ".join(need),
            "judged on": describe_bound(r),
            "yield [CI]": "—" if stat else _fmt_ci(y.estimate, y.lo, y.hi, "{:.5f}"),
            "yield bound": _fmt_ci(v.yield_bound, None, None, "{:.5f}"),
            "ppm out [CI]": "—" if stat else _fmt_ci(y.ppm, *y.ppm_ci, "{:.0f}"),
            "Cpk [CI]": _fmt_ci(c["cpk"], c["cpk_lo"], c["cpk_hi"], "{:.3f}"),
            "Cpk bound": _fmt_ci(v.cpk_bound, None, None, "{:.3f}"),
            "Cpk percentile [CI]": _fmt_ci(c["cpk_percentile"], *v.cpk_percentile_ci, "{:.3f}"),
        }
        if stat_asked:
            row["statistic [interval]"] = _fmt_ci(*v.statistic, "{:.4g}") if stat else "—"
        row.update({
            "result": v.state,
            "n to demonstrate": f"{v.n_to_demonstrate:,}" if v.n_to_demonstrate else "",
            "why": "; ".join(v.reasons),
            "notes": "; ".join(v.notes),
        })
        if any(x.requirement.reading or x.requirement.source or x.requirement.status for x in verdicts):
            row.update({"reading": r.reading or "—", "source": r.source or "—", "status": r.status or "—"})
        rows.append(row)
    methods = sorted({"Clopper–Pearson" if v.requirement.interval == "clopper-pearson" else "Wilson"
                      for v in verdicts})
    sec.add_text(policy_text([v.requirement for v in verdicts]))
    if mc.stopping is not None:
        sec.add_text(sequential_text(mc.stopping))
    frame = pd.DataFrame(rows)
    if not any(v.notes for v in verdicts):
        frame = frame.drop(columns="notes")
    sec.add_table(frame, caption=f"Requirements: intervals [in brackets] two-sided at {mc.confidence:.0%};"
                  f" the bound column is what is judged (yield: {' / '.join(methods)}; Cpk: Bissell; percentile "
                  "Cpk: ISO 22514-2 with bootstrap CI)")
    return sec


def sequential_text(stop) -> str:
    """How a sequential run stopped, and what its verdicts rest on (the report's verdict section)."""
    return (f"{stop.describe()[0].upper()}{stop.describe()[1:]}. In a sequential run the verdict of each requirement is "
            "the sequential rule's (rvtol.sequential): PASS when the evidence that the yield exceeds the required one "
            "(for a median: that the share of units on the inside of each limit exceeds ½; for a mean: its anytime-valid t interval lies inside the band) reaches 1/α, α = 1 − the "
            "bound's confidence, FAIL when the evidence of the opposite does — kept from the look that first reached "
            "it — and UNDECIDED when the budget ended first. The bounds in the table are the fixed-n ones at the final "
            "n: they describe the sample but hold for one look, not the run's many (studies/sequential.md).")


def policy_text(reqs) -> str:
    """The pass/fail rule of these requirements in words (the report and the Markdown summary state it)."""
    from ..verdict import describe_bound

    judged = sorted({describe_bound(r) for r in reqs if r.per_unit}) or [describe_bound(reqs[0])]
    text = ("A requirement passes when its yield (the fraction of all samples within the limits; samples the model "
            "could not evaluate count as out) and its Cpk reach the required values on the "
            f"{' / '.join(judged)} — the figure is then demonstrated at that confidence. "
            "A requirement the estimate meets but the bound does not is not demonstrated at this n; "
            "'n to demonstrate' is the sample size that would demonstrate it if the observed yield and Cpk held.")
    stats_ = [r for r in reqs if r.statistic is not None]
    if stats_:
        text += ("\n\nA requirement on a population statistic (a catalogue's typical value, which single units may "
                 "miss by design) is judged on the statistic's confidence interval instead — the median's from order "
                 "statistics (distribution-free; samples that failed count on either side), the mean's from Student's "
                 "t: PASS when the interval lies inside the band, FAIL when it lies wholly outside, UNDECIDED when it "
                 "reaches both sides of a limit ('n to demonstrate': the samples that would decide it if the estimate "
                 "held): " + ", ".join(r.label for r in stats_) + ".")
    defaulted = [r for r in reqs if r.yield_defaulted]
    if defaulted:
        text += (f"\n\nA requirement that names neither a yield nor a Cpk asks for yield ≥ {defaulted[0].min_yield:g} "
                 "(the ±3σ coverage of a normal distribution, rvtol's default): "
                 + ", ".join(r.label for r in defaulted) + ".")
    return text


def inputs_section(result) -> Section:
    st = result.study
    sec = Section("inputs", "Inputs")
    files = pd.DataFrame([{"role": k, "file": v["path"] + (f" (sheet {v['sheet']!r})" if v.get("sheet") else ""),
                           "sha256": (v["sha256"] or "")[:16]} for k, v in st.inputs.items()])
    sec.add_table(files, caption="Input files (first 16 hex digits of SHA-256)")
    sec.blocks.append(RunTable())      # the run's timings: they end with the run, so the renderer fills them in
    fac = st.spec.to_frame()
    fac["unit"] = [label(u) for u in fac["unit"]]
    for col in ("nominal", "mean", "std", "tolerance T"):       # each factor's numbers resolve its band
        fac[col] = [f.shown(v) if v is not None else "—" for f, v in zip(st.spec.factors, fac[col])]
    fac.insert(list(fac.columns).index("tolerance T") + 1, "band (worst case)",
               [f"{f.band[0]:.6g} … {f.band[1]:.6g}" + (" (drawing)" if f.limits is not None else "")
                for f in st.spec.factors])
    fac["source"] = [f.source for f in st.spec.factors]
    sec.add_table(fac, caption="Tolerance factors (values in each factor's own unit; "
                               "T: tolerance band the distribution stands for)", pdf_omit=("feature", "group", "source"))
    pairs = correlated_pairs(st.spec.names, st.spec.correlation) if st.spec.correlation is not None else None
    if pairs is not None and len(pairs):
        sec.add_table(pairs,
                      caption="Correlated factors: the Gaussian copula's correlation of normal scores for each pair the "
                              "spec correlates (every other pair is independent)", float_format="{:.3g}")
    measured_factors(sec, st.spec, result.measured_evidence)
    if getattr(st, "build", None) is not None:
        build_tables(sec, st.build, result.build_usage)
    if st.design is not None:
        sec.add_table(st.design.to_frame(), caption=f"Design: {st.design.name}")
    from ..plotting.mc import factor_histograms

    sec.add_figure(factor_histograms(result.mc.samples), caption="Sampled factors")
    return sec


def build_tables(sec: Section, rules, used) -> None:
    """How the reducer is built (the study's build file): every rule with its reasoning and source, and what
    each did on the Monte Carlo's reducers."""
    sec.add_text(f"How the reducer is built ({rules.name}, {rules.file}): every Monte Carlo sample is the reducer "
                 "these rules assemble from that sample's parts. A selective fit takes the largest part whose "
                 "clearance, read with the gauges' errors (the gauge.* factors above), is at least its minimum; a "
                 "shim rule takes the shim nearest to the measured end play plus the target preload's "
                 "interference; a design choice is a drawing value chosen for these rules (checked against the "
                 "drawing spec and the design when the study loads).")
    sec.add_table(rules.to_frame(), caption="Build rules applied (rvtol.production.build)", text=True,
                  pdf_omit=("source",))
    if used is not None:
        sec.add_table(used, caption="What each rule did on the Monte Carlo's reducers: the fitted clearance (true "
                                    "sizes) or preload; the share of reducers for which the supply had no part small "
                                    "enough (clearance below the minimum) or even its largest part left more than a "
                                    "step above it; the parts used per size")


def measured_factors(sec: Section, spec, evidence: dict) -> None:
    """Factors whose distribution comes from measured values: the data, the fitted families ranked
    by AIC, the Anderson–Darling test of the family used (parametric bootstrap) and a Q-Q plot — laid out
    from ``evidence`` (factor name -> :func:`rvtol.inputs.measured.report_tables.evidence`, computed in the run)."""
    from ..plotting.inputs import qq_plot
    from ..precision import shown

    for f in spec.factors:
        if f.name not in evidence:
            continue
        ev = evidence[f.name]
        # numbers in the factor's unit shown to resolve its band (rvtol.precision): 40.0033, not 40
        scale = f.dist.tolerance if getattr(f.dist, "tolerance", None) else None
        summary = ev["summary"].copy()
        for col in ("mean", "s", "min", "max"):
            summary[col] = [shown(v, scale) for v in summary[col]]
        sec.add_table(summary, caption=f"Measured factor {f.name} ({label(f.unit)}): the values behind its "
                                              "distribution (s: sample standard deviation; gauge u²/s²: the share "
                                              "of the measurement uncertainty removed)")
        if ev.get("file_statistics") is not None:
            stats = ev["file_statistics"].copy()
            counts = stats["figure"].isin(["TotalNumber", "EffectiveNumber"])
            for col in ("file", "recomputed"):
                stats[col] = [f"{v:.0f}" if c else shown(v, scale) for v, c in zip(stats[col], counts)]
            sec.add_table(stats, caption=f"{f.name}: the statistics its QIF file reports, recomputed "
                                                         f"from the measurements each study names ({label(f.unit)}; "
                                                         "each agrees to the digits it is written with)")
        if ev["ranking"] is not None:
            sec.add_table(ev["ranking"], caption=f"{f.name}: candidate families by maximum likelihood, ranked by "
                                                 "AIC = 2k − 2 ln L (weight: Akaike weight; KS p is naive — the "
                                                 "parameters come from the same data — and only ranks)")
        if ev["gof"] is not None:
            g = ev["gof"]
            sec.add_text(f"{f.name}: goodness of fit of the {g.family} family used — {g.test} statistic "
                         f"{g.statistic:.4g}, p = {g.pvalue:.3g} ({g.n_mc} bootstrap samples; a small p, e.g. "
                         "< 0.05, says the family does not describe the data).")
        if ev["qq"] is not None:
            what = f"fitted {f.measured.family}" if f.measured.family else f.measured.method
            sec.add_figure(qq_plot(ev["qq"], f.name, f.unit, what), caption=f"{f.name}: Q-Q plot against the "
                           f"{what} distribution (Hazen positions)", width="55%")


def results_section(result) -> Section:
    from ..plotting.mc import convergence, histogram

    mc = result.mc
    sec = Section("results", "Monte Carlo results")
    stt = mc.statistics()
    rows = []
    for name, r in stt.iterrows():
        if r.get("n", 0) == 0:
            rows.append({"output": name, "unit": label(r["unit"]), "n": 0, "failed": r["failed"]})
            continue
        num = partial(shown, scale=requirements_scale(mc.requirements, name, r["std"]))   # resolves its band
        rows.append({
            "output": name, "unit": label(r["unit"]), "n": int(r["n"]), "failed": int(r["failed"]),
            "mean [CI]": _fmt_ci(r["mean"], r["mean_lo"], r["mean_hi"], num),
            "std [CI]": _fmt_ci(r["std"], r["std_lo"], r["std_hi"], num),
            "min": num(r["min"]), "max": num(r["max"]),
            "P0.135 [CI]": _fmt_ci(r["P0.135"], r["P0.135_lo"], r["P0.135_hi"], num),
            "median": num(r["P50"]),
            "P99.865 [CI]": _fmt_ci(r["P99.865"], r["P99.865_lo"], r["P99.865_hi"], num),
        })
    sec.add_table(pd.DataFrame(rows), caption=f"Statistics per output with {mc.confidence:.0%} confidence "
                  "intervals (mean: t; std: χ²; percentiles: order statistics, '…' = too few samples)")
    req_outputs = [r.output for r in mc.requirements]
    plotted = list(dict.fromkeys(req_outputs + [q.name for q in mc.outputs]))[:8]
    for name in plotted:
        sec.add_figure(histogram(mc, name), caption=f"{name}: distribution, spec limits, fitted normal",
                       width="80%")
    for name in (list(dict.fromkeys(req_outputs)) or plotted[:1])[:4]:
        sec.add_figure(convergence(mc, name), caption=f"{name}: convergence of the mean and yield with n",
                       width="80%")
    return sec


def failures_section(result) -> Section | None:
    f = result.mc.failures()
    if f.empty:
        return None
    sec = Section("failures", "Samples the model could not evaluate")
    sec.add_text(f"{int(f['count'].sum())} of {result.mc.n} samples failed. They are excluded from the "
                 "statistics of the outputs and counted as non-conforming in every yield.")
    sec.add_table(f, caption="Failures by reason (first sample indices, 0-based rows of samples.parquet)")
    return sec


def standard_sections(result) -> list[Section]:
    from ..signoff import signoff_section

    out = [signoff_section(result), verdict_section(result), inputs_section(result), results_section(result)]
    f = failures_section(result)
    if f is not None:
        out.append(f)
    return out


def _parallel_share(parallel: float | None, wall: float) -> str:
    return f" ({min(parallel / wall, 1.0):.0%} in parallel evaluation)" if parallel and wall > 0 else ""


def run_table(result) -> Table:
    """The run: model, samples, executor, wall time and the time of every phase."""
    st, m, o = result.study, result.mc, result.study.options
    run = pd.DataFrame([
        {"item": "model", "value": f"{model_label(st.model)} ({len(st.model.inputs)} inputs, "
                                   f"{len(st.model.outputs)} outputs)"},
        {"item": "samples", "value": f"{m.n} ({o.method}, seed {o.seed})"},
        {"item": "executor", "value": result.executor},
        {"item": "wall time", "value": f"{result.elapsed:.1f} s (Monte Carlo, analyses and the report's figures; "
                                       "writing the files after)"},
    ] + [{"item": f"  {phase}", "value": f"{seconds:.1f} s" + _parallel_share(result.parallel.get(phase), seconds)}
         for phase, seconds in result.timings.items()])
    if m.samples.note:
        run.loc[len(run)] = {"item": "note", "value": m.samples.note}
    for note in getattr(st, "notes", ()):
        run.loc[len(run)] = {"item": "note", "value": note}
    return Table(run, "Run")
