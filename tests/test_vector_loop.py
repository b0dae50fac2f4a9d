"""Declared vector loops (rvtol.models.vector_loop) against closed forms of the same assemblies.

References: the one-way clutch's explicit formula φ = acos((a + c)/(e − c)) (studies/stack_clutch.toml) and its
derivative by hand; the offset crank-slider's closed form s = r cos θ + √(l² − (e − r sin θ)²); a 3-D loop closed
by three axis vectors (x, y, z) = −L (cos γ cos α, cos γ sin α, sin γ).  Derivatives: the hand derivatives of
these closed forms.
"""
from __future__ import annotations

import numpy as np
import pytest

from conftest import ROOT, run_cli, write
from rvtol.distributions import Distribution
from rvtol.errors import InputError
from rvtol.model import STATUS_OK
from rvtol.models.vector_loop.model import STATUS_NO_CLOSURE, STATUS_SINGULAR, Dependent, Vector, VectorLoopModel
from rvtol.spec import Factor, ToleranceSpec
from rvtol.study import load_study

CLUTCH = ROOT / "studies" / "stack_clutch_loop.toml"


def _clutch_rows(n=400, seed=4):
    g = np.random.default_rng(seed)
    return np.array([27.645, 11.43, 50.8]) + g.normal(size=(n, 3)) * np.array([0.0508, 0.0127, 0.0254]) / 3


def test_the_declared_clutch_is_the_explicit_formula_sample_by_sample_and_in_its_derivatives():
    loop = load_study(CLUTCH, execute=False).model
    explicit = load_study(ROOT / "studies" / "stack_clutch.toml", execute=False).model
    X = _clutch_rows()
    Y, status = loop.evaluate_with_status(X)
    assert np.all(status == STATUS_OK)
    a, c, e = X.T
    phi = np.arccos((a + c) / (e - c))
    np.testing.assert_allclose(Y[:, 0], phi, rtol=0, atol=1e-14)                       # rad
    np.testing.assert_allclose(Y[:, 0], explicit.evaluate(X)[:, 0], rtol=0, atol=1e-14)
    np.testing.assert_allclose(Y[:, 1], (e - c) * np.sin(phi), rtol=1e-13)              # the contact point b
    # DLM: dφ/d(a, c, e) by hand, u = (a + c)/(e − c), dφ/du = −1/√(1 − u²)
    u = (a + c) / (e - c)
    k = -1.0 / np.sqrt(1.0 - u * u)
    hand = np.stack([k / (e - c), k * (e + a) / (e - c) ** 2, -k * (a + c) / (e - c) ** 2], axis=1)
    np.testing.assert_allclose(loop.gradient(X)[:, 0, :], hand, rtol=1e-10, atol=0)
    np.testing.assert_allclose(loop.gradient(X)[:, 0, :], explicit.gradient(X)[:, 0, :], rtol=1e-10, atol=0)
    assert loop.nominal_dependents()["psi"] == pytest.approx(90.0 - 7.0184, abs=5e-5)


def test_a_row_is_the_same_alone_and_in_any_batch_and_an_assembly_that_cannot_close_fails_with_its_reason():
    loop = load_study(CLUTCH, execute=False).model
    X = _clutch_rows(50)
    X[7] = [45.0, 11.43, 50.8]          # (a + c)/(e − c) > 1: the roller cannot touch both the flat and the ring
    Y, status = loop.evaluate_with_status(X)
    assert status[7] in (STATUS_NO_CLOSURE, STATUS_SINGULAR) and np.all(np.isnan(Y[7]))
    assert "cannot be assembled" in loop.status_reasons[STATUS_NO_CLOSURE]
    assert np.all(np.delete(status, 7) == STATUS_OK)
    for i in (0, 7, 49):
        Yi, si = loop.evaluate_with_status(X[i:i + 1])
        assert si[0] == status[i] and np.array_equal(Yi[0], Y[i], equal_nan=True)


def _spec(**factors):
    return ToleranceSpec("s", tuple(Factor(n, u, Distribution.make("normal", mean=m, sigma=s))
                                    for n, (m, s, u) in factors.items()))


