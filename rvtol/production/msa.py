"""Measurement systems analysis: a crossed gauge R&R study by the ANOVA method, and the gauge's uncertainty.

**The study** (AIAG, *Measurement Systems Analysis*, 4th ed., 2010, ch. III §B, "Analysis of Variance (ANOVA)
Method"): ``p`` parts, each measured ``n`` times (trials) by each of ``a`` appraisers, in random order —
a balanced crossed design.  The random-effects model of a reading is ::

    y_ijk = μ + P_i + A_j + (PA)_ij + ε_ijk,   P ~ N(0, σ²_P), A ~ N(0, σ²_A), PA ~ N(0, σ²_PA), ε ~ N(0, σ²_E)

and the two-way ANOVA with interaction (ȳ the grand mean, ȳ_i.., ȳ_.j., ȳ_ij. the part, appraiser and cell
means) ::

    SS_P  = a n Σ_i (ȳ_i.. − ȳ)²                        df p − 1
    SS_A  = p n Σ_j (ȳ_.j. − ȳ)²                        df a − 1
    SS_PA = n Σ_ij (ȳ_ij. − ȳ_i.. − ȳ_.j. + ȳ)²         df (p − 1)(a − 1)
    SS_E  = Σ_ijk (y_ijk − ȳ_ij.)²                      df p a (n − 1)

with the random-effects F tests F_PA = MS_PA / MS_E, F_P = MS_P / MS_PA, F_A = MS_A / MS_PA (p-values from
``scipy.stats.f``).  The expected mean squares E[MS_E] = σ²_E, E[MS_PA] = σ²_E + n σ²_PA,
E[MS_A] = σ²_E + n σ²_PA + p n σ²_A, E[MS_P] = σ²_E + n σ²_PA + a n σ²_P give the variance components
(Montgomery, *Design and Analysis of Experiments*, §13.3; AIAG MSA Table III-B 6) ::

    σ²_E  = MS_E                       repeatability (equipment variation, EV)
    σ²_PA = (MS_PA − MS_E) / n         interaction, part of reproducibility
    σ²_A  = (MS_A − MS_PA) / (p n)     appraiser, part of reproducibility (AV)
    σ²_P  = (MS_P − MS_PA) / (a n)     part variation (PV)

a negative estimate set to 0 (AIAG; Minitab "if a variance component is negative, it is reported as zero").

**Pooling the interaction.**  When the interaction's p-value exceeds ``interaction_alpha`` (default **0.25**)
it is pooled into repeatability: the model is refitted without it, MS_E' = (SS_PA + SS_E) / (df_PA + df_E),
σ²_E = MS_E', σ²_PA = 0, σ²_A = (MS_A − MS_E') / (p n), σ²_P = (MS_P − MS_E') / (a n), and the F tests use
MS_E'.  0.25 is the level Bancroft recommended for such a preliminary test before pooling ("sometimes
pool": Bancroft, *Biometrics* 20, 1964, 427–442; Montgomery, *Design and Analysis of Experiments*, on pooling
a non-significant interaction) — a high level, so that an interaction that is there is kept.  Minitab's
default is 0.05 (its gauge R&R settings: "Alpha to remove interaction term … The default value is 0.05. Use a
higher significance level, such as 0.10 or 0.25, if you want to be more likely to keep the interaction in the
model"); give ``interaction_alpha = 0.05`` for Minitab's reading.

**The figures** (AIAG MSA ch. III; Minitab's crossed gauge R&R "Methods and formulas"):
GRR = σ²_E + σ²_A + σ²_PA (reproducibility AV² = σ²_A + σ²_PA), TV = GRR + σ²_P;
%Contribution = 100 · σ²_x / σ²_TV; %Study variation = 100 · σ_x / σ_TV (= 100 · 6σ_x / 6σ_TV);
%Tolerance = 100 · 6σ_x / (USL − LSL) when a tolerance is given; the number of distinct categories
ndc = ⌊1.41 · σ_P / σ_GRR⌋ (√2 · PV/GRR, AIAG: at least 5).  AIAG's acceptance reading of %GRR (of study
variation or of tolerance): under 10 % acceptable, 10 % to 30 % may be acceptable (application, cost of the
gauge), over 30 % unacceptable.

**The gauge's measurement uncertainty** (GUM, JCGM 100:2008).  A reading of one part by one appraiser,
once, differs from the part's value by A_j + (PA)_ij + ε_ijk: its variance about the part's value is
σ²_GRR, estimated from the study's series of readings by analysis of variance — a Type A evaluation
(GUM 4.2; GUM annex H.5 evaluates variance components the same way).  A calibration uncertainty u_cal of the
gauge's reference (a Type B evaluation, GUM 4.3: the certificate's expanded U over its k) is independent of
it and enters with unit sensitivity, so the combined standard uncertainty of a reading is
u = √(σ²_GRR + u²_cal) (GUM 5.1.2).  The bias of the gauge is not in u: it is corrected by calibration, not
estimated by a gauge R&R study.

**The study file** (CSV, TSV or XLSX, :func:`rvtol.inputs.sheets.read_table`; ``#`` comment rows), one
reading per row ::

    # CMM form probe, 2026-03: 10 cams × 3 appraisers × 3 trials
    part, appraiser, trial, value [um]
    1, A, 1, 0.29
    1, A, 2, 0.41

``part`` and ``appraiser`` label the part and the appraiser (text or numbers), ``trial`` (optional) numbers
the repeat — a (part, appraiser, trial) given twice is an error —, ``value`` is the reading (its unit in
brackets).  Every appraiser measures every part the same number of times (at least 2 parts, 2 appraisers,
2 trials); every problem is one located :class:`~rvtol.errors.InputError`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from ..errors import InputError
from ..inputs.sheets import Table, read_table

#: the pooling level of a non-significant part × appraiser interaction (module docstring)
INTERACTION_ALPHA = 0.25
#: the study variation is this many standard deviations (AIAG 4th ed.; 5.15 in the 3rd)
STUDY_VARIATION = 6.0
#: AIAG's reading of %GRR: below the first acceptable, up to the second conditionally, above unacceptable
ACCEPTABLE, CONDITIONAL = 10.0, 30.0
COLUMNS = ("part", "appraiser", "trial", "value")


def acceptance(percent: float) -> str:
    """AIAG's reading of a %GRR (of study variation or tolerance): < 10 acceptable, 10 to 30 conditionally
    acceptable, > 30 unacceptable."""
    if percent < ACCEPTABLE:
        return "acceptable"
    if percent <= CONDITIONAL:
        return "conditionally acceptable"
    return "unacceptable"


@dataclass(frozen=True)
class AnovaRow:
    source: str
    df: int
    ss: float
    ms: float
    f: float | None = None
    p: float | None = None


@dataclass(frozen=True)
class GaugeRR:
    """A crossed gauge R&R study's ANOVA and variance components (module docstring)."""

    readings: np.ndarray              # [parts, appraisers, trials]
    parts: tuple[str, ...]
    appraisers: tuple[str, ...]
    anova: tuple[AnovaRow, ...]       # the full model (with interaction)
    anova_used: tuple[AnovaRow, ...]  # the model the components come from (interaction pooled or not)
    interaction_p: float
    pooled: bool
    var_repeatability: float
    var_appraiser: float
    var_interaction: float
    var_part: float
    tolerance: float | None = None
    interaction_alpha: float = INTERACTION_ALPHA
    study_variation: float = STUDY_VARIATION
    unit: str | None = None           # the readings' unit as the file gives it
    file: str = ""
    sha256: str = ""

    @property
    def shape(self) -> tuple[int, int, int]:
        return self.readings.shape

    @property
    def var_reproducibility(self) -> float:
        return self.var_appraiser + self.var_interaction

    @property
    def var_grr(self) -> float:
        return self.var_repeatability + self.var_reproducibility

    @property
    def var_total(self) -> float:
        return self.var_grr + self.var_part

    @property
    def sigma_grr(self) -> float:
        return math.sqrt(self.var_grr)

    @property
    def ndc(self) -> int:
        """Number of distinct categories ⌊1.41 σ_P / σ_GRR⌋ (AIAG)."""
        return math.floor(1.41 * math.sqrt(self.var_part) / self.sigma_grr)

    @property
    def percent_study_variation(self) -> float:
        """%GRR of the study variation, 100 σ_GRR / σ_TV."""
        return 100.0 * self.sigma_grr / math.sqrt(self.var_total)

    @property
    def percent_tolerance(self) -> float | None:
        """%GRR of the tolerance, 100 · k σ_GRR / (USL − LSL) (k the study variation, 6), or None."""
        return None if self.tolerance is None else 100.0 * self.study_variation * self.sigma_grr / self.tolerance

    @property
    def acceptance(self) -> str:
        """AIAG's reading of %GRR: of the tolerance when one is given, else of the study variation."""
        pct = self.percent_tolerance if self.tolerance is not None else self.percent_study_variation
        return acceptance(pct)

    def uncertainty(self, calibration: float = 0.0) -> float:
        """The standard uncertainty of one reading, √(σ²_GRR + u_cal²) (GUM; module docstring)."""
        return math.sqrt(self.var_grr + float(calibration) ** 2)

    def components(self) -> pd.DataFrame:
        """The gauge R&R table: per source VarComp, %Contribution, StdDev, study variation (6σ), %Study var and,
        with a tolerance, %Tolerance."""
        tv = self.var_total
        rows = [("Total gauge R&R (GRR)", self.var_grr), ("  Repeatability (EV)", self.var_repeatability),
                ("  Reproducibility (AV)", self.var_reproducibility), ("    Appraiser", self.var_appraiser),
                ("    Appraiser × part", self.var_interaction), ("Part-to-part (PV)", self.var_part),
                ("Total variation (TV)", tv)]
        out = []
        for source, v in rows:
            sd = math.sqrt(v)
            row = {"source": source, "VarComp": v, "%Contribution": 100.0 * v / tv, "StdDev": sd,
                   "StudyVar": self.study_variation * sd, "%StudyVar": 100.0 * sd / math.sqrt(tv)}
            if self.tolerance is not None:
                row["%Tolerance"] = 100.0 * self.study_variation * sd / self.tolerance
            out.append(row)
        return pd.DataFrame(out)

    def anova_table(self, used: bool = False) -> pd.DataFrame:
        """The two-way ANOVA with interaction (``used``: the model the components come from)."""
        return pd.DataFrame([vars(r) for r in (self.anova_used if used else self.anova)])

    def summary(self) -> dict:
        p, a, n = self.shape
        return {"file": self.file, "parts": p, "appraisers": a, "trials": n, "unit": self.unit,
                "interaction_p": self.interaction_p, "interaction_pooled": self.pooled,
                "interaction_alpha": self.interaction_alpha,
                "sigma": {"repeatability": math.sqrt(self.var_repeatability),
                          "reproducibility": math.sqrt(self.var_reproducibility), "grr": self.sigma_grr,
                          "part": math.sqrt(self.var_part), "total": math.sqrt(self.var_total)},
                "percent_study_variation": self.percent_study_variation, "tolerance": self.tolerance,
                "percent_tolerance": self.percent_tolerance, "ndc": self.ndc, "acceptance": self.acceptance}


