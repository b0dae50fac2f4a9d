"""Study analyses of the transmission-error model (``[[analysis]] kind = ...``).

``transmission_error_curve`` — one reducer in full: TE curve over one output
revolution, its order spectrum with the error families expected at each large
order (:mod:`.orders`), forces.  Keys: ``configuration`` =
"nominal" (the spec's nominal values; default), "median" or "worst" (the
Monte Carlo sample with the median / largest Δθ_er) or "values" (with
``[analysis.values]`` = {factor = value in the factor's unit}, others
nominal); ``newmark`` (true: also run the Newmark-β solver and overlay it);
``title``, ``key``.

``transmission_error_sensitivity`` — doc 000 §3–4: five-point sensitivities of
Δθ_er to each error factor of Table 3 (one at a time, magnitude e, the others
zero) across e, and their ranking (the document's classes and printed
sensitivities beside it: :mod:`rvtol.reproduction.doc000_transmission_error`).  Keys: ``factors`` (default: the Table 3 groups),
``magnitudes`` (µm; default 0.5 … 15), ``percent`` (± range of the stencil,
10), ``title``, ``key``.  It builds its own model over those factors (same
reducer and solver options as the study's model), so it does not depend on
the study's spec.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ... import units
from ...analysis import Analysis, ModelTarget, target_model
from ...distributions import Distribution
from ...report.sections import Section, frame_records
from ...spec import Factor, ToleranceSpec
from .factors import TABLE3_GROUPS
from .model import TransmissionErrorModel
from .orders import families_frame

#: rvtol's class thresholds, as fractions of the direct sensitivity S_ref = 1 µm of arc at the disc pitch
#: radius z_c·e (206.265 / 58.5 = 3.53 arcsec/µm for the RV-80E): what a tangential error acting directly
#: on the disc rotation would give
HIGH_FRACTION, NEGLIGIBLE_FRACTION = 0.15, 0.005
DEFAULT_MAGNITUDES = (0.5, 1.0, 2.0, 3.0, 5.0, 7.5, 10.0, 12.5, 15.0)


def _mesh_order_note(mesh: int, n: int) -> str:
    """Where the pin-mesh order shows in the spectrum of ``n`` positions per revolution (it aliases above n/2)."""
    if mesh <= n // 2:
        return f"{mesh} = pin mesh"
    alias = abs(mesh - n * round(mesh / n))
    return (f"the pin-mesh order {mesh} lies above the highest resolved order {n // 2} of {n} positions per "
            f"revolution and shows aliased at order {alias}")


def _te_target(study, params) -> ModelTarget:
    """The study's TE model, or the TE stage of a composed study (key ``model`` names it)."""
    return target_model(params, study, TransmissionErrorModel, "transmission_error")


