"""How many positions a TE sweep needs (issue 15): the fast solver against the NumPy twin, a coarse sweep
against a fine one (the quasi-static equilibrium at an angle does not depend on the path to it), and the
order spectrum of fewer positions against the fine spectrum folded onto it (exact DFT identity)."""

import numpy as np
import pytest

from rvtol import units
from rvtol.design import load_design
from rvtol.errors import InputError
from rvtol.models.reducer_20dof import _kernels as K
from rvtol.models.reducer_20dof import layout as L
from rvtol.models.reducer_20dof.contacts import pin_cos_sin
from rvtol.models.reducer_20dof.geometry import geometry_from_design
from rvtol.models.transmission_error.model import TransmissionErrorModel
from numpy_twin import ReferenceModel
from rvtol.models.transmission_error.orders import order_spectrum, positions_for_order
from rvtol.models.reducer_20dof.quasistatic import MIN_PER_CRANK_REV
from rvtol.models.reducer_20dof.quasistatic import QuasiStaticSolver
from rvtol.sampling import sample
from rvtol.spec import load_spec

from conftest import ROOT

ARCSEC = units.to_base(1.0, "arcsec")


@pytest.fixture(scope="module")
def design():
    return load_design(ROOT / "data/designs/rv80e_te.toml")


@pytest.fixture(scope="module")
def reducer(design):
    """A reducer of the TE study's spec (clearances, part errors): its model and error state."""
    spec = load_spec(ROOT / "data/specs/rv80e_te.toml")
    m = TransmissionErrorModel(design, spec.names)
    x = sample(spec, 1, "lhs", 15).values[0]
    return m, m.state(x)


def te_bound(solver: QuasiStaticSolver, sweep, rows) -> np.ndarray:
    """Bound on |Δθ_ca| between two solutions that both meet the solver tolerance at positions ``rows``.

    Each solution leaves a residual |R_a| ≤ tol_f·xs_a (scaled forces); to first order the two differ by
    K⁻¹ (R₁ − R₂), so |Δθ_ca| ≤ Σ_a |K⁻¹[θ_ca, a]| · 2 tol_f xs_a, with the tangent K (as Newton uses it,
    regularisation included) at the solution.
    """
    g, e, t = solver.g, solver.errors, solver.table
    coef, off = np.zeros((t.n, 2, L.NZ)), np.zeros((t.n, 2))
    F, fc, kt, Km = np.zeros(L.NDOF), np.zeros(t.n), np.zeros((t.n, 3)), np.zeros((L.NDOF, L.NDOF))
    xs = solver.xs
    out = []
    for p in rows:
        fc[:] = 0.0        # no previous force: every contact's tangent (the unloading secant needs one)
        K.update_table(sweep.theta_c[p], 0.0, g.prm(), e.err, e.pin_err, e.disc_h, pin_cos_sin(g), coef, off)
        K.contact_forces(sweep.q[p], t.kind, t.idx, coef, off, t.k0, t.pw, t.gap, t.ser, t.tab, F, fc, kt)
        K.tangent_matrix(t.kind, t.idx, coef, kt, Km)
        Kinv = np.linalg.inv(Km + np.diag(K.REG * 1e5 * xs * xs))
        out.append(np.abs(Kinv[L.THCA]) @ (2.0 * solver.tol_f * xs))
    return np.array(out)


def test_positions_for_order_is_the_fewest_that_resolve_it():
    for z_b in (40, 39, 30):
        for k in (1, 40, 80, 120, 160, 200, 400, 719):
            p = positions_for_order(k, z_b)
            assert p * z_b > 2 * k                                      # Nyquist: order k resolved
            assert p == MIN_PER_CRANK_REV or (p - 1) * z_b <= 2 * k      # and no more than needed
    assert [positions_for_order(k, 40) for k in (120, 160, 400)] == [8, 9, 21]   # hand values
    assert TransmissionErrorModel(load_design(ROOT / "data/designs/rv80e_te.toml"), ["E_c"],
                                  max_order=400).per_crank_rev == 21
    with pytest.raises(InputError, match="not both"):
        TransmissionErrorModel(load_design(ROOT / "data/designs/rv80e_te.toml"), ["E_c"], per_crank_rev=12,
                               max_order=100)


def test_the_fast_sweep_equals_the_numpy_twin_within_the_solver_tolerance(reducer):
    """The numba sweep against the twin's own Newton (its own forces, tangent and linear algebra) over
    60 positions from the same converged start: the TE agrees within the linearised tolerance bound."""
    m, st = reducer
    solver = QuasiStaticSolver(m.geometry, st)
    th = solver.positions(36)[:60]
    fast = solver.sweep(th, -m.load_torque)
    assert fast.ok
    ref = ReferenceModel(m.geometry, st).rotation(th, -m.load_torque, fast.q[0])
    bound = te_bound(solver, fast, range(len(th)))
    assert np.all(np.abs(ref[:, L.THCA] - fast.te) <= bound)
    assert bound.max() < 1e-4 * ARCSEC           # the bound itself: far below anything a TE figure shows


