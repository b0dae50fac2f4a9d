"""Composed models: one drawing sample drives every stage; the composition equals its parts by hand."""
import numpy as np
import pytest

from conftest import ROOT, write
from rvtol.errors import InputError
from rvtol.expressions import Expression
from rvtol.mc import Evaluator
from rvtol.model import FunctionModel, LinearModel, Quantity
from rvtol.models.composite.model import CompositeModel, MappedQuantity, Stage
from rvtol.sensitivity.local import five_point
from rvtol.spec import spec_from_table
from rvtol.study import load_study, run_study

SPEC = spec_from_table({"factor": [
    {"name": "a", "unit": "um", "dist": "normal", "mean": 2.0, "tolerance": 6.0},
    {"name": "b", "unit": "um", "dist": "uniform", "lower": -4.0, "upper": 4.0},
    {"name": "c", "unit": "deg", "dist": "normal", "mean": 10.0, "tolerance": 2.0},
    {"name": "d", "unit": "um", "dist": "normal", "mean": 0.0, "tolerance": 1.0},
]})


def _composite():
    """a, b, c, d -> q = hypot(a, b) -> stage 1 (linear in q and c) -> stage 2 (nonlinear in stage 1 and d)."""
    q = MappedQuantity("q", Expression.parse("hypot(a, b)"), "mm", "um", True)
    lin = LinearModel(["x1", "x2"], ["mm", "rad"], [Quantity("u", "mm", "um"), Quantity("w", "mm")],
                      [[2.0, 0.5], [-1.0, 0.3]], [0.001, 0.0])
    nonlin = FunctionModel(lambda X: np.column_stack([np.sqrt(X[:, 0] ** 2 + 1e-6) * (1 + X[:, 1]),
                                                      np.sin(X[:, 0] * 100) + X[:, 1]]),
                           ["s", "t"], [Quantity("r", "mm", "um"), Quantity("z")], ["mm", "mm"])
    st1 = Stage("one", lin, (Expression.parse("q"), Expression.parse("c")), (0, 1))
    st2 = Stage("two", nonlin, (Expression.parse("one.u - 0.5 * one.w"), Expression.parse("d * 1000")), (0, 1))
    return CompositeModel(SPEC.names, ["mm", "mm", "rad", "mm"], [q], [st1, st2]), lin, nonlin


def test_composition_equals_its_parts_by_hand_sample_by_sample():
    m, lin, nonlin = _composite()
    X = np.random.default_rng(3).normal(size=(200, 4)) * [0.003, 0.003, 0.05, 0.001]
    Y, status = m.evaluate_with_status(X)
    assert (status == 0).all()
    q = np.hypot(X[:, 0], X[:, 1])
    y1 = lin.evaluate(np.column_stack([q, X[:, 2]]))
    y2 = nonlin.evaluate(np.column_stack([y1[:, 0] - 0.5 * y1[:, 1], X[:, 3] * 1000]))
    assert m.output_names == ("q", "one.u", "one.w", "two.r", "two.z")
    np.testing.assert_array_equal(Y, np.column_stack([q, y1, y2]))


def test_one_factor_moves_every_dependent_output_and_no_other():
    m, _, _ = _composite()
    deps = m.depends_on()
    assert deps["q"] == {"a", "b"} and deps["one.u"] == {"a", "b", "c"} and deps["two.r"] == {"a", "b", "c", "d"}
    x0 = SPEC.nominal_base()
    y0 = m.evaluate(x0[None])[0]
    for k, name in enumerate(SPEC.names):
        x = x0.copy()
        x[k] += 1e-3 * (1 + abs(x[k]))
        y = m.evaluate(x[None])[0]
        moved = {o for o, a, b in zip(m.output_names, y0, y) if a != b}
        assert moved == {o for o, d in deps.items() if name in d}, name


