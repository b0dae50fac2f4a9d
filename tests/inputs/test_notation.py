"""Drawing tolerance notation: limits by hand, ISO classes from the standard's tables, factor tables
through the existing loader, process specs by their closed forms."""
import math
import re

import numpy as np
import pytest
from scipy import stats

from rvtol.distributions import from_params
from rvtol.errors import InputError
from rvtol.inputs.notation import (NotationError, fmt, format_deviations, format_limits, zone_level,
                                   parse_tolerance)
from rvtol.params import Params


def limits(text, **kw):
    t = parse_tolerance(text, **kw)
    return t.lower_limit, t.upper_limit


def dist(table):
    return from_params(Params(table, file="t.csv", key="row"))


# (text, kwargs, lower limit, upper limit, nominal, unit)
CASES = [
    ("±0.05", {}, -0.05, 0.05, None, None),
    ("+/-0.05", {}, -0.05, 0.05, None, None),
    ("25 ±0.05", {}, 24.95, 25.05, 25, None),
    ("25 +0.10/-0.00", {}, 25.0, 25.10, 25, None),
    ("25 +0.10/−0.00", {}, 25.0, 25.10, 25, None),          # U+2212 as on the issue
    ("25 +0.10 -0.05", {}, 24.95, 25.10, 25, None),
    ("25 0/-0.02", {}, 24.98, 25.0, 25, None),
    ("0/-0.02", {"nominal": 12.0}, 11.98, 12.0, 12, None),
    ("-0.05/+0.10", {"nominal": 25.0}, 24.95, 25.10, 25, None),  # written low first
    ("+0,10/-0,05", {"nominal": 25.0}, 24.95, 25.10, 25, None),  # decimal commas
    ("5%", {"nominal": 200.0}, 190.0, 210.0, 200, None),
    ("±2 %", {"nominal": 50.0}, 49.0, 51.0, 50, None),
    ("100 +5%/-2%", {}, 98.0, 105.0, 100, None),
    ("100 +5/-2 %", {}, 98.0, 105.0, 100, None),
    ("24.95..25.05", {}, 24.95, 25.05, None, None),
    ("24.95 to 25.05 mm", {}, 24.95, 25.05, None, "mm"),
    ("24.95..25.05", {"nominal": 25.0}, 24.95, 25.05, 25, None),
    ("-0.02..+0.03", {}, -0.02, 0.03, None, None),
    ("max 0.02", {}, 0.0, 0.02, None, None),
    ("≤ 0.02 mm", {}, 0.0, 0.02, None, "mm"),
    ("25 mm +10/-5 um", {}, 24.995, 25.010, 25, "mm"),
    ("+10/-5 um", {"nominal": 25.0, "unit": "mm"}, 24.995, 25.010, 25, "mm"),
    ('1.000" ±0.002"', {}, 0.998, 1.002, 1, "in"),
    ("1 in +0.002/-0.001", {}, 0.999, 1.002, 1, "in"),
    ("1 in +0.002/-0.001", {"unit": "mm"}, 25.3746, 25.4508, 25.4, "mm"),
    ("±0.5°", {}, -0.5, 0.5, None, "deg"),
]


@pytest.mark.parametrize("text,kw,lo,hi,nom,unit", CASES, ids=[c[0] for c in CASES])
def test_forms(text, kw, lo, hi, nom, unit):
    t = parse_tolerance(text, **kw)
    assert t.lower_limit == pytest.approx(lo, abs=1e-12)
    assert t.upper_limit == pytest.approx(hi, abs=1e-12)
    assert t.nominal == (None if nom is None else pytest.approx(nom))
    assert t.unit == unit
    assert t.upper > t.lower


def test_iso_classes_come_from_the_standards_tables():
    t = parse_tolerance("25 H7")
    assert (t.unit, t.form, t.lower, t.upper) == ("mm", "iso", 0.0, 0.021)
    assert parse_tolerance("Ø7 h5").limits == (6.994, 7.0)
    assert parse_tolerance("⌀7h5").diameter
    assert parse_tolerance("h5", nominal=7.0).limits == (6.994, 7.0)
    assert parse_tolerance("50 k6").limits == pytest.approx((50.002, 50.018), abs=1e-12)
    assert parse_tolerance("100 P7").limits == pytest.approx((99.941, 99.976), abs=1e-12)
    assert parse_tolerance("25g6").limits == pytest.approx((24.980, 24.993), abs=1e-12)
    # 25e8 is the class e8 (−40/−73 µm), never 2.5e9
    assert parse_tolerance("25e8").limits == pytest.approx((24.927, 24.960), abs=1e-12)
    # inches: a 1 in H7 bore is looked up at 25.4 mm (18–30 mm: IT7 = 21 µm)
    t = parse_tolerance("1 H7", unit="in")
    assert t.unit == "in" and t.upper == pytest.approx(0.021 / 25.4, rel=1e-15)


def test_fit_gives_the_clearance_range():
    t = parse_tolerance("25 H7/g6")
    assert (t.form, t.nominal, t.unit) == ("fit", None, "mm")
    assert t.limits == pytest.approx((0.007, 0.041), abs=1e-15)
    assert t.fit.kind == "clearance"
    assert parse_tolerance("25 H7/p6").limits == pytest.approx((-0.035, -0.001), abs=1e-15)
    # as a normal factor: σ is the RSS of the two parts' σ (IT/6 each), its tolerance the WC range
    d = dist(parse_tolerance("25 H7/g6").factor_table("normal"))
    assert d.std == pytest.approx(math.hypot(0.021 / 6, 0.013 / 6), rel=1e-12)
    assert d.mean == pytest.approx(0.024, rel=1e-12)
    assert d.tolerance == pytest.approx(0.034, rel=1e-12)
    # ... the same σ as hole − shaft sampled independently (closed form: the variance of a difference)
    rng = np.random.default_rng(1)
    c = rng.normal(25.0105, 0.021 / 6, 200_000) - rng.normal(24.9865, 0.013 / 6, 200_000)
    assert c.std() == pytest.approx(d.std, rel=4 * math.sqrt(0.5 / 200_000))


