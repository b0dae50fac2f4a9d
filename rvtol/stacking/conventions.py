"""Tolerance stack-up conventions: the figures engineers and peer tools quote, beside the Monte Carlo.

For an output y with the gradient ``a`` at the nominal point x0 (exact when the model has an
analytic ``gradient``, else five-point), each factor's band [lo_i, hi_i] (:attr:`rvtol.spec.Factor.band`:
the drawing's limits), half band t_i and centre c_i, the mean μ_i and standard deviation σ_i of its
distribution, and the linearised value at the band centres y_c = y0 + Σ a_i (c_i − x0_i):

===========================  ==========================================================  =====================
convention                   interval                                                    source
===========================  ==========================================================  =====================
worst case (arithmetic)      y_c ± Σ |a_i| t_i                                           [Fortini 1967]
RSS                          y_c ± √Σ (a_i s_i)², every band read as ±3σ (s_i = t_i)     [Scholz 1995 §4.1]
MRSS, Bender                 y_c ± 1.5 · RSS                                             [Bender 1968]
MRSS, handbook               y_c ± C_f · RSS, C_f = 1 + ½ (T_wc − T_rss) / (T_rss (√n − 1))  [Drake 1999 ch. 9]
MRSS, given factor           y_c ± C · RSS (``mrss_factor``)
statistical, distributions   μ_y ± z σ_y, μ_y = y0 + Σ a_i (μ_i − x0_i), σ_y = √(aᵀ C a)    [Scholz 1995 §4.2]
6σ static                    y_c ± (Σ |a_i| |μ_i − c_i| + z √Σ (a_i σ_i)²)                [Harry & Stewart 1988]
6σ dynamic RSS               y_c ± z √Σ (a_i σ_i / (1 − k_i))², k_i = |μ_i − c_i| / t_i    [Harry & Stewart 1988]
6σ dynamic, 1.5σ shift       y_c ± z √Σ (a_i t_i / (3 Cpk))², Cpk = Cp − 1.5/3 (Cp = 2:     [Harry & Stewart 1988]
                             Cpk = 1.5): every band read as a ±Cp·3σ process shifted 1.5σ
===========================  ==========================================================  =====================

(n: the contributors with a ≠ 0; C: the normal-score correlation of the spec, as Pearson's;
``z``: the sigma levels of the user's choice, 3 by default.)  The dynamic RSS turns each mean shift
into a wider σ (σ·Cp/Cpk = σ/(1 − k)), the static form adds the shifts arithmetically; both centre
on y_c.  MRSS can exceed the worst case for few contributors (n = 2 with Bender's 1.5): the table
says so rather than capping it.

Circular position zones (two coordinates sharing ``Factor.zone``, :mod:`rvtol.spec`) enter the
worst case as the disc, not the square: the pair contributes t · √(a_x² + a_y²) (the extreme of a
linear function over the zone) instead of t · (|a_x| + |a_y|); in the RSS each coordinate's ±3σ is
its own 3σ (the zone is the Rayleigh radius's 99.73 % quantile, not a ±3σ band).

The worst case that is the true extreme of a non-linear model is :mod:`rvtol.stacking.worst_case`.

References.  P. J. Drake Jr. (ed.), *Dimensioning and Tolerancing Handbook*, McGraw-Hill, 1999,
ch. 9 (the MRSS correction factor; this C_f reproduces the handbook's motor-assembly MRSS of
±0.05047 in, see ``data/examples/``).  A. Bender Jr., "Statistical tolerancing as it relates to
quality control and the designer", SAE paper 680490, 1968 (the factor 1.5; quoted from secondary
sources, the paper was not checked).  F. Scholz, *Tolerance Stack Analysis Methods*, Boeing
Information & Support Services, December 1995 (RSS, inflation factors for non-normal parts, mean
shifts).  M. J. Harry and R. Stewart, *Six Sigma Mechanical Design Tolerancing*, Motorola, 1988
(static and dynamic RSS, the 1.5σ shift; the formulas as commonly stated — they reproduce the
MITCalc demonstration stack in ``data/examples/``).  E. T. Fortini, *Dimensioning for
Interchangeable Manufacture*, Industrial Press, 1967 (arithmetic stacks).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from .. import units
from ..spec import ToleranceSpec
from ..stats import rss
from ..sensitivity.common import derivative_to_display, ratio_unit

#: Bender's inflation factor of the RSS
BENDER = 1.5
#: the Six Sigma convention: every band a ±Cp·3σ process (Cp = 2) with its mean shifted by 1.5σ
SIX_SIGMA_CP, SIX_SIGMA_SHIFT = 2.0, 1.5


def handbook_mrss_factor(t_wc: float, t_rss: float, n: int) -> float | None:
    """The MRSS correction factor C_f = 1 + ½ (T_wc − T_rss) / (T_rss (√n − 1)) (Drake 1999, ch. 9); None for n < 2."""
    if n < 2 or not t_rss > 0:
        return None
    return 1.0 + 0.5 * (t_wc - t_rss) / (t_rss * (math.sqrt(n) - 1.0))


@dataclass
class Contributors:
    """Per factor, base units: sensitivity a, band, centre, half band t, ±3σ reading s, mean, σ, k, zone."""

    names: list[str]
    a: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    mu: np.ndarray
    sigma: np.ndarray
    zone: list[str]

    @property
    def c(self) -> np.ndarray:
        return 0.5 * (self.lo + self.hi)

    @property
    def t(self) -> np.ndarray:
        return 0.5 * (self.hi - self.lo)

    @property
    def s(self) -> np.ndarray:
        """The tolerance read as ±3σ: the half band, or 3σ for a coordinate of a position zone."""
        return np.where([bool(z) for z in self.zone], 3.0 * self.sigma, self.t)

    @property
    def k(self) -> np.ndarray:
        """The mean shift over the half band, |μ − c| / t (0 for zone coordinates: centred by definition)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            k = np.abs(self.mu - self.c) / self.t
        return np.where([bool(z) for z in self.zone], 0.0, k)

    def worst_half_width(self) -> float:
        """Σ |a_i| t_i, a position zone's pair as the disc t·√(a_x² + a_y²)."""
        total, seen = 0.0, set()
        for i, z in enumerate(self.zone):
            if not z:
                total += abs(self.a[i]) * self.t[i]
            elif z not in seen:
                seen.add(z)
                j = [m for m, zz in enumerate(self.zone) if zz == z]
                total += self.t[i] * float(np.hypot(*self.a[j]))
        return total

    @property
    def n_active(self) -> int:
        return int(np.count_nonzero(self.a))