def test_five_point_of_the_composition_is_the_chain_rule_of_its_parts():
    m, lin, nonlin = _composite()
    x0 = SPEC.nominal_base()
    env = dict(zip(SPEC.names, x0))
    comp = five_point(m, SPEC, outputs=["two.r"], percent=1.0)
    S_comp = comp.gradient("two.r", SPEC.names)
    # chain rule, each part by its own derivative: d(two.r)/d(s) by five-point on the stage model
    q, dq = Expression.parse("hypot(a, b)").gradient(env)
    x1 = np.array([q, x0[2]])
    J1 = lin.A                                              # exact: linear stage
    y1 = lin.evaluate(x1[None])[0]
    s = y1[0] - 0.5 * y1[1]
    stage_spec = spec_from_table({"factor": [{"name": "s", "unit": "mm", "dist": "normal", "mean": float(s),
                                              "tolerance": 1e-3},
                                             {"name": "t", "unit": "mm", "dist": "normal", "mean": 0.0,
                                              "tolerance": 1.0}]})
    S2 = five_point(nonlin, stage_spec, outputs=["r"], percent=1.0).gradient("r", ["s", "t"])
    ds_dx1 = J1[0] - 0.5 * J1[1]                            # d s / d (q, c)
    chain = np.array([S2[0] * ds_dx1[0] * dq["a"], S2[0] * ds_dx1[0] * dq["b"], S2[0] * ds_dx1[1], S2[1] * 1000])
    np.testing.assert_allclose(S_comp, chain, rtol=1e-6, atol=1e-12)


def test_a_failing_stage_fails_the_sample_with_its_reason():
    class Flaky(FunctionModel):
        status_reasons = {1: "non-finite", 7: "solver gave up"}

        def evaluate_with_status(self, X):
            Y = X.copy()
            st = np.where(X[:, 0] > 0, 7, 0).astype(np.int16)
            Y[st != 0] = np.nan
            return Y, st

    flaky = Flaky(lambda X: X, ["s"], [Quantity("y")], ["mm"])
    m = CompositeModel(["a"], ["mm"], [], [Stage("f", flaky, (Expression.parse("a"),), (0,)),
                                          Stage("g", LinearModel(["s"], ["1"], [Quantity("v")], [[2.0]]),
                                                (Expression.parse("f.y"),), (0,))])
    ev = Evaluator()(m, np.array([[-1.0], [1.0]]))
    assert list(ev.status) == [0, 1007] and m.status_reasons[1007] == "f: solver gave up"
    assert np.isnan(ev.Y[1]).all() and ev.Y[0].tolist() == [-1.0, -2.0]


STUDY = """
[study]
name = "composed"
spec = "SPEC"
[[quantity]]
name = "gap"
value = "c1 - c2"
unit = "mm"
display_unit = "um"
output = true
[[model]]
name = "stack"
kind = "linear"
[model.inputs]
g = "gap"
h = "c3"
[[model.output]]
name = "play"
unit = "um"
coefficients = { g = 1.0, h = -1.0 }
[[model]]
name = "lm"
kind = "lost_motion"
design = "x"
[model.inputs]
Delta_b = "max(stack.play, 0)"
[sampling]
n = 400
seed = 5
[execution]
executor = "serial"
[[requirement]]
output = "stack.play"
lower = 0
unit = "um"
[[requirement]]
output = "lm.lost_motion"
upper = 1
unit = "arcmin"
"""


STACK_SPEC = """
[[factor]]
name = "c1"
unit = "um"
dist = "normal"
mean = 20
tolerance = 6
[[factor]]
name = "c2"
unit = "um"
dist = "normal"
mean = 5
tolerance = 4
[[factor]]
name = "c3"
unit = "um"
dist = "uniform"
lower = 0
upper = 4
"""


def _study(spec) -> str:
    """STUDY with the spec file and the doc 000 RV-80E design (the lost-motion stage reads its geometry)."""
    design = (ROOT / "data/designs/rv80e_te.toml").as_posix()
    return STUDY.replace("SPEC", spec.as_posix()).replace('design = "x"\n', "").replace(
        '[study]\nname = "composed"\n', f'[study]\nname = "composed"\ndesign = "{design}"\n')


def test_a_study_with_several_models_runs_and_judges_outputs_of_each(tmp_path):
    spec = write(tmp_path / "spec.toml", STACK_SPEC)
    text = _study(spec)
    st = load_study(write(tmp_path / "s.toml", text), progress=False)
    assert st.model.output_names[:2] == ("gap", "stack.play")
    res = run_study(st)
    play = res.mc.column("stack.play")
    gap = res.mc.column("gap")
    c3 = res.mc.samples.values[:, 2] * 1e3
    np.testing.assert_allclose(play, gap - c3, atol=1e-9)
    assert len(res.mc.verdicts()) == 2


