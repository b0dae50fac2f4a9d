"""Profile and form tolerances and Rule #1 (issue 42 item 3: rvtol.inputs.geometric, rvtol.envelopes)."""
from __future__ import annotations

import numpy as np
import pint
import pytest
from scipy import stats
from scipy.optimize import linprog

from conftest import assert_refused, write
from rvtol.envelopes import Envelope, envelopes, extreme, violations
from rvtol.inputs.geometric import parse_geometric
from rvtol.inputs.notation import NotationError
from rvtol.inputs.table_spec import write_table_spec
from rvtol.spec import load_spec
from rvtol.study import load_study, run_study

UREG = pint.UnitRegistry()
CASES = [   # written, in mm: characteristic, lower, upper, datums — by hand from ASME Y14.5-2018 §11.3.1
    ("⌓0.1 A B C", "profile of a surface", -0.05, 0.05, ("A", "B", "C")),
    ("⌒0.05", "profile of a line", -0.025, 0.025, ()),
    ("profile of a surface 0.2 A|B", "profile of a surface", -0.1, 0.1, ("A", "B")),
    ("⌓0.1 U 0.03 A", "profile of a surface", -0.07, 0.03, ("A",)),          # Ⓤ: 0.03 toward added material
    ("⌓0,1 Ⓤ 0 A", "profile of a surface", -0.1, 0.0, ("A",)),               # all of it removing material
    ("⌓ 100,1 mm U 1,001", "profile of a surface", 1.001 - 100.1, 1.001, ()),  # 100,1 says the commas are decimal
    ("⌓ 1,000 mm U 0,250", "profile of a surface", 0.25 - 1.0, 0.25, ()),     # 0,250 cannot be a thousands separator
    ("⏥0.02", "flatness", 0.0, 0.02, ()),
    ("straightness 0.01", "straightness", 0.0, 0.01, ()),
    ("○5 um", "circularity", 0.0, 0.005, ()),
    ("cylindricity 0.0004\"", "cylindricity", 0.0, (0.0004 * UREG.inch).to("mm").magnitude, ()),
    # the amount after U is in the width's unit unless it writes its own (the audit's D3: it took the factor's)
    ("⌓100 um U 30 A", "profile of a surface", -0.07, 0.03, ("A",)),
    ("⌓0.1mm U 30 um A", "profile of a surface", -0.07, 0.03, ("A",)),
]


@pytest.mark.parametrize("text,characteristic,lower,upper,datums", CASES)
def test_a_profile_or_form_frame_reads_as_its_band(text, characteristic, lower, upper, datums):
    g = parse_geometric(text, unit="mm")
    assert (g.characteristic, g.datums) == (characteristic, datums)
    assert (g.lower_limit, g.upper_limit) == pytest.approx((lower, upper), abs=1e-15)


def test_a_profiles_amount_after_u_takes_the_widths_unit_on_a_factor_in_another():
    g = parse_geometric("⌓0.1 mm U 0.03 A", unit="um")          # the audit's D3: −99.97 … +0.03 µm before
    assert (g.lower_limit, g.upper_limit) == pytest.approx((-70.0, 30.0), abs=1e-9)


@pytest.mark.parametrize("text,words", [
    ("⌓0.1 U 0.2 A", "must lie between 0 and the zone's width"),
    ("⌓0.1 A (M)", "is not a datum letter"),
    ("⏥0.02 A", "relates to no datum"),
    ("⏥0.02 U 0.01", "belongs to a profile tolerance"),
    ("⌓ A B", "expected the tolerance"),
    ("⌓0 A", "positive width"),
    ("⌓0.1 A A", "datum A is named twice"),
    ("flatness 0.02 furlongs", "the tolerance (the zone's width)"),
    ("⌓0.1 U -0.03 A", "must not be negative"),
    ("⏥ 1,000 cm", "'1,000' is ambiguous"),
])
def test_a_frame_written_wrong_says_why(text, words):
    with pytest.raises(NotationError, match=words.replace("(", r"\(").replace(")", r"\)")):
        parse_geometric(text, unit="mm")


def test_the_factors_distributions_read_the_band_as_the_drawing_notation_does(tmp_path):
    spec = load_spec(write(tmp_path / "s.toml", """
[[factor]]
name = "face"
unit = "mm"
tolerance = "⌓0.1 U 0.03 A B"
[[factor]]
name = "flat"
unit = "mm"
tolerance = "⏥0.02"
"""))
    face, flat = spec.factors
    assert face.limits == pytest.approx((-0.07, 0.03)) and face.nominal == 0.0 and face.datums == ("A", "B")
    assert face.dist.kind == "normal" and face.dist.mean == pytest.approx(-0.02) and face.dist.std == pytest.approx(
        0.1 / 6)
    # a form deviation is a magnitude: Rayleigh with 99.73 % below t (scipy's quantile)
    assert flat.dist.kind == "rayleigh" and flat.characteristic == "flatness"
    three_sigma = 1 - 2 * stats.norm.cdf(-3)          # the coverage of ±3σ, 0.99730020…
    assert float(flat.dist.ppf(three_sigma)) == pytest.approx(0.02, rel=1e-9)
    assert float(flat.dist.ppf(0.5)) == pytest.approx(stats.rayleigh(scale=0.02 / stats.rayleigh.ppf(three_sigma))
                                                      .median(), rel=1e-9)


