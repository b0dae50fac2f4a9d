"""Drawing notation in every form × every unit pair of one dimension, both limits against pint converting the band
(an oracle independent of rvtol.units), and the cases of issue 37 that read wrong before: a ``±`` tolerance in
another unit than its factor converted only its lower deviation (``±5 um`` on 10 mm gave 9.995 … 15)."""
from decimal import Decimal

import pint
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rvtol.inputs.notation import NotationError, parse_tolerance

UREG = pint.UnitRegistry()
#: rvtol's spellings -> pint's ("mil" is pint's per-mille: the length is "mil_length")
LENGTH = {"mm": "millimeter", "um": "micrometer", "in": "inch", "mil": "mil_length", "thou": "thou", "m": "meter",
          "cm": "centimeter"}
ANGLE = {"deg": "degree", "arcmin": "arcminute", "arcsec": "arcsecond", "rad": "radian"}
PINT = {**LENGTH, **ANGLE}
#: other ways a drawing writes a unit
SPELLED = {"um": ("um", "µm"), "in": ("in", '"'), "deg": ("deg", "°")}


def to(v: float, src: str, dst: str) -> float:
    return UREG.Quantity(v, PINT[src]).to(PINT[dst]).magnitude


# numbers as drawings write them: up to 4 digits, up to 4 decimals (no exponent)
number = st.builds(lambda k, d: str(Decimal(k).scaleb(-d)), st.integers(1, 9999), st.integers(0, 4))


@st.composite
def units_of_one_dimension(draw):
    dim = draw(st.sampled_from([LENGTH, ANGLE]))
    return [draw(st.sampled_from(sorted(dim))) for _ in range(3)]


@st.composite
def spelled(draw, unit):
    return draw(st.sampled_from(SPELLED.get(unit, (unit,))))


@st.composite
def deviations(draw, unit_text):
    """(text of the body, lower, upper) of deviations written with ``unit_text`` ("" for none) in every form."""
    a, b = (draw(number) for _ in range(2))
    u = f" {unit_text}" if unit_text else ""
    form = draw(st.sampled_from(["pm", "plus_minus", "minus_plus", "each", "spaced", "zero_low", "zero_high"]))
    if form == "pm":
        return f"±{a}{u}", -float(a), float(a)
    if form == "plus_minus":
        return f"+{a}/-{b}{u}", -float(b), float(a)
    if form == "minus_plus":                      # written low first: the module accepts either order
        return f"-{b}/+{a}{u}", -float(b), float(a)
    if form == "each":
        return f"+{a}{u}/-{b}{u}", -float(b), float(a)
    if form == "spaced":
        return f"+{a} -{b}{u}", -float(b), float(a)
    if form == "zero_low":
        return f"+{a}/0{u}", 0.0, float(a)
    return f"0/-{b}{u}", -float(b), 0.0


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(units_of_one_dimension(), st.data())
def test_deviations_in_any_unit_match_pint_on_both_limits(us, data):
    """Nominal given beside the text (a table's nominal column, in the factor's unit), deviations written in any unit of
    the same dimension, or none (then in the factor's)."""
    factor_unit, dev_unit, _ = us
    written = data.draw(st.sampled_from([dev_unit, None]))
    body, lo, hi = data.draw(deviations(data.draw(spelled(written)) if written else ""))
    nominal = float(data.draw(number))
    t = parse_tolerance(body, nominal=nominal, unit=factor_unit)
    src = written or factor_unit
    assert to(1.0, t.unit, factor_unit) == 1.0        # the factor's unit (mil is spelled thou)
    assert t.lower_limit == pytest.approx(nominal + to(lo, src, factor_unit), rel=1e-12, abs=1e-12)
    assert t.upper_limit == pytest.approx(nominal + to(hi, src, factor_unit), rel=1e-12, abs=1e-12)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(units_of_one_dimension(), st.data())
def test_nominal_in_the_text_with_units_on_it_on_each_number_or_after_both(us, data):
    """The nominal written in the text: its unit on it (the deviations bare are in it), on it and on the deviations,
    or once after both — the last one read as the deviations' unit, and refused when the factor's unit differs (is
    the bare nominal in the factor's unit or in the deviations'?)."""
    factor_unit, dev_unit, nom_unit = us
    place = data.draw(st.sampled_from(["on_nominal", "on_each", "after_both", "after_both_no_factor_unit"]))
    nominal = data.draw(number)
    if place == "on_nominal":
        body, lo, hi = data.draw(deviations(""))
        text, kw = f"{nominal} {data.draw(spelled(nom_unit))} {body}", {"unit": factor_unit}
        lo_x = to(float(nominal) + lo, nom_unit, factor_unit)
        hi_x = to(float(nominal) + hi, nom_unit, factor_unit)
    elif place == "on_each":
        body, lo, hi = data.draw(deviations(data.draw(spelled(dev_unit))))
        text, kw = f"{nominal} {data.draw(spelled(nom_unit))} {body}", {"unit": factor_unit}
        n = to(float(nominal), nom_unit, factor_unit)
        lo_x, hi_x = n + to(lo, dev_unit, factor_unit), n + to(hi, dev_unit, factor_unit)
    else:
        body, lo, hi = data.draw(deviations(data.draw(spelled(dev_unit))))
        text = f"{nominal} {body}"
        kw = {} if place == "after_both_no_factor_unit" else {"unit": factor_unit}
        if kw and to(1.0, dev_unit, factor_unit) != 1.0:      # another unit than the factor's (mil is thou)
            with pytest.raises(NotationError, match="has no unit"):
                parse_tolerance(text, **kw)
            return
        lo_x = to(float(nominal) + lo, dev_unit, factor_unit)
        hi_x = to(float(nominal) + hi, dev_unit, factor_unit)
    t = parse_tolerance(text, **kw)
    lower, upper = (to(v, t.unit, factor_unit) for v in t.limits)
    assert lower == pytest.approx(lo_x, rel=1e-12, abs=1e-12)
    assert upper == pytest.approx(hi_x, rel=1e-12, abs=1e-12)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(units_of_one_dimension(), st.data())