@pytest.mark.parametrize("old, new, key", [
    ('g = "gap"', 'g = "gapp"', "model[0].inputs.g"),
    ('g = "gap"', 'g = "gap +"', "model[0].inputs.g"),
    ('Delta_b = "max(stack.play, 0)"', 'Delta_b = "lm.lost_motion"', "model[1].inputs.Delta_b"),
    ('name = "lm"', 'name = "stack"', "model[1].name"),
    ('value = "c1 - c2"', 'value = "c1 -- c2 ("', "quantity[0].value"),
])
def test_bad_composition_names_the_key(tmp_path, old, new, key):
    spec = write(tmp_path / "spec.toml", '[[factor]]\nname = "c1"\nunit = "um"\ndist = "normal"\ntolerance = 1\n'
                                         '[[factor]]\nname = "c2"\nunit = "um"\ndist = "normal"\ntolerance = 1\n'
                                         '[[factor]]\nname = "c3"\nunit = "um"\ndist = "normal"\ntolerance = 1\n')
    text = _study(spec)
    assert old in text
    p = write(tmp_path / "s.toml", text.replace(old, new, 1))
    with pytest.raises(InputError) as exc:
        load_study(p)
    assert exc.value.file == str(p) and exc.value.key == key, (exc.value.file, exc.value.key, exc.value.reason)


def test_sensitivity_matrix_of_a_composed_study(tmp_path):
    """The matrix ranks by the linearised shares and gives Sobol total indices of the top tolerances."""
    spec = write(tmp_path / "spec.toml", STACK_SPEC)
    text = _study(spec)
    text += '\n[[analysis]]\nkind = "sensitivity_matrix"\ntop = 2\nn = 256\n'
    res = run_study(load_study(write(tmp_path / "s.toml", text), progress=False))
    (sec,) = res.sections
    sh = sec.summary["five_point_share"]
    # stack.play = c1 - c2 - c3 (µm): variance shares σ² / Σσ² by hand
    v = {"c1": 1.0, "c2": (4 / 6) ** 2, "c3": 4.0 ** 2 / 12 / 1.0}
    tot = sum(v.values())
    for k in v:
        assert sh[k]["stack.play"] == pytest.approx(v[k] / tot, rel=1e-6)
    st = sec.summary["sobol_total"]
    assert set(st) == {"c1", "c3", "all other tolerances"}       # c1, c3 the top two; c2 lumped
    for k, g in (("c1", "c1"), ("c3", "c3"), ("all other tolerances", "c2")):
        # within twice the bootstrap 95 % half-width (≈ 4 standard errors; a linear model: Jansen's ST unbiased)
        assert abs(st[k]["stack.play"]["ST"] - v[g] / tot) < 2 * st[k]["stack.play"]["conf"]


def test_model_specific_analyses_work_on_a_stage_of_a_composed_study(tmp_path):
    """transmission_error_curve and torsion_curve on the stages named by `model`, inputs through the mapping."""
    spec = write(tmp_path / "spec.toml", '[[factor]]\nname = "cam"\nunit = "um"\ndist = "uniform"\nlower = 0\n'
                                         'upper = 4\n[[factor]]\nname = "gap"\nunit = "um"\ndist = "uniform"\n'
                                         'lower = 1\nupper = 3\n')
    design = (ROOT / "data/designs/rv80e_te.toml").as_posix()
    text = f"""
[study]
name = "stages"
spec = "{spec.as_posix()}"
design = "{design}"
[[model]]
name = "te"
kind = "transmission_error"
per_crank_rev = 12
[model.inputs]
"E_c[1,1]" = "cam"
"delta_b" = "gap"
[[model]]
name = "tc"
kind = "torsion_curve"
[model.inputs]
"delta_b" = "gap"
[sampling]
n = 6
[execution]
executor = "serial"
[[analysis]]
kind = "transmission_error_curve"
configuration = "worst"
[[analysis]]
kind = "torsion_curve"
model = "tc"
"""
    st = load_study(write(tmp_path / "s.toml", text), progress=False)
    res = run_study(st)
    te, *tc = res.sections
    i = int(np.nanargmax(res.mc.column("te.te_pp")))
    assert te.summary["te_pp_arcsec"]["quasistatic"] == pytest.approx(res.mc.column("te.te_pp")[i], rel=1e-9)
    x = res.mc.samples.values[i]
    assert te.summary["values"] == pytest.approx({"E_c[1,1]": x[0], "delta_b": x[1]})
    assert tc[0].key.startswith("torsion_curve")
    bad = write(tmp_path / "b.toml", text.replace('model = "tc"', 'model = "te"'))
    with pytest.raises(InputError, match="not a torsion_curve model"):
        load_study(bad)