def test_an_offset_crank_slider_is_its_closed_form():
    spec = _spec(r=(40.0, 0.05, "mm"), l=(120.0, 0.08, "mm"), e=(10.0, 0.05, "mm"), theta=(35.0, 0.2, "deg"))
    model = VectorLoopModel(
        [[Vector("r", "theta"), Vector("l", "beta"), Vector("-s", "0"), Vector("-e", "pi/2")]],
        [Dependent("s", "mm", 150.0), Dependent("beta", "deg", 0.0)],
        [("s", "s", "mm"), ("beta", "beta", "deg")], spec.names, spec.units)
    model.at_nominal(np.array([f.nominal_base for f in spec.factors]))
    g = np.random.default_rng(2)
    X = np.column_stack([40 + 0.05 * g.normal(size=300), 120 + 0.08 * g.normal(size=300),
                         10 + 0.05 * g.normal(size=300), np.radians(35 + 0.2 * g.normal(size=300))])
    r, l, e, th = X.T
    root = np.sqrt(l ** 2 - (e - r * np.sin(th)) ** 2)
    s = r * np.cos(th) + root
    Y, status = model.evaluate_with_status(X)
    assert np.all(status == STATUS_OK)
    np.testing.assert_allclose(Y[:, 0], s, rtol=1e-14)
    np.testing.assert_allclose(Y[:, 1], np.arcsin((e - r * np.sin(th)) / l), rtol=0, atol=1e-14)
    w = e - r * np.sin(th)                                   # ds/d(r, l, e, θ) by hand
    hand = np.stack([np.cos(th) + w * np.sin(th) / root, l / root, -w / root,
                     -r * np.sin(th) + w * r * np.cos(th) / root], axis=1)
    np.testing.assert_allclose(model.gradient(X)[:, 0, :], hand, rtol=1e-10, atol=1e-12)


def test_a_three_dimensional_loop_closes_along_its_elevation():
    spec = _spec(L=(50.0, 0.1, "mm"), alpha=(30.0, 0.5, "deg"), gamma=(20.0, 0.5, "deg"))
    model = VectorLoopModel(
        [[Vector("L", "alpha", "gamma"), Vector("x", "0"), Vector("y", "pi/2"), Vector("z", "0", "pi/2")]],
        [Dependent("x", "mm", -40.0), Dependent("y", "mm", -20.0), Dependent("z", "mm", -15.0)],
        [("x", "x", "mm"), ("y", "y", "mm"), ("z", "z", "mm")], spec.names, spec.units, dimensions=3)
    model.at_nominal(np.array([f.nominal_base for f in spec.factors]))
    g = np.random.default_rng(5)
    X = np.column_stack([50 + 0.1 * g.normal(size=100), np.radians(30 + g.normal(size=100)),
                         np.radians(20 + g.normal(size=100))])
    L, al, ga = X.T
    Y, status = model.evaluate_with_status(X)
    assert np.all(status == STATUS_OK)
    ref = -L[:, None] * np.stack([np.cos(ga) * np.cos(al), np.cos(ga) * np.sin(al), np.sin(ga)], axis=1)
    np.testing.assert_allclose(Y, ref, rtol=1e-13, atol=1e-12)
    dz = model.gradient(X)[:, 2, :]                          # z = −L sin γ: (−sin γ, 0, −L cos γ)
    np.testing.assert_allclose(dz, np.stack([-np.sin(ga), 0 * ga, -L * np.cos(ga)], axis=1), rtol=1e-10, atol=1e-12)