def test_factor_tables_through_the_existing_loader():
    t = parse_tolerance("25 +0.10/-0.00")
    d = dist(t.factor_table())
    assert (d.kind, d.mean, d.std) == ("normal", pytest.approx(25.05), pytest.approx(0.1 / 6))
    assert t.factor_table()["nominal"] == 25.0
    d = dist(t.factor_table("uniform"))
    assert d.frozen.support() == pytest.approx((25.0, 25.1))
    d = dist(t.factor_table("triangular"))
    assert d.p["mode"] == pytest.approx(25.05)
    d = dist(t.factor_table("truncnorm", sigma_level=2))
    assert d.frozen.support() == pytest.approx((25.0, 25.1)) and d.p["sigma"] == pytest.approx(0.025)
    d = dist(t.factor_table("normal", sigma_level=4))
    assert d.std == pytest.approx(0.1 / 8)
    # a magnitude: the coverage quantile is the limit
    d = dist(parse_tolerance("max 0.02").factor_table("rayleigh"))
    assert d.ppf(0.9973002039367398) == pytest.approx(0.02, rel=1e-9)
    d = dist(parse_tolerance("max 0.02").factor_table("weibull", shape=2.0))
    assert d.tolerance == pytest.approx(0.02, rel=1e-9)
    with pytest.raises(NotationError, match="cannot be read as 'lognormal'"):
        t.factor_table("lognormal")


def test_process_spec_keeps_the_drawing_limits():
    t = parse_tolerance("25 ±0.05 Cpk 1.33 k 0.25")
    cp = 1.33 / 0.75
    assert t.process.cp == pytest.approx(cp) and t.process.k == 0.25
    assert t.limits == (24.95, 25.05)          # the drawing's worst-case limits, unchanged
    d = dist(t.factor_table())
    sigma = 0.1 / (6 * cp)
    assert d.std == pytest.approx(sigma, rel=1e-12)
    assert d.mean == pytest.approx(25.0 + 0.25 * 0.05, rel=1e-12)
    assert d.tolerance == pytest.approx(0.1, rel=1e-12)   # the drawing band, not 6σ
    # closed forms: Cp = T/6σ, Cpk = min(USL − μ, μ − LSL)/3σ
    assert 0.1 / (6 * d.std) == pytest.approx(cp)
    assert min(25.05 - d.mean, d.mean - 24.95) / (3 * d.std) == pytest.approx(1.33)
    # fraction outside the drawing limits from scipy
    out = stats.norm.sf(25.05, d.mean, d.std) + stats.norm.cdf(24.95, d.mean, d.std)
    assert out == pytest.approx(stats.norm.sf(3 * 1.33), rel=1e-3)


def test_process_spec_combinations():
    p = parse_tolerance("25 ±0.05 Cp 1.33").process
    assert (p.cp, p.cpk, p.k) == (1.33, 1.33, 0.0)
    p = parse_tolerance("25 ±0.05 Cpk ≥ 1.33").process
    assert (p.cp, p.cpk, p.k) == (1.33, 1.33, 0.0)
    p = parse_tolerance("25 ±0.05 Cp 2 Cpk 1.5").process
    assert p.k == pytest.approx(0.25)
    p = parse_tolerance("25 ±0.05 Cp=2 k=-0.25").process
    assert (p.cpk, p.k) == (1.5, -0.25)
    d = dist(parse_tolerance("25 ±0.05 Cp=2 k=-0.25").factor_table())
    assert d.mean == pytest.approx(25.0 - 0.0125)
    with pytest.raises(NotationError, match="disagree"):
        parse_tolerance("25 ±0.05 Cp 2 Cpk 1.5 k 0.1")
    with pytest.raises(NotationError, match="cannot exceed"):
        parse_tolerance("25 ±0.05 Cp 1 Cpk 1.5")
    with pytest.raises(NotationError, match="normal process"):
        parse_tolerance("25 ±0.05 Cp 1.33").factor_table("uniform")
    with pytest.raises(NotationError, match="two-sided"):
        parse_tolerance("max 0.02 Cp 1.33")


@pytest.mark.parametrize("text,kw,words", [
    ("0.05", {}, "bare number is ambiguous"),
    ("25", {}, "bare number is ambiguous"),
    ("25 mm", {}, "nominal without a tolerance"),
    ("24.95-25.05", {}, "write both deviations"),
    ("25 0.1/0.05", {}, "needs a sign"),
    ("+0.05", {}, "write both deviations"),
    ("5%", {}, "percentage needs a nonzero nominal"),
    ("H7", {}, "needs the nominal size"),
    ("25 Q7", {}, "unknown fundamental deviation"),
    ("25 t6", {"nominal": 20.0}, "differs from the nominal"),
    ("20 t6", {}, "above 24"),
    ("25 H7/H6", {}, "hole/shaft"),
    ("±0.05 furlongs", {}, "unexpected 'furlongs'"),
    ("±0.05 deg", {"unit": "mm"}, "cannot convert"),
    ("25 ±0.05 Cp", {}, "ends too early"),
    ("25 +0.05/+0.05", {}, "zero width"),
    ("__import__('os')", {}, "unexpected"),
    ("", {}, "empty"),
    ("±0.05", {"unit": "milimeter"}, "unknown unit"),
])
def test_errors_say_what_is_accepted(text, kw, words):
    with pytest.raises(NotationError, match=words) as e:
        parse_tolerance(text, **kw)
    assert isinstance(e.value, InputError)
    if words not in ("unknown unit",):
        assert "accepted:" in e.value.reason and "H7/g6" in e.value.reason


