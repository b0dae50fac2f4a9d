"""The spec loader reads the engineers' forms: drawing notation in a [[factor]] (the drawing's worst-case
limits kept when a process spec shifts the mean), measured values (dist = "measured"), spec tables; and a
table spec round-trips through `rvtol spec export`."""
import json
import math

import numpy as np
import pytest
from scipy import stats

from rvtol.cli import main
from rvtol.errors import SpecError
from rvtol.model import LinearModel, Quantity
from rvtol.sensitivity.linearisation import linear_prediction
from rvtol.spec import load_spec

from conftest import write


def spec_file(tmp_path, factors: str, name="spec.toml"):
    return write(tmp_path / name, factors)


def test_iso_class_in_a_toml_factor(tmp_path):
    s = load_spec(spec_file(tmp_path, '[[factor]]\nname = "bore"\ntolerance = "25 H7"\n'))
    f = s.factors[0]
    # ISO 286-1: H7 over 18-30 mm is 0/+21 µm; no unit written -> mm
    assert f.unit == "mm" and f.nominal == 25.0 and f.limits == pytest.approx((25.0, 25.021))
    assert f.dist.mean == pytest.approx(25.0105) and f.dist.std == pytest.approx(0.021 / 6)
    assert f.band == pytest.approx((25.0, 25.021)) and f.half_band == pytest.approx(0.0105)


def test_a_process_spec_shifts_the_mean_but_the_limits_stay_the_drawing_s(tmp_path):
    s = load_spec(spec_file(tmp_path, '[[factor]]\nname = "x"\nunit = "mm"\nnominal = 25\n'
                                      'tolerance = "±0.05 Cpk 1.33 k 0.25"\n'))
    f = s.factors[0]
    cp = 1.33 / 0.75                      # Cpk = Cp (1 - k)
    assert f.dist.mean == pytest.approx(25.0 + 0.25 * 0.05)          # shifted by k·T/2 toward the upper limit
    assert f.dist.std == pytest.approx(0.1 / (6 * cp))
    # capability of the distribution against the drawing limits is the written Cpk
    assert min(25.05 - f.dist.mean, f.dist.mean - 24.95) / (3 * f.dist.std) == pytest.approx(1.33)
    assert f.limits == pytest.approx((24.95, 25.05)) and f.band == pytest.approx((24.95, 25.05))
    assert f.dist.band != pytest.approx(f.band)                       # the distribution's own band moved
    # the linearised worst case of y = x is the drawing's band, not the shifted one
    m = LinearModel(s.names, ["mm"], [Quantity("y", "mm")], [[1.0]])
    p = linear_prediction(s, np.array([1.0]), 25.0, output="y", out_unit="mm")
    assert (p.worst_low, p.worst_high) == (pytest.approx(24.95), pytest.approx(25.05))
    assert m.evaluate(np.array([[25.0]]))[0, 0] == 25.0
    # a tighter tolerance scales the drawing limits about their middle, like the distribution
    g = f.scaled(0.5)
    assert g.limits == pytest.approx((24.975, 25.025)) and g.dist.std == pytest.approx(f.dist.std / 2)


def test_inches_unequal_deviations_percent_and_refinements(tmp_path):
    s = load_spec(spec_file(tmp_path, """
[[factor]]
name = "pin"
tolerance = '1.000" +0.002/-0.001'
dist = "uniform"
[[factor]]
name = "gap"
unit = "mm"
nominal = 25
tolerance = "+0.10/-0.00"
dist = "normal"
sigma = 0.01              # an explicit σ replaces the band's reading; the limits stay
[[factor]]
name = "spring"
unit = "N"
nominal = 200
tolerance = "±5 %"
[[factor]]
name = "runout"
unit = "um"
tolerance = "max 20"
dist = "rayleigh"
direction = "-"
"""))
    pin, gap, spring, runout = s.factors
    assert pin.unit == "in" and pin.dist.frozen.support() == pytest.approx((0.999, 1.002))
    assert pin.ppf_base(np.array([0.0]))[0] == pytest.approx(0.999 * 25.4)      # inch -> mm at the edge
    assert gap.dist.std == 0.01 and gap.dist.mean == pytest.approx(25.05) and gap.limits == pytest.approx((25.0, 25.1))
    assert spring.limits == pytest.approx((190.0, 210.0)) and spring.dist.std == pytest.approx(20 / 6)
    # rayleigh whose 99.73 % quantile is the 20 µm limit
    assert runout.dist.ppf(stats.norm.cdf(3) - stats.norm.cdf(-3)) == pytest.approx(20.0)
    assert runout.direction == -1.0 and pin.direction is None