def test_a_loop_declared_wrong_is_one_located_line(tmp_path, capsys):
    text = CLUTCH.read_text("utf-8").replace('spec = "../data/examples/one_way_clutch.csv"',
                                            f'spec = "{ROOT / "data/examples/one_way_clutch.csv"}"')
    cases = [
        ('[[model.dependent]]\nname = "psi"', '[[model.dependent]]\nname = "q"\nunit = "mm"\nstart = 1\n'
         '[[model.dependent]]\nname = "psi"', "model", "give 2 equations: declare as many dependents"),
        ('{ length = "a", angle = "pi/2" }', '{ length = "a", angle = "pi/2", twist = "0" }', "model.loop[0].vectors",
         "vector 1: unknown key 'twist'"),
        ('{ length = "a", angle = "pi/2" }', '{ length = "1.7 * a", angle = "pi/2" }', "model.dependent",
         "do not close at the nominal dimensions"),
        ('{ length = "a", angle = "pi/2" }', '{ length = "a + 20", angle = "pi/2" }', "model.loop[0].vectors",
         "vector 1, length: cannot add or subtract a length (mm)"),
        ('{ length = "c", angle = "pi/2" }', '{ length = "c", angle = "c" }', "model.loop[0].vectors",
         "vector 3, angle:"),
        ('{ length = "b", angle = "0" }', '{ length = "b", angle = 90 }', "model.loop[0].vectors",
         "vector 2: the angle 90 is a bare number"),
        ('[model]\nkind = "vector_loop"', '[model]\nkind = "vector_loop"\ndimensions = 2.5', "model.dimensions", ""),
    ]
    for old, new, key, words in cases:
        assert old in text, old
        p = write(tmp_path / "s.toml", text.replace(old, new, 1))
        with pytest.raises(InputError) as ei:
            load_study(p, execute=False)
        assert ei.value.key == key and words in ei.value.reason, (key, ei.value.key, ei.value.reason)
        rc, err = run_cli(["check", p], capsys)
        assert rc == 2 and len(err) == 1 and err[0].startswith("rvtol: error: ") and words in err[0], err


def test_the_loop_study_gives_the_explicit_studys_conventions(tmp_path):
    from rvtol.study import run_study

    res = {}
    for name in ("stack_clutch_loop", "stack_clutch"):
        st = load_study(ROOT / "studies" / f"{name}.toml", executor="serial", progress=False, pdf=False, n=2000)
        res[name] = run_study(st)
    a = {c["convention"]: c for c in next(s for s in res["stack_clutch_loop"].sections
                                          if s.key == "stack_conventions").summary["phi"]["conventions"]}
    b = {c["convention"]: c for c in next(s for s in res["stack_clutch"].sections
                                          if s.key == "stack_conventions").summary["phi"]["conventions"]}
    assert a.keys() == b.keys()
    for name in a:
        for k in ("low", "high", "centre"):
            if b[name].get(k) is not None:
                assert a[name][k] == pytest.approx(b[name][k], rel=0, abs=1e-9), (name, k)
    np.testing.assert_allclose(res["stack_clutch_loop"].mc.Y[:, 0], res["stack_clutch"].mc.Y[:, 0], rtol=0,
                               atol=1e-12)                                  # deg, the same samples


def test_a_formula_gradient_with_respect_to_some_inputs_is_those_columns_of_the_full_one():
    from rvtol.models.formula.model import FormulaModel

    m = FormulaModel([("y", "a * b + sin(c) * a", "mm"), ("z", "d2", "mm")], ["a", "b", "c"], ["mm", "1", "rad"],
                     definitions={"d2": ("a * c", "mm")})
    X = np.random.default_rng(9).random((7, 3))
    Y, G = m.evaluate_with_gradient(X)
    Y2, G2 = m.evaluate_with_gradient(X, ["b", "c"])
    assert np.array_equal(Y, Y2) and np.all(G2[:, :, 0] == 0)
    np.testing.assert_allclose(G2[:, :, 1:], G[:, :, 1:], rtol=1e-15, atol=0)
    np.testing.assert_allclose(G[:, 0, 0], X[:, 1] + np.sin(X[:, 2]), rtol=1e-15)        # ∂y/∂a by hand


