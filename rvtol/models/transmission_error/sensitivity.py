"""Five-point sensitivities of Δθ_er to the error factors across their magnitude e, and their ranking.

:func:`table3_spec` builds the one-factor-at-a-time setting of doc 000 §3–4 (each factor of Table 3 in
turn at magnitude e with its phase angles and patterns, every other error zero);
:func:`te_sensitivity` returns a :class:`TESensitivityResult`: the sensitivity curves
(:func:`rvtol.sensitivity.sensitivity_curve`), the ranking by mean |S| with rvtol's classes and the
linearity Δθ_er(2e)/Δθ_er(e).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ... import units
from ...distributions import Distribution
from ...records import frame_records
from ...spec import Factor, ToleranceSpec
from .model import TransmissionErrorModel

#: rvtol's class thresholds, as fractions of the direct sensitivity S_ref = 1 µm of arc at the disc pitch
#: radius z_c·e (206.265 / 58.5 = 3.53 arcsec/µm for the RV-80E): what a tangential error acting directly
#: on the disc rotation would give
HIGH_FRACTION, NEGLIGIBLE_FRACTION = 0.15, 0.005
DEFAULT_MAGNITUDES = (0.5, 1.0, 2.0, 3.0, 5.0, 7.5, 10.0, 12.5, 15.0)


def table3_spec(factors, magnitudes) -> ToleranceSpec:
    """A spec of the magnitude factors ``factors`` (µm, nominal 0) spanning the ``magnitudes``."""
    dist = Distribution.make("uniform", lower=0.0, upper=max(magnitudes))
    return ToleranceSpec("table3", tuple(Factor(n, "um", dist, nominal=0.0, group="Table 3") for n in factors))


@dataclass
class TESensitivityResult:
    """``curve``: the sensitivity-curve result (:class:`rvtol.sensitivity.local.CurveResult`);
    ``ranking``: by mean |S| over e with rvtol's class; ``linearity``: Δθ_er(2e)/Δθ_er(e)."""

    factors: list[str]
    magnitudes: list[float]
    percent: float
    curve: object
    ranking: pd.DataFrame
    linearity: pd.DataFrame
    s_ref: float                  # arcsec/µm: 1 µm of arc at the disc pitch radius
    notes: list[str] = field(default_factory=list)

    @property
    def frame(self) -> pd.DataFrame:
        return self.curve.frame

    def to_frame(self) -> pd.DataFrame:
        return self.frame

    def table(self) -> pd.DataFrame:
        """S per factor (rows) and magnitude (columns)."""
        table = self.frame.pivot_table(index="factor", columns="magnitude", values="S", sort=False).loc[self.factors]
        table.columns = [f"e = {c:g} µm" for c in table.columns]
        return table.reset_index()

    def linearity_table(self) -> pd.DataFrame:
        wide = self.linearity.pivot_table(index="factor", columns="e [µm]", values="ratio", sort=False)
        wide.columns = [f"e = {c:g} µm" for c in wide.columns]
        return wide.reset_index()

    def plot(self, what: str = "S", ranking: pd.DataFrame | None = None):
        """``"S"``: S against e; ``"te"``: Δθ_er at each stencil's centre against e; ``"ranking"``: the
        ranking (``ranking``: a frame with more columns, e.g. a document's classes)."""
        from ...plotting import transmission as tp

        if what == "S":
            return self.curve.plot("te_pp")
        if what == "te":
            return tp.te_vs_magnitude(self.frame)
        return tp.ranking(self.ranking if ranking is None else ranking)

    def summary(self) -> dict:
        return {"percent": self.percent, "magnitudes_um": list(self.magnitudes), "curve": frame_records(self.frame),
                "ranking": frame_records(self.ranking), "linearity": frame_records(self.linearity)}


def ranking(fr: pd.DataFrame, s_ref: float) -> pd.DataFrame:
    """Factors by mean |S| over e, with rvtol's class (high ≥ HIGH_FRACTION·S_ref, negligible <
    NEGLIGIBLE_FRACTION·S_ref, low between)."""
    rows = []
    for name, g in fr.groupby("factor", sort=False):
        s = np.abs(g["S"].to_numpy())
        rows.append({"factor": name, "mean |S|": np.nanmean(s), "min |S|": np.nanmin(s), "max |S|": np.nanmax(s),
                     "unit": units.label(g["S_unit"].iloc[0])})
    d = pd.DataFrame(rows).sort_values("mean |S|", ascending=False).reset_index(drop=True)
    d["rvtol class"] = np.where(d["mean |S|"] >= HIGH_FRACTION * s_ref, "high",
                                np.where(d["mean |S|"] < NEGLIGIBLE_FRACTION * s_ref, "negligible", "low"))
    d.insert(0, "rank", np.arange(1, len(d) + 1))
    return d


def linearity(fr: pd.DataFrame) -> pd.DataFrame:
    """Δθ_er(2e) / Δθ_er(e) wherever both magnitudes were evaluated (2: the effect is proportional to e)."""
    rows = []
    for name, g in fr.groupby("factor", sort=False):
        y = dict(zip(g["magnitude"], g["y"]))
        for e in sorted(y):
            if 2 * e in y and y[e] > 0:
                rows.append({"factor": name, "e [µm]": e, "Δθ_er(e) [arcsec]": y[e], "Δθ_er(2e) [arcsec]": y[2 * e],
                             "ratio": y[2 * e] / y[e]})
    return pd.DataFrame(rows)


def te_sensitivity(model: TransmissionErrorModel, spec: ToleranceSpec, factors, magnitudes, percent: float = 10.0,
                   evaluate=None) -> TESensitivityResult:
    """S = dΔθ_er/de of each factor (one at a time, the others zero) at each magnitude (µm)."""
    from ...sensitivity import sensitivity_curve

    res = sensitivity_curve(model, spec, factors, magnitudes, "um", ["te_pp"], percent, False, evaluate)
    s_ref = units.from_base(1.0 / model.geometry.r_disc_pitch, "arcsec") * 1e-3
    return TESensitivityResult(list(factors), list(magnitudes), percent, res, ranking(res.frame, s_ref),
                               linearity(res.frame), s_ref, list(res.notes))