def _f_row(source: str, ss: float, df: int, denom: AnovaRow | None) -> AnovaRow:
    ms = ss / df
    if denom is None:
        return AnovaRow(source, df, ss, ms)
    f = ms / denom.ms if denom.ms > 0 else math.inf
    return AnovaRow(source, df, ss, ms, f, float(stats.f.sf(f, df, denom.df)))


def gauge_rr(readings, *, tolerance: float | None = None, interaction_alpha: float = INTERACTION_ALPHA,
             study_variation: float = STUDY_VARIATION, parts=None, appraisers=None, unit: str | None = None,
             file: str = "", sha256: str = "") -> GaugeRR:
    """The ANOVA-method gauge R&R of ``readings[part, appraiser, trial]`` (module docstring)."""
    y = np.asarray(readings, dtype=float)
    if y.ndim != 3:
        raise InputError(f"readings must be [parts, appraisers, trials], got {y.ndim} dimensions")
    p, a, n = y.shape
    if p < 2 or a < 2 or n < 2:
        raise InputError(f"a crossed gauge study needs at least 2 parts, 2 appraisers and 2 trials, got "
                         f"{p} × {a} × {n}")
    if not np.all(np.isfinite(y)):
        raise InputError("readings must be finite numbers")
    if tolerance is not None and not (math.isfinite(tolerance) and tolerance > 0):
        raise InputError(f"tolerance must be a positive number, got {tolerance!r}")
    if not 0.0 < interaction_alpha < 1.0:
        raise InputError(f"interaction_alpha must lie in (0, 1), got {interaction_alpha!r}")
    grand = y.mean()
    cell = y.mean(axis=2)
    part_m, app_m = cell.mean(axis=1), cell.mean(axis=0)
    ss_p = a * n * float(np.sum((part_m - grand) ** 2))
    ss_a = p * n * float(np.sum((app_m - grand) ** 2))
    ss_pa = n * float(np.sum((cell - part_m[:, None] - app_m[None, :] + grand) ** 2))
    ss_e = float(np.sum((y - cell[:, :, None]) ** 2))
    if ss_e + ss_pa + ss_a == 0.0:
        raise InputError("every reading of a part is the same: the study shows no measurement variation (is the "
                         "gauge's resolution coarser than its variation? AIAG asks for a tenth of the spread)")
    df_p, df_a, df_pa, df_e = p - 1, a - 1, (p - 1) * (a - 1), p * a * (n - 1)
    err = _f_row("Repeatability", ss_e, df_e, None)
    inter = _f_row("Part × appraiser", ss_pa, df_pa, err)
    full = (_f_row("Part", ss_p, df_p, inter), _f_row("Appraiser", ss_a, df_a, inter), inter, err,
            AnovaRow("Total", p * a * n - 1, ss_p + ss_a + ss_pa + ss_e, math.nan))
    pooled = inter.p > interaction_alpha
    if pooled:
        err2 = _f_row("Repeatability", ss_pa + ss_e, df_pa + df_e, None)
        used = (_f_row("Part", ss_p, df_p, err2), _f_row("Appraiser", ss_a, df_a, err2), err2, full[-1])
        ms_e, ms_against = err2.ms, err2.ms
        var_pa = 0.0
    else:
        used = full
        ms_e, ms_against = err.ms, inter.ms
        var_pa = max(0.0, (inter.ms - err.ms) / n)
    return GaugeRR(y, tuple(parts or map(str, range(1, p + 1))), tuple(appraisers or map(str, range(1, a + 1))),
                   full, used, float(inter.p), bool(pooled), var_repeatability=ms_e,
                   var_appraiser=max(0.0, (ss_a / df_a - ms_against) / (p * n)), var_interaction=var_pa,
                   var_part=max(0.0, (ss_p / df_p - ms_against) / (a * n)), tolerance=tolerance,
                   interaction_alpha=interaction_alpha, study_variation=study_variation, unit=unit, file=file,
                   sha256=sha256)