def contributors(spec: ToleranceSpec, gradient: np.ndarray) -> Contributors:
    """The contributors of an output with base-unit ``gradient`` (NaN → 0)."""
    b = lambda v, f: float(units.to_base(v, f.unit))  # noqa: E731
    fs = spec.factors
    return Contributors(list(spec.names), np.nan_to_num(np.asarray(gradient, float)),
                        np.array([b(f.band[0], f) for f in fs]), np.array([b(f.band[1], f) for f in fs]),
                        spec.mean_base(), spec.std_base(), [getattr(f, "zone", "") for f in fs])


@dataclass
class StackConventions:
    """The conventions' intervals for one output (display units) and the per-factor table."""

    output: str
    unit: str
    y_centre: float
    frame: pd.DataFrame          # convention, low, high, half_width, centre, sigma, note, source
    factors: pd.DataFrame        # factor, a, unit, band, t, sigma, k, Cp, Cpk, wc_pct, rss_pct
    notes: list[str] = field(default_factory=list)

    def row(self, convention: str) -> dict:
        r = self.frame[self.frame["convention"] == convention]
        if r.empty:
            raise KeyError(convention)
        return r.iloc[0].to_dict()

    def add(self, convention: str, low: float, high: float, *, centre: float | None = None,
            sigma: float | None = None, note: str = "", source: str = "") -> None:
        c = 0.5 * (low + high) if centre is None else centre
        row = {"convention": convention, "low": low, "high": high, "half_width": 0.5 * (high - low),
               "centre": c, "sigma": sigma, "note": note, "source": source}
        self.frame = pd.concat([self.frame, pd.DataFrame([row])], ignore_index=True)

    def summary(self) -> dict:
        return {"output": self.output, "unit": self.unit, "y_centre": self.y_centre,
                "conventions": self.frame.replace({np.nan: None}).to_dict("records"), "notes": self.notes}


