"""NumPy implementation of the 20-DOF model: the same equations as :mod:`rvtol.models.reducer_20dof._kernels`,
written apart — a test oracle, kept out of the package (the library never runs it).

Used by the tests (the numba kernels must agree with it to 1e-9 relative) and
by the benchmark (speed ratio).  It computes each kind of contact from its own
formula, vectorised over pins and bearings, builds the Jacobian ``G`` of each
relative displacement explicitly and assembles ``F = Σ Gᵀ f`` and
``K = Σ Gᵀ (∂f/∂d) G`` with ``einsum`` — no contact table.

Relative displacements (doc 000 §1.3; counter-clockwise angles; Δ = deviation
from the nominal motion; signs derived so that the nominal motion leaves every
contact undeformed — where the printed formulas differ, see the notes):

1. sun support ``d = (X_s − A_s cos γ_s, Y_s − A_s sin γ_s)``;
2. sun–planet mesh along ``n_i = (cos A_i, sin A_i)``, ``A_i = θ_c + φ_i + π/2 − α'``:
   ``δ = (u_s − u_pi)·n_i + R_bs Δθ_s + R_bp Δθ_pi + E_s cos(θ_s + β_s − A_i)
   − E_pi cos(θ_p + β_pi − A_i)`` (the document writes −R_bp Δθ_pi and
   cos(β_pi − θ_p − A_i): it counts the planet rotation clockwise);
3. cycloid–crank bearing ``d = u_cam − u_hole``:
   ``u_cam = (X_pi, Y_pi) + e Δθ_pi t_e + E_cji u(θ_e + β_cji)``,
   ``u_hole = η_j u_e + e Δθ_doj t_e + R_dc Δθ_dj t_h + E_hji u(θ_c + φ_i + β_hji)``
   with ``u_e = u(θ_p + ψ_j)``, ``t = ∂u/∂angle``, ``t_h = t(θ_c + φ_i)``; the
   document's x component is exactly this; its y component has the opposite
   sign on the four motion terms (inconsistent with its x component);
4. cycloid–pin ``δ = η cos α + e Δθ_do sin α + R_d Δθ_d sin α − R_jk cos(α − φ)
   − AP_jk sin(α − φ) + R_djk cos(α − φ_d) + AP_djk sin(α − φ_d) − δ_jk − δ_thjk − n_j(φ)``
   with the profile modification's normal clearance ``n_j(φ) = Δr_j − ΔR_j (1 − K1 cos φ)/√S``
   (doc 004; S = 1 − 2 K1 cos φ + K1², φ = θ_k − θ_p − ψ_j)
   (the document prints −R_d Δθ_d sin α: with that sign the nominal motion would
   compress the pins, so the sign is taken from the kinematics);
5. crank–carrier ``d = (X_pi, Y_pi) − (X_ca, Y_ca) − R_dc Δθ_ca t_h − E_cai u(θ_c + φ_i + β_cai)``
   (as printed);
6. carrier–housing ``d = (X_ca − A_c cos γ_c, Y_ca − A_c sin γ_c)``.

Coulomb friction (:mod:`rvtol.models.reducer_20dof.friction`, the torsion curve) — the friction torque at the output
``Σ m_c |J_c v|/|v_θ|`` (:meth:`ReferenceModel.friction_torque`) from the twin's own slip rows: a pin's tangential
slip ``−sin α η + e cos α θ_do + (R_d cos α + R_p √S − r_rp) θ_d`` (α, φ and S from the pin angles, as in 4.), a
bearing's relative rotation (crank − disc for the needles, crank − carrier for the tapered pair), and its own tangent.

With a compliance chain (:mod:`rvtol.models.reducer_20dof.compliance`) a contact's force is the root of ``Σ δ_i(f) = s``
(:func:`scipy.optimize.brentq`), each ``δ_i`` evaluated here apart from the kernels: the kind's power
law, linear springs, the pin–groove log law, the crank-support pair's table by SciPy's
:class:`~scipy.interpolate.CubicHermiteSpline`; the meshes' linear terms combined by
:func:`rvtol.elements.chain.series`.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from rvtol.elements import chain as springs
from rvtol.models.reducer_20dof import layout as L
from rvtol.models.reducer_20dof.compliance import log_law, table_law
from rvtol.models.reducer_20dof.factors import ErrorState
from rvtol.models.reducer_20dof.friction import Friction
from rvtol.models.reducer_20dof.geometry import RVGeometry


def _u(a):
    return np.stack([np.cos(a), np.sin(a)], axis=-1)


def _t(a):
    return np.stack([-np.sin(a), np.cos(a)], axis=-1)


class ReferenceModel:
    """Forces, tangent stiffness and equilibria of one reducer, in plain NumPy."""

    def __init__(self, g: RVGeometry, errors: ErrorState | None = None):
        self.g = g
        self.e = errors if errors is not None else ErrorState.zero(g.z_b)
        self.p = g.force_exponent
        self.theta_k = 2.0 * np.pi * np.arange(g.z_b) / g.z_b
        self.phi = 2.0 * np.pi * np.arange(L.N_CRANK) / L.N_CRANK
        self.psi = np.pi * np.arange(L.N_DISC)

    # -- geometry at one position: Jacobians G and offsets h of every relative displacement ----
    def linear_parts(self, theta_c: float, dth_s: float = 0.0) -> dict:
        g, err = self.g, self.e.err
        n = L.NDOF
        th_s = g.ratio * theta_c
        th_p = (1 - g.z_b) * theta_c
        out = {}
        # 1. sun support
        G = np.zeros((2, n))
        G[0, L.XS] = G[1, L.YS] = 1.0
        out["sun"] = (G, -err[L.A_S] * _u(err[L.GAMMA_S]))
        # 2. sun-planet meshes
        A = theta_c + self.phi + np.pi / 2 - g.alpha_w
        G = np.zeros((3, n))
        for i in range(3):
            b = L.planet(i)
            G[i, [L.XS, L.YS]] = _u(A[i])
            G[i, [b, b + 1]] = -_u(A[i])
            G[i, b + 2] = g.r_bp
        h = (g.r_bs * dth_s + err[L.E_S] * np.cos(th_s + err[L.BETA_S] - A)
             - err[L.E_P:L.E_P + 3] * np.cos(th_p + err[L.BETA_P:L.BETA_P + 3] - A)
             - g.r_bp * err[L.PHI_P:L.PHI_P + 3] + 0.5 * np.cos(g.alpha) * err[L.S_P:L.S_P + 3])
        out["mesh"] = (G, h)
        # 3. cycloid-crank bearings [j, i, xy]
        hole = theta_c + self.phi
        G = np.zeros((2, 3, 2, n))
        h = np.zeros((2, 3, 2))
        for j in range(2):
            te = th_p + self.psi[j]
            d = L.disc(j)
            for i in range(3):
                b = L.planet(i)
                G[j, i, :, b:b + 2] = np.eye(2)
                G[j, i, :, b + 2] = g.ecc * _t(te)
                G[j, i, :, d] = -_u(te)
                G[j, i, :, d + 1] = -g.ecc * _t(te)
                G[j, i, :, d + 2] = -g.a_w * _t(hole[i])
                h[j, i] = (err[L.E_C + 3 * j + i] * _u(te + err[L.BETA_C + 3 * j + i])
                           - err[L.E_H + 3 * j + i] * _u(hole[i] + err[L.BETA_H + 3 * j + i]))
        out["cam"] = (G, h)
        # 5. crank-carrier bearings [i, xy]
        G = np.zeros((3, 2, n))
        for i in range(3):
            b = L.planet(i)
            G[i, :, b:b + 2] = np.eye(2)
            G[i, :, L.XCA:L.YCA + 1] = -np.eye(2)
            G[i, :, L.THCA] = -g.a_w * _t(hole[i])
        h = -err[L.E_CA:L.E_CA + 3, None] * _u(hole + err[L.BETA_CA:L.BETA_CA + 3])
        out["crank"] = (G, h)
        # 6. carrier-housing
        G = np.zeros((2, n))
        G[0, L.XCA] = G[1, L.YCA] = 1.0
        out["housing"] = (G, -err[L.A_C] * _u(err[L.GAMMA_C]))
        # 4. pins [j, k]
        G = np.zeros((2, g.z_b, n))
        h = np.zeros((2, g.z_b))
        K1 = g.K1
        for j in range(2):
            te = th_p + self.psi[j]
            phi = self.theta_k - te
            alpha = np.arctan2(np.sin(phi), np.cos(phi) - K1)
            d = L.disc(j)
            G[j, :, d] = np.cos(alpha)
            G[j, :, d + 1] = g.ecc * np.sin(alpha)
            G[j, :, d + 2] = g.r_disc_pitch * np.sin(alpha)
            pe = self.e.pin_err
            hj = (-pe[L.PIN_R, j] * np.cos(alpha - phi) - pe[L.PIN_AP, j] * np.sin(alpha - phi)
                  - pe[L.PIN_GAP, j])
            # profile modification of disc j: normal clearance n(φ) (doc 004)
            S = 1.0 + K1 ** 2 - 2.0 * K1 * np.cos(phi)
            hj -= err[L.MOD_EQ + j] - err[L.MOD_MOVED + j] * (1.0 - K1 * np.cos(phi)) / np.sqrt(S)
            # contact point seen from the disc centre, and its disc-fixed angle
            c = g.r_pin_circle * _u(phi) - g.r_pin * _u(alpha) - np.array([g.ecc, 0.0])
            phi_d = np.arctan2(c[:, 1], c[:, 0])
            theta_d = phi_d + te - theta_c
            orders = np.arange(L.NH)[:, None]
            dh = self.e.disc_h[j]
            field = (dh[:, :, 0] @ np.cos(orders * theta_d) + dh[:, :, 1] @ np.sin(orders * theta_d))
            hj += field[L.DISC_R] * np.cos(alpha - phi_d) + field[L.DISC_AP] * np.sin(alpha - phi_d)
            h[j] = hj
        out["pin"] = (G, h)
        return out

    # -- laws -----------------------------------------------------------------------------
    def _series_terms(self, group: str, disc: int = 0, crank: int | None = None):
        """The deflection terms ``δ_i(f) -> (δ, dδ/df)`` of a contact group's series law, or None (the
        kind's power law alone); ``crank``: the crank whose own support preload sets the law (cams, cranks)."""
        ch = self.g.chain
        if ch is None:
            return None
        p = self.p
        k0 = {"cam": self.g.k0_dc, "crank": self.g.k0_oc, "pin": self.g.k0_pin}[group]
        terms = []
        lin = dict({"cam": ch.cam[disc], "crank": ch.crank, "pin": ch.pin}.get(group, {}))
        own = {"crank": ch.crank_table, "cam": ch.cam_table}.get(group)     # a table replacing doc 000's law
        pre = self.e.preload[crank] if crank is not None else np.nan
        if np.isfinite(pre) and ch.crank_table is not None:                  # this crank's own preload
            law, tilt = ch.crank_law(float(pre))
            if group == "crank":
                own = law
            elif "crank_support_bearings" in lin:
                lin["crank_support_bearings"] = tilt[disc]
        table = own is not None
        if table:
            terms.append(lambda f: table_law(own, f)[:2])
        else:
            terms.append(lambda f: (f ** (1 / p) / k0, f ** (1 / p - 1) / (p * k0) if f > 0 else np.inf))
        if group == "pin" and ch.pin_table is not None:
            terms.append(lambda f: table_law(ch.pin_table, f)[:2])
        if lin:
            c = sum(lin.values())
            terms.append(lambda f: (c * f, c))
        if group == "pin" and ch.groove is not None:
            terms.append(lambda f: log_law(ch.groove, f)[:2])
        return terms if len(terms) > 1 or table else None

    @staticmethod
    def _series(s, terms):
        """Force ``f`` with ``Σ δ_i(f) = s`` (0 for ``s <= 0``) and ``df/ds``, elementwise."""
        s = np.asarray(s, dtype=float)
        f = np.zeros(s.shape)
        df = np.zeros(s.shape)
        for i in np.ndindex(s.shape):
            si = float(s[i])
            if not si > 0:
                continue

            def g(F, si=si):
                return sum(float(t(F)[0]) for t in terms) - si

            hi = 1.0
            while g(hi) < 0:
                hi *= 2.0
            fi = brentq(g, 0.0, hi, xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=500)
            f[i] = fi
            df[i] = 1.0 / sum(float(t(fi)[1]) for t in terms)
        return f, df

    def _power(self, k0, s):
        """Hertz law f = (k0 s)^p and its derivative, zero for s <= 0."""
        sp = np.maximum(s, 0.0)
        f = (k0 * sp) ** self.p
        df = np.where(s > 0, self.p * f / np.where(s > 0, s, 1.0), 0.0)
        return f, df

    def _radial(self, k0, d, gap, terms=None):
        """Bearing with a radial dead zone: force vectors [..., 2] and tangents [..., 2, 2]."""
        r = np.linalg.norm(d, axis=-1)
        s = r - gap
        f, df = self._power(k0, s) if terms is None else self._series(s, terms)
        rr = np.where(r > 0, r, 1.0)
        nv = d / rr[..., None]
        nn = nv[..., :, None] * nv[..., None, :]
        Kc = df[..., None, None] * nn + (f / rr)[..., None, None] * (np.eye(2) - nn)
        Kc = np.where((s > 0)[..., None, None], Kc, 0.0)
        return f[..., None] * nv, Kc, f

    def forces(self, theta_c: float, q, dth_s: float = 0.0):
        """``(F, K, parts)``: internal generalised forces, tangent stiffness, per-contact forces."""
        g, err = self.g, self.e.err
        q = np.asarray(q, dtype=float)
        P = self.linear_parts(theta_c, dth_s)
        F = np.zeros(L.NDOF)
        K = np.zeros((L.NDOF, L.NDOF))
        parts = {}
        # linear: sun support, meshes (with the chain's linear terms in series)
        k_mesh = g.k_sp
        if g.chain is not None and g.chain.mesh:
            k_mesh = float(springs.series(g.k_sp, *(1.0 / c for c in g.chain.mesh.values())))
        for name, k in (("sun", g.k_s), ("mesh", k_mesh)):
            G, h = P[name]
            f = k * (G @ q + h)
            F += G.T @ f
            K += k * G.T @ G
            parts[name] = f
        # bearings
        gaps = {"cam": err[L.DELTA_B:L.DELTA_B + 6].reshape(2, 3), "crank": err[L.DELTA_OC:L.DELTA_OC + 3],
                "housing": err[L.DELTA_CA]}
        for name, k0 in (("cam", g.k0_dc), ("crank", g.k0_oc), ("housing", g.k0_ca)):
            G, h = P[name]
            d = G @ q + h
            per_crank = g.chain is not None and self.e.own_preload and name in ("cam", "crank")
            if per_crank:                                  # each crank's own support preload
                if name == "cam":
                    out = [[self._radial(k0, d[j, i], gaps[name][j, i], self._series_terms("cam", j, i))
                            for i in range(3)] for j in range(2)]
                    fv, Kc, fmag = (np.stack([np.stack([o[m] for o in row]) for row in out]) for m in range(3))
                else:
                    out = [self._radial(k0, d[i], gaps[name][i], self._series_terms("crank", crank=i)) for i in range(3)]
                    fv, Kc, fmag = (np.stack([o[m] for o in out]) for m in range(3))
            elif name == "cam" and g.chain is not None:     # the discs may differ in their series terms
                out = [self._radial(k0, d[j], gaps[name][j], self._series_terms("cam", j)) for j in range(2)]
                fv, Kc, fmag = (np.stack([o[m] for o in out]) for m in range(3))
            else:
                terms = self._series_terms(name) if name == "crank" else None
                fv, Kc, fmag = self._radial(k0, d, gaps[name], terms)
            G2 = G.reshape(-1, 2, L.NDOF)
            F += np.einsum("cxn,cx->n", G2, fv.reshape(-1, 2))
            K += np.einsum("cxa,cxy,cyb->ab", G2, Kc.reshape(-1, 2, 2), G2)
            parts[name] = fmag
        # pins
        G, h = P["pin"]
        terms = self._series_terms("pin")
        f, df = self._power(g.k0_pin, G @ q + h) if terms is None else self._series(G @ q + h, terms)
        F += np.einsum("jkn,jk->n", G, f)
        K += np.einsum("jka,jk,jkb->ab", G, df, G)
        parts["pin"] = f
        return F, K, parts

    # -- equilibria -------------------------------------------------------------------------
    def _newton(self, theta_c, torque, q, xs, tol_f, maxit):
        Q = np.zeros(L.NDOF)
        Q[L.THCA] = torque
        reg = 1e-9 * 1e5 * np.diag(xs * xs)
        for it in range(maxit + 1):
            F, K, parts = self.forces(theta_c, q)
            R = F - Q
            if np.max(np.abs(R / xs)) <= tol_f:
                return q, parts, True, it
            if it == maxit:
                break
            q = q + np.linalg.solve(K + reg, -R)
        return q, parts, False, maxit

    def rotation(self, theta_c, torque, q_start, tol_f: float = 1e-5, maxit: int = 60):
        """Equilibria along ``theta_c`` from a converged ``q_start`` (warm-started Newton, linear
        extrapolation of the last two solutions, as the numba sweep) — for the benchmark."""
        xs = self.g.arc_radii()
        out = np.zeros((len(theta_c), L.NDOF))
        q = np.array(q_start, dtype=float)
        for n, th in enumerate(theta_c):
            if n >= 2:
                q = 2 * out[n - 1] - out[n - 2]
            q, _, ok, _ = self._newton(th, torque, q, xs, tol_f, maxit)
            if not ok:
                raise RuntimeError(f"reference Newton failed at position {n}")
            out[n] = q
        return out

    # -- Coulomb friction ------------------------------------------------------------------------
    def friction_rows(self, theta_c: float, fric: Friction) -> list[tuple[str, tuple, float, float, np.ndarray]]:
        """Per friction contact ``(group, index, μ·arm, P0, J)`` with ``J`` its slip row over the 20 DOFs."""
        g = self.g
        th_p = (1 - g.z_b) * theta_c
        K1 = g.K1
        rows = []
        for j in range(2):
            phi = self.theta_k - (th_p + self.psi[j])
            S = 1.0 + K1 ** 2 - 2.0 * K1 * np.cos(phi)
            alpha = np.arctan2(np.sin(phi), np.cos(phi) - K1)
            lam = g.r_pin_circle * np.sqrt(S) - g.r_pin
            d = L.disc(j)
            for k in range(g.z_b):
                J = np.zeros(L.NDOF)
                J[d] = -np.sin(alpha[k])
                J[d + 1] = g.ecc * np.cos(alpha[k])
                J[d + 2] = g.r_disc_pitch * np.cos(alpha[k]) + lam[k]
                rows.append(("pin", (j, k), fric.pin, 0.0, J))
            for i in range(3):
                J = np.zeros(L.NDOF)
                J[L.planet(i) + 2], J[d + 2] = 1.0, -1.0
                rows.append(("cam", (j, i), fric.needle * fric.needle_bore / 2.0, 0.0, J))
        for i in range(3):
            J = np.zeros(L.NDOF)
            J[L.planet(i) + 2], J[L.THCA] = 1.0, -1.0
            rows.append(("crank", (i,), fric.crank_support * fric.crank_support_bore / 2.0, fric.crank_support_p0, J))
        return rows

    def friction_torque(self, theta_c: float, q, fric: Friction) -> tuple[float, dict]:
        """The friction torque at the output of the equilibrium ``q``
        (:func:`rvtol.models.reducer_20dof._kernels.friction_torque`, written apart): ``Σ m_c |J_c v| / |v_θ|`` with
        ``m_c`` the contact's friction force or moment at its normal force here and ``v`` the solution of the
        regularised tangent ``K v = e_θ``.  Returns ``(T_f, {group: share})``."""
        _, K, parts = self.forces(theta_c, q)
        xs = self.g.arc_radii()
        e = np.zeros(L.NDOF)
        e[L.THCA] = 1.0
        v = np.linalg.solve(K + 1e-9 * 1e5 * np.diag(xs * xs), e)
        out = {"pin": 0.0, "cam": 0.0, "crank": 0.0}
        for group, ix, m, p0, J in self.friction_rows(theta_c, fric):
            out[group] += m * (parts[group][ix] + p0) * abs(J @ v) / abs(v[L.THCA])
        return sum(out.values()), out
