"""Gauge R&R by the ANOVA method (rvtol.production.msa): a published worked example, an exact construction,
an independent least-squares check, the sampling theory of the mean squares, and the study file's errors."""
import math

import numpy as np
import pytest
from conftest import write
from scipy import stats

from rvtol.errors import InputError
from rvtol.production.msa import Gauge, acceptance, gauge_rr, read_gauge_study

# The AIAG MSA manual's worked example (4th ed., ch. III; 10 parts, appraisers A, B, C, 3 trials), also Minitab's
# sample data set Gageaiag.MTW.  AIAG[appraiser][trial][part].
AIAG = {
    "A": [[0.29, -0.56, 1.34, 0.47, -0.80, 0.02, 0.59, -0.31, 2.26, -1.36],
          [0.41, -0.68, 1.17, 0.50, -0.92, -0.11, 0.75, -0.20, 1.99, -1.25],
          [0.64, -0.58, 1.27, 0.64, -0.84, -0.21, 0.66, -0.17, 2.01, -1.31]],
    "B": [[0.08, -0.47, 1.19, 0.01, -0.56, -0.20, 0.47, -0.63, 1.80, -1.68],
          [0.25, -1.22, 0.94, 1.03, -1.20, 0.22, 0.55, 0.08, 2.12, -1.62],
          [0.07, -0.68, 1.34, 0.20, -1.28, 0.06, 0.83, -0.34, 2.19, -1.50]],
    "C": [[0.04, -1.38, 0.88, 0.14, -1.46, -0.29, 0.02, -0.46, 1.77, -1.49],
          [-0.11, -1.13, 1.09, 0.20, -1.07, -0.67, 0.01, -0.56, 1.45, -1.77],
          [-0.15, -0.96, 0.67, 0.11, -1.45, -0.49, 0.21, -0.49, 1.87, -2.16]],
}


def _aiag() -> np.ndarray:
    return np.array([AIAG[k] for k in "ABC"]).transpose(2, 0, 1)      # [part, appraiser, trial]


def test_the_aiag_worked_example_reproduces_the_published_anova_and_variance_components():
    """Published figures for this data set, to the digits printed: the AIAG manual's ANOVA table as reproduced
    by McNeese, "Three Ways to Analyze a Gage R&R Study" (BPI Consulting, 2015) — SS 88.362 parts, 3.167
    appraisers, 0.359 interaction, 2.759 equipment (94.647 total); MS 9.818, 1.584, 0.01994, 0.04598; the
    interaction pooled: repeatability SS 3.118 on 78 df, MS 0.0400; variance components 0.0400 (EV), 0.0515 (AV),
    0.0914 (GRR), 1.086 (PV); ndc 4 — and the interaction's p-value 0.974 of Minitab's Gageaiag example (Minitab
    blog, "Crossed Gage R&R: How are the Variance Components Calculated?", 2015)."""
    g = gauge_rr(_aiag())
    full = {r.source: r for r in g.anova}
    for source, ss, ms, ms_digits in (("Part", 88.362, 9.818, 5e-4), ("Appraiser", 3.167, 1.584, 5e-4),
                                      ("Part × appraiser", 0.359, 0.01994, 5e-6),
                                      ("Repeatability", 2.759, 0.04598, 5e-6)):
        assert full[source].ss == pytest.approx(ss, abs=5e-4)
        assert full[source].ms == pytest.approx(ms, abs=ms_digits)
    assert full["Total"].ss == pytest.approx(94.647, abs=5e-4)
    assert round(g.interaction_p, 3) == 0.974 and g.pooled
    used = {r.source: r for r in g.anova_used}
    assert used["Repeatability"].df == 78 and used["Repeatability"].ss == pytest.approx(3.118, abs=5e-4)
    assert g.var_repeatability == pytest.approx(0.0400, abs=5e-5)
    assert g.var_reproducibility == pytest.approx(0.0515, abs=5e-5)
    assert g.var_grr == pytest.approx(0.0914, abs=5e-5)
    assert g.var_part == pytest.approx(1.086, abs=5e-4)
    assert g.var_interaction == 0.0
    assert g.ndc == 4
    # %GRR of the study variation 27.86 %: conditionally acceptable (10-30 %)
    assert g.percent_study_variation == pytest.approx(100 * math.sqrt(g.var_grr / g.var_total))
    assert round(g.percent_study_variation, 1) == 27.9 and g.acceptance == "conditionally acceptable"