def stack_conventions(spec: ToleranceSpec, gradient: np.ndarray, y0: float, x0: np.ndarray | None = None, *,
                      output: str = "y", out_unit: str = "1", out_base_unit: str | None = None,
                      sigma_levels=(3.0,), mrss_factor: float | None = None,
                      six_sigma: tuple[float, float] | None = (SIX_SIGMA_CP, SIX_SIGMA_SHIFT)) -> StackConventions:
    """Every convention of the module docstring for one output.

    ``gradient``: ∂y/∂x (output base unit per factor base unit) at ``x0`` (default the spec's nominal
    point) where the output is ``y0`` (base units); results in ``out_unit``.  ``six_sigma``: the (Cp,
    shift in σ) of the Six Sigma convention row, None to leave it out.
    """
    x0 = spec.nominal_base() if x0 is None else np.asarray(x0, dtype=float)
    con = contributors(spec, gradient)
    a = con.a
    ob = out_base_unit or units.base_unit(out_unit)
    d = lambda v: float(units.convert(v, ob, out_unit))  # noqa: E731
    yc = y0 + float(a @ (con.c - x0))
    mu_y = y0 + float(a @ (con.mu - x0))
    C = np.eye(len(spec)) if spec.correlation is None else np.asarray(spec.correlation)
    sig_y = rss(a * con.sigma, C)
    t_wc = con.worst_half_width()
    t_rss = rss(a * con.s)
    n = con.n_active
    notes = []
    rows = []

    def add(name, centre, half, sigma=None, note="", source=""):
        rows.append({"convention": name, "low": d(centre - half), "high": d(centre + half),
                     "half_width": d(half) if math.isfinite(half) else math.nan, "centre": d(centre),
                     "sigma": None if sigma is None else d(sigma), "note": note, "source": source})

    zone_note = " (position zones as discs)" if any(con.zone) else ""
    add("worst case (arithmetic)", yc, t_wc, note="every factor at the end of its band" + zone_note,
        source="Fortini 1967")
    add("RSS", yc, t_rss, sigma=t_rss / 3, note="every band read as ±3σ of a centred normal",
        source="Scholz 1995 §4.1")
    for name, cf, src in (("MRSS, Bender", BENDER, "Bender 1968 (SAE 680490)"),
                          ("MRSS, handbook", handbook_mrss_factor(t_wc, t_rss, n), "Drake 1999, ch. 9"),
                          ("MRSS, given factor", mrss_factor, "the study's mrss_factor")):
        if cf is None:
            if name == "MRSS, handbook":
                notes.append("MRSS (handbook) needs at least two contributors")
            continue
        half = cf * t_rss
        note = f"C_f = {cf:.4g} × RSS" + (" — wider than the worst case (few contributors)" if half > t_wc else "")
        add(name, yc, half, note=note, source=src)
    k = con.k
    for z in sigma_levels:
        add(f"statistical ±{z:g}σ (the distributions)", mu_y, z * sig_y, sigma=sig_y,
            note="mean and σ of each factor's own distribution" + (", correlation included"
                                                                   if spec.correlation is not None else ""),
            source="Scholz 1995 §4.2")
    shift = float(np.sum(np.abs(a) * np.abs(con.mu - con.c)))
    sig_plain = rss(a * con.sigma)
    with np.errstate(divide="ignore", invalid="ignore"):
        infl = np.where(k < 1.0, 1.0 / (1.0 - k), np.inf)
    sig_dyn = rss(a * con.sigma * infl)
    if not math.isfinite(sig_dyn):
        notes.append("a factor's mean lies outside its band (k ≥ 1): the dynamic RSS is undefined")
    for z in sigma_levels:
        add(f"6σ static ±{z:g}σ", yc, shift + z * sig_plain, sigma=sig_plain,
            note="the factors' mean shifts added arithmetically", source="Harry & Stewart 1988")
        add(f"6σ dynamic RSS ±{z:g}σ", yc, z * sig_dyn, sigma=sig_dyn,
            note="each σ inflated by Cp/Cpk = 1/(1 − k)", source="Harry & Stewart 1988")
    if six_sigma is not None:
        cp, sh = six_sigma
        cpk = cp - sh / 3.0
        sig_c = rss(a * con.s / (3.0 * cpk))
        for z in sigma_levels:
            add(f"6σ dynamic, {sh:g}σ shift ±{z:g}σ", yc, z * sig_c, sigma=sig_c,
                note=f"every band a ±{3 * cp:g}σ process (Cp {cp:g}) shifted {sh:g}σ (Cpk {cpk:g})",
                source="Harry & Stewart 1988")
    frame = pd.DataFrame(rows)
    # per factor
    fac = []
    wc_terms = np.abs(a) * con.t
    rss_terms = (a * con.s) ** 2
    for i, f in enumerate(spec.factors):
        cp_i = con.t[i] / (3 * con.sigma[i]) if con.sigma[i] > 0 else math.nan
        fac.append({"factor": f.name, "a": float(derivative_to_display(a[i], out_unit, f.unit)) * units.factor(ob),
                    "a_unit": ratio_unit(out_unit, f.unit), "band": f"{f.band[0]:.6g} … {f.band[1]:.6g}",
                    "unit": f.unit, "sigma": f.dist.std, "k": float(k[i]), "Cp": cp_i, "Cpk": cp_i * (1 - k[i]),
                    "zone": con.zone[i], "wc_pct": 100 * wc_terms[i] / wc_terms.sum() if wc_terms.sum() else 0.0,
                    "rss_pct": 100 * rss_terms[i] / rss_terms.sum() if rss_terms.sum() else 0.0})
    return StackConventions(output, out_unit, d(yc), frame, pd.DataFrame(fac), notes)