def test_formatting_round_trips():
    for lo, hi in [(-0.05, 0.05), (0.0, 0.1), (-0.02, 0.0), (-0.020, -0.007), (0.01, 0.03),
                   (-1 / 3, 2 / 3), (-0.010499999999999999, 0.0105)]:
        s = format_deviations(lo, hi)
        t = parse_tolerance(s)
        assert (t.lower, t.upper) == pytest.approx((lo, hi), rel=1e-11, abs=1e-15), s
    assert format_deviations(-0.05, 0.05) == "±0.05"
    assert format_deviations(-0.02, 0.0) == "0/-0.02"
    assert format_deviations(-0.020, -0.007) == "-0.007/-0.02"
    assert format_limits(24.95, 25.05) == "24.95..25.05"
    assert fmt(1e-7) == "0.0000001" and "e" not in fmt(123456789012.5)
    assert parse_tolerance(format_limits(24.0695, 24.0905)).limits == (24.0695, 24.0905)


# ---------------------------------------------------------------- issue 25: drawing forms and general tolerances
def test_a_class_with_its_deviations_as_drawings_print_it():
    """``50 H7 (+0.025/0)``: ISO 286-1 Table 1 gives IT7 = 25 µm for 30–50 mm and H has EI = 0."""
    from rvtol.inputs.notation import parse_tolerance

    t = parse_tolerance("50 H7 (+0.025/0)")
    assert (t.form, t.nominal, t.lower, t.upper) == ("iso", 50.0, 0.0, pytest.approx(0.025))
    assert parse_tolerance("50 +0.025/0 (H7)").upper == pytest.approx(0.025)
    assert parse_tolerance("25 g6 (-0.007/-0.020)").limits == (pytest.approx(24.980), pytest.approx(24.993))
    with pytest.raises(InputError, match="mistyped"):
        parse_tolerance("50 H7 (+0.030/0)")
    # a bore is drawn with its diameter sign: the same class and deviations, the feature marked a diameter
    t = parse_tolerance("Ø50 H7 (+0.025/0)")
    assert (t.form, t.nominal, t.lower, t.upper, t.diameter) == ("iso", 50.0, 0.0, pytest.approx(0.025), True)
    assert parse_tolerance("⌀25 g6 (-0.007/-0.020)").limits == (pytest.approx(24.980), pytest.approx(24.993))
    with pytest.raises(InputError, match="mistyped"):
        parse_tolerance("Ø50 H7 (+0.030/0)")


def test_a_percent_sign_on_one_deviation_only_is_refused():
    """``50 +5 %/-2`` read the upper deviation as 5 % of 50 (2.5) and the lower as −2 mm: two units in one pair,
    most likely a percent sign left off.  ``+5/-2 %`` (the sign after the pair) and ``+5 %/-2 %`` are both 5 % / 2 %
    (2.5 / 1.0 at 50)."""
    from rvtol.inputs.notation import parse_tolerance

    for text in ("50 +5 %/-2", "50 +5 % -2", "50 +5 %/-2 mm", "50 +0.1 mm/-2 %"):
        with pytest.raises(InputError, match="one deviation in percent"):
            parse_tolerance(text, unit="mm")
    for text in ("50 +5/-2 %", "50 +5 %/-2 %", "50 +5% -2%"):
        assert parse_tolerance(text, unit="mm").limits == (pytest.approx(49.0), pytest.approx(52.5))


def test_iso_2768_general_tolerances():
    """ISO 2768-1:1989 Table 1: class m is ±0.3 over 30–120 mm, ±0.5 over 120–400; f ±0.05 at 0.5–6; v has none
    below 3 mm; ISO 2768-2 Table 1: straightness K over 100–300 mm is 0.4; Table 4: run-out H 0.1."""
    from rvtol.inputs import iso2768
    from rvtol.inputs.notation import parse_tolerance

    assert parse_tolerance("50 ISO 2768-m").limits == (pytest.approx(49.7), pytest.approx(50.3))
    assert parse_tolerance("120 ISO 2768-mK").upper == pytest.approx(0.3)     # 120 is in 30–120
    assert parse_tolerance("120.5 ISO 2768-m").upper == pytest.approx(0.5)
    assert parse_tolerance("ISO 2768-f", nominal=4.0).upper == pytest.approx(0.05)
    with pytest.raises(InputError, match="no value"):
        parse_tolerance("2 ISO 2768-v")
    assert iso2768.geometric("straightness", "K", 150) == 0.4 and iso2768.geometric("runout", "H") == 0.1
    assert iso2768.geometric("perpendicularity", "L", 80) == 0.6


def test_zone_material_condition_modifiers():
    from rvtol.inputs.notation import parse_tolerance

    for text, mod in (("⌀0.4 (M)", "MMC"), ("⌀0.4 Ⓜ", "MMC"), ("Ø0.4 MMC", "MMC"), ("⌀0.4 (L)", "LMC"),
                      ("⌀0.4 Ⓛ", "LMC"), ("⌀0.4 (S)", ""), ("⌀0.4", "")):
        t = parse_tolerance(text)
        assert (t.form, t.modifier, t.width) == ("zone", mod, pytest.approx(0.4))
    with pytest.raises(InputError, match="position zone"):
        parse_tolerance("25 ±0.1 (M)")