def test_the_sums_of_squares_equal_those_of_nested_least_squares_fits():
    """An independent route: SS of a term = the drop in residual sum of squares when its dummy columns join the
    model (balanced design: sequential = adjusted), fitted with numpy's lstsq."""
    y = _aiag()
    p, a, n = y.shape
    P, A, _ = np.meshgrid(np.arange(p), np.arange(a), np.arange(n), indexing="ij")
    P, A, v = P.ravel(), A.ravel(), y.ravel()
    one = np.ones((v.size, 1))
    dp = (P[:, None] == np.arange(1, p)).astype(float)
    da = (A[:, None] == np.arange(1, a)).astype(float)
    dpa = np.column_stack([dp[:, i] * da[:, j] for i in range(p - 1) for j in range(a - 1)])

    def rss(X):
        beta = np.linalg.lstsq(X, v, rcond=None)[0]
        return float(np.sum((v - X @ beta) ** 2))

    r0, r1, r2, r3 = rss(one), rss(np.hstack([one, dp])), rss(np.hstack([one, dp, da])), rss(np.hstack([one, dp, da,
                                                                                                        dpa]))
    g = {r.source: r.ss for r in gauge_rr(y).anova}
    np.testing.assert_allclose([g["Part"], g["Appraiser"], g["Part × appraiser"], g["Repeatability"], g["Total"]],
                               [r0 - r1, r1 - r2, r2 - r3, r3, r0], rtol=1e-10)


def _constructed(d: float) -> np.ndarray:
    """3 parts × 2 appraisers × 2 trials with every effect chosen: part −2, 0, 2; appraiser ∓0.5; an interaction
    table with zero row and column sums; the two trials of each cell at ±d."""
    part = np.array([-2.0, 0.0, 2.0])
    app = np.array([-0.5, 0.5])
    inter = np.array([[0.3, -0.3], [-0.1, 0.1], [-0.2, 0.2]])
    cell = 10.0 + part[:, None] + app[None, :] + inter
    return np.stack([cell - d, cell + d], axis=2)


def test_an_exactly_constructed_study_gives_the_hand_computed_components():
    """SS_P = a·n·ΣP² = 2·2·8 = 32 (MS 16), SS_A = p·n·ΣA² = 3·2·0.5 = 3 (MS 3), SS_PA = n·ΣI² = 2·0.28 = 0.56
    (MS 0.28), SS_E = 12·0.1² = 0.12 (MS 0.02).  F_PA = 14 on (2, 6) df: p = (1 + 2·14/6)^−3 = 0.005496 (the F
    survival function for 2 numerator df) < 0.25: kept.  σ²_E = 0.02, σ²_PA = (0.28 − 0.02)/2 = 0.13,
    σ²_A = (3 − 0.28)/(3·2) = 0.45333, σ²_P = (16 − 0.28)/(2·2) = 3.93."""
    g = gauge_rr(_constructed(0.1), tolerance=12.0)
    ms = {r.source: r.ms for r in g.anova}
    assert ms == pytest.approx({"Part": 16.0, "Appraiser": 3.0, "Part × appraiser": 0.28, "Repeatability": 0.02,
                                "Total": math.nan}, nan_ok=True)
    assert g.interaction_p == pytest.approx((1 + 2 * 14 / 6) ** -3, rel=1e-9) and not g.pooled
    f = {r.source: r.f for r in g.anova}                            # random effects: P and A against MS_PA
    assert (f["Part"], f["Appraiser"], f["Part × appraiser"]) == pytest.approx((16 / 0.28, 3 / 0.28, 14.0))
    assert (g.var_repeatability, g.var_interaction, g.var_appraiser, g.var_part) == pytest.approx(
        (0.02, 0.13, 2.72 / 6, 3.93), rel=1e-12)
    grr = 0.02 + 0.13 + 2.72 / 6
    assert g.var_grr == pytest.approx(grr) and g.var_total == pytest.approx(grr + 3.93)
    assert g.ndc == math.floor(1.41 * math.sqrt(3.93 / grr))        # 1.41·2.551 = 3.597 -> 3
    assert g.ndc == 3
    assert g.percent_tolerance == pytest.approx(100 * 6 * math.sqrt(grr) / 12.0)
    assert g.acceptance == "unacceptable"                           # 38.9 % of the tolerance
    comp = g.components().set_index("source")
    assert comp["%Contribution"].iloc[[0, 5]].sum() == pytest.approx(100.0)     # GRR + PV = TV
    assert g.uncertainty(calibration=0.3) == pytest.approx(math.sqrt(grr + 0.09))


