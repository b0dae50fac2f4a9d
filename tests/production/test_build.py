"""How the reducer is built (rvtol.production.build, data/products/rv80e/build.toml; issue 23 item 1).

Each rule against a hand computation or a closed form: a selective fit leaves ``minimum`` + a residual uniform
over one class step + the gauge's normal error (mean, variance and the whole CDF of that convolution); the
RV-80E's pin, needle and shim rules at the nominal reducer by hand; the preload law against the pair's own
equilibrium; the design choices against the rules they come from; the composed model on the as-built parts;
the sign-off's nominal lost motion against a hand sum of its parts."""
import json
import math

import numpy as np
import pytest
from scipy import optimize, stats

from conftest import ROOT, write
from rvtol.design import load_design
from rvtol.errors import InputError
from rvtol.production.build import PreloadLaw, load_build
from rvtol.spec import load_spec, spec_from_table
from rvtol.study import load_study, run_study

UM = 1e-3                     # mm per µm
PRODUCT = ROOT / "data/products/rv80e"
SIGNOFF = ROOT / "studies/rv80e_signoff.toml"


# ---------------------------------------------------------------------------------------------- a fit, closed form
SPEC = {"factor": [
    {"name": "bore", "unit": "um", "dist": "uniform", "lower": -50.0, "upper": 50.0},
    {"name": "shaft", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 1.0},
    {"name": "roller", "unit": "um", "dist": "uniform", "lower": -1.0, "upper": 1.0},
]}


def _fit_file(tmp_path, step=1.0, u=0.3, minimum=1.0, extra=""):
    sizes = f"{{ from = -40, to = 40, step = {step} }}"
    return write(tmp_path / "build.toml", f"""
[build]
name = "test"
[[gauge]]
name = "gauge.bore"
unit = "um"
dist = "normal"
mean = 0.0
sigma = {u}
[[fit]]
name = "rollers"
sets = "roller"
unit = "um"
sizes = {sizes}
minimum = {minimum}
target = "((bore + gauge.bore) - shaft - minimum) / 2"
clearance = "bore - shaft - 2 * part"
value = "part"
rule = "largest roller whose measured clearance is at least the minimum"
source = "test"
{extra}""")


def test_a_fit_leaves_the_minimum_plus_a_uniform_step_plus_the_gauge_error(tmp_path):
    """Clearance c = bore − shaft − 2·part, parts every w µm, bore uniform over 100 µm (the demand covers 50 whole
    class steps), the bore read with a normal error of u.  The rule takes the largest part with measured c ≥ c_min,
    so c = c_min + R − e with R uniform on [0, 2w) (the clearance moves 2 µm per µm of part) and e ~ N(0, u):
    mean c_min + w, variance (2w)²/12 + u², and the CDF of the uniform ⊛ normal convolution,
    F(z) = [G(z − c_min) − G(z − c_min − 2w)]/(2w) with G(x) = x Φ(x/u) + u φ(x/u)."""
    w, u, cmin = 1.0, 0.3, 1.0
    spec = spec_from_table(SPEC)
    rules = load_build(_fit_file(tmp_path, w, u, cmin), spec)
    n = 200_000
    rng = np.random.default_rng(7)
    env = {"bore": rng.uniform(-50, 50, n) * UM, "shaft": rng.normal(0, 1, n) * UM,
           "roller": np.zeros(n), "gauge.bore": rng.normal(0, u, n) * UM}
    changed, named = rules.apply(env, n)
    c = named["build.rollers.clearance"] / UM
    part = changed["roller"] / UM
    np.testing.assert_allclose(c, env["bore"] / UM - env["shaft"] / UM - 2 * part, atol=1e-9)
    assert set(np.round(part, 9)) <= set(np.arange(-40, 41) * w)
    a, b = cmin, cmin + 2 * w                        # the residual's range in clearance
    mean, var = 0.5 * (a + b), (b - a) ** 2 / 12 + u ** 2
    mu4 = (b - a) ** 4 / 80 + 6 * (b - a) ** 2 / 12 * u ** 2 + 3 * u ** 4        # 4th central moment of U ⊛ N
    assert abs(c.mean() - mean) < 4 * math.sqrt(var / n)
    assert abs(c.var(ddof=1) - var) < 4 * math.sqrt((mu4 - var ** 2) / n)

    def G(x):
        return x * stats.norm.cdf(x / u) + u * stats.norm.pdf(x / u)

    def cdf(z):
        return (G(z - a) - G(z - b)) / (b - a)

    assert stats.kstest(c, cdf).pvalue > 1e-3
    # without the gauge error the clearance never falls below the minimum
    env0 = dict(env, **{"gauge.bore": np.zeros(n)})
    c0 = rules.apply(env0, n)[1]["build.rollers.clearance"] / UM
    assert c0.min() >= cmin - 1e-9 and c0.max() < cmin + 2 * w


