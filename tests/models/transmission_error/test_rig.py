"""The measurement chain of a TE test rig (issue 23 item 5; rvtol.models.transmission_error.rig): the eccentric
graduation's reading against its exact geometry, the TE a rig reads on an error-free reducer against the closed
form, the order table's attribution, the rig file's errors, a study's spec made of several files."""
import math

import numpy as np
import pytest

from rvtol import units
from rvtol.errors import InputError, SpecError
from rvtol.models.transmission_error.model import TransmissionErrorModel
from rvtol.models.transmission_error.orders import order_spectrum
from rvtol.models.transmission_error.rig import INPUTS, Encoder, Rig, load_rig, measurement_terms
from rvtol.spec import load_spec, merge_specs

from conftest import ROOT

RIG = ROOT / "data/rigs/te_rig_single_head.toml"


def graduation_radius(encoder: str) -> float:
    """The graduation radius (mm) of ``encoder`` as the rig file states it, read here with tomllib (not the rig
    loader under test): half the stated diameter."""
    import tomllib

    with open(RIG, "rb") as fh:
        d = tomllib.load(fh)["rig"][encoder]["graduation_diameter"]
    assert d["unit"] == "mm"
    return d["value"] / 2


def exact_reading(phi, e, r, head=0.0):
    """The angle a head at ``head`` (radius r) reads on a graduation centred at R(φ)e that turned by φ: the
    graduation mark under the head, arg(head point − centre) in the graduation's own frame, turned back."""
    c = np.stack([e[0] * np.cos(phi) - e[1] * np.sin(phi), e[0] * np.sin(phi) + e[1] * np.cos(phi)])
    hx, hy = r * math.cos(head), r * math.sin(head)
    mark = np.arctan2(hy - c[1], hx - c[0]) - phi            # the mark's angle on the graduation
    return np.unwrap(head - mark)                             # the reading grows with φ


@pytest.mark.parametrize("e", [(0.005, 0.0), (-0.003, 0.004), (0.0, 0.002)])
def test_one_head_reads_an_eccentric_graduation_as_e_over_r_once_per_turn(e):
    r = 75.0
    phi = np.linspace(0.0, 2 * np.pi, 361)
    err = exact_reading(phi, e, r) - phi
    err -= err[0] - measurement_terms(Rig("t", Encoder(r, 1), Encoder(1.0, 1)).terms(81.0, e), phi)[0]
    lin = measurement_terms(Rig("t", Encoder(r, 1), Encoder(1.0, 1)).terms(81.0, e), phi)
    assert np.max(np.abs(err - lin)) < 2 * (math.hypot(*e) / r) ** 2           # second order in e/r
    # HEIDENHAIN's ±412 e/D arcsec (e µm, D mm) is the amplitude
    amp = float(units.from_base(np.max(np.abs(lin)), "arcsec"))
    assert amp == pytest.approx(412.5 * math.hypot(*e) * 1e3 / (2 * r), rel=1e-3)


def test_two_diametral_heads_cancel_the_eccentricity():
    r, e = 75.0, (0.004, -0.003)
    phi = np.linspace(0.0, 2 * np.pi, 361)
    a = exact_reading(phi, e, r, 0.0) - phi
    b = exact_reading(phi, e, r, math.pi) - phi - math.pi
    mean = 0.5 * (a + b)
    assert np.ptp(mean) < 2 * (math.hypot(*e) / r) ** 2
    assert Rig("t", Encoder(r, 2), Encoder(1.0, 2)).terms(81.0, e, e).shape == (0, 3)
    assert Rig("t", Encoder(r, 1, "coupled"), Encoder(1.0, 1, "coupled")).terms(81.0, e, e).shape == (0, 3)


@pytest.fixture(scope="module")
def rig_model(te_design):
    return TransmissionErrorModel(te_design, list(INPUTS), per_crank_rev=12, rig=load_rig(RIG))


