"""Non-smooth stack-ups handled honestly: the ASME floating fastener (RFS and MMC) gives margin 0 by every
worst-case method; a kinked output is never linearised by a silent 0; an undefined derivative is an error.

The floating-fastener formula (ASME Y14.5-2018, Appendix B "Formulas for positional tolerancing", B.3:
T = H − F; ASME Y14.5M-1994 Appendix B, B4): two parts with clearance holes of MMC size H = 6.4 mm, a
fastener of MMC size F = 6.0 mm, each hole located within ⌀T = 0.4 mm of true position.  The fastener
fits when the holes' axes are no further apart than (H₁ − F)/2 + (H₂ − F)/2; the margin
(H₁ − F)/2 + (H₂ − F)/2 − |p₁ − p₂| is 0 at worst: holes at MMC, fastener at MMC, the two axes at
opposite ends of their zones.  At MMC (⌀0.4 Ⓜ) the zone grows with the hole's departure from MMC, and the
worst case is 0 at every hole size (the bonus exactly pays for the larger hole's extra clearance)."""
import math

import numpy as np
import pytest

from rvtol.errors import InputError
from rvtol.expressions import Expression
from rvtol.models.formula.model import FormulaModel
from rvtol.sampling import sample
from rvtol.spec import spec_from_table
from rvtol.stacking import stack_conventions, true_worst_case
from rvtol.stacking.slopes import one_sided_slopes

MARGIN = "(H1 - F)/2 + (H2 - F)/2 - hypot(x1 - x2, y1 - y2)"


def fastener_spec(modifier=""):
    zone = {"tolerance": f"⌀0.4{modifier}", "unit": "mm"}
    extra = lambda z: ({"size": z, "feature_type": "internal"} if modifier else {})  # noqa: E731
    return spec_from_table({"factor": [
        {"name": "H1", "tolerance": "6.4 +0.2/0", "unit": "mm"},
        {"name": "H2", "tolerance": "6.4 +0.2/0", "unit": "mm"},
        {"name": "F", "tolerance": "6.0 0/-0.1", "unit": "mm"},
        {"name": "x1", "zone": "hole1", **zone, **extra("H1")}, {"name": "y1", "zone": "hole1", **zone, **extra("H1")},
        {"name": "x2", "zone": "hole2", **zone, **extra("H2")}, {"name": "y2", "zone": "hole2", **zone, **extra("H2")},
    ]}, name="floating_fastener")


def test_the_derivative_of_a_norm_at_its_zero_is_not_nan():
    env = {"x": np.array([0.0, 3.0]), "y": np.array([0.0, 4.0]), "H": np.array([1.0, 1.0])}
    for text in ("hypot(x, y)", "sqrt(x**2 + y**2)", "(x**2 + y**2)**0.5"):
        v, g = Expression.parse(text).gradient(env)
        assert np.all(np.isfinite(g["x"])) and np.all(np.isfinite(g["y"]))
        assert (g["x"][0], g["y"][0]) == (0.0, 0.0)               # the least-norm subgradient at the cone's tip
        assert (g["x"][1], g["y"][1]) == (pytest.approx(0.6), pytest.approx(0.8))
    # a linear term of the same output survives (the NaN used to erase it)
    _, g = Expression.parse("H/2 - hypot(x, y)").gradient(env)
    assert g["H"][0] == 0.5
    # a root of a moving zero keeps its infinite slope; atan2 at the origin stays undefined
    assert math.isinf(Expression.parse("sqrt(x)").gradient(env)[1]["x"][0])
    assert math.isnan(Expression.parse("atan2(y, x)").gradient(env)[1]["x"][0])


@pytest.mark.parametrize("modifier", ["", " (M)"], ids=["RFS", "MMC"])
def test_the_floating_fastener_gives_margin_zero_by_every_worst_case_method(modifier):
    spec = fastener_spec(modifier)
    model = FormulaModel.from_spec(spec, {"margin": (MARGIN, "mm")})
    x0 = spec.nominal_base()
    g = model.gradient(x0[None])[0, 0]
    y0 = float(model.evaluate(x0[None])[0, 0])
    slopes = one_sided_slopes(model, spec, "margin")
    assert set(slopes.kinked) == {"hole1", "hole2"}
    assert slopes.zone_max["hole1"] == pytest.approx(-1.0) and slopes.zone_min["hole1"] == pytest.approx(-1.0)
    sc = stack_conventions(spec, g, y0, x0, output="margin", out_unit="mm", slopes=slopes)
    wc = sc.row("worst case (arithmetic)")
    # H_min − F_max − T = 6.4 − 6.0 − 0.4 = 0; the upper end: H_max − F_min with the axes aligned = 0.7
    assert wc["low"] == pytest.approx(0.0, abs=1e-9) and wc["high"] == pytest.approx(0.7, abs=1e-9)
    assert any("kink" in n for n in sc.notes)
    assert ("zones at MMC/LMC with their bonus" in wc["note"]) == bool(modifier)
    # the RSS: each zone as ±(radius × its larger slope 1) — radius 0.2, at MMC 0.2 + ½(6.5 − 6.4) at the holes' band
    # centre, where a hole's size then enters with its coupled sensitivity ½ − ½·1 = 0 (the bonus pays for it) — and
    # F's ±0.05; the shares (a·s)² of H1, H2, F and the zones' ½(r·1)² per coordinate (RFS: 0.0025 each, 0.02 each)
    rss = sc.row("RSS")["half_width"]
    if modifier:
        assert rss == pytest.approx(math.sqrt(0.05 ** 2 + 2 * 0.25 ** 2), rel=1e-6)
    else:
        assert rss == pytest.approx(math.sqrt(3 * 0.05 ** 2 + 2 * 0.2 ** 2), rel=1e-6)
        terms = np.array([0.0025, 0.0025, 0.0025, 0.02, 0.02, 0.02, 0.02])
        assert sc.factors["rss_pct"].tolist() == pytest.approx((100 * terms / terms.sum()).tolist(), rel=1e-6)
    true = true_worst_case(model, spec, "margin", gradient=g, max_evaluations=20000)
    assert true.low == pytest.approx(0.0, abs=1e-6) and true.high == pytest.approx(0.7, abs=1e-6)
    assert "not guaranteed" in true.how and not any("could not be evaluated" in n for n in true.notes)
    # the corners reach it on their own, the global search once polished; the linearised corner start too
    reached = true.methods["low"]
    for method in ("corners", "corners → L-BFGS-B", "differential evolution → L-BFGS-B"):
        assert reached[method] == pytest.approx(0.0, abs=1e-6), (method, reached)
    # the worst point: the two axes at opposite ends of their zones, ⌀(0.4 + bonus) apart
    p = true.x_low
    sep = math.hypot(p["x1"] - p["x2"], p["y1"] - p["y2"])
    bonus = (p["H1"] - 6.4 + p["H2"] - 6.4) / 2 if modifier else 0.0
    assert sep == pytest.approx(0.4 + bonus, abs=1e-4)
    # and no conforming part of a Monte Carlo sample is worse than the worst case (holes inside their zones,
    # with their bonus at MMC)
    X = sample(spec, 4000, "random", 1).values
    r1 = 0.2 + (0.5 * (X[:, 0] - 6.4) if modifier else 0.0)
    r2 = 0.2 + (0.5 * (X[:, 1] - 6.4) if modifier else 0.0)
    ok = (np.hypot(X[:, 3], X[:, 4]) <= r1) & (np.hypot(X[:, 5], X[:, 6]) <= r2)
    assert ok.mean() > 0.99 and model.evaluate(X[ok])[:, 0].min() > 0.0