def test_a_demand_beyond_the_supply_takes_the_end_part_and_is_flagged(tmp_path):
    spec = spec_from_table(SPEC)
    fit = load_build(_fit_file(tmp_path), spec).fits[0]
    env = {"bore": np.array([-100.0, 0.0, 100.0]) * UM, "shaft": np.zeros(3), "gauge.bore": np.zeros(3)}
    r = fit.choose(env, 3)
    # demand (bore − 1)/2 = −50.5, −0.5, 49.5 µm against parts −40 … 40: the smallest, −1, the largest
    np.testing.assert_allclose(r.part / UM, [-40, -1, 40])
    np.testing.assert_allclose(r.clearance / UM, [-20, 2, 20])      # −100 + 80; 0 + 2; 100 − 80
    assert r.short.tolist() == [True, False, False] and r.loose.tolist() == [False, False, True]


@pytest.mark.parametrize("change, key, reason", [
    ('target = "((bore + gauge.bore) - shaft - minimum) / 2"', "fit[0].target", "unknown name 'bor'"),
    ('target = "((bore + gauge.bore) - shaft - minimum) / 2"', "fit[0].target", "target and clearance disagree"),
    ('sets = "roller"', "fit[0].sets", "not a factor of the spec"),
    ('clearance = "bore - shaft - 2 * part"', "fit[0].clearance", "must fall as the part grows"),
    ('name = "gauge.bore"', "gauge", "has the name of a factor"),
])
def test_a_bad_build_file_names_its_key(tmp_path, change, key, reason):
    new = {"unknown name 'bor'": change.replace("(bore +", "(bor +"),
           "target and clearance disagree": change.replace("/ 2", "/ 3"),
           "not a factor of the spec": 'sets = "rollers"',
           "must fall as the part grows": 'clearance = "bore - shaft + 2 * part"',
           "has the name of a factor": 'name = "bore"'}[reason]
    p = _fit_file(tmp_path)
    p.write_text(p.read_text().replace(change, new, 1))
    with pytest.raises(InputError) as e:
        load_build(p, spec_from_table(SPEC))
    assert e.value.file == str(p) and e.value.key == key and reason in e.value.reason


def test_a_rule_may_not_read_a_factor_the_build_sets(tmp_path):
    p = _fit_file(tmp_path)
    p.write_text(p.read_text().replace('- shaft - minimum) / 2"', '- shaft - minimum) / 2 + 0 * roller"'))
    with pytest.raises(InputError, match="reads 'roller', a factor a fit sets"):
        load_build(p, spec_from_table(SPEC))


# ---------------------------------------------------------------------------------------------- the RV-80E rules by hand
@pytest.fixture(scope="module")
def product():
    st = load_study(SIGNOFF, n=3, executor="serial", progress=False)
    return st, st.build


def _env(st, **um):
    """The spec's nominal reducer (gauge errors 0) with some factors replaced (µm), as the build reads it."""
    x = st.spec.nominal_base()
    for k, v in um.items():
        x[st.spec.index(k)] = v * UM
    env, _ = st.model.without_build().environment(x[None], set())
    return env


def c1_of(design):
    k1 = design["pin.count"] * design["cycloid.eccentricity"] / design["pin.circle_radius"]
    return math.sqrt(1 - k1 ** 2)