# ------------------------------------------------------------------------------------------------ units, text, limits
def test_in_unit_converts_every_number_whichever_way_the_unit_names_sort():
    t = parse_tolerance("+10/-5 um").in_unit("mm")                  # "um" sorts after "mm"
    assert (t.unit, t.nominal, t.lower, t.upper) == ("mm", None, pytest.approx(-0.005), pytest.approx(0.010))
    t = parse_tolerance("25 +0.1/-0.2 mm").in_unit("um")            # a nominal too: 25 mm = 25000 µm
    assert (t.unit, t.nominal, t.lower, t.upper) == ("um", pytest.approx(25000), pytest.approx(-200),
                                                     pytest.approx(100))
    assert parse_tolerance("±0.1 mm").in_unit("mm") == parse_tolerance("±0.1 mm")


def test_describe_writes_each_form_back_as_a_drawing_does():
    assert parse_tolerance("25 +0.1/-0.2 mm").describe() == "25 +0.1/-0.2 mm"
    assert parse_tolerance("24.95..25.05").describe() == "24.95..25.05"
    assert parse_tolerance("max 0.02").describe() == "0..0.02"
    assert parse_tolerance("⌀0.4").describe() == "⌀0.4"


def test_a_tolerance_sent_to_a_worker_process_reads_the_same():
    # pickling (multiprocessing) rebuilds the form's string: a new object, equal but not the same
    import pickle
    for text in ("⌀0.4 mm (M)", "25 +0.1/-0.2 mm", "24.95..25.05"):
        t = parse_tolerance(text)
        back = pickle.loads(pickle.dumps(t))
        assert back.describe() == t.describe()
        assert back.factor_table() == t.factor_table()


def test_sigma_level_zero_is_refused():
    with pytest.raises(NotationError, match="sigma_level must be > 0, got 0"):
        parse_tolerance("±0.1").factor_table(sigma_level=0)


def test_a_symmetric_and_a_percent_tolerance_keep_their_form():
    assert parse_tolerance("±0.1 mm").form == "symmetric"
    assert parse_tolerance("100 ±5 %").form == "percent"
    # two deviations too (rvtol.spec asks for the nominal of deviations, not of percentages, which carry it)
    assert parse_tolerance("25 +0.1/-0.2").form == "deviations"
    assert parse_tolerance("100 +5%/-2%").form == "percent"


def test_two_deviations_without_a_slash_one_of_them_zero():
    t = parse_tolerance("25 +0.1 0")                                  # stacked on the drawing: +0.1 over 0
    assert (t.nominal, t.lower, t.upper) == (25.0, 0.0, 0.1)


def test_a_minus_zero_deviation_is_stored_and_written_as_zero():
    t = parse_tolerance("+0.05/-0")
    assert math.copysign(1.0, t.lower) == 1.0 and t.describe() == "+0.05/0"


def test_200_characters_are_read_and_201_refused():
    assert parse_tolerance("±0.1".ljust(200)).upper == 0.1
    with pytest.raises(NotationError, match="longer than 200 characters"):
        parse_tolerance("±0.1".ljust(201))


def test_an_error_names_the_position_of_the_stray_character():
    with pytest.raises(NotationError, match="unexpected '@' at position 6"):   # ±0.1 @: the 6th character
        parse_tolerance("±0.1 @")


def test_an_ambiguous_thousands_comma_is_a_located_notation_error():
    with pytest.raises(NotationError, match=r"cannot read tolerance '25 ±1,250': '1,250' is ambiguous"):
        parse_tolerance("25 ±1,250")


def test_a_nominal_without_a_unit_beside_a_tolerance_in_another_unit_is_refused():
    with pytest.raises(NotationError, match="the nominal 25 has no unit and the tolerance is in µm while the factor "
                                            r"is in mm: write the nominal's unit \(e.g. 25 mm or 25 µm\)"):
        parse_tolerance("25 +10/-5 um", unit="mm")
    t = parse_tolerance("25 +0.1/-0.2", unit="mm")                    # no unit written: the factor's
    assert (t.nominal, t.lower, t.upper, t.unit) == (25.0, -0.2, 0.1, "mm")


# a nominal beside absolute limits: how far off its band it may lie (ISO 286-2, the a/A fundamental deviation:
# −270 µm for 1–3 mm, −300 µm for 18–30 mm, −310 µm for 30–40 mm; below 1 mm there is no a, c gives −60 µm)
def test_a_nominal_beside_its_limits_may_lie_as_far_off_as_iso_286_puts_a_band():
    t = parse_tolerance("24.70..24.75 mm", nominal=25)                # 25 a: 300 µm below, accepted
    assert (t.lower, t.upper) == (pytest.approx(-0.3), pytest.approx(-0.25))
    # the reach is inclusive: exactly 270 µm (with its 1e-9 rounding allowance) off a 1.1 mm nominal is accepted,
    # the next float beyond it refused
    reach = 0.27 * (1 + 1e-9)
    hi = 1.1 - reach
    assert parse_tolerance(f"{hi - 0.01!r}..{hi!r} mm", nominal=1.1).upper == -reach
    beyond = math.nextafter(hi, 0.0)
    with pytest.raises(NotationError, match="farther than any ISO 286"):
        parse_tolerance(f"{beyond - 0.01!r}..{beyond!r} mm", nominal=1.1)