def test_the_mmc_bonus_pays_for_the_hole_size():
    """At MMC (⌀0.4 Ⓜ) a hole's zone grows with its departure from MMC: ⌀0.4 + (H − 6.4) (ASME Y14.5-2018 §7.3.3),
    so with both holes at LMC (6.6) each axis may lie 0.3 from true position and the two axes 0.6 apart; at RFS 0.2
    and 0.4 whatever the size.  The margin's worst case then does not depend on the hole's size at MMC (the
    clearance the larger hole gains, ½ per hole per mm, is what its larger zone takes) and at RFS it does: with the
    holes' clearance at LMC, (6.6 − F) − separation is 0.2 at worst at RFS and still 0 at MMC.  Hand numbers, by
    the linearised conventions and the true worst case (its corners: these outputs are monotone in each factor)."""
    separation = "hypot(x1 - x2, y1 - y2)"
    for modifier, far, lmc_low in (("", 0.4, 0.2), (" (M)", 0.6, 0.0)):
        spec = fastener_spec(modifier)
        x0 = spec.nominal_base()
        m = FormulaModel.from_spec(spec, {"margin": (MARGIN, "mm")})
        sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], float(m.evaluate(x0[None])[0, 0]), x0,
                               out_unit="mm", slopes=one_sided_slopes(m, spec, "margin"))
        assert sc.row("worst case (arithmetic)")["low"] == pytest.approx(0.0, abs=1e-9)
        assert sc.factors.set_index("factor").loc["H1", "a"] == pytest.approx(0.5)
        # the two axes' largest distance
        sep = FormulaModel.from_spec(spec, {"sep": (separation, "mm")})
        assert true_worst_case(sep, spec, "sep", max_evaluations=300).high == pytest.approx(far, abs=1e-9), modifier
        sc = stack_conventions(spec, sep.gradient(x0[None])[0, 0], 0.0, x0, out_unit="mm",
                               slopes=one_sided_slopes(sep, spec, "sep"))
        assert sc.row("worst case (arithmetic)")["high"] == pytest.approx(far, abs=1e-9), modifier
        # the margin with the holes' clearance of the LMC size, their zones as the holes' sizes make them
        lmc = FormulaModel.from_spec(spec, {"m": (f"(H_lmc - F) - {separation} + 0 * (H1 + H2)", "mm")},
                                     definitions={"H_lmc": ("6.6", "mm")})
        assert true_worst_case(lmc, spec, "m", max_evaluations=300).low == pytest.approx(lmc_low, abs=1e-9), modifier


def test_an_undefined_derivative_is_an_error_not_a_zero():
    spec = fastener_spec()
    g = np.zeros(len(spec))
    g[3] = np.nan
    with pytest.raises(InputError, match="undefined"):
        stack_conventions(spec, g, 0.0, out_unit="mm")


def test_many_undefined_derivatives_are_named_five_then_an_ellipsis():
    """Six undefined derivatives and no slopes: the error names the first five and says there are more."""
    spec = spec_from_table({"factor": [{"name": f"f{i}", "tolerance": "±0.1", "unit": "mm", "nominal": 0.0}
                                       for i in range(1, 7)]})
    with pytest.raises(InputError, match="undefined \\(NaN or ∞\\) for f1, f2, f3, f4, f5 …: it cannot be read as 0"):
        stack_conventions(spec, np.full(6, np.nan), 0.0, out_unit="mm")
    with pytest.raises(InputError, match="undefined \\(NaN or ∞\\) for f1, f2, f3, f4, f5: it cannot be read as 0"):
        stack_conventions(spec, np.r_[np.full(5, np.nan), 1.0], 0.0, out_unit="mm")


def test_a_kinked_plain_factor_is_taken_by_the_side_that_hurts():
    spec = spec_from_table({"factor": [{"name": "u", "tolerance": "±0.1", "unit": "mm", "nominal": 0.0},
                                       {"name": "w", "tolerance": "±0.05", "unit": "mm", "nominal": 0.0}]})
    m = FormulaModel.from_spec(spec, {"y": ("abs(u) + 2*w", "mm")})
    x0 = spec.nominal_base()
    sl = one_sided_slopes(m, spec, "y")
    assert sl.kinked == ["u"]
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], 0.0, x0, out_unit="mm", slopes=sl)
    wc = sc.row("worst case (arithmetic)")
    # |u| ∈ [0, 0.1] whatever the sign of u; 2w ∈ ±0.1: y ∈ [−0.1, 0.2] — a silent 0 gave ±0.1
    assert (wc["low"], wc["high"]) == (pytest.approx(-0.1, abs=1e-9), pytest.approx(0.2, abs=1e-9))
    true = true_worst_case(m, spec, "y")
    assert (true.low, true.high) == (pytest.approx(-0.1, abs=1e-7), pytest.approx(0.2, abs=1e-7))


def test_the_fixed_fastener_formula():
    """ASME Y14.5-2018 Appendix B, fixed fastener: H = F + T₁ + T₂ — a stud of MMC 6.0 fixed in one part (⌀0.2 zone), a
    6.4 clearance hole in the other (⌀0.2 zone): the margin (H − F)/2 − |p₁ − p₂| is 0 at worst."""
    spec = spec_from_table({"factor": [
        {"name": "H", "tolerance": "6.4 +0.2/0", "unit": "mm"}, {"name": "F", "tolerance": "6.0 0/-0.1", "unit": "mm"},
        {"name": "x1", "tolerance": "⌀0.2", "unit": "mm", "zone": "stud"},
        {"name": "y1", "tolerance": "⌀0.2", "unit": "mm", "zone": "stud"},
        {"name": "x2", "tolerance": "⌀0.2", "unit": "mm", "zone": "hole"},
        {"name": "y2", "tolerance": "⌀0.2", "unit": "mm", "zone": "hole"}]})
    m = FormulaModel.from_spec(spec, {"margin": ("(H - F)/2 - hypot(x1 - x2, y1 - y2)", "mm")})
    x0 = spec.nominal_base()
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], float(m.evaluate(x0[None])[0, 0]), x0, out_unit="mm",
                           slopes=one_sided_slopes(m, spec, "margin"))
    assert sc.row("worst case (arithmetic)")["low"] == pytest.approx(0.0, abs=1e-9)
    assert true_worst_case(m, spec, "margin").low == pytest.approx(0.0, abs=1e-6)