def test_the_pin_rule_at_the_nominal_reducer_by_hand(product):
    """n0 = Δr − c1·ΔR = −22.11 + 0.6204·30 = −3.499 µm on both discs, δR = 0, groove +2 µm: the measured demand
    −3.499 + 0 + 1 − 1 = −3.499 µm → the −4 µm gauge; clearance −3.499 + 1 + 4 = 1.501 µm.  A +1.2 µm error of
    the groove reading raises the demand to −2.899 → the −3 µm gauge, and the true clearance falls to 0.501 µm
    (the rule believed 1.101)."""
    st, rules = product
    pins = next(f for f in rules.fits if f.name == "pins")
    n0 = -22.11 + c1_of(st.design) * 30.0
    r = pins.choose(_env(st), 1)
    assert r.part[0] / UM == pytest.approx(-4.0)
    assert r.clearance[0] / UM == pytest.approx(n0 + 1.0 + 4.0, abs=1e-9)
    r = pins.choose(_env(st, **{"gauge.housing.pin_groove.diameter": 1.2}), 1)
    assert r.part[0] / UM == pytest.approx(-3.0)
    assert r.clearance[0] / UM == pytest.approx(n0 + 1.0 + 3.0, abs=1e-9)
    # the tighter disc decides: disc 2 ground 1 µm fuller (Δr −23.11) → demand −4.499 → the −5 µm gauge
    r = pins.choose(_env(st, **{"disc_2.profile.equidistance_mod": -23.11}), 1)
    assert r.part[0] / UM == pytest.approx(-5.0) and r.clearance[0] / UM == pytest.approx(n0 - 1 + 1 + 5, abs=1e-9)


def test_the_needle_rule_at_the_nominal_reducer_by_hand(product):
    """Bore −8, eccentric −3 µm: demand (−8 + 3 − 0)/2 = −2.5 → the gauge with upper limit −3 µm, two-point
    clearance −8 + 3 + 6 = 1 µm.  A bore at −14 µm needs −5.5 µm, below every preferred gauge: the −5 µm gauge,
    clearance −1 µm (a measured interference), flagged."""
    st, rules = product
    fit = next(f for f in rules.fits if f.name == "needles.disc_1.crank_2")
    r = fit.choose(_env(st), 1)
    assert r.part[0] / UM == pytest.approx(-3.0) and r.clearance[0] / UM == pytest.approx(1.0, abs=1e-9)
    r = fit.choose(_env(st, **{"disc_1.crank_hole_2.diameter": -14.0}), 1)
    assert r.part[0] / UM == pytest.approx(-5.0) and r.clearance[0] / UM == pytest.approx(-1.0, abs=1e-9)
    assert r.short[0]


def test_the_preload_law_is_the_pairs_own_equilibrium(product):
    """F = Z K sin α (Δ sin α/2)^(10/9) against BearingPair.with_preload_force (the pair solved for its preload)."""
    from rvtol.elements.reducer_chain import ChainElements

    st, rules = product
    law = rules.shims[0].law
    pair = ChainElements.from_design(st.design, st.design["crank_bearing.centre_radius"]).pair
    for F in (250.0, 1000.0, 2000.0):
        delta = pair.with_preload_force(F).interference
        assert law.force(delta) == pytest.approx(F, rel=1e-9)
        assert law.interference(F) == pytest.approx(delta, rel=1e-9)
    assert law.force(-1e-3) == 0.0