@pytest.mark.parametrize("text, nominal, why", [
    ("24.0..24.1 mm", 25, "lies 0.9 mm above its limits 24..24.1, farther than any ISO 286 tolerance class puts a "
                          r"band at this size \(0.3 mm\)"),
    ("1.45..1.46 in", 1.5, "lies 0.04 in above its limits 1.45..1.46, farther than any ISO 286 tolerance class puts "
                           r"a band at this size \(0.0122047 in\)"),       # 38.1 mm: 310 µm = 0.0122047 in
    ("1..5 mm", 10, "lies 5 mm above its limits 1..5, farther than the band's own width"),
    ("12..13 mm", 10, "lies 2 mm below its limits 12..13, farther than the band's own width"),
    ("10..12 deg", 30, "lies 18 ° above its limits 10..12, farther than the band's own width"),
    ("10..12", 30, "lies 18 above its limits 10..12, farther than the band's own width"),
    ("1..1.234567", 10, "lies 8.76543 above its limits 1..1.234567, farther than the band's own width"),  # 6 digits
    # a band as wide as ISO's farthest (300 µm at 25 mm) is named by its own width
    ("20000..20300 um", 25000, "lies 4700 µm above its limits 20000..20300, farther than the band's own width"),
])
def test_a_nominal_too_far_from_its_limits_is_refused_with_the_distance_and_side(text, nominal, why):
    with pytest.raises(NotationError, match=f"the nominal {nominal} {why}: one of them is mistyped"):
        parse_tolerance(text, nominal=nominal)


def test_a_magnitude_factor_starts_where_the_band_says():
    # max x: from 0; a..b: from a (shift a); +x/0: from the nominal (here none: 0)
    assert parse_tolerance("max 0.02").factor_table("rayleigh") == {"dist": "rayleigh", "tolerance": 0.02}
    assert parse_tolerance("0.02..0.05").factor_table("rayleigh") == {
        "dist": "rayleigh", "tolerance": pytest.approx(0.03), "shift": 0.02}
    assert parse_tolerance("+0.05/0").factor_table("rayleigh") == {"dist": "rayleigh", "tolerance": 0.05}
    with pytest.raises(NotationError, match="a rayleigh factor is a magnitude"):   # does not start at the nominal
        parse_tolerance("+0.1/+0.05").factor_table("rayleigh")


def test_a_number_or_a_percent_sign_after_the_unit_place_is_not_a_unit():
    # "1" and "%" are units of the table (dimensionless, percent) but never as tokens of their own kind
    with pytest.raises(NotationError, match="unexpected '1' at position 6, expected a unit or a process spec"):
        parse_tolerance("±0.1 1")
    with pytest.raises(NotationError, match="unexpected '%' at position 10, expected a unit or a process spec"):
        parse_tolerance("100 ±5 % %")


def test_a_material_condition_on_anything_but_a_position_zone_is_refused_first():
    for text in ("25 ±0.1 (M)", "±0.1 @ (M)"):       # the condition is named even where the rest cannot be read
        with pytest.raises(NotationError, match=r"a material condition \(M\)/\(L\)/MMC/LMC belongs to a position "
                                                r"zone: ⌀t \(M\)"):
            parse_tolerance(text)


def test_a_position_zone_is_converted_to_the_unit_asked_for():
    t = parse_tolerance("⌀0.1 mm", unit="um")                        # ⌀0.1 mm: radius 50 µm
    assert (t.form, t.unit, t.lower, t.upper) == ("zone", "um", pytest.approx(-50.0), pytest.approx(50.0))


@pytest.mark.parametrize("unit", ["deg", "s", "N*mm"])
def test_an_iso_class_in_a_unit_that_is_not_a_length_is_refused(unit):
    with pytest.raises(NotationError, match=rf"an ISO 286 class is a length tolerance, not in {re.escape(unit)}"):
        parse_tolerance("25 H7", unit=unit)


@pytest.mark.parametrize("k", ["1", "1.5", "-1", "-1.5"])
def test_a_mean_shift_outside_minus_one_to_one_is_refused(k):
    with pytest.raises(NotationError, match=r"k \(the mean shift over the half tolerance\) must lie in \(-1, 1\)"):
        parse_tolerance(f"±0.1 Cp 1.33 k {k}")


@pytest.mark.parametrize("text, second, at", [
    ("25 ±0.1 um mm", "mm", 12),          # the grammar's one unit after the body, written twice: was read as µm
    ("±0.1 mm mm", "mm", 9),
    ("24.95..25.05 mm in", "in", 17),
    ("25 +10/-5 um mm", "mm", 14),
    ("max 0.02 mm um", "um", 13),
    ("25 mm H7 in", "in", 10),            # a class's unit is the nominal's or the one after it, not both
])
def test_a_second_unit_is_refused_not_ignored(text, second, at):
    with pytest.raises(NotationError, match=f"a second unit '{second}' at position {at}: write the unit once"):
        parse_tolerance(text)
    assert parse_tolerance("25 H7 mm").unit == "mm" and parse_tolerance("25 mm H7").unit == "mm"


def test_a_fits_factor_table_is_the_same_for_a_dist_read_from_a_file():
    import tomllib
    dist = tomllib.loads('dist = "normal"')["dist"]          # a new string, equal to "normal" but not the constant
    t = parse_tolerance("25 H7/g6")
    assert t.factor_table(dist) == t.factor_table()
    th, ts = t.fit.hole.width, t.fit.shaft.width               # RSS of the parts' σ at 3σ each, over the worst case
    assert t.factor_table(dist)["sigma_level"] == pytest.approx(3.0 * (th + ts) / math.hypot(th, ts))


def test_limits_written_in_two_units_convert_each_limit_by_its_own():
    t = parse_tolerance("24.9 mm..1 in")                        # 1 in = 25.4 mm
    assert (t.unit, t.lower_limit, t.upper_limit) == ("mm", 24.9, pytest.approx(25.4))
    t = parse_tolerance("0.98 in..25 mm")
    assert (t.unit, t.lower_limit, t.upper_limit) == ("in", 0.98, pytest.approx(25 / 25.4))