def test_a_datum_feature_shift_adds_to_the_zone():
    """A hole 10.4 +0.1/0 positioned ⌀0.2 Ⓜ to a datum bore B 20 +0.1/0 referenced at MMB: at the largest hole and
    the largest datum bore the axis may lie 0.1 (t/2) + 0.05 (the hole's bonus, (10.5 − 10.4)/2) + 0.05 (the datum
    shift, (20.1 − 20.0)/2) = 0.2 from true position.  The datum-feature shift equals the datum feature's departure
    from its MMB (ASME Y14.5-2018, datum features referenced at MMB; ISO 2692:2014 for the maximum material
    requirement); the numbers are ours, checked by hand — a textbook's printed example could not be checked here."""
    common = {"tolerance": "⌀0.2 (M)", "unit": "mm", "zone": "h", "size": "D", "feature_type": "internal",
              "datum_size": "B", "datum_type": "internal"}
    spec = spec_from_table({"factor": [
        {"name": "D", "tolerance": "10.4 +0.1/0", "unit": "mm"}, {"name": "B", "tolerance": "20 +0.1/0", "unit": "mm"},
        {"name": "x", **common}, {"name": "y", **common}]})
    from rvtol.spec import DatumShift, datum_shifts, zone_bonus
    assert zone_bonus(spec, "h") == [(0, 0.5, pytest.approx(10.4))]            # the hole's own bonus
    assert datum_shifts(spec) == [DatumShift("B", 1, 0.5, pytest.approx(20.0), ("h",))]   # the pattern's shift
    m = FormulaModel.from_spec(spec, {"r": ("hypot(x, y)", "mm")})
    true = true_worst_case(m, spec, "r")
    assert true.high == pytest.approx(0.2, abs=1e-6) and true.x_high["D"] == pytest.approx(10.5)
    assert true.x_high["B"] == pytest.approx(20.1)
    x0 = spec.nominal_base()
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], 0.0, x0, out_unit="mm", slopes=one_sided_slopes(m, spec, "r"))
    assert sc.row("worst case (arithmetic)")["high"] == pytest.approx(0.2, abs=1e-9)
    assert sc.row("worst case (arithmetic)")["low"] == pytest.approx(0.0, abs=1e-12)   # a radius is never negative
    # the handbook MRSS over n = 3 contributors (the zone's two coordinates, the datum shift): T_wc = 0.1, the RSS of
    # the zone's radius 0.1 + ½·0.05 and the shift's ½·0.05 (each × its larger slope 1) and of D and B at their
    # coupled sensitivity ½ over their half bands 0.05
    t_rss = math.sqrt(0.125 ** 2 + 3 * 0.025 ** 2)
    cf = 1 + 0.5 * (0.1 - t_rss) / (t_rss * (math.sqrt(3) - 1))
    assert sc.row("RSS")["half_width"] == pytest.approx(t_rss, rel=1e-6)
    assert sc.row("MRSS, handbook")["half_width"] == pytest.approx(cf * t_rss, rel=1e-6)
    # the axis's x alone (smooth: the zone and the shift each move it 1 per unit, exactly): ±0.2, and n = 2 (x and
    # the datum shift; the zone's coordinates are the disc, not counted again), the same RSS
    mx = FormulaModel.from_spec(spec, {"px": ("x", "mm")})
    sc = stack_conventions(spec, mx.gradient(x0[None])[0, 0], 0.0, x0, out_unit="mm",
                           slopes=one_sided_slopes(mx, spec, "px"))
    assert sc.row("worst case (arithmetic)")["half_width"] == pytest.approx(0.2, abs=1e-12)
    cf = 1 + 0.5 * (0.2 - t_rss) / (t_rss * (math.sqrt(2) - 1))
    assert sc.row("MRSS, handbook")["half_width"] == pytest.approx(cf * t_rss, rel=1e-9)
    # an external datum feature (a boss) at MMB: its MMC is the largest size, the shift grows as it gets smaller
    spec2 = spec_from_table({"factor": [
        {"name": "D", "tolerance": "10.4 +0.1/0", "unit": "mm"}, {"name": "B", "tolerance": "20 0/-0.1", "unit": "mm"},
        {"name": "x", **common, "datum_type": "external"}, {"name": "y", **common, "datum_type": "external"}]})
    assert (datum_shifts(spec2)[0].kappa, datum_shifts(spec2)[0].reference) == (-0.5, pytest.approx(20.0))
    # and the axis still lies up to 0.1 + 0.05 + 0.05 = 0.2 from true position, the boss at its smallest (19.9)
    m2, x2 = FormulaModel.from_spec(spec2, {"r": ("hypot(x, y)", "mm")}), spec2.nominal_base()
    sc2 = stack_conventions(spec2, m2.gradient(x2[None])[0, 0], 0.0, x2, out_unit="mm",
                            slopes=one_sided_slopes(m2, spec2, "r"))
    assert sc2.row("worst case (arithmetic)")["high"] == pytest.approx(0.2, abs=1e-9)
    # its RSS as the internal datum's: the boss's size enters at its coupled sensitivity −½ (the shift grows as it
    # shrinks), the hole's at +½, the radii 0.125 and 0.025 as before
    assert sc2.row("RSS")["half_width"] == pytest.approx(t_rss, rel=1e-6)


def test_the_floating_fastener_study_from_a_spreadsheet_spec(tmp_path):
    """The study reads the MMC zones from a CSV spec (columns zone, size, feature type) and gives 0 by both worst cases."""
    import json

    from rvtol.cli import main

    from conftest import ROOT

    out = tmp_path / "report"
    rc = main(["run", str(ROOT / "studies" / "stack_floating_fastener.toml"), "--out", str(out), "--executor", "serial",
               "--no-pdf", "--quiet", "--n", "2000"])
    assert rc == 0
    s = json.loads((out / "summary.json").read_text())["analyses"]["stack_conventions"]["margin"]
    rows = {r["convention"]: r for r in s["conventions"]}
    assert rows["worst case (arithmetic)"]["low"] == pytest.approx(0.0, abs=1e-9)
    assert rows["worst case (true extreme)"]["low"] == pytest.approx(0.0, abs=1e-6)
    assert rows["worst case (arithmetic)"]["high"] == pytest.approx(0.7, abs=1e-9)


@pytest.mark.parametrize("extra, key, reason", [
    ({}, "size", "bonus from the feature's actual size"),
    ({"size": "H1"}, "feature_type", "feature type"),
    ({"size": "nope", "feature_type": "internal"}, "size", "names no factor"),
])
def test_a_zone_at_mmc_needs_its_feature_of_size(extra, key, reason):
    z = {"tolerance": "⌀0.4 (M)", "unit": "mm", "zone": "h", **extra}
    with pytest.raises(InputError, match=reason) as e:
        spec_from_table({"factor": [{"name": "H1", "tolerance": "6.4 +0.2/0", "unit": "mm"},
                                    {"name": "x", **z}, {"name": "y", **z}]}, file="s.toml")
    assert key in (e.value.key or "")


def test_mmc_zones_round_trip_through_a_spreadsheet(tmp_path):
    from conftest import ROOT

    from rvtol.inputs.table_spec import write_table_spec
    from rvtol.spec import load_spec

    spec = load_spec(ROOT / "data" / "examples" / "floating_fastener_mmc.csv")
    f = spec.factor("x1")
    assert (f.zone, f.modifier, f.size, f.feature_type) == ("hole1", "MMC", "H1", "internal")
    out = write_table_spec(spec, tmp_path / "back.csv")
    back = load_spec(out)
    for a, b in zip(spec.factors, back.factors):
        assert (a.name, a.zone, a.modifier, a.size, a.feature_type, a.limits) == \
            (b.name, b.zone, b.modifier, b.size, b.feature_type, b.limits)
        assert a.dist.std == pytest.approx(b.dist.std)


def test_the_datum_shift_of_tec_ease_tip_223():
    """Tec-Ease GD&T tip 223 ("Datum Features can Give You a Shift — not a Bonus", 1998; ASME Y14.5-2009/2018): datum
    feature B referenced at MMB has a simulator of ⌀19.6 and may be produced as large as ⌀20.2, so the pattern it
    locates "could shift as much as 0.6 total" — 0.3 from the datum axis each way.  Here one feature of the pattern,
    positioned ⌀0.2 RFS: its axis lies within 0.1 + 0.3 = 0.4 of true position when B is at ⌀20.2, within 0.1 when B
    is at its MMB (the tip gives no tolerance of its own to the pattern: ⌀0.2 is ours)."""
    common = {"tolerance": "⌀0.2", "unit": "mm", "zone": "p", "datum_size": "B", "datum_type": "internal"}
    spec = spec_from_table({"factor": [{"name": "B", "tolerance": "19.6 +0.6/0", "unit": "mm"},
                                       {"name": "x", **common}, {"name": "y", **common}]})
    m = FormulaModel.from_spec(spec, {"r": ("hypot(x, y)", "mm")})
    true = true_worst_case(m, spec, "r")
    assert true.high == pytest.approx(0.1 + 0.6 / 2, abs=1e-6) and true.x_high["B"] == pytest.approx(20.2)
    x0 = spec.nominal_base()
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], 0.0, x0, out_unit="mm", slopes=one_sided_slopes(m, spec, "r"))
    assert sc.row("worst case (arithmetic)")["high"] == pytest.approx(0.4, abs=1e-9)
    # the shift, total: twice the largest radial displacement the datum's departure from MMB adds (0.6, the tip's)
    assert 2 * (true.high - 0.1) == pytest.approx(0.6, abs=2e-6)


