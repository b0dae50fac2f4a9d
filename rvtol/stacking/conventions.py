"""Tolerance stack-up conventions: the figures engineers and peer tools quote, beside the Monte Carlo.

For an output y with the gradient ``a`` at the nominal point x0 (exact when the model has an
analytic ``gradient``, else five-point), each factor's band [lo_i, hi_i] (:attr:`rvtol.spec.Factor.band`:
the drawing's limits), half band t_i and centre c_i, the mean μ_i and standard deviation σ_i of its
distribution, and the linearised value at the band centres y_c = y0 + Σ a_i (c_i − x0_i):

===========================  ==========================================================  =====================
convention                   interval                                                    source
===========================  ==========================================================  =====================
worst case (arithmetic)      y_c ± Σ |a_i| t_i                                           [Fortini 1967]
RSS                          y_c ± √(sᵀ R s), s_i = a_i t_i: every band read as ±3σ       [Scholz 1995 §4.1]
MRSS, Bender                 y_c ± 1.5 · RSS                                             [Bender 1968]
MRSS, handbook               y_c ± C_f · RSS, C_f = 1 + ½ (T_wc − T_rss) / (T_rss (√n − 1))  [Drake 1999 ch. 9]
MRSS, given factor           y_c ± C · RSS (``mrss_factor``)
statistical, distributions   μ_y ± z σ_y, μ_y = y0 + Σ a_i (μ_i − x0_i), σ_y = √(vᵀ P v),   [Scholz 1995 §4.2]
                             v_i = a_i σ_i
6σ static                    y_c ± (Σ |a_i| |μ_i − c_i| + z √(vᵀ P v))                      [Harry & Stewart 1988]
6σ dynamic RSS               y_c ± z √(wᵀ P w), w_i = a_i σ_i / (1 − k_i),                  [Harry & Stewart 1988]
                             k_i = |μ_i − c_i| / t_i
6σ dynamic, 1.5σ shift       y_c ± z √(eᵀ R e), e_i = a_i t_i / (3 Cpk), Cpk = Cp − 1.5/3   [Harry & Stewart 1988]
                             (Cp = 2: Cpk = 1.5): every band read as a ±Cp·3σ process
                             shifted 1.5σ
===========================  ==========================================================  =====================

(n: the contributors with a ≠ 0; ``z``: the sigma levels of the user's choice, 3 by default.)

Correlation.  Every row that adds variances honours the spec's correlation (σ² = cᵀ Σ c, the variance of a
linear function of correlated factors): the rows that read each band as a normal (RSS, MRSS, the 1.5σ shift)
with R, the spec's normal-score correlation, which is the correlation of those normals; the rows of the
factors' own distributions (statistical, 6σ static and dynamic) with P, the Pearson correlation that the
Gaussian copula gives those distributions (:func:`rvtol.sampling.factor_correlation`; P = R for two normal factors, |P| < |R|
otherwise).  Each row's note says so.  A one-sided contributor (below) has no sign to correlate: its
correlation, if the spec gives one, is left out and the row's note names it.  The dynamic RSS turns each mean shift
into a wider σ (σ·Cp/Cpk = σ/(1 − k)), the static form adds the shifts arithmetically; both centre
on y_c.  MRSS can exceed the worst case for few contributors (n = 2 with Bender's 1.5): the table
says so rather than capping it.

Circular position zones (two coordinates sharing ``Factor.zone``, :mod:`rvtol.spec`) enter the
worst case as the disc, not the square: the pair contributes t · √(a_x² + a_y²) (the extreme of a
linear function over the zone) instead of t · (|a_x| + |a_y|); in the RSS each coordinate's ±3σ is
its own 3σ (the zone is the Rayleigh radius's 99.73 % quantile, not a ±3σ band).

Non-smooth outputs.  A derivative at the nominal point says nothing about a kink there: a norm of a
centred position zone (the clearance of a floating fastener, −|p₁ − p₂|) has no gradient, an
``abs`` or a ``min``/``max`` at a tie has two.  Given the model's one-sided slopes
(:mod:`rvtol.stacking.slopes`), every contributor whose two sides disagree is treated by the side that
hurts: a factor adds t·max(0, D⁺, D⁻) to the upper worst case and t·max(0, −D⁺, −D⁻) to the lower; a
kinked position zone of diameter t adds (t/2)·max(0, max_φ D) above and (t/2)·max(0, −min_φ D) below —
"a position tolerance ⌀t contributes t/2 in the direction that hurts" (Drake 1999 ch. 9), the direction
and the effect per unit radius measured on the model.  The RSS and the statistical rows read such a
contributor as bilateral, ±(t/2)·(its largest one-sided slope) — the handbooks' equal-bilateral
conversion — which is an approximation for a one-sided effect (said in the notes; the Monte Carlo and
the second-order rows are the reference).  A derivative that is NaN or infinite is never read as 0:
with slopes it is replaced by their central difference (noted; a kinked zone's by its sides), else it is an error.

Material condition (ASME Y14.5-2018 §7.3.3, ISO 2692).  A zone at MMC or LMC grows with the bonus of its
feature's actual size (:func:`rvtol.spec.zone_bonus`: the radius r = t/2 + κ (x_s − ref_s), κ = ±½).  A
datum feature of size referenced at MMB adds one more disc, shared: its departure from MMB lets the whole
pattern of zones that reference it translate by one vector s, |s| ≤ r_d = κ (x_d − ref_d)
(:func:`rvtol.spec.datum_shifts`, the simultaneous requirement; a zone marked ``separate``, SEP REQT, has its own
disc), whose effect per unit of shift is
|Σ_z ∇_z y| — the zones' gradients added (0 for a distance within the pattern) — or, where a zone is
kinked, the model's one-sided slopes with the pattern moved as one.  The worst-case rows take these discs
exactly for the linearised output: the lower end is y_c − Σ_z lo_z r_z(c) − Σ_i t_i · max(0, −(D⁺_i − Σ_z
lo_z κ_z), −(D⁻_i + Σ_z lo_z κ_z)), the upper end likewise with hi_z (z over the zones and the datum
shifts) — each size factor's effect through the disc it enlarges added to its own.  The RSS reads each disc
at its radius at the size's band centre and the size with that coupled sensitivity; the statistical rows
describe the produced parts, whose deviations the bonus and the shift do not change (they widen
acceptance, not the process).

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
from ..errors import InputError

from ..sampling import factor_correlation
from ..spec import ToleranceSpec, datum_shifts, zone_bonus
from ..stats import rss
from . import notes as N
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
    """The contributors of an output with base-unit ``gradient`` (finite: see :func:`stack_conventions`)."""
    b = lambda v, f: float(units.to_base(v, f.unit))  # noqa: E731
    fs = spec.factors
    g = np.asarray(gradient, float)
    if not np.all(np.isfinite(g)):
        bad = [spec.names[i] for i in np.flatnonzero(~np.isfinite(g))]
        raise InputError(f"the derivative of the output is undefined (NaN or ∞) for {', '.join(bad[:5])}"
                         f"{' …' if len(bad) > 5 else ''}: it cannot be read as 0; give the model's one-sided "
                         "slopes (rvtol.stacking.slopes) so the side that hurts is taken", key="gradient")
    return Contributors(list(spec.names), g,
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


@dataclass
class _OneSided:
    """A contributor the linearised rows take by its sides: a kinked factor or zone, or a zone at MMC/LMC."""

    name: str
    unit: float          # half band (factor) or radius at the size centres (zone), base units
    hi: float            # upper worst-case effect per unit of ``unit`` (≥ 0)
    lo: float            # lower worst-case effect per unit (≥ 0)
    sigma: float         # σ of the factor or of one zone coordinate
    s: float             # the band read as ±3σ (the half band, or 3σ of a zone coordinate)
    zone: str = ""
    kinked: bool = False
    bonus: list = field(default_factory=list)   # [(factor index, κ)] of a zone's radius
    datum: str = ""      # a datum-feature shift: the datum's size factor (the pattern's one translation)
    zones: tuple = ()    # a datum-feature shift: the zones it moves together

    @property
    def plain(self) -> bool:
        """A plain factor (kinked), not a zone or a datum-feature shift."""
        return not self.zone and not self.datum


def _linear_parts(spec: ToleranceSpec, gradient: np.ndarray, slopes, notes: list) -> tuple[np.ndarray, list, dict]:
    """The smooth gradient (kinked and undefined entries resolved), the one-sided contributors, and the plain factors'
    one-sided slopes {i: (D⁺, D⁻)} of the kinked ones."""
    g = np.array(gradient, dtype=float)
    names = spec.names
    zone_of = [f.zone for f in spec.factors]
    bad = [i for i in range(len(g)) if not np.isfinite(g[i])]
    if bad and slopes is None:
        contributors(spec, g)   # raises: an undefined derivative is never read as 0
    kinked_plain: dict[int, tuple[float, float]] = {}
    kinked_zones = set()
    if slopes is not None:
        kinked_zones = {z for z in slopes.kinked if z in zone_of}
        undefined = [n for n in slopes.undefined if n in names or n in zone_of]   # a plain factor or a zone
        if undefined:
            raise InputError(f"the model cannot be evaluated next to the nominal point for {', '.join(undefined)}: "
                             "no linearised stack", key="gradient")
        for i in range(len(g)):
            if zone_of[i]:
                if not np.isfinite(g[i]):   # a kinked zone is taken by its sides (its gradient is zeroed below)
                    g[i] = 0.0 if zone_of[i] in kinked_zones else slopes.zone_grad[zone_of[i]][
                        0 if spec.factors[i].name == _zone_pair(spec, zone_of[i])[0] else 1]
                continue
            if names[i] in slopes.kinked:
                kinked_plain[i] = (float(slopes.up[i]), float(slopes.down[i]))
                g[i] = 0.0
            elif not np.isfinite(g[i]):
                g[i] = slopes.central(i)
        replaced = [names[i] for i in bad if not zone_of[i] or zone_of[i] not in kinked_zones]
        if replaced:
            notes.append(N.UNDEFINED_DERIVATIVE.format(names=", ".join(replaced)))
    return g, sorted(kinked_zones), kinked_plain


def _zone_pair(spec: ToleranceSpec, z: str) -> tuple[str, str]:
    return tuple(f.name for f in spec.factors if f.zone == z)


def stack_conventions(spec: ToleranceSpec, gradient: np.ndarray, y0: float, x0: np.ndarray | None = None, *,
                      output: str = "y", out_unit: str = "1", out_base_unit: str | None = None,
                      sigma_levels=(3.0,), mrss_factor: float | None = None,
                      six_sigma: tuple[float, float] | None = (SIX_SIGMA_CP, SIX_SIGMA_SHIFT),
                      slopes=None) -> StackConventions:
    """Every convention of the module docstring for one output.

    ``gradient``: ∂y/∂x (output base unit per factor base unit) at ``x0`` (default the spec's nominal
    point) where the output is ``y0`` (base units); results in ``out_unit``.  ``six_sigma``: the (Cp,
    shift in σ) of the Six Sigma convention row, None to leave it out.  ``slopes``: the model's one-sided
    slopes at ``x0`` (:func:`rvtol.stacking.slopes.one_sided_slopes`): kinked contributors are then taken by
    the side that hurts and undefined derivatives by their central difference; without them an undefined
    derivative is an error.
    """
    x0 = spec.nominal_base() if x0 is None else np.asarray(x0, dtype=float)
    notes: list[str] = []
    gradient, kinked_zones, kinked_plain = _linear_parts(spec, gradient, slopes, notes)
    con = contributors(spec, gradient)
    a = con.a
    ob = out_base_unit or units.base_unit(out_unit)
    d = lambda v: float(units.convert(v, ob, out_unit))  # noqa: E731
    sided = _one_sided(spec, con, a, kinked_plain, kinked_zones, slopes, notes, d)
    bonus_zone = {o.zone for o in sided if o.bonus and o.zone}
    plain_in_sided = {spec.names.index(o.name) for o in sided if o.plain}
    yc = y0 + float(a @ (con.c - x0))
    mu_y = y0 + float(a @ (con.mu - x0))
    # the correlations (module docstring): R of the normals the bands are read as, P of the distributions
    R, P = spec.correlation, factor_correlation(spec)
    # the statistical rows: the produced parts (no bonus); kinked contributors as ±(largest slope)·σ
    a_stat = a.copy()
    for o in sided:
        if o.zone and not o.kinked:   # a smooth zone at MMC: its coordinates as they are
            ix, iy = [m for m, zz in enumerate(con.zone) if zz == o.zone]
            a_stat[ix], a_stat[iy] = a[ix], a[iy]
    extra_sig2 = rss([max(o.hi, o.lo) * o.sigma for o in sided if o.kinked], squared=True)
    sig_y = math.sqrt(rss(a_stat * con.sigma, P, squared=True) + extra_sig2)
    zone_idx = {m for o in sided if o.zone for m, zz in enumerate(con.zone) if zz == o.zone}
    if not sided:
        t_wc = con.worst_half_width()
        wc_low, wc_high = yc - t_wc, yc + t_wc
        t_rss = rss(a * con.s, R)
    else:
        wc_low, wc_high = _worst_sided(con, a, sided, yc)
        t_wc = 0.5 * (wc_high - wc_low)
        a_rss = a.copy()
        for o in sided:
            down = o.lo >= o.hi
            for m, kap in o.bonus:
                a_rss[m] += -o.lo * kap if down else o.hi * kap
        signed = np.array([a_rss[m] * con.s[m] if m not in zone_idx and m not in plain_in_sided else 0.0
                           for m in range(len(spec))])
        t_rss = math.sqrt(rss(signed, R, squared=True) + rss([max(o.hi, o.lo) * o.unit for o in sided], squared=True))
    # one-sided contributors have no sign to correlate: name those the spec correlates
    unsigned = sorted(zone_idx | plain_in_sided)
    uncorrelated = "" if R is None else ", ".join(
        spec.names[m] for m in unsigned if np.any(np.delete(np.asarray(R)[m], m) != 0.0))
    kinked_idx = [m for m in unsigned if m in plain_in_sided or any(o.kinked and o.zone == con.zone[m] for o in sided)]
    stat_uncorrelated = "" if R is None else ", ".join(
        spec.names[m] for m in kinked_idx if np.any(np.delete(np.asarray(R)[m], m) != 0.0))

    def correlation_note(template, left_out):
        if R is None:
            return ""
        return template + (N.CORRELATION_LEFT_OUT.format(names=left_out) if left_out else "")
    n = (con.n_active + len(kinked_plain) + sum(2 for o in sided if o.kinked and o.zone)
         + sum(1 for o in sided if o.datum and max(o.hi, o.lo) > 0))
    rows = []

    def add(name, centre, half, sigma=None, note="", source="", low=None, high=None):
        lo_, hi_ = (centre - half, centre + half) if low is None else (low, high)
        rows.append({"convention": name, "low": d(lo_), "high": d(hi_),
                     "half_width": d(half) if math.isfinite(half) else math.nan, "centre": d(centre),
                     "sigma": None if sigma is None else d(sigma), "note": note, "source": source})

    zone_note = N.ZONES_AS_DISCS if any(con.zone) else ""
    if any(o.kinked for o in sided):
        zone_note += N.KINKED_ONE_SIDED
    if bonus_zone:
        zone_note += N.ZONES_WITH_BONUS
    if any(o.datum for o in sided):
        zone_note += N.PATTERN_SHIFTS
    add("worst case (arithmetic)", 0.5 * (wc_low + wc_high) if sided else yc, t_wc,
        note=N.WORST_CASE.format(zones=zone_note), source="Fortini 1967", low=wc_low, high=wc_high)
    rss_corr = correlation_note(N.CORRELATION_OF_NORMALS, uncorrelated)
    add("RSS", yc, t_rss, sigma=t_rss / 3, note=N.RSS.format(sided=N.RSS_SIDED if sided else "", correlation=rss_corr),
        source="Scholz 1995 §4.1")
    for name, cf, src in (("MRSS, Bender", BENDER, "Bender 1968 (SAE 680490)"),
                          ("MRSS, handbook", handbook_mrss_factor(t_wc, t_rss, n), "Drake 1999, ch. 9"),
                          ("MRSS, given factor", mrss_factor, "the study's mrss_factor")):
        if cf is None:
            if name == "MRSS, handbook":
                notes.append(N.MRSS_FEW)
            continue
        half = cf * t_rss
        add(name, yc, half, note=N.MRSS.format(cf=cf, wider=N.MRSS_WIDER if half > t_wc else "") + rss_corr,
            source=src)
    k = con.k
    stat_corr = correlation_note(N.CORRELATION_OF_DISTRIBUTIONS, stat_uncorrelated)
    for z in sigma_levels:
        add(f"statistical ±{z:g}σ (the distributions)", mu_y, z * sig_y, sigma=sig_y,
            note=N.STATISTICAL.format(correlation=stat_corr, kinked=N.STATISTICAL_KINKED if extra_sig2 else ""),
            source="Scholz 1995 §4.2")
    shift = float(np.sum(np.abs(a) * np.abs(con.mu - con.c)))
    with np.errstate(divide="ignore", invalid="ignore"):   # 1/(1 − k) at k = 1; 0·∞ of a factor with no effect
        infl = np.where(k < 1.0, 1.0 / (1.0 - k), np.inf)
        inflated = np.where(a_stat != 0.0, a_stat * con.sigma * infl, 0.0)
    sig_dyn = math.sqrt(rss(inflated, P, squared=True) + extra_sig2) if np.all(np.isfinite(inflated)) else math.inf
    if not math.isfinite(sig_dyn):
        notes.append(N.DYNAMIC_UNDEFINED)
    for z in sigma_levels:
        add(f"6σ static ±{z:g}σ", yc, shift + z * sig_y, sigma=sig_y,
            note=N.SIX_SIGMA_STATIC + stat_corr, source="Harry & Stewart 1988")
        add(f"6σ dynamic RSS ±{z:g}σ", yc, z * sig_dyn, sigma=sig_dyn,
            note=N.SIX_SIGMA_DYNAMIC + stat_corr, source="Harry & Stewart 1988")
    if six_sigma is not None:
        cp, sh = six_sigma
        cpk = cp - sh / 3.0
        sig_c = math.sqrt(rss(a * con.s / (3.0 * cpk), R, squared=True)   # kinked contributors: a = 0, below
                          + rss([max(o.hi, o.lo) * o.s / (3.0 * cpk) for o in sided if o.kinked], squared=True))
        for z in sigma_levels:
            add(f"6σ dynamic, {sh:g}σ shift ±{z:g}σ", yc, z * sig_c, sigma=sig_c,
                note=N.SIX_SIGMA_SHIFT.format(width=3 * cp, cp=cp, shift=sh, cpk=cpk)
                + correlation_note(N.CORRELATION_OF_NORMALS, stat_uncorrelated), source="Harry & Stewart 1988")
    frame = pd.DataFrame(rows)
    fac = _factor_rows(spec, con, a, sided, out_unit, ob)
    return StackConventions(output, out_unit, d(yc), frame, pd.DataFrame(fac), notes)


def _one_sided(spec: ToleranceSpec, con: Contributors, a: np.ndarray, kinked_plain: dict, kinked_zones, slopes,
               notes: list, d) -> list[_OneSided]:
    """The one-sided contributors: kinked plain factors, kinked zones, zones at MMC/LMC, datum-feature shifts (a kinked
    zone's coordinates in ``a`` are set to 0: its sides take it)."""
    a_smooth = a.copy()   # the zones' gradients before the kinked ones are taken by their sides
    sided: list[_OneSided] = []
    for i, (up, dn) in kinked_plain.items():
        sided.append(_OneSided(spec.names[i], float(con.t[i]), max(0.0, up, dn), max(0.0, -up, -dn),
                               float(con.sigma[i]), float(con.t[i]), kinked=True))
        notes.append(N.KINKED_FACTOR.format(name=spec.names[i], up=up, down=dn))
    for z in dict.fromkeys(zz for zz in con.zone if zz):
        ix, iy = [m for m, zz in enumerate(con.zone) if zz == z]
        bonus = zone_bonus(spec, z)
        if z not in kinked_zones and not bonus:
            continue
        r0 = float(con.t[ix]) + sum(kap * (float(con.c[m]) - ref) for m, kap, ref in bonus)
        if z in kinked_zones:
            hi, lo = max(0.0, float(slopes.zone_max[z])), max(0.0, -float(slopes.zone_min[z]))
            a[ix] = a[iy] = 0.0
            notes.append(N.KINKED_ZONE.format(zone=z, hi=hi, lo=lo))
        else:
            hi = lo = float(np.hypot(a[ix], a[iy]))
        sided.append(_OneSided(z, r0, hi, lo, float(con.sigma[ix]), float(con.s[ix]), zone=z,
                               kinked=z in kinked_zones, bonus=[(m, kap) for m, kap, _ in bonus]))
        if bonus:
            notes.append(N.ZONE_BONUS.format(zone=z, modifier=spec.factors[ix].modifier, radius=d(r0),
                                             sizes=", ".join(spec.names[m] for m, _, _ in bonus)))
    sided += _pattern_shifts(spec, con, a_smooth, kinked_zones, slopes, notes, d)
    return sided


def _factor_rows(spec: ToleranceSpec, con: Contributors, a: np.ndarray, sided: list, out_unit: str,
                 ob: str) -> list[dict]:
    """Per factor: its coefficient, band, σ, k, Cp, Cpk, zone, its share of the worst case and of the RSS, and how a
    one-sided contributor was linearised."""
    k = con.k
    fac = []
    wc_terms = np.abs(a) * con.t
    for o in sided:
        if o.datum:      # the shift its departure from MMB allows, beside the datum feature's own effect
            wc_terms[o.bonus[0][0]] += max(o.hi, o.lo) * o.unit
        elif not o.zone:
            wc_terms[spec.names.index(o.name)] = max(o.hi, o.lo) * o.unit
        else:
            ix = [m for m, zz in enumerate(con.zone) if zz == o.zone]
            wc_terms[ix] = 0.5 * max(o.hi, o.lo) * o.unit
    rss_terms = (a * con.s) ** 2
    for o in sided:
        if o.kinked:
            w = (max(o.hi, o.lo) * o.unit) ** 2
            if o.zone:
                rss_terms[[m for m, zz in enumerate(con.zone) if zz == o.zone]] = 0.5 * w
            else:
                rss_terms[spec.names.index(o.name)] = w
    side_of = {o.name: o for o in sided if o.plain}
    side_of.update({spec.names[o.bonus[0][0]]: o for o in sided if o.datum})
    side_of.update({spec.names[m]: o for o in sided if o.zone for m, zz in enumerate(con.zone) if zz == o.zone})
    for i, f in enumerate(spec.factors):
        cp_i = con.t[i] / (3 * con.sigma[i]) if con.sigma[i] > 0 else math.nan
        o = side_of.get(f.name)
        how = ""
        if o is not None and o.datum:
            how = f"datum feature at MMB: shifts {', '.join(o.zones)} together (per unit up {o.hi:.4g}, down {o.lo:.4g})"
        elif o is not None and o.kinked:
            how = f"kink: per unit {'radius' if o.zone else 'of band'} up {o.hi:.4g}, down {o.lo:.4g}"
        elif o is not None:
            how = f"zone at {f.modifier}"
        fac.append({"factor": f.name, "a": float(derivative_to_display(a[i], out_unit, f.unit)) * units.factor(ob),
                    "a_unit": ratio_unit(out_unit, f.unit), "band": f"{f.band[0]:.6g} … {f.band[1]:.6g}",
                    "unit": f.unit, "sigma": f.dist.std, "k": float(k[i]), "Cp": cp_i, "Cpk": cp_i * (1 - k[i]),
                    "zone": con.zone[i], "wc_pct": 100 * wc_terms[i] / wc_terms.sum() if wc_terms.sum() else 0.0,
                    "rss_pct": 100 * rss_terms[i] / rss_terms.sum() if rss_terms.sum() else 0.0,
                    **({"linearisation": how} if sided else {})})
    return fac


def _pattern_shifts(spec: ToleranceSpec, con: Contributors, a: np.ndarray, kinked_zones, slopes, notes: list,
                    d) -> list[_OneSided]:
    """The datum-feature shifts (:func:`rvtol.spec.datum_shifts`) as one-sided contributors: a disc of radius
    κ (x_d − reference) (at the datum's band centre) that moves every zone it locates by the same vector; per unit
    of shift the output changes by |Σ_z ∇_z y| (smooth zones: the gradients of the pattern's zones added), or by the
    extremes of the model's slopes with the pattern moved as one (:func:`rvtol.stacking.slopes.one_sided_slopes`)
    where a zone is kinked.  ``a``: the gradient before kinked zones are zeroed; ``d``: base → display unit."""
    out = []
    for ds in datum_shifts(spec):
        pairs = [[m for m, zz in enumerate(con.zone) if zz == z] for z in ds.zones]
        r0 = ds.kappa * (float(con.c[ds.index]) - ds.reference)
        if any(z in kinked_zones for z in ds.zones):
            if slopes is None or ds.label not in slopes.pattern_max:
                raise InputError(f"the model cannot be evaluated with the pattern located by datum feature {ds.label} "
                                 f"({', '.join(ds.zones)}) shifted: no linearised stack", key="gradient")
            hi, lo = max(0.0, float(slopes.pattern_max[ds.label])), max(0.0, -float(slopes.pattern_min[ds.label]))
        else:
            hi = lo = float(np.hypot(sum(a[ix] for ix, _ in pairs), sum(a[iy] for _, iy in pairs)))
        out.append(_OneSided(ds.label, r0, hi, lo, 0.0, 0.0, datum=ds.label, zones=ds.zones,
                             bonus=[(ds.index, ds.kappa)]))
        notes.append((N.DATUM_SHIFT_SEPARATE if ds.separate else N.DATUM_SHIFT).format(datum=ds.label, zones=", ".join(ds.zones), radius=d(r0), hi=hi, lo=lo))
    return out


def _worst_sided(con: Contributors, a: np.ndarray, sided: list[_OneSided], yc: float) -> tuple[float, float]:
    """The linearised worst case with one-sided contributors and zones whose radius grows with sizes (module
    docstring): (low, high) in base units."""
    k = len(a)
    zone_idx = {m for o in sided if o.zone for m, zz in enumerate(con.zone) if zz == o.zone}
    plain_sided = {o.name: o for o in sided if o.plain}
    up = a.astype(float).copy()   # D⁺ per factor (kinked ones: their hi/lo below)
    dn = -up                      # D⁻
    low = high = yc
    # smooth zones without bonus: the disc
    seen = set()
    for m in range(k):
        z = con.zone[m]
        if z and m not in zone_idx and z not in seen:
            seen.add(z)
            j = [q for q, zz in enumerate(con.zone) if zz == z]
            w = float(con.t[m]) * float(np.hypot(*a[j]))
            low, high = low - w, high + w
    up_hi, dn_hi, up_lo, dn_lo = up.copy(), dn.copy(), up.copy(), dn.copy()
    for o in sided:      # zones and datum-feature shifts: a disc of radius ``unit`` growing with sizes
        if o.plain:
            continue
        low -= o.lo * o.unit
        high += o.hi * o.unit
        for m, kap in o.bonus:
            up_hi[m] += o.hi * kap
            dn_hi[m] -= o.hi * kap
            up_lo[m] -= o.lo * kap
            dn_lo[m] += o.lo * kap
    for i in range(k):
        if con.zone[i]:
            continue
        o = plain_sided.get(con.names[i])
        if o is not None:
            high += o.hi * o.unit
            low -= o.lo * o.unit
            continue
        t = float(con.t[i])
        high += t * max(0.0, up_hi[i], dn_hi[i])
        low -= t * max(0.0, -up_lo[i], -dn_lo[i])
    return low + 0.0, high + 0.0