def test_an_insignificant_interaction_is_pooled_into_repeatability_above_its_alpha():
    """d = 0.5: SS_E = 12·0.25 = 3 (MS 0.5), F_PA = 0.56, p = (1 + 2·0.56/6)^−3 = 0.5985 > 0.25: pooled,
    MS_E' = (0.56 + 3)/(2 + 6) = 0.445, σ²_A = (3 − 0.445)/6, σ²_P = (16 − 0.445)/4.  With interaction_alpha 0.7
    (p below it) the interaction stays: σ²_PA = max(0, (0.28 − 0.5)/2) = 0, σ²_A = (3 − 0.28)/6."""
    g = gauge_rr(_constructed(0.5))
    assert g.interaction_p == pytest.approx((1 + 2 * 0.56 / 6) ** -3, rel=1e-9) and g.pooled
    assert (g.var_repeatability, g.var_interaction, g.var_appraiser, g.var_part) == pytest.approx(
        (0.445, 0.0, (3 - 0.445) / 6, (16 - 0.445) / 4), rel=1e-12)
    used = {r.source: r for r in g.anova_used}
    assert "Part × appraiser" not in used and used["Appraiser"].f == pytest.approx(3 / 0.445)
    kept = gauge_rr(_constructed(0.5), interaction_alpha=0.7)
    assert not kept.pooled
    assert (kept.var_repeatability, kept.var_interaction, kept.var_appraiser) == pytest.approx(
        (0.5, 0.0, 2.72 / 6), rel=1e-12)


def test_the_mean_squares_average_to_their_expected_values_over_simulated_studies():
    """Random-effects model with σ_P = 1, σ_A = 0.3, σ_PA = 0.2, σ_E = 0.25 (10 × 3 × 3): E[MS_E] = σ²_E,
    E[MS_PA] = σ²_E + n σ²_PA, E[MS_A] = … + p n σ²_A, E[MS_P] = … + a n σ²_P.  Over R studies the mean of MS·df/E[MS]
    is a χ²_{R·df}/R variable: within its 99.9 % interval."""
    rng = np.random.default_rng(20261129)
    p, a, n, R = 10, 3, 3, 300
    sP, sA, sPA, sE = 1.0, 0.3, 0.2, 0.25
    y = (rng.normal(0, sP, (R, p, 1, 1)) + rng.normal(0, sA, (R, 1, a, 1)) + rng.normal(0, sPA, (R, p, a, 1))
         + rng.normal(0, sE, (R, p, a, n)))
    ems = {"Repeatability": sE ** 2, "Part × appraiser": sE ** 2 + n * sPA ** 2,
           "Appraiser": sE ** 2 + n * sPA ** 2 + p * n * sA ** 2, "Part": sE ** 2 + n * sPA ** 2 + a * n * sP ** 2}
    sums = dict.fromkeys(ems, 0.0)
    dfs = {}
    for r in range(R):
        for row in gauge_rr(y[r]).anova:
            if row.source in ems:
                sums[row.source] += row.ss / ems[row.source]
                dfs[row.source] = row.df
    for source, total in sums.items():
        k = R * dfs[source]
        lo, hi = stats.chi2.ppf([0.0005, 0.9995], k)
        assert lo < total < hi, (source, total, k)


def test_acceptance_reads_the_aiag_thresholds():
    assert [acceptance(x) for x in (9.99, 10.0, 30.0, 30.01)] == [
        "acceptable", "conditionally acceptable", "conditionally acceptable", "unacceptable"]