def two_hole_pattern(modifier=""):
    """Two holes ⌀10.4 +0.1/0 of a pattern, each positioned ⌀0.2 (at RFS, or Ⓜ with its own size), 50 mm apart along x,
    both to datum bore B ⌀20 +0.1/0 referenced at MMB; the coordinates are the holes' deviations from true position."""
    def zone(z, size):
        own = {"size": size, "feature_type": "internal"} if modifier else {}
        return {"tolerance": f"⌀0.2{modifier}", "unit": "mm", "zone": z, "datum_size": "B", "datum_type": "internal",
                **own}
    return spec_from_table({"factor": [
        {"name": "B", "tolerance": "20 +0.1/0", "unit": "mm"},
        {"name": "D1", "tolerance": "10.4 +0.1/0", "unit": "mm"}, {"name": "D2", "tolerance": "10.4 +0.1/0", "unit": "mm"},
        {"name": "x1", **zone("h1", "D1")}, {"name": "y1", **zone("h1", "D1")},
        {"name": "x2", **zone("h2", "D2")}, {"name": "y2", **zone("h2", "D2")}]})


def _both_worst_cases(spec, formula: str, half: float, oriented: bool = False):
    """The linearised and the true worst case of ``formula`` (mm) are its nominal ± ``half``; both results (the true
    search's corner start oriented by the model's gradient when ``oriented``, as the stack-up analysis does)."""
    m = FormulaModel.from_spec(spec, {"y": (formula, "mm")})
    x0 = spec.nominal_base()
    y0 = float(m.evaluate(x0[None])[0, 0])
    g = m.gradient(x0[None])[0, 0]
    sc = stack_conventions(spec, g, y0, x0, out_unit="mm", slopes=one_sided_slopes(m, spec, "y"))
    wc = sc.row("worst case (arithmetic)")
    assert (wc["low"], wc["high"]) == (pytest.approx(y0 - half, abs=1e-9), pytest.approx(y0 + half, abs=1e-9)), formula
    true = true_worst_case(m, spec, "y", max_evaluations=1000, gradient=g if oriented else None)
    assert (true.low, true.high) == (pytest.approx(y0 - half, abs=1e-6), pytest.approx(y0 + half, abs=1e-6)), formula
    return sc, true


@pytest.mark.parametrize("modifier", ["", " (M)"], ids=["RFS", "MMC"])
def test_a_datum_shift_moves_the_pattern_as_one(modifier):
    """Issue 37: the distance between two holes of a pattern located from datum bore B at MMB does not change with
    B's departure from MMB — the datum-feature shift translates the whole pattern (ASME Y14.5 simultaneous
    requirement; Drake 1999 ch. 5).  By hand: the spacing's deviation x₂ − x₁ (true spacing 50 along x), each hole
    within its own ⌀0.2 zone (+ its bonus (D − 10.4)/2 at MMC, at most 0.05): ±(0.1 + 0.1) at RFS, ±(0.15 + 0.15)
    at MMC; the datum's up-to-0.05 shift adds 0.  Each zone's own share of the datum shift gave ±0.3 at RFS (−0.1
    too low).  The
    location of one hole from the datum axis still takes the shift: x₁ ∈ ±(0.1 + 0.05) at RFS."""
    spec = two_hole_pattern(modifier)
    own = 0.1 + (0.05 if modifier else 0.0)
    for formula, half in (("x2 - x1", 2 * own), ("x1", own + 0.05), ("x1 + x2", 2 * own + 2 * 0.05)):
        sc, true = _both_worst_cases(spec, formula, half)
        # the run's notes say how the datum shift was applied
        assert any("shifts h1, h2 together" in n and "one translation of the pattern" in n for n in sc.notes)
        assert any("shifts h1, h2 together" in n for n in true.notes)


@pytest.mark.parametrize("modifier", ["", " (M)"], ids=["RFS", "MMC"])
def test_a_separate_requirement_shifts_its_zone_on_its_own(modifier):
    """Issue 42: SEP REQT beneath hole 2's frame makes its datum-feature shift its own — the two holes no longer move
    as one pattern on B's departure from MMB.  By hand (two_hole_pattern): the spacing x₂ − x₁ now takes both shifts,
    ±(2·own + 2·0.05); one hole from the datum axis is unchanged, ±(own + 0.05)."""
    from dataclasses import replace

    from rvtol.spec import ToleranceSpec, datum_shifts
    base = two_hole_pattern(modifier)
    spec = ToleranceSpec("sep", tuple(replace(f, separate=True) if f.zone == "h2" else f for f in base.factors))
    assert [(d.label, d.zones) for d in datum_shifts(spec)] == [("B", ("h1",)), ("B (SEP REQT h2)", ("h2",))]
    own = 0.1 + (0.05 if modifier else 0.0)
    for formula, half in (("x2 - x1", 2 * own + 2 * 0.05), ("x1", own + 0.05), ("x2", own + 0.05)):
        sc, true = _both_worst_cases(spec, formula, half, oriented=True)
        assert any("separate requirement (SEP REQT) of h2" in n for n in sc.notes)
        assert any("shifts h2 on its own" in n for n in true.notes)


def test_a_separate_requirement_is_a_spreadsheet_column_and_needs_a_datum_shift(tmp_path):
    rows = ["name,unit,tolerance,zone,datum size,datum type,sep reqt", "B,mm,20 +0.1/0,,,,",
            "x1,mm,⌀0.2,h1,B,internal,", "y1,mm,⌀0.2,h1,B,internal,", "x2,mm,⌀0.2,h2,B,internal,yes",
            "y2,mm,⌀0.2,h2,B,internal,yes"]
    (tmp_path / "s.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    from rvtol.inputs.table_spec import write_table_spec
    from rvtol.spec import datum_shifts, load_spec
    spec = load_spec(tmp_path / "s.csv")
    assert [d.label for d in datum_shifts(spec)] == ["B", "B (SEP REQT h2)"]
    write_table_spec(spec, tmp_path / "out.xlsx")
    assert load_spec(tmp_path / "out.xlsx").factors == spec.factors
    with pytest.raises(InputError, match="needs datum_size") as ei:
        spec_from_table({"factor": [{"name": "x", "tolerance": "⌀0.2", "unit": "mm", "zone": "h", "separate": True},
                                    {"name": "y", "tolerance": "⌀0.2", "unit": "mm", "zone": "h", "separate": True}]})
    assert ei.value.key == "factor[0].separate"


def test_a_separate_requirement_belongs_to_a_frame_whose_zones_move_together(tmp_path):
    """The audit's D2: SEP REQT is written beneath a frame; an nX frame's zones (``frame``) still move as one. Four
    holes ⌀0.2 RFS to datum bore B ⌀20 +0.1/0 at MMB (shift ≤ 0.05); holes 2 and 3 under their own 2X frame with SEP
    REQT. By hand: x₃ − x₂ ±0.2 (their own zones: one frame, one shift); x₂ − x₁ ±(0.2 + 2 × 0.05) (two shifts);
    x₄ − x₁ ±0.2 (the simultaneous frames)."""
    from rvtol.spec import datum_shifts

    def zone(z, frame=None):
        own = {"frame": frame, "separate": True} if frame else {}
        return {"tolerance": "⌀0.2", "unit": "mm", "zone": z, "datum_size": "B", "datum_type": "internal", **own}
    rows = [{"name": "B", "tolerance": "20 +0.1/0", "unit": "mm"}]
    for k in (1, 2, 3, 4):
        frame = "2X" if k in (2, 3) else None
        rows += [{"name": f"x{k}", **zone(f"h{k}", frame)}, {"name": f"y{k}", **zone(f"h{k}", frame)}]
    spec = spec_from_table({"factor": rows})
    assert [(d.label, d.zones) for d in datum_shifts(spec)] == [("B", ("h1", "h4")), ("B (SEP REQT 2X)", ("h2", "h3"))]
    x0 = spec.nominal_base()
    for formula, half in (("x3 - x2", 0.2), ("x2 - x1", 0.3), ("x4 - x1", 0.2)):
        m = FormulaModel.from_spec(spec, {"y": (formula, "mm")})
        sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], 0.0, x0, out_unit="mm",
                               slopes=one_sided_slopes(m, spec, "y"))
        assert sc.row("worst case (arithmetic)")["high"] == pytest.approx(half, abs=1e-9), formula
    with pytest.raises(InputError, match="share its datums and its SEP REQT") as ei:   # h2 without its frame's SEP REQT
        spec_from_table({"factor": rows[:3] + [dict(rows[3], separate=False), dict(rows[4], separate=False)]
                         + rows[5:]})
    assert ei.value.key == "factor.frame"


