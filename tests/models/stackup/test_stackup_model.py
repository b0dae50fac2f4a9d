"""The stack-up Model: linear chain MC vs analytic RSS, Jacobian vs finite differences, hand-checked
poses of the RV chain, floats in the clearance domain, numba vs NumPy, sequences."""
import math
import tomllib

import numpy as np
import pytest

from rvtol.design import load_design
from rvtol.executors import SerialExecutor
from rvtol.mc import evaluate, run_monte_carlo
from rvtol.sampling import sample
from rvtol.sensitivity import five_point
from rvtol.spec import load_spec, spec_from_table
from rvtol.models.stackup import domains as dm
from rvtol.models.stackup.graph import assembly_from_table, load_assembly
from rvtol.stacking.chain_conventions import Factors, linearise_output
from rvtol.models.stackup.model import StackupModel

from conftest import ROOT

Z = 4.5

GAP_CHAIN = """
[assembly]
name = "gap"
ground = "housing"
[[part]]
name = "housing"
[[part.feature]]
name = "floor"
datum = true
[[part.feature]]
name = "ceiling"
z = 50
[[part.feature.deviation]]
name = "h"
kind = "dof"
dofs = ["w"]
[[part]]
name = "A"
[[part.feature]]
name = "bottom"
datum = true
[[part.feature]]
name = "top"
z = 20
[[part.feature.deviation]]
name = "h"
kind = "dof"
dofs = ["w"]
[[part]]
name = "B"
[[part.feature]]
name = "bottom"
datum = true
[[part.feature]]
name = "top"
z = 25
[[part.feature.deviation]]
name = "h"
kind = "dof"
dofs = ["w"]
[[fit]]
name = "fA"
base = "housing.floor"
mate = "A.bottom"
[[fit]]
name = "fB"
base = "A.top"
mate = "B.bottom"
[[sequence]]
name = "stack"
steps = [{ part = "A", by = "fA" }, { part = "B", by = "fB" }]
[[kc]]
name = "gap"
feature = "housing.ceiling"
relative_to = "B.top"
components = ["w"]
length_unit = "mm"
"""

GAP_SPEC = """
[[factor]]
name = "housing.ceiling.h.w"
unit = "mm"
dist = "normal"
mean = 0.01
sigma = 0.02
[[factor]]
name = "A.top.h.w"
unit = "mm"
dist = "uniform"
lower = -0.03
upper = 0.03
[[factor]]
name = "B.top.h.w"
unit = "mm"
dist = "normal"
mean = -0.005
sigma = 0.01
"""


@pytest.fixture(scope="module")
def gap():
    asm = assembly_from_table(tomllib.loads(GAP_CHAIN), file="gap.toml")
    spec = spec_from_table(tomllib.loads(GAP_SPEC), file="gap_spec.toml")
    return asm, spec, StackupModel(asm, None, spec.names)


@pytest.fixture(scope="module")
def rv(root):
    design = load_design(root / "data/designs/rv80e_te.toml")
    asm = load_assembly(root / "data/assemblies/rv_crank_chain.toml", design)
    spec = load_spec(root / "data/specs/stackup_rv_crank_chain.toml")
    return asm, spec


@pytest.fixture(scope="module")
def root():
    return ROOT


def test_linear_chain_monte_carlo_converges_to_analytic_rss(gap):
    """gap = h_ceiling − h_A − h_B: the MC mean and σ within Z standard errors (from n) of the closed form."""
    _, spec, model = gap
    mean = 0.01 - 0.0 - (-0.005)
    sigma = math.sqrt(0.02**2 + 0.06**2 / 12 + 0.01**2)
    for n in (2_000, 50_000):
        mc = run_monte_carlo(model, spec, n, "random", seed=11, progress=False)
        y = mc.column("gap.w")
        assert abs(y.mean() - mean) < Z * sigma / math.sqrt(n)
        assert abs(y.std(ddof=1) - sigma) < Z * sigma / math.sqrt(2 * n)


def test_linear_chain_linearisation_and_loop_signs(gap):
    _, spec, model = gap
    J = model.jacobian(spec.nominal_base())  # nominal = mean ≠ 0: central differences of the (linear) chain
    np.testing.assert_allclose(J["gap"][2], [1.0, -1.0, -1.0], atol=1e-9)
    np.testing.assert_allclose(model.jacobian(np.zeros(3))["gap"][2], [1.0, -1.0, -1.0], atol=1e-15)
    lin = linearise_output(model, spec, "gap.w", J, Factors.of(spec))
    assert lin.figures["RSS mean"] == pytest.approx(0.015)
    assert lin.figures["RSS σ"] == pytest.approx(math.sqrt(0.02**2 + 0.06**2 / 12 + 0.01**2))
    # worst case: each factor at the band end that widens the gap (normal: ±3σ, uniform: support)
    assert lin.figures["WC high"] == pytest.approx(0.01 + 0.06 + 0.03 + (0.005 + 0.03))
    assert lin.figures["WC low"] == pytest.approx(0.01 - 0.06 - 0.03 + (0.005 - 0.03))
    assert list(lin.contributions["sign"]) == ["+", "−", "−"]
    assert list(lin.contributions["accumulator"]) == ["positive", "negative", "negative"]