def test_the_shim_rule_by_hand_and_its_spread_in_closed_form(product):
    """Nominal end play 500 µm: target interference Δ* = 15.22 µm (1 kN); the nearest 5-µm shim to 515.22 is 515,
    Δ = 15 µm as set, less the nominal run-in settling (the mean of U(0, 7.5 µm)) 3.75 µm: 11.25 µm in the unit.
    Over end plays spread across many steps, a reading error u = 1 µm and a settling U(0, w) the interference is
    Δ* + U(−s/2, s/2) − e − U(0, w): mean Δ* − w/2, variance s²/12 + u² + w²/12."""
    st, rules = product
    shim = rules.shims[0]
    assert shim.interference_target / UM == pytest.approx(15.22, abs=0.01)
    r = shim.choose(_env(st), 1)
    assert r.shim[0] / UM == pytest.approx(515.0) and r.interference[0] / UM == pytest.approx(15.0 - 3.75)
    assert r.preload_as_set[0] == pytest.approx(shim.law.force(15.0 * UM))
    assert r.preload[0] == pytest.approx(shim.law.force(11.25 * UM))
    n = 100_000
    rng = np.random.default_rng(3)
    name = shim.end_play.names[0]
    w = 7.5
    env = {name: rng.uniform(200, 800, n) * UM, f"gauge.{name}": rng.normal(0, 1.0, n) * UM,
           shim.settling.names[0]: rng.uniform(0, w, n) * UM}
    d = shim.choose(env, n).interference / UM
    s, u = shim.step / UM, 1.0
    var = s ** 2 / 12 + u ** 2 + w ** 2 / 12
    mu4 = (s ** 4 / 80 + 3 * u ** 4 + w ** 4 / 80
           + 6 * (s ** 2 / 12 * u ** 2 + s ** 2 / 12 * w ** 2 / 12 + u ** 2 * w ** 2 / 12))
    assert abs(d.mean() - (shim.interference_target / UM - w / 2)) < 4 * math.sqrt(var / n)
    assert abs(d.var(ddof=1) - var) < 4 * math.sqrt((mu4 - var ** 2) / n)


def test_the_design_choices_follow_from_the_rules(product):
    """Profile: n0 = (middle of the pin supply) + minimum − δD̄_g/2 = −3.5 + 1 − 1 = −3.5 µm, Δr = n0 + c1·ΔR with
    ΔR = −30 µm; crank holes: δD̄ = 2·(middle of the needle supply) + δd̄_cam + minimum = 2·(−2.5) − 3 + 0."""
    st, rules = product
    spec = st.spec
    pins = next(f for f in rules.fits if f.name == "pins")
    middle = 0.5 * (pins.sizes[0] + pins.sizes[-1]) / UM
    groove = spec.factor("housing.pin_groove.diameter").dist.mean
    n0 = middle + pins.minimum / UM - groove / 2
    dR = spec.factor("disc_1.profile.moved_distance_mod").dist.mean
    choice = {c.name: c for c in rules.choices}
    assert choice["profile modification"].value == pytest.approx(n0 + c1_of(st.design) * dR, abs=0.005)
    needle = next(f for f in rules.fits if f.name == "needles.disc_1.crank_1")
    cam = spec.factor("crank_1.cam_1.diameter").dist.mean
    assert choice["crank-hole band"].value == pytest.approx(
        2 * 0.5 * (needle.sizes[0] + needle.sizes[-1]) / UM + cam + needle.minimum / UM, abs=1e-9)
    # the shims' target is the design's own preload (a variant of the design sets its own): no choice to drift
    assert "crank support preload" not in choice
    assert rules.shims[0].preload_target == pytest.approx(st.design.value("crank_support_bearing.preload", "N"))
    # the pins in their grooves as the nominal housing is built: its demand is the supply's middle (−3.5 µm, above),
    # the fit takes the largest gauge at or below it (−4 µm); r_g = r_p + (δD̄_g − δd)/2 = 3 mm + (2 + 4)/2 µm
    gauge = max(x for x in pins.sizes / UM if x <= middle + 1e-9)
    assert gauge == pytest.approx(-4.0)
    assert choice["pin-in-groove fit"].value == pytest.approx(3.0 + (groove - gauge) / 2 * 1e-3, abs=1e-12)
    assert st.design.value("pin.groove_radius", "mm") == pytest.approx(3.003, abs=1e-12)


def test_a_choice_the_drawing_does_not_hold_is_refused(tmp_path):
    text = (PRODUCT / "build.toml").read_text()
    p = write(tmp_path / "build.toml", text.replace("value = -22.11", "value = -15.0", 1))
    from rvtol.models.composite.model import design_quantities, quantities_from_tables
    from rvtol.params import Params, read_toml

    design = load_design(PRODUCT / "design.toml")
    qs = quantities_from_tables(Params(read_toml(PRODUCT / "mapping.toml")[0]).tables("quantity"))
    qs = design_quantities([n for q in qs for n in q.expression.names], design) + qs
    spec = load_spec(PRODUCT / "tolerances.toml")
    assert len(load_build(PRODUCT / "build.toml", spec, design, qs).choices) == 3
    with pytest.raises(InputError) as e:
        load_build(p, spec, design, qs)
    assert e.value.key == "choice[0].value" and "not the chosen -15" in e.value.reason