JOINT_CLUTCH = """[study]
name = "clutch_joints"
spec = "{spec}"
[model]
kind = "vector_loop"
[[model.joint]]
name = "roller on hub flat"
type = "cylinder_on_plane"
direction = "0"
radius = "c"
slide = "b"
start = 4.5
[[model.joint]]
name = "roller in ring"
type = "cylinder_in_cylinder"
radius = "c"
outer_radius = "e"
angle = "chi"
start = 260
[[model.loop]]
vectors = [{{ length = "a", angle = "pi/2" }}, {{ joint = "roller on hub flat" }}, {{ joint = "roller in ring" }}]
[[model.output]]
name = "phi"
formula = "3*pi/2 - chi"
unit = "deg"
"""


def test_the_clutch_declared_by_its_two_contacts_is_the_explicit_formula(tmp_path):
    # the roller on the hub flat (it slides along it by b, its centre c above) and inside the ring (the line of centres
    # at the dependent angle χ, e − c long): the joints stand for the vectors of studies/stack_clutch_loop.toml
    path = write(tmp_path / "s.toml", JOINT_CLUTCH.format(spec=ROOT / "data/examples/one_way_clutch.csv"))
    model = load_study(path, execute=False).model
    X = _clutch_rows()
    Y, status = model.evaluate_with_status(X)
    a, c, e = X.T
    assert np.all(status == STATUS_OK)
    np.testing.assert_allclose(Y[:, 0], np.arccos((a + c) / (e - c)), rtol=0, atol=1e-14)
    loop = load_study(CLUTCH, execute=False).model
    np.testing.assert_allclose(model.gradient(X)[:, 0, :], loop.gradient(X)[:, 0, :], rtol=1e-10)
    bad = JOINT_CLUTCH.replace('{{ joint = "roller in ring" }}', '{{ joint = "roller in rng" }}')
    with pytest.raises(InputError) as ei:
        load_study(write(tmp_path / "b.toml", bad.format(spec=ROOT / "data/examples/one_way_clutch.csv")), execute=False)
    assert ei.value.key == "model.loop[0].vectors" and "no joint 'roller in rng'" in ei.value.reason \
        and "did you mean 'roller in ring'" in ei.value.reason


def test_a_disc_touching_another_and_resting_at_a_height_slides_to_its_closed_form(tmp_path):
    # disc 1 (r1) fixed at the origin, disc 2 (r2) touching it outside, its centre held at height h: the line of
    # centres at γ with sin γ = h/(r1 + r2), disc 2 at x = (r1 + r2) cos γ — a cylinder_on_cylinder and a slider
    text = """[study]
name = "discs"
[[factor]]
name = "r1"
unit = "mm"
nominal = 10
tolerance = "±0.1"
[[factor]]
name = "r2"
unit = "mm"
nominal = 6
tolerance = "±0.1"
[[factor]]
name = "h"
unit = "mm"
nominal = 9
tolerance = "±0.2"
[model]
kind = "vector_loop"
[[model.joint]]
name = "disc on disc"
type = "cylinder_on_cylinder"
radius = "r1"
outer_radius = "r2"
angle = "gamma"
start = 30
[[model.joint]]
name = "disc 2 on its rail"
type = "slider"
direction = "pi"
slide = "x"
start = 12
[[model.loop]]
vectors = [{ joint = "disc on disc" }, { joint = "disc 2 on its rail" }, { length = "h", angle = "-pi/2" }]
[[model.output]]
name = "x"
formula = "x"
unit = "mm"
"""
    model = load_study(write(tmp_path / "d.toml", text), execute=False).model
    g = np.random.default_rng(8)
    X = np.array([10.0, 6.0, 9.0]) + g.normal(size=(200, 3)) * np.array([0.1, 0.1, 0.2]) / 3
    r1, r2, h = X.T
    Y, status = model.evaluate_with_status(X)
    assert np.all(status == STATUS_OK)
    np.testing.assert_allclose(Y[:, 0], np.sqrt((r1 + r2) ** 2 - h ** 2), rtol=1e-13)
    root = np.sqrt((r1 + r2) ** 2 - h ** 2)                 # dx/d(r1, r2, h) by hand
    hand = np.stack([(r1 + r2) / root, (r1 + r2) / root, -h / root], axis=1)
    np.testing.assert_allclose(model.gradient(X)[:, 0, :], hand, rtol=1e-10)