# ----------------------------------------------------------------------------- the study file
def _csv(y, unit="um", trial=True) -> str:
    head = "part, appraiser, trial, value" if trial else "part, appraiser, value"
    lines = ["# gauge study (test)", head + (f" [{unit}]" if unit else "")]
    p, a, n = y.shape
    for i in range(p):
        for j in range(a):
            for k in range(n):
                lines.append(f"P{i + 1}, {'ABC'[j]}, " + (f"{k + 1}, " if trial else "") + f"{y[i, j, k]:.17g}")
    return "\n".join(lines) + "\n"


def test_a_study_file_is_read_back_to_the_same_analysis(tmp_path):
    y = _aiag()
    g = read_gauge_study(write(tmp_path / "g.csv", _csv(y)), tolerance=6.0)
    ref = gauge_rr(y, tolerance=6.0)
    np.testing.assert_array_equal(g.readings, y)
    assert g.parts == tuple(f"P{i}" for i in range(1, 11)) and g.appraisers == ("A", "B", "C")
    assert g.unit == "um" and g.sha256 and g.ndc == ref.ndc and g.var_grr == pytest.approx(ref.var_grr, rel=1e-13)
    no_trial = read_gauge_study(write(tmp_path / "h.csv", _csv(y, unit=None, trial=False)))
    assert no_trial.unit is None and no_trial.var_grr == pytest.approx(ref.var_grr, rel=1e-13)
    gauge = Gauge(g, ("cam.x",), calibration_u=0.1)
    assert gauge.u == pytest.approx(math.sqrt(ref.var_grr + 0.01))


def _body(y_rows: str, head: str = "part, appraiser, trial, value [um]") -> str:
    return head + "\n" + y_rows


GOOD = "".join(f"P{i}, {a}, {t}, {0.1 * i + 0.01 * t + (0.02 if a == 'B' else 0):.2f}\n"
               for i in (1, 2) for a in "AB" for t in (1, 2))


@pytest.mark.parametrize("text, key, reason", [
    (_body(GOOD, "part, operator, trial, value [um]"), "row 1", "no column 'appraiser'"),
    (_body(GOOD, "part, appraiser, trial, reading"), "row 1", "no column 'value'"),
    (_body(GOOD.replace("P2, B, 2, 0.24", "P2, B, 2, x")), "row 9, column 'value [um]'", "not a number: 'x'"),
    (_body(GOOD.replace("P2, B, 2, 0.24\n", "")), "row 8",
     "part 'P2', appraiser 'B': 1 readings, part 'P1' by appraiser 'A' has 2"),
    (_body(GOOD.replace("P2, B, 2, 0.24", "P2, B, 1, 0.24")), "row 9, column 'trial'", "given twice"),
    (_body(GOOD.replace(", B,", ", A,")), "row 4, column 'trial'", "trial '1' is given twice (also on row 2)"),
    (_body("".join(f"P{i}, A, {t}, {0.1 * i + 0.01 * t}\n" for i in (1, 2) for t in (1, 2))),
     "row 1, column 'appraiser'", "1 appraiser: a crossed gauge study needs at least 2 appraisers"),
    (_body("".join(f"P{i}, {a}, 1, {0.1 * i}\n" for i in (1, 2) for a in "AB")), "row 1, column 'trial'",
     "1 trial"),
    (_body("".join(f"P{i}, {a}, {t}, {0.1 * i + 0.01 * t}\n" for i in (1, 2) for a in "AB" for t in (1, 2)
                   if (i, a) != (2, "B"))), "row 1, column 'appraiser'", "appraiser 'B' has no reading of part 'P2'"),
    (_body(GOOD.replace("P2, B, 2, 0.24", "P2, , 2, 0.24")), "row 9, column 'appraiser'", "empty cell"),
])
def test_bad_study_files_give_one_located_error(tmp_path, text, key, reason):
    f = write(tmp_path / "g.csv", text)
    with pytest.raises(InputError) as exc:
        read_gauge_study(f)
    assert exc.value.file == str(f) and exc.value.key == key and reason in exc.value.reason, (
        exc.value.key, exc.value.reason)


def test_a_study_without_measurement_variation_is_refused(tmp_path):
    rows = "".join(f"P{i}, {a}, {t}, {i}\n" for i in (1, 2) for a in "AB" for t in (1, 2))
    f = write(tmp_path / "g.csv", _body(rows))
    with pytest.raises(InputError, match="no measurement variation") as exc:
        read_gauge_study(f)
    assert exc.value.file == str(f)