def test_design_numbers_and_a_shared_mapping(tmp_path):
    """``design.<key>`` reads the study design (base units); ``same_inputs_as`` reuses an earlier mapping."""
    spec = write(tmp_path / "spec.toml", '[[factor]]\nname = "c1"\nunit = "um"\ndist = "normal"\ntolerance = 1\n'
                                         '[[factor]]\nname = "c2"\nunit = "um"\ndist = "normal"\ntolerance = 1\n'
                                         '[[factor]]\nname = "c3"\nunit = "um"\ndist = "normal"\ntolerance = 1\n')
    text = _study(spec).replace('value = "c1 - c2"', 'value = "c1 - c2 + design.cycloid.eccentricity"')
    text = text.replace('[sampling]', '[[model]]\nname = "lm2"\nkind = "lost_motion"\nsame_inputs_as = "lm"\n\n[sampling]')
    st = load_study(write(tmp_path / "s.toml", text), progress=False)
    m = st.model
    assert m.stage("lm2").inputs == m.stage("lm").inputs and m.stage("lm2").model.inputs == ("Delta_b",)
    X = np.array([[0.001, 0.0005, 0.0]])
    env, _ = m.environment(X)
    assert env["gap"][0] == pytest.approx(0.0005 + 1.5)            # e = 1.5 mm (doc 000 Table 1)
    np.testing.assert_array_equal(env["lm2.lost_motion"], env["lm.lost_motion"])
    bad = text.replace('same_inputs_as = "lm"', 'same_inputs_as = "lm3"')
    with pytest.raises(InputError) as exc:
        load_study(write(tmp_path / "b.toml", bad))
    assert exc.value.key == "model[2].same_inputs_as"
    # [model.inputs] beside same_inputs_as adds inputs of the model's own; it cannot remap the shared ones
    more = text.replace('same_inputs_as = "lm"', 'same_inputs_as = "lm"\n[model.inputs]\n"Delta_r_c" = "c3"')
    m2 = load_study(write(tmp_path / "d.toml", more), progress=False).model
    assert m2.stage("lm2").model.inputs == ("Delta_b", "Delta_r_c")
    assert m2.stage("lm2").inputs[0] == m2.stage("lm").inputs[0] and m2.stage("lm2").inputs[1].text == "c3"
    env2, _ = m2.environment(np.array([[0.001, 0.0005, 0.002]]))
    assert env2["lm2.lost_motion"][0] > env2["lm.lost_motion"][0]         # 2 µm more profile clearance
    with pytest.raises(InputError) as exc:
        load_study(write(tmp_path / "e.toml", more.replace('"Delta_r_c" = "c3"', '"Delta_b" = "c3"')))
    assert exc.value.key == "model[2].inputs.Delta_b" and "already mapped by same_inputs_as" in exc.value.reason
    bad = text.replace("design.cycloid.eccentricity", "design.cycloid.nothing")
    with pytest.raises(InputError) as exc:
        load_study(write(tmp_path / "c.toml", bad))
    assert exc.value.key == "quantity.gap" and "'design.cycloid.nothing'" in exc.value.reason