def test_the_envelopes_corners_are_the_extremes_of_a_linear_programme_over_what_the_drawing_admits():
    rng = np.random.default_rng(7)
    for external in (True, False):
        for t_form in (0.004, 0.03):          # within the size band, and wider than it (the envelope alone binds)
            env = Envelope(1, 0, external, (9.98, 10.0), t_form)
            # f + d ≤ 10 (a shaft: d + f within MMC), or f − d ≤ −9.98 (a hole: D − f at least MMC)
            A, b = ([[1.0, 1.0]], [10.0]) if external else ([[-1.0, 1.0]], [-9.98])
            for _ in range(5):
                a = rng.normal(size=2)
                c = np.array([9.99, t_form / 2])
                box = abs(a[0]) * 0.01 + abs(a[1]) * t_form / 2
                dl, dh = extreme(env, a[0], a[1], tuple(c))
                for sign, end in ((1, -box + dl), (-1, box + dh)):
                    lp = linprog(sign * a, A_ub=A, b_ub=b, bounds=[(9.98, 10.0), (0, t_form)], method="highs")
                    assert end == pytest.approx(sign * lp.fun - a @ c, abs=1e-12)


FIT = """
[[factor]]
name = "D"
unit = "mm"
tolerance = "25 H7"
[[factor]]
name = "form_hole"
unit = "mm"
tolerance = "⌭0.015"
envelope = "D"
feature_type = "internal"
[[factor]]
name = "d"
unit = "mm"
tolerance = "25 g6"
[[factor]]
name = "form_shaft"
unit = "um"
tolerance = "⌭10 um"
envelope = "d"
feature_type = "external"
"""
STUDY = """[study]
name = "rule1"
spec = "spec.toml"
[sampling]
n = 4000
seed = 2
[model]
kind = "formula"
[[model.output]]
name = "clearance"
unit = "mm"
formula = "(D - form_hole) - (d + form_shaft)"
[[requirement]]
name = "clearance ≥ 0"
output = "clearance"
lower = 0
unit = "mm"
[[analysis]]
kind = "stack_conventions"
true_worst_case = false
second_order = false
"""


def test_rule_1_gives_a_fit_its_minimum_clearance_whatever_the_form_tolerances(tmp_path):
    write(tmp_path / "spec.toml", FIT)
    res = run_study(load_study(write(tmp_path / "study.toml", STUDY), executor="serial", progress=False, pdf=False))
    s = next(s for s in res.sections if s.key == "stack_conventions").summary["clearance"]
    rows = {c["convention"]: c for c in s["conventions"]}
    # 25 H7/g6: MMC hole 25.000, MMC shaft 24.993, LMC 25.021 and 24.980 (ISO 286-2)
    assert rows["worst case (GD&T domains)"]["low"] == pytest.approx(25.000 - 24.993, abs=1e-12)
    assert rows["worst case (GD&T domains)"]["high"] == pytest.approx(25.021 - 24.980, abs=1e-12)
    assert rows["worst case (arithmetic)"]["low"] == pytest.approx(25.000 - 0.015 - 24.993 - 0.010, abs=1e-12)
    # the produced parts that break the envelope, counted independently from the samples
    X = res.mc.samples.values
    D, fh, d, fs = X.T
    for name, n in (("form_hole", np.sum(fh > np.maximum(D - 25.0, 0))), ("form_shaft", np.sum(fs > np.maximum(
            24.993 - d, 0)))):
        assert n > 0 and any(note.startswith(f"{n} of 4000 sampled parts break Rule #1 ({name}") for note in s["notes"])


def test_profile_form_and_envelope_survive_a_spreadsheet_round_trip(tmp_path):
    spec = load_spec(write(tmp_path / "s.toml", FIT + """
[[factor]]
name = "face"
unit = "mm"
tolerance = "⌓0.1 U 0.03 A B"
[[factor]]
name = "edge"
unit = "mm"
tolerance = "⌒0.05"
"""))
    for suffix in (".csv", ".xlsx"):
        write_table_spec(spec, tmp_path / f"out{suffix}")
        back = load_spec(tmp_path / f"out{suffix}")
        assert back.factors == spec.factors
    assert [e.size for e in envelopes(spec)] == [0, 2]