def test_a_design_value_that_no_longer_follows_the_build_is_refused(tmp_path):
    """Issue 39 item 5a: design.toml kept the pin-in-groove fit of the drawn pins (3.002 mm) after the build chose
    the −4 µm gauge (3.003 mm); the choice's formula of the nominal build now refuses the stale value, and a pin
    supply that moves the nominal gauge moves the value the design must hold."""
    from rvtol.models.composite.model import design_quantities, quantities_from_tables
    from rvtol.params import Params, read_toml

    qs = quantities_from_tables(Params(read_toml(PRODUCT / "mapping.toml")[0]).tables("quantity"))
    design = load_design(PRODUCT / "design.toml")
    qs = design_quantities([n for q in qs for n in q.expression.names], design) + qs
    spec = load_spec(PRODUCT / "tolerances.toml")
    stale = write(tmp_path / "design.toml", (PRODUCT / "design.toml").read_text().replace(
        'groove_radius = { formula = "pin.radius + 0.003"', 'groove_radius = { formula = "pin.radius + 0.002"', 1))
    with pytest.raises(InputError) as e:
        load_build(PRODUCT / "build.toml", spec, load_design(stale), qs)
    assert e.value.key == "choice[2].value"
    assert "pin.groove_radius is 3.002 mm, not the chosen 3.003" in e.value.reason and "nominal build" in e.value.reason
    # a supply one micrometre smaller at the middle: the nominal housing gets the −5 µm gauge → 3.5 µm radial
    text = (PRODUCT / "build.toml").read_text().replace("sizes = [-6, -5, -4, -3, -2, -1]", "sizes = [-6, -5, -3, -2, -1]", 1)
    with pytest.raises(InputError) as e:
        load_build(write(tmp_path / "build.toml", text), spec, design, qs)
    assert "not the chosen 3.0035" in e.value.reason


# ---------------------------------------------------------------------------------------------- the composed model
def test_the_composition_without_its_build_knows_what_each_output_depends_on(product):
    """Without the build (a study with build = false) a stage reading a build value (the cranks' support preload)
    reads its value as drawn, a constant: the outputs depend on factors only, and no longer on the shim rule's
    readings. (Before: a KeyError on 'build.crank_1.support_pair.preload' in the sign-off's drivers.)"""
    st, rules = product
    deps = st.model.without_build().depends_on()
    built = st.model.depends_on()
    assert set(deps) == {o for o in built if not o.startswith("build.")}     # the build's own outputs go with it
    factors = set(st.spec.names)
    assert all(d <= factors for d in deps.values())
    shim = set().union(*(r for f, r in rules.reads().items() if f.startswith("build.crank_1.support_pair")))
    only_shim = shim - set().union(*(r for f, r in rules.reads().items() if not f.startswith("build.crank_")))
    assert only_shim and only_shim <= built["torsion.lost_motion"]       # the end-play reading, the settling, ...
    assert not only_shim & deps["torsion.lost_motion"]