def test_error_free_reducer_on_the_rig_reads_the_closed_form(rig_model):
    """Error-free reducer (its own TE is a constant wind-up plus a ripple of about 0.001″): the rig reads
    (e_x sin θ + e_y cos θ)/r_out at order 1 and −(e_x sin iθ + e_y cos iθ)/(i r_in) at order i."""
    m = rig_model
    i = 81.0                                                   # the RV-80E's ratio
    r_out, r_in = graduation_radius("output_encoder"), graduation_radius("input_encoder")
    assert (m.geometry.ratio, r_out, r_in) == (i, 100.0, 26.0)  # ⌀200 (issue 39: the middle of ⌀150–250), ⌀52 mm
    e_out, e_in = (0.004, -0.0025), (0.003, 0.002)
    res = m.run(dict(zip(INPUTS, (*e_out, *e_in))))
    assert res.ok
    th = res.theta_c
    want = (e_out[0] * np.sin(th) + e_out[1] * np.cos(th)) / r_out \
        - (e_in[0] * np.sin(i * th) + e_in[1] * np.cos(i * th)) / (i * r_in)
    extra = units.to_base(res.te_rig - res.te, "arcsec")
    assert np.max(np.abs(extra - want)) < 1e-12
    k, a = order_spectrum(res.te_rig)
    assert a[1] == pytest.approx(float(units.from_base(math.hypot(*e_out) / r_out, "arcsec")), rel=1e-6)
    assert a[int(i)] == pytest.approx(float(units.from_base(math.hypot(*e_in) / (i * r_in), "arcsec")),
                                      rel=1e-3)
    # peak-to-peak: the two sinusoids' sum, its extremes refined, plus the reducer's ripple
    dense = np.linspace(0.0, 2 * np.pi, 200001)
    sig = (e_out[0] * np.sin(dense) + e_out[1] * np.cos(dense)) / r_out \
        - (e_in[0] * np.sin(i * dense) + e_in[1] * np.cos(i * dense)) / (i * r_in)
    assert res.te_pp < 2e-3
    assert res.te_pp_rig == pytest.approx(float(units.from_base(np.ptp(sig), "arcsec")), abs=res.te_pp + 1e-4)
    y = m.evaluate(np.array([[*e_out, *e_in]]))[0]
    assert float(units.from_base(y[-1], "arcsec")) == pytest.approx(res.te_pp_rig, abs=1e-9)


def test_order_table_names_the_rig_at_orders_1_and_i(rig_model):
    res = rig_model.run(dict(zip(INPUTS, (0.004, 0.0, 0.004, 0.0))))
    t = rig_model.order_table(res, rig=True)
    row1 = t[t["order [1/rev]"] == 1].iloc[0]
    assert "output encoder" in row1["expected from"]
    row81 = t[t["order [1/rev]"] == 81].iloc[0]
    assert "input encoder" in row81["expected from"]


def test_rig_inputs_need_a_rig(te_design):
    with pytest.raises(InputError, match="test rig's"):
        TransmissionErrorModel(te_design, ["E_c", INPUTS[0]])


@pytest.mark.parametrize("change, key, reason", [
    ('read_heads = { value = 1, unit = "1", source = "rig assumption: one read head (the first',
     "read_heads", "must be 1 or 2"),
    ('mounting = { value = "flange", unit = "1", source = "rig assumption: the ring is centred',
     "mounting", "must be one of flange, coupled"),
    ('centring = { value = "indicated", unit = "1", source = "rig assumption: the ring is centred with',
     "centring", "must be one of indicated, pilot"),
    ('graduation_diameter = { value = 200, unit = "mm", range = [150, 250]', "graduation_diameter.range",
     "around the value 200"),
])
def test_bad_rig_file_is_one_line_naming_file_and_key(tmp_path, change, key, reason):
    bad = change.replace('value = 1,', 'value = 3,').replace('value = "flange"', 'value = "glued"').replace(
        'value = "indicated"', 'value = "glued"').replace("[150, 250]", "[210, 250]")
    text = RIG.read_text(encoding="utf-8").replace(change, bad, 1)
    p = tmp_path / "rig.toml"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=reason) as ei:
        load_rig(p)
    assert key in str(ei.value.key)


def test_a_spec_of_several_files_keeps_each_files_factors_and_correlation(tmp_path):
    a = tmp_path / "a.toml"
    a.write_text('[[factor]]\nname = "x"\nunit = "um"\ndist = "normal"\nsigma = 1.0\n'
                 '[[factor]]\nname = "y"\nunit = "um"\ndist = "normal"\nsigma = 1.0\n'
                 '[[correlation]]\nfactors = ["x", "y"]\nmatrix = [[1.0, 0.5], [0.5, 1.0]]\n', encoding="utf-8")
    rig = load_spec(RIG)
    s = merge_specs([load_spec(a), rig])
    assert s.names == ("x", "y") + rig.names
    assert s.correlation[0, 1] == 0.5 and s.correlation[0, 2] == 0.0 and s.correlation[2, 2] == 1.0
    with pytest.raises(SpecError, match="in one spec only"):
        merge_specs([rig, rig])


def test_the_assumed_rig_is_a_central_value_with_its_range_and_centred_on_the_rotation_axis():
    """Issue 39: the ring's diameter is the middle of its assumed range (not the end that maximises e/r), and a
    ring centred by dial indicator is eccentric by its centring residual alone — the sign-off's mapping must not
    add the pilot's eccentricity (which the indicator takes out) on top."""
    import tomllib

    rig = load_rig(RIG)
    assert rig.output.centring == "indicated" and rig.output.radius_range == (75.0, 125.0)
    assert rig.output.radius == pytest.approx(100.0)
    study = tomllib.loads((ROOT / "studies/rv80e_signoff.toml").read_text(encoding="utf-8"))
    te = next(m for m in study["model"] if m["name"] == "te")
    for c in ("x", "y"):
        assert te["inputs"][f"rig.output_eccentricity.{c}"] == f"rig.output_encoder.centring.{c}"