def test_a_restricted_composition_evaluates_only_the_stages_its_outputs_need():
    """Keeping stage one's u needs stage one only; keeping stage two's r needs both (r reads one.u, one.w)."""
    comp, lin, nonlin = _composite()
    X = np.array([[2.0e-3, 1.0e-3, 0.2, 1e-4], [1.0e-3, -2.0e-3, 0.1, -2e-4]])
    full = comp.evaluate(X)
    only_one = comp.restricted(["one.u"])
    assert [st.name for st in only_one.stages] == ["one"] and only_one.output_names == ("one.u",)
    np.testing.assert_array_equal(only_one.evaluate(X)[:, 0], full[:, comp.output_names.index("one.u")])
    r = comp.restricted(["two.r", "q"])
    assert [st.name for st in r.stages] == ["one", "two"] and r.output_names == ("q", "two.r")
    np.testing.assert_array_equal(r.evaluate(X), full[:, [comp.output_names.index(n) for n in ("q", "two.r")]])
    with pytest.raises(InputError):
        comp.restricted(["nope"])


PER_OUTPUT = """
[study]
name = "per-output top"

[model]
kind = "formula"
[[model.output]]
name = "y1"
formula = "a + 0.9 * b"
unit = "um"
[[model.output]]
name = "y2"
formula = "c + d + 1.15 * e"
unit = "um"
[[model.output]]
name = "y3"
formula = "hypot(f, 0.5 * g)"
unit = "um"
""" + "".join(f"""
[[factor]]
name = "{x}"
unit = "um"
dist = "normal"
mean = 0.0
tolerance = 6.0
""" for x in "abcdefg") + """
[[analysis]]
kind = "sensitivity_matrix"
top = 3
n = 64

[sampling]
n = 512
seed = 5
"""


def test_sensitivity_matrix_takes_each_outputs_largest_tolerance_in_turn(tmp_path):
    """Shares by hand (equal σ): y1: a 1/1.81 = 0.55, b 0.45; y2: e 1.3225/3.3225 = 0.40, c = d = 0.30; y3 = hypot(f, g/2)
    has zero derivatives at the nominal 0 (no share). The largest shares over all outputs would pick a, b, e and leave
    y3 with none; taken per output in turn: a (y1), e (y2), and for y3 its largest first-order index from the Monte
    Carlo: f (four times g's variance inside the hypot)."""
    res = run_study(load_study(write(tmp_path / "s.toml", PER_OUTPUT), progress=False))
    (sec,) = res.sections
    sh = sec.summary["five_point_share"]
    assert sh["a"]["y1"] == pytest.approx(1 / 1.81, rel=1e-6) and sh["e"]["y2"] == pytest.approx(1.3225 / 3.3225, rel=1e-6)
    assert all(sh[t]["y3"] is None for t in "abcdefg")
    assert list(sec.summary["sobol_total"]) == ["a", "e", "f", "all other tolerances"]


def test_a_stage_evaluates_each_distinct_row_of_its_inputs_once_with_the_same_result():
    """Issue 40 item 6: the five-point stencils of the factors that do not reach a stage leave its inputs at the
    centre's values — the stage is evaluated once for them (each distinct row once), and every output is the same
    as evaluating every row (the model contract: a row does not depend on its batch)."""
    m, lin, nonlin = _composite()
    seen = {"one": [], "two": []}
    for st in m.stages:
        own = st.model.evaluate_with_status
        st.model.evaluate_with_status = lambda X, own=own, name=st.name: (seen[name].append(len(X)), own(X))[1]
    x0 = SPEC.nominal_base()
    X = np.repeat(x0[None], 20, axis=0)
    X[5:10, 3] += np.linspace(-2e-3, 2e-3, 5)     # d moves: stage two only; a moves: both (q) — four distinct values
    X[10:15, 0] += np.linspace(-2e-3, 2e-3, 5)
    Y, status = m.evaluate_with_status(X)
    assert seen["one"] == [1 + 4] and seen["two"] == [1 + 4 + 4]   # the centre, a's four moves (and d's for two)
    y1 = lin.evaluate(np.column_stack([np.hypot(X[:, 0], X[:, 1]), X[:, 2]]))
    y2 = nonlin.evaluate(np.column_stack([y1[:, 0] - 0.5 * y1[:, 1], X[:, 3] * 1000]))
    np.testing.assert_array_equal(Y[:, 1:], np.column_stack([y1, y2]))