@pytest.mark.parametrize("factor, key, words", [
    ('name = "a"\nunit = "mm"\ntolerance = "+0.1"', "factor[0].tolerance", "write both deviations"),
    ('name = "a"\ntolerance = "±0.1"', "factor[0].unit", "missing unit"),
    ('name = "a"\nunit = "mm"\ntolerance = "±0.1"\ndist = "lognormal"', "factor[0].dist", "cannot be read as"),
    ('name = "a"\nunit = "deg"\ntolerance = "25 H7"', "factor[0].tolerance", "length tolerance"),
    ('name = "a"\nunit = "mm"\nnominal = 25\ntolerance = "±0.1 Cp 1.33"\nsigma_level = 4',
     "factor[0].sigma_level", "give no sigma_level"),
    ('name = "a"\nunit = "mm"\ntolerance = "±0.1"\ndist = "triangular"\nmode = 3', "factor[0].mode", "outside"),
    ('name = "a"\nunit = "mm"\ntolerance = "±0.1"\ncolour = "red"', "factor[0].colour", "unknown key"),
    ('name = "a"\nunit = "mm"\ntolerance = "±0.1"\ndirection = "up"', "factor[0].direction", "expected a number"),
])
def test_drawing_notation_errors_name_file_and_key(tmp_path, factor, key, words):
    p = spec_file(tmp_path, f"[[factor]]\n{factor}\n")
    with pytest.raises(SpecError) as e:
        load_spec(p)
    assert str(e.value).startswith(f"{p}: {key}: ") and words in str(e.value), str(e.value)


def cmm(tmp_path, n=400, seed=3):
    x = stats.norm(25.010, 0.004).rvs(n, random_state=np.random.default_rng(seed))
    write(tmp_path / "cmm.csv", "part,bore\n" + "\n".join(f"{i},{float(v)!r}" for i, v in enumerate(x)))
    return x


def test_measured_values_in_a_toml_factor_keep_the_drawing_limits(tmp_path):
    x = cmm(tmp_path)
    s = load_spec(spec_file(tmp_path, """
[[factor]]
name = "bore"
unit = "mm"
dist = "measured"
data = "cmm.csv"
column = "bore"
families = ["normal", "lognormal", "uniform"]
tolerance = "25 H7"
[[factor]]
name = "bore_resampled"
unit = "mm"
dist = "measured"
data = "cmm.csv"
column = "bore"
method = "empirical"
"""))
    fit, emp = s.factors
    assert fit.measured.method == "fit" and fit.measured.n == 400 and fit.measured.fit is not None
    # maximum likelihood of a normal: the sample mean and the ddof=0 standard deviation
    assert fit.dist.kind in ("normal", "lognormal")
    assert fit.dist.mean == pytest.approx(np.mean(x), rel=1e-9)
    assert fit.limits == pytest.approx((25.0, 25.021)) and fit.band == pytest.approx((25.0, 25.021))
    assert emp.dist.kind == "empirical" and emp.limits is None and emp.dist.mean == pytest.approx(np.mean(x))
    with pytest.raises(SpecError, match=r"spec.toml: factor\[0\].data: file not found"):
        load_spec(spec_file(tmp_path, '[[factor]]\nname = "a"\nunit = "mm"\ndist = "measured"\ndata = "no.csv"\n'))


def test_measured_cell_in_a_table_and_export_round_trip(tmp_path):
    cmm(tmp_path)
    write(tmp_path / "stack.csv", "name,nominal,tolerance,distribution,unit,direction\n"
                                  "bore,25,H7,\"measured(data=cmm.csv, column=bore, method=kde)\",mm,+\n"
                                  "shaft,25,g6,normal,mm,-\n"
                                  "process,25,±0.05 Cpk 1.33 k 0.25,,mm,\n")
    s = load_spec(tmp_path / "stack.csv")
    assert s.factors[0].dist.kind == "kde" and s.factors[0].measured.source == "cmm.csv[bore]"
    assert [f.direction for f in s.factors] == [1.0, -1.0, None]
    for ext in ("csv", "xlsx"):
        out = tmp_path / f"exported.{ext}"
        assert main(["spec", "export", str(tmp_path / "stack.csv"), "--out", str(out)]) == 0
        t = load_spec(out)
        for f, g in zip(s.factors, t.factors):
            assert (f.name, f.unit, f.direction, f.dist.kind) == (g.name, g.unit, g.direction, g.dist.kind)
            assert f.band == pytest.approx(g.band, rel=1e-12) and f.dist.std == pytest.approx(g.dist.std, rel=1e-11)
            assert f.dist.mean == pytest.approx(g.dist.mean, rel=1e-12)
        assert main(["spec", "export", str(tmp_path / "stack.csv"), "--out", str(out)]) == 2   # no --force