def test_the_composition_sees_the_parts_as_built(product):
    """model(X) = model without the build on X with every set factor at its as-built value (here the stages up to
    the stack-up and doc 001's screening: the build acts on the inputs, not on the physics)."""
    st, rules = product
    outs = ["pin_ring.disc_1.margin", "screening.lost_motion", "screening.crank_bearing",
            "build.pins.clearance", "pin_ring.disc_1.clearance_min"]
    m = st.model.restricted(outs)
    from rvtol.sampling import sample

    X = sample(st.spec, 12, "random", seed=4).values
    Y = m.evaluate(X)
    env, _ = st.model.without_build().environment(X, set())
    changed, named = rules.apply(env, len(X))
    Xb = X.copy()
    for name, v in changed.items():
        Xb[:, st.spec.index(name)] = v
    m0 = m.without_build()
    Y0 = m0.evaluate(Xb)
    for o in outs[:3]:
        np.testing.assert_array_equal(Y[:, m.output_index(o)], Y0[:, m0.output_index(o)], err_msg=o)
    np.testing.assert_array_equal(Y[:, m.output_index(outs[3])], named["build.pins.clearance"])
    # the disc's clearance in its pin ring is the fitted pin-stage clearance at the tighter disc, n0 + g at φ0, plus
    # n(φ_k) − n0 at the pin nearest φ0 (mapping.md §6): here the nominal reducer without its pattern amplitudes
    # (all pins alike) and with no disc offset, whose margin is that pin's clearance (a symmetric ring: no turn)
    x = st.spec.nominal_base()
    for n in ("housing.pin_grooves.radial_harmonic", "housing.pin_grooves.cumulative_pitch", "disc_1.profile.form",
              "disc_1.profile.cumulative_pitch", "disc_2.profile.form", "disc_2.profile.cumulative_pitch"):
        x[st.spec.index(n)] = 0.0
    y = m.evaluate(x[None])[0]
    zb, e, rp = st.design["pin.count"], st.design["cycloid.eccentricity"], st.design["pin.circle_radius"]
    k1 = zb * e / rp
    phi = 2 * np.pi * np.arange(int(zb)) / zb
    n = -22.11 - (-30.0) * (1 - k1 * np.cos(phi)) / np.sqrt(1 + k1 * k1 - 2 * k1 * np.cos(phi))   # n(φ_k), µm
    n0 = -22.11 + c1_of(st.design) * 30.0
    assert y[m.output_index(outs[4])] / UM == pytest.approx(y[m.output_index(outs[3])] / UM + n.min() - n0, abs=1e-9)
    assert y[m.output_index(outs[0])] == pytest.approx(y[m.output_index(outs[4])], abs=1e-15)


def test_the_signoff_nominal_lost_motion_is_the_hand_sum_of_its_parts(product):
    """At the nominal reducer the build fits the pins to c = 1.501 µm per side and the needles to 1 µm two-point
    clearance, which the cylindricities (nominal 0.73 + 0.55 µm) turn into a slight preload (0 in the model).
    Plays in series add (doc 001's consistent mode, studies/lost_motion.md):

        lost motion = elastic part (the same reducer with the pins closed to c = 0)
                      + i_b·2c/(a z_c)         (pins, flank to flank, i_b = (1 − 1/i) z_c/z_p)
                      + Δφ12/i                 (first stage: doc 001's involute play at the output)

    The first stage by hand: j = −(E_sn,s + Ē_sn,p) + ΔF_r sin α_w / cos α (Δa = 0), Δφ12 = 2j/d1, α_w from
    inv α_w = inv α + 2 tan α (x1 + x2)/(z1 + z2).  Tolerance: the 20-DOF lost-motion rate of a pin clearance is
    within 4 % of the kinematic backlash rate (studies/stiffness.md: the soft low-load range re-entered), so 4 % of
    the pin play, plus 1e-4′ of rounding."""
    st, rules = product
    d, spec = st.design, st.spec
    m = st.model.restricted(["reducer.lost_motion", "torsion.lost_motion", "build.pins.clearance"])
    x0 = spec.nominal_base()
    Y = m.evaluate(x0[None])[0]
    lm, c = Y[m.output_index("reducer.lost_motion")], Y[m.output_index("build.pins.clearance")]
    assert c / UM == pytest.approx(-22.11 + c1_of(d) * 30 + 1 + 4, abs=1e-9)
    # elastic part: the built reducer with its pin set c larger (pin clearance 0), needles as built
    env, _ = st.model.without_build().environment(x0[None], set())
    changed, _ = rules.apply(env, 1)
    xb = x0.copy()
    for name, v in changed.items():
        xb[spec.index(name)] = v[0]
    xb[spec.index("pins.diameter_lot")] += c
    elastic = st.model.without_build().restricted(["torsion.lost_motion"]).evaluate(xb[None])[0, 0]
    z_c, z_p, e, i = d["cycloid.teeth"], d["pin.count"], d["cycloid.eccentricity"], d["reducer.ratio"]
    i_b = (1 - 1 / i) * z_c / z_p
    pins = i_b * 2 * c / (e * z_c)
    # first stage (doc 001 consistent mode): tooth thicknesses and runouts at their nominal
    alpha = d["sun.pressure_angle"]
    z1, z2 = d["sun.teeth"], d["planet.teeth"]
    x1, x2 = d["sun.profile_shift"], d["planet.profile_shift"]
    inv = lambda a: math.tan(a) - a                                                   # noqa: E731
    aw = optimize.brentq(lambda a: inv(a) - inv(alpha) - 2 * math.tan(alpha) * (x1 + x2) / (z1 + z2), 0.1, 0.6)
    nom = lambda n: spec.factor(n).nominal_value * UM                                  # noqa: E731
    esn = nom("sun.tooth_thickness") + np.mean([nom(f"crank_{k}.planet_gear.tooth_thickness") for k in (1, 2, 3)])
    fr = nom("sun.runout") + np.mean([nom(f"crank_{k}.planet_gear.runout") for k in (1, 2, 3)])
    j = -esn + fr * math.sin(aw) / math.cos(alpha)
    first = 2 * j / (d["sun.module"] * z1) / i
    hand = elastic + pins + first
    assert lm == pytest.approx(hand, abs=0.04 * pins + 1e-4 * math.pi / 180 / 60)
    # before issue 23 the same reducer had n0 = 3.61 µm and the pin gap 3 µm: 6.6 µm more play per side than now
    assert pins * 60 * 180 / math.pi < 0.2