def test_sensitivity_runs_on_the_chain_unchanged(gap):
    """The five-point local sensitivity of the gap is the hand derivative (+1, −1, −1), in mm/mm."""
    _, spec, model = gap
    d = five_point(model, spec).frame.set_index("factor")
    np.testing.assert_allclose(d.loc[list(spec.names), "S"], [1.0, -1.0, -1.0], rtol=1e-9)
    assert list(d.loc[list(spec.names), "sign"]) == ["+", "−", "−"]


def test_loop_signs_of_the_disc_offset_along_the_eccentricity(rv):
    """∂u/∂x by hand: an axis-end x moves the axis middle by ½ and tilts it by 1/L, seen at the disc centre
    z = 6.5 mm above the main-seat and carrier-bore origins; the disc's own bore moves the disc the other way."""
    asm, spec = rv
    m = StackupModel(asm, "carrier_first", spec.names)
    lin = linearise_output(m, spec, "cycloid_axis.u", m.jacobian(spec.nominal_base()), Factors.of(spec))
    d = lin.contributions.set_index("factor")
    hand = {"housing.main_seats.coaxiality.x1": 0.5 + 6.5 / 64, "housing.main_seats.bearing_runout.x2": 0.5 - 6.5 / 64,
            "carrier.crank_hole_1.position.x1": 0.5 + 6.5 / 46, "crank_1.eccentric.position.x2": 0.5,
            "cycloid.crank_hole_1.position.x1": -0.5, "cycloid.crank_hole_1.position.y1": 0.0}
    for name, v in hand.items():
        assert d.loc[name, "derivative"] == pytest.approx(v, abs=1e-9), name
        assert d.loc[name, "accumulator"] == ("positive" if v > 0 else "negative" if v < 0 else "uncorrelated")
    assert (d["accumulator"] == "negative").sum() == 2 and (d["accumulator"] == "positive").sum() == 12


@pytest.mark.parametrize("rotation", ["exact", "small"])
def test_jacobian_against_finite_differences(rv, rotation):
    asm, spec = rv
    for seq in asm.sequences:
        m = StackupModel(asm, seq, spec.names, rotation=rotation)
        x0 = spec.nominal_base()
        J = m.jacobian(x0)
        h = 1e-5  # mm for lengths, 1 for the float factors
        k = len(x0)
        X = np.repeat(x0[None], 2 * k, axis=0)
        X[np.arange(k), np.arange(k)] += h
        X[k + np.arange(k), np.arange(k)] -= h
        devs, status = m.kc_deviations(X)
        assert not status.any()
        for kc, D in devs.items():
            fd = (D[:k] - D[k:]).T / (2 * h)
            scale = np.abs(J[kc]).max()
            np.testing.assert_allclose(J[kc], fd, atol=1e-7 * scale, err_msg=f"{seq} {kc}")


def test_rv_chain_poses_by_hand(rv):
    """A tilt of the main-bearing seats and an eccentric offset give poses one can write down."""
    asm, spec = rv
    m = StackupModel(asm, "carrier_first", spec.names)
    L = 64.0
    alpha = 2e-4  # rad: main-seat axis ends at y = ∓αL/2
    x = np.zeros(len(spec))
    x[spec.index("housing.main_seats.coaxiality.y1")] = -alpha * L / 2 * 1e-3 * 1e3  # mm
    x[spec.index("housing.main_seats.coaxiality.y2")] = alpha * L / 2
    devs, _ = m.kc_deviations(x[None])
    c = devs["cycloid_axis"][0]
    # the disc centre sits at z = 6.5 mm: Rx(α) moves it by (0, −6.5 sin α, 6.5 (cos α − 1))
    np.testing.assert_allclose(c, [0, -6.5 * math.sin(alpha), 6.5 * (math.cos(alpha) - 1), alpha, 0, 0],
                               atol=1e-15)
    np.testing.assert_allclose(devs["crank_axis"][0], [0, 0, 0, alpha, 0, 0], atol=1e-15)
    # an eccentric journal 3 µm off along x moves the disc (zero float) by 3 µm; crank 2 then misfits by 3 µm
    x = np.zeros(len(spec))
    for c_ in ("x1", "x2"):
        x[spec.index(f"crank_1.eccentric.position.{c_}")] = 0.003
    Y = dict(zip(m.output_names, m.evaluate(x[None])[0]))
    assert Y["cycloid_axis.radial"] == pytest.approx(0.003, abs=1e-15)
    assert Y["cycloid_axis.u"] == pytest.approx(0.003, abs=1e-15)  # along the eccentricity (+x)
    assert Y["crank_axis.radial"] == pytest.approx(0.0, abs=1e-15)
    assert Y["needle_2_misfit.radial"] == pytest.approx(0.003, abs=1e-15)
    assert Y["needle_2_misfit.margin"] == pytest.approx(0.005 - 0.003, abs=1e-15)  # c0/2 − offset


