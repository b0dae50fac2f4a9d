"""Study analyses of the stack-up (``[[analysis]] kind = ...``).

==================  ===========================================================================
kind                keys
==================  ===========================================================================
stackup_linear      see :class:`StackupLinear` (worst case, RSS and loop signs beside the Monte Carlo)
stackup_graph       (none): picture of the assembly graph, flows, fits, dimensions with sources
stackup_sequences   ``sequences`` (default all of the assembly's), ``outputs`` (default those all
                    share): the same samples through each assembly sequence, side by side
stackup_domains     ``n`` (samples per check, 200000), ``[[analysis.domain]]`` tables with
                    ``kind`` = "plane" (``t1``, ``t2``, ``length``, ``width``), "cylinder" (``t``,
                    ``length``) or "clearance" (``clearance``, ``length``, ``hole`` and ``shaft``
                    distribution tables in mm), ``k`` (3), ``name``: derived mean/σ beside sampled
==================  ===========================================================================

Doc 003's shaft–hole figures are compared in :mod:`rvtol.reproduction.doc003_stackup`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ... import units
from ...distributions import from_params
from ...errors import InputError
from ...analysis import Analysis
from ...report.sections import Section, Table, Text, frame_records
from ...sampling import substream_seed
from ...stats import percentile_ci
from ...units import label
from . import domains as dm
from .linearise import COVERAGE, Factors, linearise_output
from .model import StackupModel


def need_stackup(params, study) -> StackupModel:
    if not isinstance(study.model, StackupModel):
        raise params.error("kind", "this analysis needs a [model] of kind 'stackup'")
    return study.model


# --------------------------------------------------------------------------- graph
class StackupGraph(Analysis):
    def setup(self, params, study):
        self.model = need_stackup(params, study)

    def run(self, ctx) -> Section:
        from ...plotting.stackup import assembly_graph

        m = self.model
        asm, seq = m.assembly, m.sequence
        sec = Section("stackup_graph", f"Stack-up: assembly graph of {asm.name}")
        sec.add_text(f"{asm.description}\n\nModel: {m.describe()}. Transform T = Trans × Rot "
                     f"({'exact rotation Rz(γ)·Ry(β)·Rx(α)' if m.rotation == 'exact' else 'small-angle I + [ω]×'}).")
        sec.add_figure(assembly_graph(asm, seq), caption="Parts (in placing order), features, fits and deviation flows")
        flows = asm.flows(seq)
        sec.add_table(flows, caption="Deviation flows (doc 003 types f1–f5)")
        fits = pd.DataFrame([{
            "fit": f.name, "type": f.type, "base": f.base, "mate": f.mate,
            "clearance [µm]": None if f.clearance is None else f.clearance * 1e3,
            "length [mm]": f.length, "float": m.float_modes.get(f.name, "—") if f.is_clearance else "—",
            "role": "locates" if f.name in seq.locating else "closes (misfit KC)", "description": f.description}
            for f in asm.fits.values()])
        sec.add_table(fits, caption="Fits: MDD/MgD/Mgg from the datum flags; clearance fits float (f4)")
        dims = pd.DataFrame([{"dimension": d.name, "value": units.from_base(d.value, d.unit), "unit": label(d.unit),
                              "source": d.source, "note": d.note} for d in asm.dimensions.values()])
        if not dims.empty:
            sec.add_table(dims, caption="Dimensions and where each number comes from")
        seqs = pd.DataFrame([{"sequence": s.name, "order": " → ".join([asm.ground] + [p for p, _ in s.steps]),
                              "locating fits": ", ".join(f for _, f in s.steps),
                              "closing fits": ", ".join(f.name for f in asm.closing_fits(s)),
                              "description": s.description} for s in asm.sequences.values()])
        sec.add_table(seqs, caption="Assembly sequences")
        sec.summary = {"assembly": asm.name, "sequence": seq.name, "flows": frame_records(flows),
                       "fits": frame_records(fits), "dimensions": frame_records(dims)}
        return sec


# --------------------------------------------------------------------------- sequences
@dataclass
class SequenceComparison:
    """The same factor samples through several assembly sequences (display units)."""

    sequences: list[str]
    outputs: dict[str, list]  # sequence -> Quantities
    Y: dict[str, np.ndarray]  # sequence -> (n, m) display units

    def names(self, seq: str) -> list[str]:
        return [q.name for q in self.outputs[seq]]

    def common_outputs(self) -> list[str]:
        first = self.names(self.sequences[0])
        return [n for n in first if all(n in self.names(s) for s in self.sequences)]

    def column(self, seq: str, name: str) -> np.ndarray:
        return self.Y[seq][:, self.names(seq).index(name)]

    def unit(self, name: str) -> str:
        for s in self.sequences:
            if name in self.names(s):
                return self.outputs[s][self.names(s).index(name)].shown_unit
        raise KeyError(name)

    def to_frame(self) -> pd.DataFrame:
        allnames = list(dict.fromkeys(n for s in self.sequences for n in self.names(s)))
        rows = []
        for n in allnames:
            for s in self.sequences:
                if n not in self.names(s):
                    continue
                y = self.column(s, n)
                y = np.sort(y[np.isfinite(y)])
                rows.append({"output": n, "unit": label(self.unit(n)), "sequence": s, "mean": y.mean(),
                             "std": y.std(ddof=1), "P99.73": percentile_ci(y, 0.9973)[0], "max": y[-1],
                             "failed": int(len(self.column(s, n)) - len(y))})
        return pd.DataFrame(rows)

    def plot(self, outputs=None):
        from ...plotting.stackup import sequence_histograms

        return sequence_histograms(self, outputs)


class StackupSequences(Analysis):
    def setup(self, params, study):
        m = need_stackup(params, study)
        asm = m.assembly
        self.sequences = params.strs("sequences", list(asm.sequences), min_length=2)
        for s in self.sequences:
            if s not in asm.sequences:
                raise params.error("sequences", f"unknown sequence {s!r} (assembly has: {', '.join(asm.sequences)})")
        if len(set(self.sequences)) != len(self.sequences):
            raise params.error("sequences", "a sequence is named twice")
        try:
            self.models = {s: StackupModel(asm, s, m.inputs, m.input_units, m.rotation, m.backend,
                                           {k: v for k, v in m.float_modes.items()}) for s in self.sequences}
        except InputError as exc:  # e.g. a fit that locates only in another sequence needs float factors
            if exc.key == "factor":
                raise exc.located(file=study.spec.file) from None
            raise exc.located(file=params.file, key=params.path("sequences")) from None
        common = [n for n in self.models[self.sequences[0]].output_names
                  if all(n in mm.output_names for mm in self.models.values())]
        self.outputs = params.strs("outputs", common, min_length=1)
        for o in self.outputs:
            if o not in common:
                raise params.error("outputs", f"{o!r} is not an output of every sequence (common: {', '.join(common)})")

    def compare(self, ctx) -> SequenceComparison:
        X = ctx.mc.samples.values
        Y, outs = {}, {}
        for s, model in self.models.items():
            ev = ctx.evaluator(model, X, f"sequence {s}")
            Y[s] = np.column_stack([q.to_display(ev.Y[:, j]) for j, q in enumerate(model.outputs)])
            outs[s] = list(model.outputs)
        return SequenceComparison(self.sequences, outs, Y)

    def run(self, ctx) -> Section:
        cmp = self.compare(ctx)
        sec = Section("stackup_sequences", "Stack-up: assembly sequences compared on the same samples")
        asm = self.models[self.sequences[0]].assembly
        sec.add_text("Every sequence evaluates the Monte Carlo factor samples of this study (paired comparison). "
                     "A sequence decides which fit locates each part; the fits left over close the loop and appear "
                     "as '<fit>_misfit' outputs (radial and tilt misfit, and for clearance fits the assembly margin "
                     "c⁺/2 − end-point offset: negative means the part cannot go in without force).\n\n" +
                     "\n".join(f"{s}: {asm.sequences[s].description}" for s in self.sequences))
        table = cmp.to_frame()
        sec.add_table(table, caption="Output statistics per sequence (display units; P99.73 = 99.73 % quantile)")
        sec.add_figure(cmp.plot(self.outputs), caption="Outputs both sequences share")
        margins = [n for n in table["output"].unique() if n.endswith(".margin")]
        if margins:
            rows = []
            for s in self.sequences:
                for n in margins:
                    if n in cmp.names(s):
                        y = cmp.column(s, n)
                        rows.append({"sequence": s, "closing fit": n.split("_misfit")[0],
                                     "share assemblable (margin ≥ 0) %": 100.0 * np.mean(y[np.isfinite(y)] >= 0)})
            sec.add_table(pd.DataFrame(rows), caption="Assemblability where a clearance fit closes the loop")
        sec.summary = {"sequences": self.sequences, "statistics": frame_records(table)}
        return sec


# --------------------------------------------------------------------------- domains
class StackupDomains(Analysis):
    def setup(self, params, study):
        self.n = params.int("n", 200_000, min=1000)
        self.domains = []
        tables = params.tables("domain")
        if not tables:
            raise params.error("domain", "give at least one [[analysis.domain]]")
        for t in tables:
            kind = t.str("kind", choices=("plane", "cylinder", "clearance"))
            name = t.str("name", kind)
            k = t.float("k", 3.0, positive=True)
            try:
                if kind == "plane":
                    d = dm.ParallelPlaneZone(t.quantity("t1", "mm"), t.quantity("t2", "mm"),
                                             t.quantity("length", "mm", positive=True),
                                             t.quantity("width", "mm", positive=True), k)
                elif kind == "cylinder":
                    d = dm.CylindricalZone(t.quantity("t", "mm", positive=True),
                                           t.quantity("length", "mm", positive=True), k)
                else:
                    d = dm.ClearanceFit(t.quantity("clearance", "mm"), _mm_dist(t.sub("hole")),
                                        _mm_dist(t.sub("shaft")), t.quantity("length", "mm", positive=True), k)
            except InputError as exc:  # a domain's own check (e.g. t1 < t2): name the table it came from
                raise exc.located(file=t.file, key=t.key) from None
            t.finish()
            self.domains.append((name, d))

    def run(self, ctx) -> Section:
        from ...plotting.stackup import planar_domain

        sec = Section("stackup_domains", "Stack-up: deviation domains — derived moments against sampling")
        sec.add_text("Mean vector and standard deviations derived in closed form (uniform in the domain; truncated "
                     "normal: plane by quadrature, axis and clearance in closed form) beside the same moments of "
                     f"{self.n} samples drawn inside the domain. 'z' is (sampled − derived)/standard error of the sampled "
                     "mean or σ (σ's from the sample fourth moment, valid for any distribution); |z| > 4 would "
                     "contradict the derivation.")
        summary = {}
        for i, (name, d) in enumerate(self.domains):
            rows, few = [], {}
            for dist in dm.DISTRIBUTIONS:
                E = d.sample(self.n, dist, seed=substream_seed(ctx.seed, "stackup_domains", i))
                mean, cov = d.mean(dist), d.cov(dist)
                moving = int(np.count_nonzero(np.any(E != 0.0, axis=1)))
                testable = moving >= MIN_MOVING
                if not testable:
                    few[dist] = moving
                for j in d.dofs:
                    f = 1e3 if j < 3 else 1e6
                    m_s, s_s, se_m, se_s = _moments_with_errors(E[:, j])
                    sd = np.sqrt(cov[j, j])
                    rows.append({"distribution": dist, "dof": dm.DOF[j], "unit": "µm" if j < 3 else "µrad",
                                 "mean derived": mean[j] * f, "mean sampled": m_s * f,
                                 "z(mean)": (m_s - mean[j]) / se_m if se_m > 0 and testable else np.nan,
                                 "σ derived": sd * f, "σ sampled": s_s * f,
                                 "z(σ)": (s_s - sd) / se_s if se_s > 0 and testable else np.nan})
            df = pd.DataFrame(rows)
            sec.add_table(df, caption=f"{name}: {_describe_domain(d)}", float_format="{:.5g}")
            summary[name] = {"domain": _describe_domain(d), "moments": frame_records(df)}
            if few:
                sec.add_text(f"{name}: only " + " and ".join(f"{v} ({k})" for k, v in few.items()) +
                             f" of the {self.n} samples deviate from zero (e.g. a fit whose clearance is almost "
                             f"never positive). Moments resting on fewer than {MIN_MOVING} samples are ruled by "
                             "a handful of rare values and their standard errors are unreliable, so no z is given.")
                summary[name]["samples_deviating"] = few
            if isinstance(d, dm.ParallelPlaneZone):
                rec = dm.planar_record(d)
                sec.add_table(rec, caption=f"{name}: the document's printed planar-zone formulas against the "
                                           "derivation (lengths mm, angles rad)", float_format="{:.4g}")
                sec.add_figure(planar_domain(d, d.sample(3000, "uniform", seed=ctx.seed)),
                               caption=f"{name}: uniform samples, exact domain, its box and the printed box")
                summary[name]["record"] = frame_records(rec)
            if isinstance(d, dm.ClearanceFit):
                wc = d.worst_case()
                sec.add_text(f"{name}: largest clearance {d.max_clearance() * 1e3:.4g} µm → worst radial offset "
                             f"{wc['radial_offset'] * 1e3:.4g} µm, worst tilt {np.degrees(wc['tilt']):.4g}° "
                             f"({wc['tilt'] * 1e3:.4g} mrad); E[c⁺²] = {d.clearance_mean_square() * 1e6:.4g} µm².")
                summary[name]["worst_case"] = wc
        sec.summary = summary
        return sec


MIN_MOVING = 1000  # samples that must deviate from zero before a z test of the sampled moments means anything


def _moments_with_errors(x: np.ndarray) -> tuple[float, float, float, float]:
    """Sample mean and σ with their standard errors (σ's from the sample 4th moment, any distribution)."""
    n = len(x)
    m = float(x.mean())
    c = x - m
    v = float(np.mean(c * c))
    s = float(np.sqrt(v * n / (n - 1)))
    se_v = float(np.sqrt(max(np.mean(c**4) - v * v, 0.0) / n))
    return m, s, s / np.sqrt(n), se_v / (2 * s) if s > 0 else 0.0


def _mm_dist(p):
    d = from_params(p)
    p.finish()
    return d


def _describe_domain(d) -> str:
    if isinstance(d, dm.ParallelPlaneZone):
        return (f"planar face {d.L:g} × {d.W:g} mm between w = {d.t1 * 1e3:g} and {d.t2 * 1e3:g} µm "
                f"(exact domain |w−m| + |α|W/2 + |β|L/2 ≤ Δt/2)")
    if isinstance(d, dm.CylindricalZone):
        return f"axis of length {d.L:g} mm in a cylindrical zone ⌀{d.t * 1e3:g} µm"
    return (f"shaft in hole, nominal clearance {d.c0 * 1e3:g} µm, hole {d.hole.describe('mm')}, "
            f"shaft {d.shaft.describe('mm')}, engagement {d.L:g} mm")


# --------------------------------------------------------------------------- linearised chain vs Monte Carlo
def mc_figures(mc, name: str, form: str) -> dict:
    y = mc.column(name)
    y = np.sort(y[np.isfinite(y)])
    if len(y) == 0:
        return {}
    out = {"MC mean": float(y.mean()), "MC σ": float(y.std(ddof=1)) if len(y) > 1 else float("nan")}
    if form == "dof":
        out["MC low"] = percentile_ci(y, 0.00135)[0]
        out["MC high"] = percentile_ci(y, 0.99865)[0]
    elif form == "weighted":
        out["MC high"] = float(np.sqrt(np.mean(y**2)))
    else:
        if form == "none":
            out["MC low"] = percentile_ci(y, 1 - COVERAGE)[0]
        out["MC high"] = percentile_ci(y, COVERAGE)[0]
    out["MC min"], out["MC max"] = float(y[0]), float(y[-1])
    return out


BASIS = {  # what the WC / RSS / MC columns hold, per kind of output
    "dof": "signed: WC = arithmetic worst case; RSS = mean ± 3σ; MC = P0.135 / P99.865",
    "norm": "magnitude: WC high = max over the tolerance box; RSS high = P99.73 of the linearised pair's norm; "
            "MC high = P99.73",
    "weighted": "‖e‖/‖ε‖: WC high = upper bound; RSS high = rms; MC high = rms",
    "none": "margin: Monte Carlo only (MC low = P0.27, MC high = P99.73)",
}


class StackupLinear(Analysis):
    """``[[analysis]] kind = "stackup_linear"``: worst case, RSS and loop signs beside the Monte Carlo.

    Keys: ``outputs`` (default all), ``top`` (contributors shown per output, 12),
    ``figures`` (outputs that get a contribution chart, default the first 4).
    """

    def setup(self, params, study):
        model = study.model
        if not isinstance(model, StackupModel):
            raise params.error("kind", "stackup_linear needs a [model] of kind 'stackup'")
        self.outputs = params.strs("outputs", list(model.output_names), min_length=1)
        for o in self.outputs:
            if o not in model.output_names:
                raise params.error("outputs", f"unknown output name {o!r} (model has: {', '.join(model.output_names)})")
        self.top = params.int("top", 12, min=1)
        self.figures = params.strs("figures", self.outputs[:4])
        for o in self.figures:
            if o not in self.outputs:
                raise params.error("figures", f"{o!r} is not among the analysed outputs")
        worst = model.nonlinear_floats()
        if worst:
            raise params.error("kind", f"fit {worst[0]!r} floats in a worst-case mode, which is not differentiable "
                                       "in its direction; linearise a model with uniform (or centred) floats")

    def run(self, ctx) -> Section:
        from ...plotting.stackup import contribution_bars

        model, spec = ctx.model, ctx.spec
        fx = Factors.of(spec)
        J = model.jacobian(fx.x0)
        E0 = model.kc_deviations(fx.x0[None])[0]
        sec = Section("stackup_linear", "Stack-up: worst case and RSS of the linearised chain beside Monte Carlo")
        sec.add_text(
            "The chain is linearised analytically at the nominal point (small-displacement torsors carried through "
            "the assembly program). Signed KC components get the first-order mean, RSS σ (±3σ) and the "
            "arithmetic worst case; radial offsets and tilts (norms of a pair) get the exact worst case of the "
            "linearised pair over the tolerance box and the 99.73 % quantile of its normal RSS distribution; "
            "‖e‖/‖ε‖ get a worst-case bound and the RSS rms. Loop-method sign of a contributor: '+' positive "
            "accumulator (raises the KC), '−' negative accumulator (compensates), '0' uncorrelated. Clearance floats "
            "enter through their derivative at the centred position, i.e. as the disc's circumscribed square: "
            "linear worst cases of floats are conservative by up to √2, and clearance × position terms are absent "
            "from the linearisation (see the Monte Carlo).")
        rows, summary = [], {}
        for name in self.outputs:
            lin = linearise_output(model, spec, name, J, fx, E0)
            mc = mc_figures(ctx.mc, name, lin.form)
            row = {"output": name, "unit": label(lin.unit), "kind": lin.form, **lin.figures, **mc}
            rows.append(row)
            summary[name] = {"form": lin.form, "linear": lin.figures, "monte_carlo": mc, "notes": lin.notes}
            if lin.contributions.empty:
                continue
            top = lin.contributions.sort_values("variance share %", ascending=False).head(self.top)
            summary[name]["contributions"] = frame_records(lin.contributions)
            what = {"dof": "loop-method sign and accumulator from the derivative",
                    "norm": "derivatives and signs of the pair's two components",
                    "weighted": "shares of the weighted magnitude"}[lin.form]
            sec.add_table(top, caption=f"{name}: largest contributors ({what}; derivative in {label(lin.unit)} per "
                                       f"factor unit; worst-case and variance shares in %)", float_format="{:.4g}")
            if name in self.figures:
                sec.add_figure(contribution_bars(lin, top=self.top), caption=f"{name}: contributions")
        cols = ["output", "unit", "kind", "WC low", "WC high", "RSS mean", "RSS σ", "RSS low", "RSS high",
                "MC mean", "MC σ", "MC low", "MC high", "MC max"]
        table = pd.DataFrame(rows).reindex(columns=cols)
        sec.blocks.insert(1, _table_block(table))
        sec.blocks.insert(2, Text("Columns by kind — " + "; ".join(f"{k}: {v}" for k, v in BASIS.items()) + "."))
        sec.summary = {"outputs": summary}
        return sec


def _table_block(table: pd.DataFrame):
    return Table(table, "Linearised worst case / RSS beside Monte Carlo (display units of each output; "
                        "blank where a figure does not apply)", "{:.4g}")