def test_a_nominal_exactly_one_band_width_off_its_limits_is_accepted():
    t = parse_tolerance("11..12", nominal=10)                  # off by 1, the band 1 wide: the bound is inclusive
    assert (t.lower, t.upper) == (1.0, 2.0)


@pytest.mark.parametrize("cp", ["0.5", "1", "1.33"])
def test_a_centred_process_may_have_cpk_equal_to_cp_below_one_too(cp):
    t = parse_tolerance(f"±0.1 Cp {cp} Cpk {cp}")
    assert (t.process.cp, t.process.cpk, t.process.k) == (float(cp), float(cp), 0.0)


@pytest.mark.parametrize("text, stray", [("(M)", "("), ("≥ 0.02", "≥"), ("= 0.02", "=")])
def test_a_tolerance_cannot_start_with_a_condition_or_a_lower_bound(text, stray):
    # "≥ x" is no form of the notation (only "≤ x", "max x"); a lone "(M)" has no zone to belong to
    with pytest.raises(NotationError, match=f"cannot read tolerance '{re.escape(text)}': unexpected "
                                            f"'{re.escape(stray)}' at position 1"):
        parse_tolerance(text)


def test_a_cpk_above_cp_by_rounding_only_is_taken_as_equal():
    t = parse_tolerance("±0.1 Cp 1.33 Cpk 1.3300000001")      # 7.5e-11 above: a rounding, not a contradiction
    assert t.process.cp == 1.33 and abs(t.process.k) < 1e-9
    with pytest.raises(NotationError, match=r"Cpk \(1.34\) cannot exceed Cp \(1.33\)"):
        parse_tolerance("±0.1 Cp 1.33 Cpk 1.34")


def test_a_number_with_three_decimals_and_no_comma_is_a_plain_decimal():
    t = parse_tolerance("25 ±1.000")
    assert (t.nominal, t.lower, t.upper) == (25.0, -1.0, 1.0)


def test_parentheses_pair_only_a_class_with_its_deviations():
    with pytest.raises(NotationError, match="a tolerance in parentheses must pair an ISO 286 class with its deviations"):
        parse_tolerance("25 ±0.1 (24.9..25.1)")


def test_deviations_beside_their_class_may_differ_by_half_a_micrometre():
    # 50 h7 is 0/-25 µm; the written deviations are rounded to the micrometre: ±0.5 µm is allowed, 0.6 µm is not
    assert parse_tolerance("50 h7 (+0.0005/-0.025)").limits == (49.975, 50.0)
    assert parse_tolerance("50 h7 (0/-0.0255)").limits == (49.975, 50.0)
    for text in ("50 h7 (+0.0006/-0.025)", "50 h7 (0/-0.0256)"):
        with pytest.raises(NotationError, match="differ from ISO 286's h7 at 50"):
            parse_tolerance(text)


def test_a_word_other_than_max_does_not_start_a_tolerance():
    with pytest.raises(NotationError, match="unexpected 'x' at position 1, expected a tolerance"):
        parse_tolerance("x 0.02")


def test_an_error_quotes_a_number_as_written_and_counts_positions_in_the_text():
    with pytest.raises(NotationError, match=r"the deviation '0.100' needs a sign \(\+ or -\)"):
        parse_tolerance("25 0.100/-0.05")
    with pytest.raises(NotationError, match="unexpected '@' at position 8"):
        parse_tolerance("±0.100 @")


def test_numbers_already_in_the_results_unit_are_taken_exactly_as_written():
    # 1.7 in and 0.003 in do not survive a round trip through mm (×25.4, ÷25.4) bit for bit: none is made
    for text in ("1.7 in +0.003/-0.0015", "1.7 in +0.003/-0.0015 in", '1.7" +0.003"/-0.0015"'):
        t = parse_tolerance(text)
        assert (t.unit, t.nominal, t.lower, t.upper) == ("in", 1.7, -0.0015, 0.003)


def test_a_position_zone_in_micrometres_is_converted_to_millimetres():
    t = parse_tolerance("⌀100 um", unit="mm")                     # "um" sorts after "mm": converted all the same
    assert (t.unit, t.lower, t.upper) == ("mm", pytest.approx(-0.05), pytest.approx(0.05))


def test_a_magnitude_from_below_zero_keeps_its_negative_start():
    assert parse_tolerance("-0.01..0.05").factor_table("rayleigh") == {
        "dist": "rayleigh", "tolerance": pytest.approx(0.06), "shift": -0.01}


def test_a_unitless_nominal_beside_inches_is_refused_when_the_factor_is_in_mm():
    # "in" sorts before "mm" (the µm case above sorts after): refused all the same
    with pytest.raises(NotationError, match="the nominal 25 has no unit and the tolerance is in in while the factor "
                                            "is in mm"):
        parse_tolerance("25 +0.002/-0.001 in", unit="mm")


def test_a_single_signed_percentage_is_not_a_tolerance():
    with pytest.raises(NotationError, match=r"write both deviations, e.g. \+0.05/0 or 0/-0.02 \(or ±x\)"):
        parse_tolerance("100 +5%")


@pytest.mark.parametrize("name", ["Cp", "Cpk"])
def test_a_capability_of_zero_is_refused(name):
    with pytest.raises(NotationError, match=f"{name} must be > 0"):
        parse_tolerance(f"±0.1 {name} 0")