def test_numba_and_numpy_backends_agree_and_rows_are_independent(rv):
    asm, spec = rv
    X = sample(spec, 3000, "random", seed=4).values
    for seq in asm.sequences:
        a = StackupModel(asm, seq, spec.names, backend="numba")
        b = StackupModel(asm, seq, spec.names, backend="numpy")
        Ya, Yb = a.evaluate(X), b.evaluate(X)
        np.testing.assert_allclose(Ya, Yb, rtol=1e-10, atol=1e-12)  # rounding (mm, rad)
        whole = evaluate(a, X, SerialExecutor(), chunk_size=3000, progress=False).Y
        chunked = evaluate(a, X, SerialExecutor(), chunk_size=97, progress=False).Y
        np.testing.assert_array_equal(whole, chunked)


def test_small_and_exact_rotations_differ_at_second_order(rv):
    """On the real chain, scaling every factor by s scales the exact-vs-small-angle difference by s²."""
    asm, spec = rv
    X = sample(spec, 500, "random", seed=5).values
    a = StackupModel(asm, None, spec.names, rotation="exact")
    b = StackupModel(asm, None, spec.names, rotation="small")
    diff = []
    for s in (1.0, 0.1, 0.01):
        Da, Db = a.kc_deviations(s * X)[0], b.kc_deviations(s * X)[0]
        diff.append(max(np.abs(Da[k] - Db[k]).max() for k in Da))
    assert 80 < diff[1] / diff[2] < 120 and 50 < diff[0] / diff[1] < 150, diff
    assert diff[0] < 1e-4  # mm / rad: tiny against µm-level deviations (angles ~1e-4 rad)


def test_uniform_float_fills_the_clearance_domain(root):
    """Through the model, the shaft axis has the derived mean/covariance of the clearance domain."""
    asm = load_assembly(root / "data/assemblies/shaft_hole_doc003.toml")
    spec = load_spec(root / "data/specs/stackup_shaft_hole.toml")
    m = StackupModel(asm, None, spec.names)
    n = 400_000
    X = sample(spec, n, "random", seed=6).values
    E = m.kc_deviations(X)[0]["shaft_axis"]
    f = dm.ClearanceFit(0.0, spec.factor("hole.size").dist, spec.factor("shaft.size").dist, 25.0)
    cov = f.cov("uniform")
    for i in (0, 1, 3, 4):
        se_m = E[:, i].std() / np.sqrt(n)
        assert abs(E[:, i].mean()) < Z * se_m
        dev = E[:, i] ** 2
        assert abs(dev.mean() - cov[i, i]) < Z * dev.std() / np.sqrt(n)
    assert np.abs(E[:, [2, 5]]).max() < 1e-15  # the float moves neither along nor about the axis


def test_worst_case_floats_push_the_shaft_to_the_wall(root):
    asm = load_assembly(root / "data/assemblies/shaft_hole_doc003.toml")
    spec = load_spec(root / "data/specs/stackup_shaft_hole.toml")
    X = sample(spec, 1000, "random", seed=7).values
    c = StackupModel(asm, None, spec.names).clearance(asm.fits["fit"], X)
    tilt = StackupModel(asm, None, spec.names, floats={"fit": "worst_tilt"})
    off = StackupModel(asm, None, spec.names, floats={"fit": "worst_offset"})
    Yt = dict(zip(tilt.output_names, tilt.evaluate(X).T))
    Yo = dict(zip(off.output_names, off.evaluate(X).T))
    np.testing.assert_allclose(Yt["shaft_axis.tilt"], np.maximum(c, 0) / 25.0, rtol=1e-12)
    np.testing.assert_allclose(Yt["shaft_axis.radial"], 0.0, atol=1e-15)
    np.testing.assert_allclose(Yo["shaft_axis.radial"], np.maximum(c, 0) / 2, rtol=1e-12)
    np.testing.assert_allclose(Yo["shaft_axis.tilt"], 0.0, atol=1e-15)


def test_sequences_decide_which_fits_close_the_loop(rv):
    asm, spec = rv
    a = StackupModel(asm, "carrier_first", spec.names)
    b = StackupModel(asm, "cycloid_first", spec.names)
    assert {f.name for f in asm.closing_fits(a.sequence)} == {"needle_2", "pin_ring"}
    assert {f.name for f in asm.closing_fits(b.sequence)} == {"needle_2", "main_bearing"}
    assert "main_bearing_misfit.radial" in b.output_names and "main_bearing_misfit.radial" not in a.output_names
    X = sample(spec, 400, "random", seed=8).values
    Ya, Yb = dict(zip(a.output_names, a.evaluate(X).T)), dict(zip(b.output_names, b.evaluate(X).T))
    # needle 1 locates in both: its alignment is the float alone, the same in both sequences
    np.testing.assert_allclose(Ya["needle_1_alignment.tilt"], Yb["needle_1_alignment.tilt"], rtol=1e-9)
    # the loop closes: with all deviations zero every KC is zero in every sequence
    for m in (a, b):
        y = m.evaluate(np.zeros((1, len(spec))))[0]
        margins = [i for i, nme in enumerate(m.output_names) if nme.endswith(".margin")]
        assert np.abs(np.delete(y, margins)).max() < 1e-13