def _built_study(tmp_path, rest: str, spec_tables: str = ""):
    """A composed study of one fit with the roller build (spec, build file and study in ``tmp_path``); ``rest``:
    the study's tables after the model; ``spec_tables``: more tables of the drawing spec (its correlation)."""
    spec = write(tmp_path / "spec.toml", "\n".join(
        f'[[factor]]\nname = "{f["name"]}"\nunit = "um"\ndist = "{f["dist"]}"\n'
        + "".join(f"{k} = {v}\n" for k, v in f.items() if k not in ("name", "unit", "dist"))
        for f in SPEC["factor"]) + spec_tables)
    _fit_file(tmp_path)
    return write(tmp_path / "s.toml", f"""
[study]
name = "built"
spec = "{spec.as_posix()}"
build = "build.toml"
[[model]]
name = "fit"
kind = "linear"
[model.inputs]
c = "bore - shaft - 2 * roller"
[[model.output]]
name = "play"
unit = "um"
coefficients = {{ c = 1.0 }}
""" + rest)


def test_the_study_reports_the_build_rules(tmp_path):
    """A small composed study with a build: the stage reads the as-built clearance, summary.json and the inputs
    page say which rules were applied and what they did."""
    study = _built_study(tmp_path, """[[requirement]]
output = "fit.play"
lower = 0
upper = 4
unit = "um"
[sampling]
n = 500
seed = 3
[execution]
executor = "serial"
[report]
pdf = false
""")
    st = load_study(study, progress=False)
    assert st.spec.names[-1] == "gauge.bore" and st.inputs["build"]["path"].endswith("build.toml")
    res = run_study(st)
    np.testing.assert_allclose(res.mc.column("fit.play"), res.mc.column("build.rollers.clearance"), atol=1e-12)
    s = res.summary()
    json.dumps(s)
    from rvtol.ci.schema import validate_summary

    validate_summary(s)
    assert [r["rule"] for r in s["build"]["rules"]] == ["rollers"]
    assert s["build"]["usage"][0]["no part small enough"] == 0.0
    assert s["build"]["gauges"][0] == {"name": "gauge.bore", "unit": "um", "u": pytest.approx(0.3), "source": ""}
    inputs = next(x for x in res.standard_sections if x.key == "inputs")
    captions = [getattr(b, "caption", "") for b in inputs.blocks]
    assert "Build rules applied (rvtol.production.build)" in captions
    # without the build the drawn roller is used
    p = tmp_path / "s.toml"
    p.write_text(p.read_text().replace('build = "build.toml"', "build = false"))
    st0 = load_study(p, progress=False)
    assert st0.build is None and "gauge.bore" not in st0.spec.names