def test_a_floating_fastener_pair_on_a_shifted_datum():
    """The floating fastener's two holes (fastener_spec, at RFS) both located from datum bore B ⌀20 +0.1/0 at MMB:
    the margin depends on |p₁ − p₂| only, which a common shift does not change — worst case 0 still (the kinked
    pattern's slopes taken with the pattern moved as one; each zone's own shift gave −0.1)."""
    base = fastener_spec()
    from dataclasses import replace

    from rvtol.spec import Factor, ToleranceSpec
    from rvtol.distributions import Distribution
    B = Factor("B", "mm", Distribution.make("uniform", lower=20.0, upper=20.1))
    fs = tuple(replace(f, datum_size="B", datum_type="internal") if f.zone else f for f in base.factors) + (B,)
    spec = ToleranceSpec("ff", fs)
    m = FormulaModel.from_spec(spec, {"margin": (MARGIN, "mm")})
    x0 = spec.nominal_base()
    sl = one_sided_slopes(m, spec, "margin")
    assert sl.pattern_max["B"] == pytest.approx(0.0, abs=1e-9) and sl.pattern_min["B"] == pytest.approx(0.0, abs=1e-9)
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], float(m.evaluate(x0[None])[0, 0]), x0, out_unit="mm",
                           slopes=sl)
    assert sc.row("worst case (arithmetic)")["low"] == pytest.approx(0.0, abs=1e-9)
    assert true_worst_case(m, spec, "margin", max_evaluations=3000).low == pytest.approx(0.0, abs=1e-6)


def test_one_datum_feature_has_one_type():
    """Two zones naming datum feature B, one as a bore and one as a boss: refused (each would shift the pattern the
    other way), with the key."""
    z = lambda name, t: [{"name": f"{c}{name}", "tolerance": "⌀0.2", "unit": "mm", "zone": name, "datum_size": "B",  # noqa: E731
                          "datum_type": t} for c in "xy"]
    with pytest.raises(InputError, match="one feature has one type") as e:
        spec_from_table({"factor": [{"name": "B", "tolerance": "20 +0.1/0", "unit": "mm"},
                                    *z("h1", "internal"), *z("h2", "external")]}, file="s.toml")
    assert e.value.key == "factor.datum_type"


def _zone_and_w():
    """A zone ⌀0.05 and w ±0.01, read from TOML text (each coordinate's zone name a string of its own, as a study's)."""
    import tomllib

    return spec_from_table(tomllib.loads(ZONE_AND_W))


def test_an_undefined_zone_derivative_is_the_zones_central_difference_coordinate_by_coordinate():
    """The model's derivative is NaN for both coordinates of a smooth zone (e.g. atan2 off its cut): each is replaced
    by its own component of the slopes' central difference (2 for hole.x, 1 for hole.y), noted; the worst case is then the
    disc 0.025·√(2² + 1²) + 0.01."""
    from rvtol.stacking.slopes import Slopes

    spec = _zone_and_w()
    nan = math.nan
    slopes = Slopes(up=np.array([nan, nan, 1.0]), down=np.array([nan, nan, -1.0]), zone_grad={"hole": (2.0, 1.0)},
                    zone_max={"hole": math.sqrt(5)}, zone_min={"hole": -math.sqrt(5)})
    sc = stack_conventions(spec, np.array([nan, nan, 1.0]), 0.0, out_unit="mm", slopes=slopes)
    assert sc.factors["a"].tolist() == pytest.approx([2.0, 1.0, 1.0])
    assert sc.row("worst case (arithmetic)")["half_width"] == pytest.approx(0.025 * math.sqrt(5) + 0.01)
    assert sc.notes == [("the model's derivative is undefined (NaN/∞) for hole.x, hole.y: the central difference of "
                         "its one-sided slopes is used instead")]


def test_undefined_derivatives_of_two_zones_are_each_their_own_zones():
    """A plain factor w, then two zones with undefined derivatives, the one named later in the alphabet written first:
    each coordinate takes its own zone's central difference (zb: 2, 1; za: 3, 4) — w's 0.01 and the disc of each,
    0.025·√5 + 0.025·5."""
    import tomllib

    from rvtol.stacking.slopes import Slopes

    text = '[[factor]]\nname = "w"\nunit = "mm"\ntolerance = "±0.01"\nnominal = 0\n' + "".join(
        f'[[factor]]\nname = "{z}.{c}"\nunit = "mm"\ntolerance = "⌀0.05"\nzone = "{z}"\n' for z in ("zb", "za")
        for c in "xy")
    spec = spec_from_table(tomllib.loads(text))
    nan = math.nan
    slopes = Slopes(up=np.r_[1.0, np.full(4, nan)], down=np.r_[-1.0, np.full(4, nan)],
                    zone_grad={"zb": (2.0, 1.0), "za": (3.0, 4.0)},
                    zone_max={"zb": math.sqrt(5), "za": 5.0}, zone_min={"zb": -math.sqrt(5), "za": -5.0})
    sc = stack_conventions(spec, np.r_[1.0, np.full(4, nan)], 0.0, out_unit="mm", slopes=slopes)
    assert sc.factors["a"].tolist() == pytest.approx([1.0, 2.0, 1.0, 3.0, 4.0])
    assert sc.row("worst case (arithmetic)")["half_width"] == pytest.approx(0.01 + 0.025 * math.sqrt(5) + 0.025 * 5)


def test_an_undefined_derivative_of_a_kinked_zone_is_taken_by_its_sides():
    """A cone at the zone's centre whose model gives NaN for the coordinates' derivative (the least-norm subgradient
    not taken): the zone is kinked, so its sides decide — it rises 1 per unit radius, falls at most 0 — and the
    output lies in [−0.01, 0.025 + 0.01]; no 'central difference used' note (none is), and no error (slopes given)."""
    from rvtol.stacking.slopes import Slopes

    spec = _zone_and_w()
    nan = math.nan
    slopes = Slopes(up=np.array([nan, nan, 1.0]), down=np.array([nan, nan, -1.0]), zone_grad={"hole": (0.0, 0.0)},
                    zone_max={"hole": 1.0}, zone_min={"hole": 1.0}, kinked=["hole"])
    sc = stack_conventions(spec, np.array([nan, nan, 1.0]), 0.0, out_unit="mm", slopes=slopes)
    wc = sc.row("worst case (arithmetic)")
    assert (wc["low"], wc["high"]) == (pytest.approx(-0.01), pytest.approx(0.035))
    assert not any("undefined" in n for n in sc.notes) and any(n.startswith("position zone hole: ") for n in sc.notes)