# ----------------------------------------------------------------------------- the study file
def _label(v) -> str:
    return v if isinstance(v, str) else (f"{v:g}" if isinstance(v, float) else str(v))


def _column(t: Table, name: str, required: bool = True) -> int | None:
    hits = [i for i, c in enumerate(t.names) if c.lower() == name]
    if len(hits) > 1:
        raise t.error(f"column {name!r} appears twice", col=hits[1])
    if not hits and required:
        raise t.error(f"no column {name!r} (a gauge study has the columns part, appraiser, [trial,] value: one "
                      "reading per row)")
    return hits[0] if hits else None


def read_gauge_study(path, *, tolerance: float | None = None, interaction_alpha: float = INTERACTION_ALPHA,
                     sheet: str | None = None) -> GaugeRR:
    """Read a gauge study file (module docstring) and analyse it (:func:`gauge_rr`); the readings stay in the
    file's unit (:attr:`GaugeRR.unit`, None when the header gives none)."""
    t = read_table(path, sheet, what="part, appraiser, [trial,] value [unit]")
    jp, ja, jv = _column(t, "part"), _column(t, "appraiser"), _column(t, "value")
    jt = _column(t, "trial", required=False)
    unit = t.unit(jv)
    cells: dict[tuple[str, str], list[tuple[int, float]]] = {}
    trials: dict[tuple[str, str, str], int] = {}
    for row, c in t.rows:
        part, app = _label(c[jp]) if jp < len(c) else "", _label(c[ja]) if ja < len(c) else ""
        for j, v in ((jp, part), (ja, app)):
            if not v:
                raise t.error("empty cell: every reading names its part and appraiser", row, j)
        x = t.number(row, c, jv)
        if jt is not None:
            tr = _label(c[jt]) if jt < len(c) else ""
            if not tr:
                raise t.error("empty cell: number the trials, or leave out the trial column", row, jt)
            if (part, app, tr) in trials:
                raise t.error(f"part {part!r}, appraiser {app!r}, trial {tr!r} is given twice (also on row "
                              f"{trials[(part, app, tr)]})", row, jt)
            trials[(part, app, tr)] = row
        cells.setdefault((part, app), []).append((row, x))
    if not cells:
        raise t.error("no readings (rows) in the file")
    parts = list(dict.fromkeys(k[0] for k in cells))
    apps = list(dict.fromkeys(k[1] for k in cells))
    for what, labels, j in (("parts", parts, jp), ("appraisers", apps, ja)):
        if len(labels) < 2:
            raise t.error(f"{len(labels)} {what[:-1] if len(labels) == 1 else what}: a crossed gauge study needs at "
                          f"least 2 {what}", col=j)
    missing = next(((pt, ap) for pt in parts for ap in apps if (pt, ap) not in cells), None)
    if missing is not None:
        raise t.error(f"appraiser {missing[1]!r} has no reading of part {missing[0]!r}: a crossed study has every "
                      "appraiser measure every part", col=ja)
    n = len(cells[(parts[0], apps[0])])
    for (pt, ap), rs in cells.items():
        if len(rs) != n:
            raise t.error(f"part {pt!r}, appraiser {ap!r}: {len(rs)} readings, part {parts[0]!r} by appraiser "
                          f"{apps[0]!r} has {n} (the design must be balanced: every appraiser measures every part "
                          "the same number of times)", rs[-1][0])
    if n < 2:
        raise t.error("1 trial: a gauge study needs at least 2 readings of each part by each appraiser (the "
                      "repeatability)", col=jt if jt is not None else jv)
    y = np.array([[[x for _, x in cells[(pt, ap)]] for ap in apps] for pt in parts])
    try:
        return gauge_rr(y, tolerance=tolerance, interaction_alpha=interaction_alpha, parts=parts, appraisers=apps,
                        unit=unit, file=t.file, sha256=t.sha256)
    except InputError as exc:
        raise t.error(exc.reason, col=jv) from None