def _correlated_pairs(names, corr) -> dict:
    """{(a, b): ρ} of every pair with ρ ≠ 0 above the diagonal of ``corr`` (the pair's names sorted)."""
    c = np.asarray(corr, dtype=float)
    i, j = np.nonzero(np.triu(c, 1))
    return {tuple(sorted((names[a], names[b]))): float(c[a, b]) for a, b in zip(i, j)}


def test_the_composed_spec_keeps_the_drawings_correlation(tmp_path):
    """The build appends its gauge errors to the drawing spec (``extended_spec``): every correlated pair of the
    drawing keeps its ρ (typed here: bore–shaft +0.6, shaft–roller −0.3), the gauge is independent of every factor
    and the diagonal stays 1 — a composed spec that dropped the drawing's correlation would sample the parts
    independently without a word."""
    study = _built_study(tmp_path, '[execution]\nexecutor = "serial"\n', spec_tables="""
[[correlation]]
pair = ["bore", "shaft"]
rho = 0.6
[[correlation]]
pair = ["shaft", "roller"]
rho = -0.3
""")
    st = load_study(study, progress=False)
    assert st.spec.names == ("bore", "shaft", "roller", "gauge.bore")
    assert _correlated_pairs(st.spec.names, st.spec.correlation) == {("bore", "shaft"): 0.6,
                                                                      ("roller", "shaft"): -0.3}
    np.testing.assert_array_equal(np.diag(st.spec.correlation), 1.0)


def test_the_signoff_composed_spec_keeps_every_correlated_pair_of_the_drawing(product):
    """The RV-80E sign-off's composed spec (drawing + TE rig + the build's gauges) holds exactly the [[correlation]]
    pairs of data/products/rv80e/tolerances.toml, read here with tomllib (names and ρ), and nothing else."""
    import tomllib

    st, _ = product
    with open(PRODUCT / "tolerances.toml", "rb") as fh:
        tables = tomllib.load(fh)["correlation"]
    assert all(set(t) == {"pair", "rho"} for t in tables)           # the file states pairs one by one
    drawn = {tuple(sorted(t["pair"])): float(t["rho"]) for t in tables}
    assert len(drawn) == 14
    assert _correlated_pairs(st.spec.names, st.spec.correlation) == drawn
    assert any(n.startswith("gauge.") for n in st.spec.names)


def test_a_build_needs_a_composed_study(tmp_path):
    _fit_file(tmp_path)
    from conftest import GAP_MODEL, gap_factors

    p = write(tmp_path / "s.toml", '[study]\nname = "x"\nbuild = "build.toml"\n' + gap_factors(1.0) + GAP_MODEL)
    with pytest.raises(InputError) as e:
        load_study(p)
    assert e.value.key == "study.build" and "composed study" in e.value.reason


def test_production_analyses_refuse_a_study_that_builds_its_own_parts(tmp_path):
    """per_unit_prediction (built units, measured) and selective_assembly (its own grading) would be overruled by
    the study's build: one error naming the analysis."""
    p = _built_study(tmp_path, """[[analysis]]
kind = "selective_assembly"
factor = "roller"
target = "bore"
""")
    with pytest.raises(InputError) as e:
        load_study(p)
    assert e.value.key == "analysis[0].kind" and "build = false" in e.value.reason


def test_a_study_that_does_not_apply_the_build_reads_its_values_as_drawn():
    """rv80e_production.toml extends the sign-off with build = false (its kits are built units): the models that
    read a build value (each crank's support preload) get it as drawn — the shim's target, the design's preload —
    and no gauge or process factor is sampled."""
    st = load_study(ROOT / "studies/rv80e_production.toml", analyses=False, progress=False)
    target = load_design(PRODUCT / "design.toml").value("crank_support_bearing.preload", "N")
    assert st.build is None and not any(n.startswith("process.") for n in st.spec.names)
    assert {k: v for k, v in st.model.constants.items() if k.endswith(".support_pair.preload")} == {
        f"build.crank_{i}.support_pair.preload": pytest.approx(target) for i in (1, 2, 3)}