BAD = [
    ('envelope = "D"\nfeature_type = "internal"', 'envelope = "Dd"\nfeature_type = "internal"', "factor.envelope",
     "envelope names no factor ('Dd')"),
    ('envelope = "D"\nfeature_type = "internal"', 'envelope = "D"', "factor[1].feature_type", "needs the feature type"),
    ('tolerance = "⌭0.015"', 'tolerance = "±0.015"\nnominal = 0', "factor[1].envelope", "bounds a form tolerance"),
    ('tolerance = "⌭0.015"', 'tolerance = "⌭0.015"\nnominal = 3', "factor[1].nominal", "give no nominal"),
    ('envelope = "D"\nfeature_type = "internal"', 'envelope = "form_shaft"\nfeature_type = "internal"',
     "factor.envelope", "is not a size"),
    ('tolerance = "⌭0.015"', 'tolerance = "⌭0.015 A"', "factor[1].tolerance", "relates to no datum"),
    ('unit = "um"\ntolerance = "⌭10 um"', 'unit = "deg"\ntolerance = "⌭0.1 deg"', "factor.envelope",
     "a form and its size must both be lengths"),
    ('envelope = "d"\nfeature_type = "external"', 'envelope = "D"\nfeature_type = "external"', "factor.feature_type",
     "one feature has one type"),
]


@pytest.mark.parametrize("old,new,key,words", BAD)
def test_an_envelope_or_frame_written_wrong_is_one_located_line(tmp_path, capsys, old, new, key, words):
    assert old in FIT
    p = write(tmp_path / "spec.toml", FIT.replace(old, new, 1))
    assert_refused(p, write(tmp_path / "study.toml", STUDY), capsys, key, words)


def test_violations_count_a_size_beyond_mmc_with_any_form():
    env = Envelope(1, 0, True, (9.98, 10.0), 0.01)
    X = np.array([[9.99, 0.005], [9.99, 0.011], [10.001, 0.0], [10.001, 1e-6], [9.995, 0.005]])
    assert violations(env, X) == 2


# ---- every form × every length unit pair against pint (issue 42 item 3; the notation properties' oracle) ----------
from decimal import Decimal  # noqa: E402

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

LENGTH = {"mm": "millimeter", "um": "micrometer", "in": "inch", "mil": "mil_length", "m": "meter", "cm": "centimeter"}
SPELLED = {"um": ("um", "µm"), "in": ("in", '"')}
HEADS = {"profile": ("⌓", "⌒", "profile", "profile of a surface", "line profile"),
         "form": ("⏥", "⏤", "○", "⌭", "flatness", "straightness", "roundness", "cylindricity")}
number = st.builds(lambda k, d: Decimal(k).scaleb(-d), st.integers(1, 9999), st.integers(0, 4))


def _len(v, src, dst):
    return UREG.Quantity(float(v), LENGTH[src]).to(LENGTH[dst]).magnitude


@st.composite
def frames(draw):
    kind = draw(st.sampled_from(sorted(HEADS)))
    head = draw(st.sampled_from(HEADS[kind]))
    factor, wu = draw(st.sampled_from(sorted(LENGTH))), draw(st.sampled_from(sorted(LENGTH)))
    width = draw(number)
    comma = draw(st.booleans()) and width.as_tuple().exponent != -3    # 1,000: ambiguous, refused (above)
    num = lambda d: str(d).replace(".", ",") if comma else str(d)  # noqa: E731
    text = f"{head} {num(width)} {draw(st.sampled_from(SPELLED.get(wu, (wu,))))}"
    lo, hi = (0.0, _len(width, wu, factor)) if kind == "form" else (-_len(width, wu, factor) / 2,
                                                                     _len(width, wu, factor) / 2)
    if kind == "profile":
        if draw(st.booleans()):                          # unequally disposed: u toward added material
            u = width * Decimal(draw(st.integers(0, 100))) / 100
            uu = draw(st.sampled_from([None, wu] + (["um"] if wu == "mm" else [])))   # the width's unit, or its own
            written = u * 1000 if uu == "um" and wu == "mm" else u
            text += f" {draw(st.sampled_from(('U', 'Ⓤ')))} {num(format(written.normalize(), 'f'))}" + (f" {uu}" if uu else "")
            hi = _len(written, uu or wu, factor)
            lo = hi - _len(width, wu, factor)
        letters = draw(st.lists(st.sampled_from("ABCDEFGH"), unique=True, max_size=3))
        text += "".join(f" {d}" for d in letters)
    return text, factor, lo, hi


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(frames())
def test_every_profile_and_form_frame_in_every_unit_pair_is_pints_band(case):
    text, factor, lo, hi = case
    g = parse_geometric(text, unit=factor)
    scale = max(abs(lo), abs(hi))
    assert g.lower_limit == pytest.approx(lo, rel=1e-9, abs=1e-12 * scale), text
    assert g.upper_limit == pytest.approx(hi, rel=1e-9, abs=1e-12 * scale), text