def test_spec_export_errors(tmp_path, capsys):
    assert main(["spec", "export", str(tmp_path / "none.toml"), "--out", str(tmp_path / "x.csv")]) == 2
    assert "none.toml: -: file not found" in capsys.readouterr().err
    assert not (tmp_path / "x.csv").exists()
    write(tmp_path / "bad.csv", "name,unit,tolerance\na,mm,0.05x\n")
    assert main(["spec", "export", str(tmp_path / "bad.csv"), "--out", str(tmp_path / "x.xlsx")]) == 2
    assert "bad.csv: row 2, column 'tolerance': cannot read tolerance" in capsys.readouterr().err
    assert not (tmp_path / "x.xlsx").exists()


def test_a_study_on_measured_data_reports_the_fit_gof_and_qq_plot(tmp_path):
    cmm(tmp_path)
    write(tmp_path / "stack.csv", "name,nominal,tolerance,distribution,unit,direction\n"
                                  "bore,25,H7,\"measured(data=cmm.csv, column=bore, families=normal|uniform)\",mm,+\n"
                                  "shaft,25,g6,normal,mm,-\n")
    study = write(tmp_path / "fit.toml", """
[study]
name = "fit"
spec = "stack.csv"
[model]
kind = "linear"
[[model.output]]
name = "clearance"
unit = "mm"
display_unit = "um"
coefficients = "spec"
[[requirement]]
output = "clearance"
lower = 0
upper = 60
unit = "um"
basis = "estimate"
[sampling]
n = 400
""")
    out = tmp_path / "rep"
    assert main(["run", str(study), "--out", str(out), "--executor", "serial", "--no-pdf", "--quiet"]) == 0
    html = (out / "report.html").read_text(encoding="utf-8")
    assert "Measured factor bore" in html and "ranked by AIC" in html
    assert "Anderson-Darling, parametric bootstrap statistic" in html and "Q-Q plot against the fitted normal" in html
    # the bootstrap ran in the run (a timed phase), not while the report was laid out
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert "measured_factors" in summary["timings_s"]


def test_a_circular_position_zone_is_two_rayleigh_coordinates(tmp_path):
    s = load_spec(spec_file(tmp_path, """
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
"""))
    x, y = s.factors
    assert x.limits == pytest.approx((-0.025, 0.025)) and x.zone == y.zone == "hole"
    # σ of each coordinate: the radius sqrt(x² + y²) is Rayleigh(σ) with 99.73 % inside the zone (r ≤ 0.025)
    sigma = x.dist.std
    assert 1 - math.exp(-0.025 ** 2 / (2 * sigma ** 2)) == pytest.approx(stats.norm.cdf(3) - stats.norm.cdf(-3))
    out = tmp_path / "zone.csv"
    assert main(["spec", "export", str(tmp_path / "spec.toml"), "--out", str(out)]) == 0
    back = load_spec(out)
    assert [f.zone for f in back.factors] == ["hole", "hole"] and back.factors[0].dist.std == pytest.approx(sigma)


@pytest.mark.parametrize("factors, key, words", [
    ('[[factor]]\nname = "x"\nunit = "mm"\ntolerance = "⌀0.05"\n', "factor[0].tolerance", "give zone = NAME"),
    ('[[factor]]\nname = "x"\nunit = "mm"\ntolerance = "±0.05"\nzone = "h"\n', "factor[0].zone", "needs tolerance"),
    ('[[factor]]\nname = "x"\nunit = "mm"\ntolerance = "⌀0.05"\nzone = "h"\n', "factor.zone", "needs two"),
    ('[[factor]]\nname = "x"\nunit = "mm"\ntolerance = "⌀0.05"\nzone = "h"\n'
     '[[factor]]\nname = "y"\nunit = "mm"\ntolerance = "⌀0.06"\nzone = "h"\n', "factor.zone", "same unit and diameter"),
    ('[[factor]]\nname = "x"\nunit = "mm"\ntolerance = "⌀0.05"\nzone = "h"\ndist = "uniform"\n', "factor[0].dist",
     "coordinates are normal"),
])
def test_position_zone_errors(tmp_path, factors, key, words):
    p = spec_file(tmp_path, factors)
    with pytest.raises(SpecError) as e:
        load_spec(p)
    assert f": {key}: " in str(e.value) and words in str(e.value), str(e.value)