def test_a_kinked_factor_in_the_rss_statistical_and_six_sigma_rows_by_hand():
    """y = |u| + 2w (u uniform ±0.3, kinked at 0: rises 1 per unit either side, so the larger slope is 1; w normal
    ±0.05, σ_w = 0.05/3), u and w correlated −0.5.  The rows that read u as bilateral ±(larger slope)·(its reading):
    RSS √((2·0.05)² + (1·0.3)²), statistical and dynamic RSS σ = √((2σ_w)² + (1·σ_u)²) with σ_u = 0.3/√3 (u at its
    zero slope contributes nothing else, k = 0: no inflation), the Six Sigma row with Cp 2 and no shift (Cpk 2) σ =
    √((2·0.05/6)² + (1·0.3/6)²).  The one-sided u has no sign to correlate — its negative correlation too is named as
    left out — and the dynamic RSS is defined (no mean outside its band).  Each factor's RSS share: 0.09 and 0.01
    of 0.1."""
    spec = spec_from_table({"factor": [{"name": "u", "tolerance": "±0.3", "unit": "mm", "nominal": 0.0,
                                        "dist": "uniform"},
                                       {"name": "w", "tolerance": "±0.05", "unit": "mm", "nominal": 0.0}],
                            "correlation": [{"pair": ["u", "w"], "rho": -0.5}]})
    m = FormulaModel.from_spec(spec, {"y": ("abs(u) + 2*w", "mm")})
    x0 = spec.nominal_base()
    sl = one_sided_slopes(m, spec, "y")
    assert sl.kinked == ["u"]
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], 0.0, x0, out_unit="mm", slopes=sl, six_sigma=(2.0, 0.0))
    rss = sc.row("RSS")
    assert rss["half_width"] == pytest.approx(math.hypot(2 * 0.05, 0.3), rel=1e-6)
    assert "except for the one-sided u, taken as independent" in rss["note"]
    sigma = math.hypot(2 * 0.05 / 3, 0.3 / math.sqrt(3))
    assert sc.row("statistical ±3σ (the distributions)")["sigma"] == pytest.approx(sigma, rel=1e-6)
    assert "kinked contributors as ±(largest one-sided slope)·σ" in sc.row("statistical ±3σ (the distributions)")["note"]
    assert sc.row("6σ dynamic RSS ±3σ")["half_width"] == pytest.approx(3 * sigma, rel=1e-6)
    assert sc.row("6σ dynamic, 0σ shift ±3σ")["sigma"] == pytest.approx(math.hypot(2 * 0.05 / 6, 0.3 / 6), rel=1e-6)
    assert not any("dynamic RSS is undefined" in n for n in sc.notes)
    assert sc.factors["rss_pct"].tolist() == pytest.approx([90.0, 10.0], rel=1e-6)


def test_a_kinked_zone_read_from_a_spec_file_names_its_correlated_coordinates_as_left_out():
    """r = |p| + w at the zone's centre (a cone: kinked), the spec read from TOML text (each coordinate's zone a string
    of its own) with both coordinates correlated to w: the statistical rows take the kinked zone as independent and
    say so for each of the pair."""
    import tomllib

    pairs = "".join(f'[[correlation]]\npair = ["{c}", "w"]\nrho = 0.5\n' for c in ("hole.x", "hole.y"))
    spec = spec_from_table(tomllib.loads(ZONE_AND_W + pairs))
    assert spec.factors[0].zone is not spec.factors[1].zone
    m = FormulaModel.from_spec(spec, {"r": ("hypot(hole.x, hole.y) + w", "mm")})
    x0 = spec.nominal_base()
    sl = one_sided_slopes(m, spec, "r")
    assert sl.kinked == ["hole"]
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], 0.0, x0, out_unit="mm", slopes=sl)
    note = sc.row("statistical ±3σ (the distributions)")["note"]
    assert "except for the one-sided hole.x, hole.y, taken as independent" in note
    # both coordinates share the zone's worst-case term ½·(radius 0.025 × slope 1), w its 0.01; both are "kinked"
    f = sc.factors
    assert f["wc_pct"].tolist() == pytest.approx([100 * 0.0125 / 0.035, 100 * 0.0125 / 0.035, 100 * 0.01 / 0.035])
    assert f["linearisation"].tolist() == ["kink: per unit radius up 1, down 0"] * 2 + [""]


ZONE_AND_W = """
[[factor]]
name = "hole.x"
unit = "mm"
tolerance = "⌀0.05"
zone = "hole"
[[factor]]
name = "hole.y"
unit = "mm"
tolerance = "⌀0.05"
zone = "hole"
[[factor]]
name = "w"
unit = "mm"
tolerance = "±0.01"
nominal = 0
"""


def _hole_and_w():
    return spec_from_table({"factor": [
        {"name": "x", "tolerance": "⌀0.2", "unit": "mm", "zone": "hole"},
        {"name": "y", "tolerance": "⌀0.2", "unit": "mm", "zone": "hole"},
        {"name": "w", "tolerance": "±0.05", "unit": "mm", "nominal": 0.0}]})


@pytest.mark.parametrize("expr,name", [("sqrt(x * L) + w", "hole"), ("sqrt(w * L) + x", "w")])
def test_a_model_that_cannot_be_evaluated_beside_the_nominal_point_has_no_linearised_stack(expr, name):
    """√(x·L) is undefined for x < 0: the ring of the zone's directions (or w's step below its nominal) leaves the
    model's domain, so no one-sided slope exists there — a clear error naming the zone or the factor (a zone gave a
    KeyError: its slopes were looked up as if it were kinked)."""
    spec = _hole_and_w()
    m = FormulaModel.from_spec(spec, {"r": (expr, "mm")}, definitions={"L": ("1", "mm")})
    x0 = spec.nominal_base()
    with np.errstate(invalid="ignore", divide="ignore"):
        g = m.gradient(x0[None])[0, 0]
        sl = one_sided_slopes(m, spec, "r")
    assert sl.undefined == [name]
    with pytest.raises(InputError, match=f"cannot be evaluated next to the nominal point for {name}: no linearised"):
        stack_conventions(spec, g, 0.0, x0, out_unit="mm", slopes=sl)


def test_an_undefined_derivative_of_a_smooth_factor_is_its_central_difference():
    """The model's derivative is ∞ for w, its one-sided slopes agree (D⁺ = 3, D⁻ = −3: smooth): w enters with the
    central difference 3, noted — the worst case 0.1·1 (the disc ⌀0.2 of x) + 0.05·3."""
    from rvtol.stacking.slopes import Slopes

    spec = _hole_and_w()
    slopes = Slopes(up=np.array([math.nan, math.nan, 3.0]), down=np.array([math.nan, math.nan, -3.0]),
                    zone_grad={"hole": (1.0, 0.0)}, zone_max={"hole": 1.0}, zone_min={"hole": -1.0})
    sc = stack_conventions(spec, np.array([1.0, 0.0, math.inf]), 0.0, out_unit="mm", slopes=slopes)
    assert sc.row("worst case (arithmetic)")["half_width"] == pytest.approx(0.1 + 0.15)
    assert sc.notes == [("the model's derivative is undefined (NaN/∞) for w: the central difference of its "
                         "one-sided slopes is used instead")]