def test_a_coarse_sweep_is_the_fine_sweep_at_its_positions(reducer):
    m, st = reducer
    solver = QuasiStaticSolver(m.geometry, st)
    fine = solver.rotation(m.load_torque, per_crank_rev=36)
    coarse = solver.rotation(m.load_torque, per_crank_rev=12)
    assert fine.ok and coarse.ok
    np.testing.assert_allclose(coarse.theta_c, fine.theta_c[::3], rtol=0, atol=1e-14)   # the same angles (to 1 ulp)
    bound = te_bound(solver, fine, range(0, fine.te.size, 3))
    assert np.all(np.abs(coarse.te - fine.te[::3]) <= bound)
    # fewer samples of the same curve: the peak-to-peak can only read lower (by the sampled-peak error)
    assert np.ptp(coarse.te) <= np.ptp(fine.te) + 2 * bound.max()


def test_the_coarse_spectrum_is_the_fine_spectrum_folded(reducer):
    """x_c[n] = x_f[r n]  ⇒  X_c[k]/N_c = Σ_{m<r} X_f[k + m N_c]/N_f (the DFT of a subsample), so the orders
    up to max_order of a coarse sweep differ from the fine ones by the fine content folded onto them."""
    m, st = reducer
    coarse_m = TransmissionErrorModel(m.geometry, m.inputs, max_order=160)      # 9 per crank rev: N_c = 360
    assert coarse_m.per_crank_rev == 9
    solver = QuasiStaticSolver(m.geometry, st)
    fine = solver.rotation(m.load_torque, per_crank_rev=36)                   # N_f = 1440 = 4 N_c
    coarse = solver.rotation(m.load_torque, per_crank_rev=9)
    nf, nc = fine.te.size, coarse.te.size
    r = nf // nc
    Xf, Xc = np.fft.fft(fine.te) / nf, np.fft.fft(coarse.te) / nc
    folded = sum(Xf[(np.arange(nc) + j * nc) % nf] for j in range(r))
    tol = te_bound(solver, fine, range(0, nf, r)).max()                        # |DFT of the difference| ≤ max
    assert np.max(np.abs(Xc - folded)) <= tol
    # what a user reads: amplitudes up to max_order, off by at most the folded content above N_c / 2
    kmax = coarse_m.max_order
    _, a_f = order_spectrum(fine.te)
    _, a_c = order_spectrum(coarse.te)
    alias_bound = np.array([2 * sum(abs(Xf[(k + j * nc) % nf]) for j in range(1, r)) for k in range(1, kmax + 1)])
    assert np.all(np.abs(a_c[1:kmax + 1] - a_f[1:kmax + 1]) <= alias_bound + 2 * tol)


def test_the_crank_revolution_predictor_reaches_the_same_equilibria_in_fewer_iterations(reducer):
    """A rotation sweep starts each position from the solution one crank revolution earlier plus the change since
    then (estimated from the changes beside it): the equilibria are the linear extrapolation's within the
    tolerance bound, reached in fewer Newton iterations (the pins engage at the same crank angles every
    revolution).  ``rotation`` uses the period only when its positions are exactly one crank revolution apart."""
    m, st = reducer
    solver = QuasiStaticSolver(m.geometry, st)
    th = solver.positions(36)[:360]                     # 10 crank revolutions
    plain = solver.sweep(th, -m.load_torque)
    periodic = solver.sweep(th, -m.load_torque, period=36)
    assert plain.ok and periodic.ok
    bound = te_bound(solver, plain, range(len(th)))
    assert np.all(np.abs(periodic.te - plain.te) <= bound)
    assert periodic.iterations[37:].sum() < 0.95 * plain.iterations[37:].sum()
    np.testing.assert_array_equal(periodic.iterations[:37], plain.iterations[:37])   # the same until a period


def test_rotation_passes_the_period_only_when_positions_are_one_crank_revolution_apart(reducer, monkeypatch):
    m, st = reducer
    solver = QuasiStaticSolver(m.geometry, st)
    seen = []
    monkeypatch.setattr(solver, "sweep", lambda theta, torque, period=0: seen.append((theta.size, period)))
    z = m.geometry.z_b
    cases = ((36, 1.0), (36, 0.5), (36, 0.7), (10, 1.1), (36, 0.71), (12.5, 1.0))
    for pcr, rev in cases:
        solver.rotation(None, pcr, rev)
    # 36·z·0.7 and 10·z·1.1 are whole though their float products are not; 0.71 revolutions and a fractional
    # per_crank_rev space the positions otherwise
    assert seen == [(36 * z, 36), (18 * z, 36), (round(25.2 * z), 36), (11 * z, 10), (round(36 * z * 0.71), 0),
                    (round(12.5 * z), 0)]