@dataclass(frozen=True)
class Gauge:
    """A gauge study and the features of a part family it measures: their standard uncertainty is
    u = √(σ²_GRR + u_cal²) (module docstring), in the study's unit (:attr:`GaugeRR.unit`; None: the features')."""

    result: GaugeRR
    features: tuple[str, ...]
    calibration_u: float = 0.0

    @property
    def u(self) -> float:
        return self.result.uncertainty(self.calibration_u)

    @property
    def unit(self) -> str | None:
        return self.result.unit

    def row(self) -> dict:
        """One line of the report's gauge table."""
        g = self.result
        p, a, n = g.shape
        pct_tol = g.percent_tolerance
        return {"gauge study": Path(g.file).name, "features": ", ".join(self.features),
                "parts × appraisers × trials": f"{p} × {a} × {n}", "unit": g.unit or "(features')",
                "σ repeatability": math.sqrt(g.var_repeatability), "σ reproducibility": math.sqrt(g.var_reproducibility),
                "σ GRR": g.sigma_grr, "interaction": "pooled" if g.pooled else "kept",
                "%GRR (study var.)": g.percent_study_variation, "%GRR (tolerance)": pct_tol, "ndc": g.ndc,
                "AIAG": g.acceptance, "u_cal": self.calibration_u, "u": self.u}