def test_a_kinked_zone_on_a_datum_feature_needs_the_slopes_of_its_pattern():
    """A kinked zone located by a datum feature at MMB: the shift's effect is measured by moving the pattern; slopes
    that do not have it (the model could not be evaluated with the pattern moved) give a clear error, not a guess."""
    from rvtol.stacking.slopes import Slopes

    common = {"tolerance": "⌀0.2 (M)", "unit": "mm", "zone": "h", "size": "D", "feature_type": "internal",
              "datum_size": "B", "datum_type": "internal"}
    spec = spec_from_table({"factor": [
        {"name": "D", "tolerance": "10.4 +0.1/0", "unit": "mm"}, {"name": "B", "tolerance": "20 +0.1/0", "unit": "mm"},
        {"name": "x", **common}, {"name": "y", **common}]})
    nan = math.nan
    slopes = Slopes(up=np.array([0.0, 0.0, nan, nan]), down=np.array([0.0, 0.0, nan, nan]), zone_grad={"h": (0, 0)},
                    zone_max={"h": 1.0}, zone_min={"h": 1.0}, kinked=["h"])
    with pytest.raises(InputError, match="with the pattern located by datum feature B \\(h\\) shifted"):
        stack_conventions(spec, np.zeros(4), 0.0, out_unit="mm", slopes=slopes)


DATUM_AND_PEG = """
[[factor]]
name = "D"
unit = "mm"
tolerance = "10.4 +0.1/0"
[[factor]]
name = "B"
unit = "mm"
tolerance = "20 +0.1/0"
[[factor]]
name = "hole.x"
unit = "mm"
tolerance = "⌀0.2 (M)"
zone = "hole"
size = "D"
feature_type = "internal"
datum_size = "B"
datum_type = "internal"
[[factor]]
name = "hole.y"
unit = "mm"
tolerance = "⌀0.2 (M)"
zone = "hole"
size = "D"
feature_type = "internal"
datum_size = "B"
datum_type = "internal"
[[factor]]
name = "peg.x"
unit = "mm"
tolerance = "⌀0.1"
zone = "peg"
[[factor]]
name = "peg.y"
unit = "mm"
tolerance = "⌀0.1"
zone = "peg"
"""


def test_zones_at_mmc_on_a_datum_and_a_plain_zone_read_from_a_spec_file():
    """The spec of test_a_datum_feature_shift_adds_to_the_zone plus a plain zone "peg" ⌀0.1, read from TOML text (each
    coordinate's zone name a string of its own): hole.x + peg.x reaches ±(0.1 + 0.05 + 0.05) from the hole, its bonus
    and the datum shift, and ±0.05 from the peg's disc — ±0.25."""
    import tomllib

    spec = spec_from_table(tomllib.loads(DATUM_AND_PEG))
    assert spec.factors[2].zone is not spec.factors[3].zone
    m = FormulaModel.from_spec(spec, {"s": ("hole.x + peg.x", "mm")})
    x0 = spec.nominal_base()
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], 0.0, x0, out_unit="mm",
                           slopes=one_sided_slopes(m, spec, "s"))
    wc = sc.row("worst case (arithmetic)")
    assert (wc["low"], wc["high"]) == (pytest.approx(-0.25, abs=1e-12), pytest.approx(0.25, abs=1e-12))
    assert "datum-feature shift" in wc["note"] and "kinked" not in wc["note"]      # nothing here is kinked
    assert "kinked" not in sc.row("statistical ±3σ (the distributions)")["note"]
    # the worst-case shares: B's shift 0.025, the hole's radius 0.125 halved over its coordinates, the peg's 0.05
    f = sc.factors
    assert f["wc_pct"].tolist() == pytest.approx([0.0, 12.5, 31.25, 31.25, 25.0, 0.0])
    assert f["linearisation"].tolist() == ["", "datum feature at MMB: shifts hole together (per unit up 1, down 1)",
                                           "zone at MMC", "zone at MMC", "", ""]
    # the RSS: D and B at their coupled sensitivity −½ over ±0.05, the hole's radius 0.125 and the shift's 0.025, and
    # peg.x as its own 3σ (the Rayleigh σ whose 99.73 % radius is 0.05)
    from scipy.stats import norm

    sigma_peg = 0.05 / math.sqrt(-2 * math.log(2 * norm.sf(3)))
    t_rss = math.sqrt(2 * 0.025 ** 2 + 0.125 ** 2 + 0.025 ** 2 + (3 * sigma_peg) ** 2)
    assert sc.row("RSS")["half_width"] == pytest.approx(t_rss, rel=1e-9)


def test_a_kinked_zone_beside_a_plain_zone_keeps_their_rss_shares_apart():
    """r = |hole| + w + pin.x (the hole's zone kinked, the pin's plain and written first, read from TOML): the RSS
    shares are pin.x's (3σ)² with σ the Rayleigh σ of its ⌀0.02, pin.y's 0, the hole's ½(0.025 × slope 1)² per
    coordinate, w's 0.01²; the worst case |hole| ∈ [0, 0.025], w ± 0.01, pin.x ± 0.01."""
    import tomllib

    from scipy.stats import norm

    pin = "".join(f'[[factor]]\nname = "pin.{c}"\nunit = "mm"\ntolerance = "⌀0.02"\nzone = "pin"\n' for c in "xy")
    spec = spec_from_table(tomllib.loads(pin + ZONE_AND_W))
    m = FormulaModel.from_spec(spec, {"r": ("hypot(hole.x, hole.y) + w + pin.x", "mm")})
    x0 = spec.nominal_base()
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], 0.0, x0, out_unit="mm",
                           slopes=one_sided_slopes(m, spec, "r"))
    sigma_pin = 0.01 / math.sqrt(-2 * math.log(2 * norm.sf(3)))
    terms = np.array([(3 * sigma_pin) ** 2, 0.0, 0.5 * 0.025 ** 2, 0.5 * 0.025 ** 2, 0.01 ** 2])
    assert sc.factors["rss_pct"].tolist() == pytest.approx((100 * terms / terms.sum()).tolist(), rel=1e-6)
    wc = sc.row("worst case (arithmetic)")
    assert (wc["low"], wc["high"]) == (pytest.approx(-0.02, rel=1e-6), pytest.approx(0.045, rel=1e-6))


@pytest.mark.parametrize("mmc,kinked", [("amc", "zk"), ("zmc", "ak")])
def test_only_a_kinked_zone_is_left_out_of_the_statistical_rows_correlation(mmc, kinked):
    """A smooth zone at MMC whose x is correlated with w, beside a kinked zone (either name first in the alphabet): the
    RSS reads the MMC zone as its disc, one-sided, and names its correlation as left out; the statistical rows describe
    the produced parts with the MMC zone's coordinates as they are — its correlation kept, nothing named there."""
    import tomllib

    def zone(z, c, tol, extra=""):
        return f'[[factor]]\nname = "{z}.{c}"\nunit = "mm"\ntolerance = "{tol}"\nzone = "{z}"\n{extra}'

    text = ('[[factor]]\nname = "D"\nunit = "mm"\ntolerance = "10.4 +0.1/0"\n'
            '[[factor]]\nname = "w"\nunit = "mm"\ntolerance = "±0.01"\nnominal = 0\n'
            + "".join(zone(mmc, c, "⌀0.2 (M)", 'size = "D"\nfeature_type = "internal"\n') for c in "xy")
            + "".join(zone(kinked, c, "⌀0.05") for c in "xy")
            + f'[[correlation]]\npair = ["{mmc}.x", "w"]\nrho = 0.5\n')
    spec = spec_from_table(tomllib.loads(text))
    m = FormulaModel.from_spec(spec, {"r": (f"{mmc}.x + hypot({kinked}.x, {kinked}.y) + w", "mm")})
    x0 = spec.nominal_base()
    sl = one_sided_slopes(m, spec, "r")
    assert sl.kinked == [kinked]
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], 0.0, x0, out_unit="mm", slopes=sl)
    assert f"except for the one-sided {mmc}.x, taken as independent" in sc.row("RSS")["note"]
    assert "except for" not in sc.row("statistical ±3σ (the distributions)")["note"]