class TECurve(Analysis):
    """One reducer over one output revolution (see module docstring)."""

    kind = "transmission_error_curve"

    def setup(self, params, study):
        self.target = _te_target(study, params)
        self.model = self.target.model
        self.key = params.str("key", self.kind)
        self.title = params.str("title", "Transmission error over one output revolution")
        self.configuration = params.str("configuration", "nominal", choices=("nominal", "median", "worst", "values"))
        vals = params.sub("values", {})
        self.values = {}
        for name in list(vals.keys()):
            if name not in study.spec.names:
                raise vals.error(name, f"unknown factor name {name!r} (spec has: {', '.join(study.spec.names)})")
            self.values[name] = float(units.to_base(vals.float(name), study.spec.factor(name).unit))
        vals.finish()
        if self.values and self.configuration != "values":
            raise params.error("values", 'values are used only with configuration = "values"')
        self.newmark = params.bool("newmark", False)
        params.finish()

    def _row(self, ctx) -> tuple[np.ndarray, str]:
        x = ctx.spec.nominal_base()
        if self.configuration == "values":
            for n, v in self.values.items():
                x[ctx.spec.index(n)] = v
            return x, "factor values given in the study"
        if self.configuration == "nominal":
            return x, "every factor at its nominal value"
        y = ctx.mc.column(self.target.output("te_pp"))
        ok = np.flatnonzero(ctx.mc.ok & np.isfinite(y))
        if ok.size == 0:
            return x, "no successful Monte Carlo sample: nominal values instead"
        if self.configuration == "worst":
            i = ok[np.argmax(y[ok])]
        else:
            i = ok[np.argsort(y[ok])[ok.size // 2]]
        return ctx.mc.samples.values[i].copy(), f"Monte Carlo sample {i} ({self.configuration} Δθ_er)"

    def run(self, ctx) -> Section:
        from ...plotting import transmission as tp

        x_study, how = self._row(ctx)
        x = self.target.inputs(x_study)[0]
        res = {self.model.mode: self.model.run(x)}
        if self.newmark and self.model.mode != "newmark":
            res["newmark"] = self.model.variant(mode="newmark").run(x)
        sec = Section(self.key, self.title)
        g = self.model.geometry
        sec.add_text(f"Configuration: {how}. Load torque {self.model.load_torque / 1e3:.4g} N·m resisting "
                     f"({100 * self.model.load_torque / g.rated_torque:.3g} % of rated), "
                     f"{self.model.per_crank_rev} positions per crank revolution ({self.model.per_crank_rev * g.z_b} "
                     "per output revolution) for the quasi-static sweep; its Δθ_er is the curve's, from its largest "
                     "and smallest values refined between the positions (marked).")
        if self.target.stage is None:
            spec = ctx.spec
            names, shown = spec.names, [f.unit for f in spec.factors]
        else:                       # a stage of a composed study: its inputs as the mapping gives them
            names = self.model.inputs
            shown = ["um" if u == "mm" else "arcsec" if u == "rad" else u for u in self.model.input_units]
        sec.add_table(pd.DataFrame({
            "factor": names,
            "value": [float(units.from_base(v, u)) for v, u in zip(x, shown)],
            "unit": [units.label(u) for u in shown]}),
            caption="Factor values of this reducer" + ("" if self.target.stage is None else
                                                       f" (inputs of model {self.target.stage!r})"))
        rows = []
        for mode, r in res.items():
            if not r.ok:
                sec.add_text(f"{mode}: the solver failed ({r.reason}).")
                continue
            rec = r.to_frame()
            rows.append({"solver": mode, "Δθ_er [arcsec]": r.te_pp, "mean Δθ_ca [arcsec]": float(r.te.mean()),
                         "max pin force [N]": rec["max pin force [N]"].max(),
                         "max cycloid-crank bearing force [N]": rec["max cycloid-crank bearing force [N]"].max(),
                         "max crank-carrier bearing force [N]": rec["max crank-carrier bearing force [N]"].max(),
                         "loaded pins per disc (min-max)":
                             f"{int(rec[['loaded pins disc 1', 'loaded pins disc 2']].min().min())}–"
                             f"{int(rec[['loaded pins disc 1', 'loaded pins disc 2']].max().max())}"})
        good = {m: r for m, r in res.items() if r.ok}
        if not good:
            return sec
        sec.add_table(pd.DataFrame(rows), caption="Transmission error and peak forces over one output revolution")
        sec.add_figure(tp.te_curves(good) if len(good) > 1 else tp.te_curve(next(iter(good.values()))),
                       caption="Transmission error Δθ_ca = θ_ca − θ_c over one output revolution")
        first = next(iter(good.values()))
        sec.add_figure(tp.spectrum(first), caption=f"Order spectrum of the {first.mode} TE (orders per output "
                                                   f"revolution; {g.z_b} = crank rotation relative to the carrier, "
                                                   f"{g.z_c} = absolute crank/eccentric rotation; "
                                                   f"{_mesh_order_note(g.z_c * g.z_b, first.te.size)})")
        top = first.top_orders(8)
        attributed = self.model.order_table(first, top=12, min_fraction=0.01)
        sec.add_table(attributed, caption="Largest orders of the TE spectrum (≥ 1 % of the largest) and the error "
                                          "families expected there: active families (non-zero factors) whose "
                                          "orders contain it, or, where none does, products of two families' base "
                                          f"orders (z_b = {g.z_b}, z_c = {g.z_c}, Z = z_b·z_c = {g.z_b * g.z_c}; "
                                          "derivation in rvtol/models/transmission/orders.py)",
                      float_format="{:.4g}")
        sec.add_table(families_frame(g), caption="Error families and their base orders per output revolution")
        sec.summary = {"configuration": how, "values": dict(zip(names, map(float, x))),
                       "te_pp_arcsec": {m: r.te_pp for m, r in good.items()},
                       "top_orders": frame_records(top), "order_attribution": frame_records(attributed)}
        if first.te_rig is not None:          # the TE its test rig reads (rvtol/models/transmission/rig.py)
            on_rig = self.model.order_table(first, top=12, min_fraction=0.01, rig=True)
            sec.add_table(on_rig, caption=f"The TE the test rig ({self.model.rig.name}) reads, Δθ_er "
                                          f"{first.te_pp_rig:.4g}″: its largest orders, the measurement chain's "
                                          "(order 1: output encoder; order i: input encoder) named first",
                          float_format="{:.4g}")
            sec.summary.update(te_pp_rig_arcsec=first.te_pp_rig, order_attribution_rig=frame_records(on_rig))
        return sec


class TESensitivity(Analysis):
    """Doc 000 §3–4: five-point sensitivity of Δθ_er to the Table 3 factors across e."""

    kind = "transmission_error_sensitivity"

    def setup(self, params, study):
        base = _te_target(study, params).model
        self.key = params.str("key", self.kind)
        self.title = params.str("title", "Sensitivity of the transmission error to the error factors (doc 000 §3–4)")
        self.factors = params.strs("factors", list(TABLE3_GROUPS), min_length=1)
        self.magnitudes = params.floats("magnitudes", list(DEFAULT_MAGNITUDES), min_length=1, positive=True)
        self.percent = params.float("percent", 10.0, positive=True, max=50.0)
        self.read_printed(params, study)
        params.finish()
        try:
            self.model = base.variant(inputs=self.factors)
        except Exception as exc:  # unknown factor names: say where
            raise params.error("factors", getattr(exc, "reason", str(exc))) from None
        for u in self.model.input_units:
            if u != "mm":
                raise params.error("factors", "only magnitude factors (lengths) have an S-versus-e curve")
        dist = Distribution.make("uniform", lower=0.0, upper=max(self.magnitudes))
        self.spec = ToleranceSpec("table3", tuple(Factor(n, "um", dist, nominal=0.0, group="Table 3")
                                                  for n in self.factors))

    def run(self, ctx) -> list[Section]:
        from ...plotting import transmission as tp
        from ...sensitivity import sensitivity_curve

        res = sensitivity_curve(self.model, self.spec, self.factors, self.magnitudes, "um", ["te_pp"],
                                self.percent, False, ctx.evaluator)
        fr = res.frame
        unit = fr["S_unit"].iloc[0]
        sec = Section(self.key, self.title)
        sec.add_text(
            "As in the document: each factor of Table 3 in turn has magnitude e (with the Table 3 phase "
            "angles and patterns), every other error is zero; the five points span ±"
            f"{self.percent:g} % of e and S is the five-point central derivative of Δθ_er (peak-to-peak TE over "
            "one output revolution, quasi-static, light load) — in arcsec per µm. The band around each curve "
            "spans the one-sided five-point derivatives at the ends of the interval.")
        table = fr.pivot_table(index="factor", columns="magnitude", values="S", sort=False).loc[self.factors]
        table.columns = [f"e = {c:g} µm" for c in table.columns]
        sec.add_table(table.reset_index(), caption=f"Five-point sensitivity S of Δθ_er [{units.label(unit)}] against "
                                                   "the magnitude e", float_format="{:.3g}")
        sec.add_figure(res.plot("te_pp"), caption="Sensitivity of Δθ_er against e (Table 3 factors)")
        sec.add_figure(tp.te_vs_magnitude(fr), caption="Δθ_er at the centre of each stencil against e")
        s_ref = units.from_base(1.0 / self.model.geometry.r_disc_pitch, "arcsec") * 1e-3
        rank = self.ranking(fr, s_ref)
        sec.add_table(rank, caption=f"Ranking by mean |S| over e; rvtol class: high ≥ {HIGH_FRACTION:g} S_ref, "
                                    f"negligible < {NEGLIGIBLE_FRACTION:g} S_ref, low between, where S_ref = "
                                    f"{s_ref:.3g} arcsec/µm is 1 µm of arc at the disc pitch radius z_c·e",
                      float_format="{:.4g}")
        sec.add_figure(tp.ranking(rank), caption="Sensitivity ranking (log scale), coloured by the document's class")
        comp = self.printed_table(fr)
        if len(comp):
            sec.add_table(comp, caption="Printed sensitivities (doc 000 §4) against rvtol's over the same e range "
                                        "(reasons in studies/transmission_error.md)", float_format="{:.4g}")
        lin = self.linearity(fr)
        if len(lin):
            wide = lin.pivot_table(index="factor", columns="e [µm]", values="ratio", sort=False)
            wide.columns = [f"e = {c:g} µm" for c in wide.columns]
            sec.add_table(wide.reset_index(), caption="Linearity: Δθ_er(2e) / Δθ_er(e) (2 for a factor whose "
                                                      "effect is proportional to its magnitude)", float_format="{:.3g}")
        for n in res.notes:
            sec.add_text("Note: " + n)
        sec.summary = {"percent": self.percent, "magnitudes_um": list(self.magnitudes),
                       "curve": frame_records(fr), "ranking": frame_records(rank),
                       "printed": frame_records(comp), "linearity": frame_records(lin)}
        return [sec]

    # -- hooks the reproduction of doc 000 fills in -----------------------------------
    def read_printed(self, params, study) -> None:
        """Read the document's printed figures (none here)."""

    def document_class(self, factor: str) -> str | None:
        """The document's class of a factor (None: no document to compare with)."""
        return None

    def printed_table(self, fr: pd.DataFrame) -> pd.DataFrame:
        """Printed sensitivities beside rvtol's (none here)."""
        return pd.DataFrame()

    def ranking(self, fr: pd.DataFrame, s_ref: float) -> pd.DataFrame:
        rows = []
        for name, g in fr.groupby("factor", sort=False):
            s = np.abs(g["S"].to_numpy())
            row = {"factor": name, "mean |S|": np.nanmean(s), "min |S|": np.nanmin(s), "max |S|": np.nanmax(s),
                   "unit": units.label(g["S_unit"].iloc[0])}
            doc = self.document_class(name)
            if doc is not None:
                row["document class"] = doc
            rows.append(row)
        d = pd.DataFrame(rows).sort_values("mean |S|", ascending=False).reset_index(drop=True)
        d["rvtol class"] = np.where(d["mean |S|"] >= HIGH_FRACTION * s_ref, "high",
                                    np.where(d["mean |S|"] < NEGLIGIBLE_FRACTION * s_ref, "negligible", "low"))
        if "document class" in d:
            d["document class"] = d["document class"].fillna("—")
            d["agrees"] = np.where(d["document class"] == "—", "—",
                                   np.where(d["document class"] == d["rvtol class"], "yes", "no"))
        d.insert(0, "rank", np.arange(1, len(d) + 1))
        return d

    @staticmethod
    def linearity(fr: pd.DataFrame) -> pd.DataFrame:
        rows = []
        for name, g in fr.groupby("factor", sort=False):
            y = dict(zip(g["magnitude"], g["y"]))
            for e in sorted(y):
                if 2 * e in y and y[e] > 0:
                    rows.append({"factor": name, "e [µm]": e, "Δθ_er(e) [arcsec]": y[e],
                                 "Δθ_er(2e) [arcsec]": y[2 * e], "ratio": y[2 * e] / y[e]})
        return pd.DataFrame(rows)