# ------------------------------------------------------------------- issue 37: mutants of notation.py that survived
@pytest.mark.parametrize("level", [0.5, 1.0, 2.0])
def test_a_band_may_be_read_at_any_positive_sigma_level_below_three(level):
    # T = 0.1 read at ±level·σ: σ = T / (2·level) (0.1 at half a σ, 0.05 at one)
    d = dist(parse_tolerance("25 +0.10/-0.00").factor_table("normal", sigma_level=level))
    assert d.std == pytest.approx(0.1 / (2.0 * level), rel=1e-12)


def test_a_process_specs_factor_table_is_the_same_for_a_dist_read_from_a_file():
    import tomllib
    dist_name = tomllib.loads('dist = "normal"')["dist"]       # equal to "normal", not the same object
    t = parse_tolerance("25 ±0.05 Cp 1.33")
    assert t.factor_table(dist_name) == t.factor_table()
    assert t.factor_table(dist_name)["sigma_level"] == pytest.approx(3.0 * 1.33)   # σ = T/(6·Cp)


def test_a_magnitude_cannot_start_below_the_nominal():
    # +0.05/-0.01 is a band about the nominal from -0.01: neither from 0 (max x) nor from the nominal (+x/0)
    with pytest.raises(NotationError, match="a rayleigh factor is a magnitude"):
        parse_tolerance("+0.05/-0.01").factor_table("rayleigh")


@pytest.mark.parametrize("text", ["⌀25 ±0.1 (M)", "Ø25 H7 MMC", "⌀24.9..25.1 (L)"])
def test_a_material_condition_on_a_diameter_that_is_not_a_position_zone_is_refused(text):
    # the diameter sign lets the text past the first check; the condition still needs a zone (⌀t alone)
    with pytest.raises(NotationError, match=r"a material condition \(M\)/\(L\) belongs to a position zone ⌀t"):
        parse_tolerance(text)


def test_deviations_in_parentheses_beside_deviations_are_refused():
    # the parentheses pair a class with its deviations; two deviations (here even equal) pair nothing
    with pytest.raises(NotationError, match="must pair an ISO 286 class with its deviations"):
        parse_tolerance("25 ±0.1 (+0.1/-0.1)")


def test_a_text_over_200_characters_is_quoted_by_its_first_40():
    text = "".join(str(i % 10) for i in range(201))
    with pytest.raises(NotationError, match=re.escape(f"cannot read tolerance '{text[:40]}…': longer than 200 "
                                                      "characters")):
        parse_tolerance(text)


@pytest.mark.parametrize("nominal", [math.nan, math.inf, -math.inf, "25"])
def test_a_nominal_that_is_no_finite_number_is_refused(nominal):
    with pytest.raises(NotationError, match="nominal must be a finite number"):
        parse_tolerance("±0.1", nominal=nominal)


def test_a_position_zone_is_written_with_the_diameter_sign():
    assert parse_tolerance("⌀0.05").diameter and parse_tolerance("Ø0.1 mm (M)").diameter


def test_a_percentage_of_a_negative_nominal_is_a_band_about_it_and_of_zero_refused():
    # 5 % of −200 is ±10 (of its magnitude): −210 … −190
    assert parse_tolerance("5%", nominal=-200.0).limits == (pytest.approx(-210.0), pytest.approx(-190.0))
    with pytest.raises(NotationError, match="a percentage needs a nonzero nominal"):
        parse_tolerance("5%", nominal=0.0)


def test_a_nominal_far_from_limits_in_a_unit_that_is_no_length_is_checked_against_the_band_alone():
    # seconds: no ISO 286 class reaches a time (its dimension name sorts after "length")
    with pytest.raises(NotationError, match="the nominal 10 lies 5 s above its limits 1..5, farther than the band's "
                                            "own width"):
        parse_tolerance("1..5 s", nominal=10)


@pytest.mark.parametrize("level", [0.5, 1.0, 3.0])
def test_zone_level_is_the_rayleigh_quantile_of_the_normal_coverage(level):
    # the radial deviation of two independent N(0, σ²) coordinates is Rayleigh(σ): its quantile at the coverage
    # c = P(|Z| ≤ level) is the zone's radius in σ (scipy's Rayleigh, an independent closed form)
    c = stats.norm.cdf(level) - stats.norm.cdf(-level)
    assert zone_level(level) == pytest.approx(stats.rayleigh.ppf(c), rel=1e-12)
    d = dist(parse_tolerance("⌀0.4").factor_table(sigma_level=level))
    assert d.std == pytest.approx(0.2 / stats.rayleigh.ppf(c), rel=1e-12)


def test_zone_level_defaults_to_three_sigma():
    assert zone_level() == pytest.approx(stats.rayleigh.ppf(stats.norm.cdf(3) - stats.norm.cdf(-3)), rel=1e-12)


@pytest.mark.parametrize("x", [1 / 3, 2 / 3 * 1e-3, 123.456789012345, -0.0105 / 7])
def test_numbers_are_written_with_twelve_significant_digits(x):
    # Python's own '.12g' as the reference (these magnitudes print without an exponent there)
    assert fmt(x) == format(x, ".12g")
    assert format_limits(x, 2 * abs(x)) == f"{x:.12g}..{2 * abs(x):.12g}"
    assert format_deviations(-abs(x), 2 * abs(x)) == f"+{2 * abs(x):.12g}/-{abs(x):.12g}"


@pytest.mark.parametrize("level, sigma", [(None, 0.1), (1.5, 0.2), (4.0, 0.075)])
def test_a_truncated_normal_reads_its_band_at_the_sigma_level(level, sigma):
    # by hand: the band 9.7..10.3 (width 0.6) is ±level·σ, so σ = 0.6 / (2·level) — level 3 by default
    table = parse_tolerance("10 ±0.3").factor_table("truncnorm", sigma_level=level)
    assert table["sigma"] == pytest.approx(sigma, rel=1e-12)
    assert dist(table).frozen.support() == pytest.approx((9.7, 10.3), rel=1e-12)