def test_limits_and_magnitudes_in_any_unit_match_pint(us, data):
    """``a..b`` / ``a to b`` (a unit after b, or on each), ``max x``: absolute, with or without a nominal (in the
    factor's unit, inside the limits)."""
    factor_unit, unit_a, _ = us
    ua, ub = data.draw(spelled(unit_a)), data.draw(spelled(unit_a))
    start, width = Decimal(data.draw(number)), Decimal(data.draw(number))
    a, b = float(start), float(start + width)
    form = data.draw(st.sampled_from(["dots", "to", "each", "max"]))
    sa, sb = str(start), str(start + width)
    text = {"dots": f"{sa}..{sb} {ub}", "to": f"{sa} to {sb} {ub}", "each": f"{sa} {ua}..{sb} {ub}",
            "max": f"max {sb} {ub}"}[form]
    lo, hi = (0.0, b) if form == "max" else (a, b)
    nominal = None if form == "max" or data.draw(st.booleans()) else to(0.5 * (lo + hi), unit_a, factor_unit)
    t = parse_tolerance(text, nominal=nominal, unit=factor_unit)
    scale = abs(to(hi, unit_a, factor_unit))      # limits are kept as nominal + deviation: round-off of that size
    assert t.lower_limit == pytest.approx(to(lo, unit_a, factor_unit), rel=1e-12, abs=1e-12 * scale)
    assert t.upper_limit == pytest.approx(to(hi, unit_a, factor_unit), rel=1e-12, abs=1e-12 * scale)


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(sorted(PINT)), number, number, st.data())
def test_percent_and_process_specs_keep_both_limits(unit, nominal, p, data):
    """``x %`` of the nominal is unit-free; a process spec after a ``±`` in another unit keeps the converted band."""
    t = parse_tolerance(f"±{p} %", nominal=float(nominal), unit=unit)
    assert t.limits == pytest.approx((float(nominal) * (1 - float(p) / 100), float(nominal) * (1 + float(p) / 100)),
                                     rel=1e-12)
    other = data.draw(st.sampled_from(sorted(LENGTH if unit in LENGTH else ANGLE)))
    t = parse_tolerance(f"±{p} {other} Cpk 1.33", nominal=float(nominal), unit=unit)
    half = to(float(p), other, unit)
    assert t.limits == pytest.approx((float(nominal) - half, float(nominal) + half), rel=1e-12, abs=1e-12)


# -- the cases issue 37 found, by hand (old answer in the comment) -----------------------------------------------------
@pytest.mark.parametrize("text,kw,limits", [
    ("±5 um", {"nominal": 10, "unit": "mm"}, (9.995, 10.005)),                # was (9.995, 15.0)
    ("±50 um", {"unit": "mm"}, (-0.05, 0.05)),                               # was (-0.05, 50)
    ("±3 arcmin", {"nominal": 10, "unit": "deg"}, (9.95, 10.05)),           # was (9.95, 13)
    ('±0.002"', {"nominal": 25, "unit": "mm"}, (24.9492, 25.0508)),         # was (24.9492, 25.002)
    ("±50 um Cpk 1.33", {"nominal": 10, "unit": "mm"}, (9.95, 10.05)),      # was (9.95, 60)
    ("±2 mil", {"nominal": 1, "unit": "in"}, (0.998, 1.002)),               # mil was unknown
])
def test_issue_37_symmetric_tolerances_in_another_unit(text, kw, limits):
    assert parse_tolerance(text, **kw).limits == pytest.approx(limits, rel=1e-12)


def test_a_bare_nominal_beside_a_unit_of_another_scale_is_refused():
    """``10 ±5 um`` on a factor in mm: 10 mm ± 5 µm or 10 µm ± 5 µm?  Before: read as 10 mm without a word."""
    with pytest.raises(NotationError, match=r"the nominal 10 has no unit .* write the nominal's unit \(e\.g\. 10 mm or "
                                            r"10 µm\)"):
        parse_tolerance("10 ±5 um", unit="mm")
    assert parse_tolerance("10 mm ±5 um", unit="mm").limits == pytest.approx((9.995, 10.005))
    assert parse_tolerance("10 ±5 um").limits == pytest.approx((5.0, 15.0))       # no other unit: all in µm
    assert parse_tolerance("25 H7 in", unit="mm").nominal == pytest.approx(635.0)   # the class's nominal in inches