def test_a_kink_flat_on_one_side_is_taken_by_its_falling_side_only():
    """½·min(u, 0) at u = 0: flat above (D⁺ = 0), falling ½ per unit below (D⁻ = −½): u adds nothing to the upper worst
    case and ½·0.1 to the lower — y ∈ [−0.05 − 0.01, 0 + 0.01] with w's ±0.01."""
    from rvtol.stacking.slopes import Slopes

    spec = spec_from_table({"factor": [{"name": "u", "tolerance": "±0.1", "unit": "mm", "nominal": 0.0},
                                       {"name": "w", "tolerance": "±0.01", "unit": "mm", "nominal": 0.0}]})
    slopes = Slopes(up=np.array([0.0, 1.0]), down=np.array([-0.5, -1.0]), kinked=["u"])
    sc = stack_conventions(spec, np.array([0.25, 1.0]), 0.0, out_unit="mm", slopes=slopes)
    wc = sc.row("worst case (arithmetic)")
    assert (wc["low"], wc["high"]) == (pytest.approx(-0.06), pytest.approx(0.01))


def test_a_kinked_factor_and_a_kinked_zone_both_take_their_sides():
    """|w| + |hole| (both kinked at the nominal point, the factor listed among the one-sided contributors before the
    zone): each is ≥ 0, so the worst case is [0, 0.01 + 0.025]."""
    spec = _zone_and_w()
    m = FormulaModel.from_spec(spec, {"r": ("abs(w) + hypot(hole.x, hole.y)", "mm")})
    x0 = spec.nominal_base()
    sl = one_sided_slopes(m, spec, "r")
    assert sorted(sl.kinked) == ["hole", "w"]
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], 0.0, x0, out_unit="mm", slopes=sl)
    wc = sc.row("worst case (arithmetic)")
    assert (wc["low"], wc["high"]) == (pytest.approx(0.0, abs=1e-12), pytest.approx(0.035, rel=1e-6))


def test_a_kinked_factors_worst_case_share_is_its_larger_slope_times_its_band():
    """y = 2|u| + w, u ±0.3 kinked at 0 (rises 2 per unit either side: D⁺ = D⁻ = 2), w ±0.2: y ∈ [−0.2, 0.6 + 0.2].
    Each factor's worst-case share: u's 2 · 0.3 = 0.6 and w's 1 · 0.2 of 0.8 — 75 % and 25 %; the RSS shares
    0.6² and 0.2² of 0.4 — 90 % and 10 %."""
    spec = spec_from_table({"factor": [{"name": "u", "tolerance": "±0.3", "unit": "mm", "nominal": 0.0},
                                       {"name": "w", "tolerance": "±0.2", "unit": "mm", "nominal": 0.0}]})
    m = FormulaModel.from_spec(spec, {"y": ("2*abs(u) + w", "mm")})
    x0 = spec.nominal_base()
    sl = one_sided_slopes(m, spec, "y")
    assert sl.kinked == ["u"]
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], 0.0, x0, out_unit="mm", slopes=sl)
    wc = sc.row("worst case (arithmetic)")
    assert (wc["low"], wc["high"]) == (pytest.approx(-0.2, abs=1e-9), pytest.approx(0.8, abs=1e-9))
    f = sc.factors
    assert f["wc_pct"].tolist() == pytest.approx([75.0, 25.0], rel=1e-6)
    assert f["rss_pct"].tolist() == pytest.approx([90.0, 10.0], rel=1e-6)
    assert f["linearisation"].tolist() == ["kink: per unit of band up 2, down 0", ""]


@pytest.mark.parametrize("sign", [1, -1], ids=["lowered", "raised"])
def test_a_datum_shift_that_moves_the_output_one_way_only_adds_nothing_the_other_way(sign):
    """y = ±(B/2 − |p|): datum bore B 20 +0.1/0 at MMB locates a hole whose axis p lies in a ⌀0.2 zone (RFS); B's
    departure from MMB lets the pattern shift by up to (B − 20)/2.  With +, every shift lowers y (slope −1 whichever
    way): per unit of shift y rises at most max(0, −1) = 0 (module docstring) and falls at most 1.  By hand, y's
    largest value is B/2 at p = 0 and B = 20.1: 10.05; its smallest B/2 − 0.1 − (B − 20)/2 = 9.9 at every B.  A
    shift that rose by −1 per unit took the datum's whole radius off the upper end: 10.0.  With −, the mirror image:
    every shift raises y, y ∈ [−10.05, −9.9]."""
    common = {"tolerance": "⌀0.2", "unit": "mm", "zone": "h", "datum_size": "B", "datum_type": "internal"}
    spec = spec_from_table({"factor": [{"name": "B", "tolerance": "20 +0.1/0", "unit": "mm"},
                                       {"name": "x", **common}, {"name": "y", **common}]})
    m = FormulaModel.from_spec(spec, {"wall": (f"{sign}*(B/2 - hypot(x, y))", "mm")})
    x0 = spec.nominal_base()
    sl = one_sided_slopes(m, spec, "wall")
    assert sl.pattern_max["B"] == pytest.approx(-sign) and sl.pattern_min["B"] == pytest.approx(-sign)
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], float(m.evaluate(x0[None])[0, 0]), x0, out_unit="mm",
                           slopes=sl)
    wc = sc.row("worst case (arithmetic)")
    low, high = sorted((sign * 9.9, sign * 10.05))
    assert (wc["low"], wc["high"]) == (pytest.approx(low, abs=1e-9), pytest.approx(high, abs=1e-9))
    up, down = (0, 1) if sign > 0 else (1, 0)
    assert sc.factors["linearisation"][0] == f"datum feature at MMB: shifts h together (per unit up {up}, down {down})"


def test_a_size_that_lowers_the_output_more_than_its_bonus_raises_it():
    """y = 2x − 3D, x a coordinate of a hole's ⌀0.2 Ⓜ zone, D the hole's size 10.4 +0.1/0: the zone's radius is
    0.1 + (D − 10.4)/2, so y's largest value is max over D of 2·(0.1 + (D − 10.4)/2) − 3D, falling with D: −31.0 at
    D = 10.4; its smallest −2·(0.1 + (D − 10.4)/2) − 3D, lowest at D = 10.5: −31.8.  The size's net effect on the
    upper end is −3 + 2·½ = −2 per unit: it hurts going down, not up."""
    own = {"tolerance": "⌀0.2 (M)", "unit": "mm", "zone": "h", "size": "D", "feature_type": "internal"}
    spec = spec_from_table({"factor": [{"name": "D", "tolerance": "10.4 +0.1/0", "unit": "mm"},
                                       {"name": "x", **own}, {"name": "y", **own}]})
    m = FormulaModel.from_spec(spec, {"s": ("2*x - 3*D", "mm")})
    x0 = spec.nominal_base()
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], float(m.evaluate(x0[None])[0, 0]), x0, out_unit="mm",
                           slopes=one_sided_slopes(m, spec, "s"))
    wc = sc.row("worst case (arithmetic)")
    assert (wc["low"], wc["high"]) == (pytest.approx(-31.8, abs=1e-9), pytest.approx(-31.0, abs=1e-9))