@pytest.mark.parametrize("kind", ["lognormal", "beta", "gamma", "gumbel", "johnsonsu", "weibull", "truncnorm"])
def test_a_process_spec_is_refused_as_any_law_but_normal(kind):
    # laws that sort before "normal" (lognormal, beta, …) as well as after it
    with pytest.raises(NotationError, match=f"describes a normal process, not '{kind}'"):
        parse_tolerance("25 ±0.05 Cp 1.33").factor_table(kind)


@pytest.mark.parametrize("tight, spaced", [("max5", "max 5"), ("25 ±0.05 Cpk2", "25 ±0.05 Cpk 2")])
def test_a_word_of_three_letters_before_a_digit_is_no_iso_class(tight, spaced):
    # ISO 286 classes have one or two letters (H7, zc11): "max5" is max 5, "Cpk2" is Cpk 2
    t, ref = parse_tolerance(tight), parse_tolerance(spaced)
    assert (t.form, t.lower, t.upper, t.process) == (ref.form, ref.lower, ref.upper, ref.process)
    assert t.form in ("max", "symmetric") and t.iso is None


@pytest.mark.parametrize("given", [10.5, 9.2, 10.001])
def test_a_nominal_given_beside_a_different_one_in_the_text_is_refused_even_within_one_unit(given):
    with pytest.raises(NotationError, match=r"its nominal 10 differs from the nominal given with it"):
        parse_tolerance("10 ±0.1", nominal=given)
    # the same number (to 1e-9 of it) is the same nominal
    assert parse_tolerance("10 ±0.1", nominal=10.0 + 1e-9).nominal == 10.0


def test_ellipses_that_normalise_past_256_characters_are_a_notation_error():
    # each '…' is read as '..' (two characters): 200 of them make 400, a text the tokens must still reach the end of
    with pytest.raises(NotationError, match=r"unexpected '\.\.' at position 1, expected a tolerance"):
        parse_tolerance("…" * 200)
    with pytest.raises(NotationError, match=r"unexpected '\.\.'"):
        parse_tolerance("25 " + "…" * 150 + " 26")


# ------------------------------------------------------------------------------------------------ mutation run (issue 37)
@pytest.mark.parametrize("text, nominal, lower, upper", [
    ("10 js6", 10.0, -0.0045, 0.0045),        # 6–10 mm: IT6 = 9 µm, js = ±IT/2 (ISO 286-1 Table 1)
    ("50 JS7", 50.0, -0.0125, 0.0125),        # 30–50 mm: IT7 = 25 µm
    ("50 zc11", 50.0, 0.325, 0.485),          # 40–50 mm: ei = +325 µm (ISO 286-2 Table 12), IT11 = 160 µm
])
def test_an_iso_class_of_two_letters_is_read(text, nominal, lower, upper):
    t = parse_tolerance(text)
    assert (t.form, t.nominal, t.unit) == ("iso", nominal, "mm")
    assert (t.lower, t.upper) == (pytest.approx(lower, abs=1e-12), pytest.approx(upper, abs=1e-12))


def test_a_fit_is_refused_as_a_law_that_sorts_before_normal():
    # a fit's clearance is normal (or any band kind): lognormal, beta, gumbel sort before "normal"
    t = parse_tolerance("25 H7/g6")
    for kind in ("lognormal", "beta", "gumbel"):
        with pytest.raises(NotationError, match=f"cannot be read as '{kind}'"):
            t.factor_table(kind)


def test_a_tolerance_in_its_own_unit_is_unchanged_to_the_last_bit():
    # the unit read from the text is a new string (not the literal "in"): same unit, no conversion — 0.375 in
    # through mm and back is 0.37499999999999994
    t = parse_tolerance("10 ±0.375 in")
    assert t.in_unit("in") == t and (t.lower, t.upper) == (-0.375, 0.375)


def test_the_class_after_the_deviations_takes_their_unit():
    """2 in +0.00118/0 (H7): the class is H7 at 2 in = 50.8 mm (50–80 mm: IT7 = 30 µm, 0.0011811 in), whose
    deviations are the ones written to 0.5 µm — not H7 at 2 mm (IT7 = 10 µm)."""
    t = parse_tolerance("2 in +0.00118/0 (H7)")
    assert (t.form, t.nominal, t.unit, t.lower) == ("iso", 2.0, "in", 0.0)
    assert t.upper == pytest.approx(0.030 / 25.4, rel=1e-12) and t.iso.it == 30.0


def test_a_minus_zero_upper_deviation_is_stored_as_zero():
    t = parse_tolerance("50 -0.00/-0.1")
    assert math.copysign(1.0, t.upper) == 1.0 and (t.lower, t.upper) == (-0.1, 0.0)


def test_a_general_tolerance_has_no_diameter_sign():
    t = parse_tolerance("50 ISO 2768-m")        # 30–120 mm, class m: ±0.3 (ISO 2768-1 Table 1)
    assert (t.lower, t.upper, t.diameter) == (-0.3, 0.3, False)


def test_cpk_above_cp_by_the_rounding_allowance_is_accepted():
    # Cpk may exceed Cp by 1e-9 of it (rounding of the two figures): 1.000000001 = 1·(1 + 1e-9) in binary
    t = parse_tolerance("10 ±0.1 Cp 1 Cpk 1.000000001")
    assert t.process.cpk == 1.000000001 and t.process.k == pytest.approx(-1e-9, rel=1e-6)
    with pytest.raises(NotationError, match="cannot exceed Cp"):
        parse_tolerance("10 ±0.1 Cp 1 Cpk 1.000000002")
