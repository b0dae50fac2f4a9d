"""Numba kernels of the 20-DOF RV reducer model (doc 000, section 1).

Pure array functions, ``@njit(cache=True, nogil=True)``, returning status codes
(:mod:`.layout`).  Python wrappers (:mod:`.quasistatic`, :mod:`.newmark`)
validate, convert and raise; ``tests/numpy_twin.py`` (outside the package) holds a NumPy
implementation of the same equations for the tests and the benchmark ratio.

Structure: every contact is one row of a *contact table*.  A contact's relative
displacement is affine in the coordinates q, ``d = G q + h``; ``G`` (``coef``
over the DOF indices ``idx``) and ``h`` (``off``: the error terms) depend on the
nominal angles only and are rewritten at each position by
:func:`update_table`.  The force law depends on the contact kind (linear,
unilateral power law, radial bearing with a dead zone) and, where a compliance
chain puts further elements in series with a contact (:mod:`.compliance`), on
its series law (:func:`series_law`: the force whose deflections add up).  Internal generalised
forces are ``F = Σ Gᵀ f(d)`` and the tangent stiffness ``K = Σ Gᵀ (∂f/∂d) G``;
equilibrium is ``F(q) = Q``.  The same Newton solver serves the quasi-static
sweep and every step of the Newmark-β integration, and the Newmark loop also
runs on a static table (``rv=False``) — the 1-DOF oscillators of the tests.

Cost (issue 15; ``studies/benchmarks/bench_transmission.py`` measures it against the kernels before):
a sweep computes the reducer's constants once (:func:`table_constants`: the error vectors, so a
position costs 8 trigonometric calls instead of 64) and the pin geometry in passes over contiguous
arrays (:func:`update_table_fast`); the 2·z_b pins are evaluated in a loop of their own (:func:`_forces`,
:func:`_tangent`); the Cholesky factor works on rows; a Newmark step forms its dynamic stiffness
once.  The small helpers of the contact laws called per contact and evaluation (:func:`_unilateral`,
:func:`_series_deflection`) are inlined by numba (``inline="always"``): left as calls (LLVM did not inline
them) they cost a quarter of the force evaluation of an error-free reducer, whose every pin is loaded —
same arithmetic, bit-identical results.  Division follows IEEE (``error_model="numpy"``: a zero divisor
gives inf/NaN, which Newton reports as ``ST_NONFINITE``, instead of a Python exception).  No ``fastmath``: with contraction /
reassociation the same kernel gave results 1e-15 apart when compiled in the process and when loaded from
numba's cache (LLVM fuses differently across inlined and linked callees), so a process pool's workers
and its parent could disagree in the last bit — the engine promises bit-identical results whatever the
executor, and IEEE arithmetic keeps that promise.
Newton iterations: a rotation sweep predicts each position from the one a crank revolution earlier and
the changes since (:func:`qs_sequence`), and a contact that unloads gets its secant slope
(:func:`_slope`).  What remains
is set by the contact state changing between positions (pins engaging, bearings crossing their dead
zones): ≈ 4 iterations per position, each at the arithmetic of its pieces — see
``studies/transmission_error.md``.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .layout import (A_C, A_S, BETA_C, BETA_CA, BETA_H, BETA_P, BETA_S, C_CAM, C_CRANK, C_HOUSING, C_MESH,
                     C_PIN, C_SUN, E_C, E_CA, E_H, E_P, E_S, GAMMA_C, GAMMA_S, LINEAR, MOD_EQ, MOD_MOVED, NH, NZ,
                     P_COSA, PHI_P, S_P,
                     N_CRANK, N_DISC, PIN_AP, PIN_GAP, PIN_R, P_ALPHAW, P_ECC, P_RATIO, P_RBP, P_RBS, P_RDC, P_RP,
                     P_RRP, P_ZB, P_ZC, RADIAL, ST_DIVERGED, ST_LOST_CONTACT, ST_MAXITER, ST_NONFINITE, ST_OK,
                     ST_SINGULAR, ST_UNRESOLVED, S_LIN, S_LOGA, S_LOGB, S_LOGCAP, S_ON, S_TAB, THCA, T_C, T_D, T_F,
                     T_M, UNILATERAL, FR_A, FR_ARM, FR_B, FR_KIND, FR_MU, FR_P0, FR_PIN, FR_ROTATION)

_JIT = dict(cache=True, nogil=True, error_model="numpy")   # IEEE arithmetic: no fastmath (see the docstring)
TWO_PI = 2.0 * math.pi

# per-position record columns
R_PIN_MAX, R_NPIN0, R_NPIN1, R_CAM_MAX, R_CRANK_MAX, R_HOUSING, R_TORQUE_IN = 0, 1, 2, 3, 4, 5, 6
NREC = 7

#: force (N) used to linearise the Hertz laws for the cold-start guess
P_LINEARISE = 100.0
#: displacement bound (mm, arc length): beyond it the small-deviation model no longer applies
Q_MAX = 1.0
#: Jacobian regularisation, per DOF: REG * 1e5 N/mm * radius^2 (residuals are not modified)
REG = 1e-9
#: a contact whose force fell below this share of its previous evaluation's is *unloading*: its Newton slope
#: is the secant f/d (see :func:`_slope`)
UNLOADING = 0.1


# --------------------------------------------------------------------------- contact table
# rows of the per-reducer constants `aux` (:func:`table_constants`): every eccentricity error as a vector
# (E cos β, E sin β), the crank directions (cos φ_i, sin φ_i) and the mesh-line turn (cos, sin)(π/2 − α')
AX_AS, AX_ECA, AX_AC, AX_EC, AX_EH, AX_PHI, AX_MESH = 0, 1, 4, 5, 11, 17, 20
NAUX = 21
#: rows of the pin scratch array of :func:`update_table_fast`: cos φ, sin φ, cos α, sin α, offset
NPINW = 5


@njit(**_JIT)
def _polar(aux, r, mag, ang):
    aux[r, 0] = mag * math.cos(ang)
    aux[r, 1] = mag * math.sin(ang)


@njit(**_JIT)
def table_constants(prm, err):
    """The angle-independent part of :func:`update_table` for one reducer (``aux[NAUX, 2]``).

    The bearing errors ``E (cos(θ + β), sin(θ + β))`` of the table are the error vector
    ``(Ex, Ey) = E (cos β, sin β)`` turned by θ, so a position needs the sines and cosines of the
    nominal angles θ_c and θ_p and the two mesh terms per planet (8 trigonometric calls instead of 64).
    """
    aux = np.zeros((NAUX, 2))
    _polar(aux, AX_AS, err[A_S], err[GAMMA_S])
    _polar(aux, AX_AC, err[A_C], err[GAMMA_C])
    for i in range(N_CRANK):
        _polar(aux, AX_ECA + i, err[E_CA + i], err[BETA_CA + i])
        _polar(aux, AX_PHI + i, 1.0, TWO_PI * i / N_CRANK)
    for m in range(N_DISC * N_CRANK):
        _polar(aux, AX_EC + m, err[E_C + m], err[BETA_C + m])
        _polar(aux, AX_EH + m, err[E_H + m], err[BETA_H + m])
    _polar(aux, AX_MESH, 1.0, 0.5 * math.pi - prm[P_ALPHAW])
    return aux


@njit(**_JIT)
def update_table(theta_c, dth_s, prm, err, pin_err, disc_h, pin_cs, coef, off):
    """Fill ``coef``/``off`` of every contact for the nominal carrier angle ``theta_c``.

    ``dth_s`` is the deviation of the input (sun) angle from its nominal
    ``i·theta_c`` (0 for a prescribed input; the locked-input torsion test keeps
    ``theta_c`` fixed and ``dth_s = 0``).  One call; a sweep computes the constants
    (:func:`table_constants`) and the scratch once and calls :func:`update_table_fast`.
    """
    update_table_fast(theta_c, dth_s, prm, err, table_constants(prm, err), pin_err, disc_h, pin_cs, coef, off,
                      np.empty((NPINW, pin_cs.shape[1])))


@njit(**_JIT)
def _turn(vx, vy, c, s):
    """The vector (vx, vy) turned by the angle whose cosine and sine are (c, s)."""
    return vx * c - vy * s, vx * s + vy * c


@njit(**_JIT)
def update_table_fast(theta_c, dth_s, prm, err, aux, pin_err, disc_h, pin_cs, coef, off, w):
    """:func:`update_table` with the reducer's constants ``aux`` (:func:`table_constants`) and a pin
    scratch array ``w[NPINW, z_b]``: the pin geometry in passes over contiguous arrays (vectorised)."""
    zb = int(prm[P_ZB])
    zc = prm[P_ZC]
    e = prm[P_ECC]
    rp = prm[P_RP]
    rr = prm[P_RRP]
    rdc = prm[P_RDC]
    rbs = prm[P_RBS]
    rbp = prm[P_RBP]
    k1 = zb * e / rp
    th_s = prm[P_RATIO] * theta_c
    th_p = (1.0 - zb) * theta_c
    cth, sth = math.cos(theta_c), math.sin(theta_c)
    cp, sp = math.cos(th_p), math.sin(th_p)

    # 1. sun support
    coef[C_SUN, 0, 0] = 1.0
    off[C_SUN, 0] = -aux[AX_AS, 0]
    coef[C_SUN + 1, 0, 0] = 1.0
    off[C_SUN + 1, 0] = -aux[AX_AS, 1]

    for i in range(N_CRANK):
        ch, sh = _turn(cth, sth, aux[AX_PHI + i, 0], aux[AX_PHI + i, 1])       # h = θ_c + φ_i
        # 2. sun-planet mesh along the line of action at A_i = h + π/2 − α'
        ca, sa = _turn(ch, sh, aux[AX_MESH, 0], aux[AX_MESH, 1])
        c = C_MESH + i
        coef[c, 0, 0] = ca
        coef[c, 0, 1] = sa
        coef[c, 0, 2] = -ca
        coef[c, 0, 3] = -sa
        coef[c, 0, 4] = rbp
        # the base-circle eccentricities: the cosine of the summed angle, as the document writes it (θ_s reaches
        # ~500 rad: a product form would round differently in the last digits of these small terms)
        a = theta_c + TWO_PI * i / N_CRANK + 0.5 * math.pi - prm[P_ALPHAW]
        off[c, 0] = (rbs * dth_s + err[E_S] * math.cos(th_s + err[BETA_S] - a)
                     - err[E_P + i] * math.cos(th_p + err[BETA_P + i] - a)
                     # crank phase: the planet's teeth φ_i behind its eccentrics; a thicker driving flank closes
                     - rbp * err[PHI_P + i] + 0.5 * prm[P_COSA] * err[S_P + i])
        # 5. crank - carrier bearing
        c = C_CRANK + i
        coef[c, 0, 0] = 1.0
        coef[c, 0, 1] = -1.0
        coef[c, 0, 2] = rdc * sh
        coef[c, 1, 0] = 1.0
        coef[c, 1, 1] = -1.0
        coef[c, 1, 2] = -rdc * ch
        ex, ey = _turn(aux[AX_ECA + i, 0], aux[AX_ECA + i, 1], ch, sh)
        off[c, 0] = -ex
        off[c, 1] = -ey

    # 6. carrier - housing bearing
    coef[C_HOUSING, 0, 0] = 1.0
    coef[C_HOUSING, 1, 0] = 1.0
    off[C_HOUSING, 0] = -aux[AX_AC, 0]
    off[C_HOUSING, 1] = -aux[AX_AC, 1]

    ze = zc * e
    kk = 1.0 + k1 * k1
    pc = pin_cs[0]
    ps = pin_cs[1]
    cphi_ = w[0]
    sphi_ = w[1]
    cal_ = w[2]
    sal_ = w[3]
    o_ = w[4]
    for j in range(N_DISC):
        sign = 1.0 if j % 2 == 0 else -1.0   # eccentric direction of disc j: θ_e = θ_p + π j
        ce = sign * cp
        se = sign * sp
        # 3. cycloid j - crank i bearing: d = u_cam − u_hole
        for i in range(N_CRANK):
            ch, sh = _turn(cth, sth, aux[AX_PHI + i, 0], aux[AX_PHI + i, 1])
            c = C_CAM + 3 * j + i
            coef[c, 0, 0] = 1.0
            coef[c, 0, 1] = -e * se
            coef[c, 0, 2] = -ce
            coef[c, 0, 3] = e * se
            coef[c, 0, 4] = rdc * sh
            coef[c, 1, 0] = 1.0
            coef[c, 1, 1] = e * ce
            coef[c, 1, 2] = -se
            coef[c, 1, 3] = -e * ce
            coef[c, 1, 4] = -rdc * ch
            m = 3 * j + i
            cx_, cy_ = _turn(aux[AX_EC + m, 0], aux[AX_EC + m, 1], ce, se)
            hx_, hy_ = _turn(aux[AX_EH + m, 0], aux[AX_EH + m, 1], ch, sh)
            off[c, 0] = cx_ - hx_
            off[c, 1] = cy_ - hy_
        # 4. cycloid j - pin k
        has_disc_err = False
        for f in range(2):
            for n in range(NH):
                if disc_h[j, f, n, 0] != 0.0 or disc_h[j, f, n, 1] != 0.0:
                    has_disc_err = True
        dr_mod = err[MOD_EQ + j]
        dR_mod = err[MOD_MOVED + j]
        has_mod = dr_mod != 0.0 or dR_mod != 0.0
        pr = pin_err[PIN_R, j]
        pa = pin_err[PIN_AP, j]
        pg = pin_err[PIN_GAP, j]
        for k in range(zb):
            cphi = pc[k] * ce + ps[k] * se      # φ = θ_k − θ_e
            sphi = ps[k] * ce - pc[k] * se
            inv = 1.0 / math.sqrt(kk - 2.0 * k1 * cphi)
            cal = (cphi - k1) * inv
            sal = sphi * inv
            o = -(pr[k] * (cal * cphi + sal * sphi) + pa[k] * (sal * cphi - cal * sphi)) - pg[k]
            if has_mod:
                # profile modification: normal clearance n(φ) = Δr − ΔR (1 − K1 cos φ)/√S (doc 004)
                o -= dr_mod - dR_mod * (1.0 - k1 * cphi) * inv
            cphi_[k] = cphi
            sphi_[k] = sphi
            cal_[k] = cal
            sal_[k] = sal
            o_[k] = o
        if has_disc_err:
            # disc-fixed angle = absolute angle − disc spin: turn by rot = θ_e − θ_c
            cr = ce * cth + se * sth
            sr = se * cth - ce * sth
            a0r = disc_h[j, 0, 0, 0]
            a0t = disc_h[j, 1, 0, 0]
            for k in range(zb):
                cal = cal_[k]
                sal = sal_[k]
                # contact point C = pin centre − r_rp n, seen from the disc centre (eccentric frame)
                cx = rp * cphi_[k] - rr * cal - e
                cy = rp * sphi_[k] - rr * sal
                icn = 1.0 / math.sqrt(cx * cx + cy * cy)
                cc = cx * icn
                sc = cy * icn
                c1 = cc * cr - sc * sr     # cos, sin of the disc-fixed angle of C
                s1 = sc * cr + cc * sr
                fr = a0r
                ft = a0t
                cn_ = c1
                sn_ = s1
                for n in range(1, NH):
                    fr += disc_h[j, 0, n, 0] * cn_ + disc_h[j, 0, n, 1] * sn_
                    ft += disc_h[j, 1, n, 0] * cn_ + disc_h[j, 1, n, 1] * sn_
                    t = cn_ * c1 - sn_ * s1
                    sn_ = sn_ * c1 + cn_ * s1
                    cn_ = t
                o_[k] += fr * (cal * cc + sal * sc) + ft * (sal * cc - cal * sc)
        base = C_PIN + j * zb
        for k in range(zb):
            c = base + k
            coef[c, 0, 0] = cal_[k]
            coef[c, 0, 1] = e * sal_[k]
            coef[c, 0, 2] = ze * sal_[k]
            off[c, 0] = o_[k]


# --------------------------------------------------------------------------- series laws
@njit(**_JIT)
def _table_law(tab, t, f):
    """``(δ, dδ/df, ∫_0^f δ)`` of table ``t`` at ``f >= 0``: cubic Hermite between the knots, linear
    with the last slope beyond the last knot."""
    x = tab[t, T_F]
    n = x.size
    if f >= x[n - 1]:
        e = f - x[n - 1]
        d = tab[t, T_D, n - 1]
        m = tab[t, T_M, n - 1]
        return d + m * e, m, tab[t, T_C, n - 1] + d * e + 0.5 * m * e * e
    lo = 0
    hi = n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if x[mid] <= f:
            lo = mid
        else:
            hi = mid
    h = x[hi] - x[lo]
    u = (f - x[lo]) / h
    y0 = tab[t, T_D, lo]
    y1 = tab[t, T_D, hi]
    m0 = tab[t, T_M, lo]
    m1 = tab[t, T_M, hi]
    u2 = u * u
    u3 = u2 * u
    u4 = u3 * u
    d = (2 * u3 - 3 * u2 + 1) * y0 + h * (u3 - 2 * u2 + u) * m0 + (3 * u2 - 2 * u3) * y1 + h * (u3 - u2) * m1
    dd = (6 * u2 - 6 * u) * (y0 - y1) / h + (3 * u2 - 4 * u + 1) * m0 + (3 * u2 - 2 * u) * m1
    ce = tab[t, T_C, lo] + h * (y0 * (u - u3 + 0.5 * u4) + h * m0 * (0.5 * u2 - 2.0 * u3 / 3.0 + 0.25 * u4)
                                + y1 * (u3 - 0.5 * u4) + h * m1 * (0.25 * u4 - u3 / 3.0))
    return d, dd, ce


@njit(inline="always", **_JIT)
def _series_deflection(f, k0, pw, ser, c, tab):
    """``(δ, dδ/df, ∫_0^f δ)`` of contact ``c``'s series law at ``f > 0`` (terms: :mod:`.layout`)."""
    cl = ser[c, S_LIN]
    d = cl * f
    dd = cl
    ce = 0.5 * cl * f * f
    if k0 > 0.0:                      # the kind's power law, f = (k0 δ)^pw
        e = 1.0 / pw
        t = f ** e / k0
        d += t
        dd += e * t / f
        ce += t * f / (1.0 + e)
    b = ser[c, S_LOGB]
    if b > 0.0:                       # line contact f (a − b ln f), linear beyond f_cap
        a = ser[c, S_LOGA]
        cap = ser[c, S_LOGCAP]
        x = min(f, cap)
        lx = math.log(x)
        dx = x * (a - b * lx)
        cx = 0.5 * x * x * (a - b * lx + 0.5 * b)
        if f > cap:
            r = f - cap
            d += dx + b * r
            dd += b
            ce += cx + dx * r + 0.5 * b * r * r
        else:
            d += dx
            dd += a - b - b * lx
            ce += cx
    t = int(ser[c, S_TAB])
    if t >= 0:
        dt, ddt, ct = _table_law(tab, t, f)
        d += dt
        dd += ddt
        ce += ct
    return d, dd, ce


@njit(**_JIT)
def series_law(s, k0, pw, ser, c, tab, f0=0.0):
    """Force ``f`` of contact ``c``'s series law at deflection ``s > 0`` (``δ(f) = s``), the tangent
    ``df/ds = 1/δ'(f)`` and the energy ``∫_0^s f = f s − ∫_0^f δ``.

    Newton on ``δ(f) − s`` kept inside a bracket (bisection when a step leaves it), from ``f0`` when it
    lies inside (the contact's force at the previous evaluation: Newton's iterates move little), else
    from the upper end: every term of δ is increasing from δ(0) = 0, so the kind's power law alone
    (or the linear term alone) bounds f from above.  Newton converges quadratically: once a step is
    below 1e-9 of f, the point it gives is exact to rounding, and the tangent and energy of the
    point before it differ by less than that (relative 1e-9 × the law's curvature).
    """
    lo = 0.0
    if k0 > 0.0:
        hi = (k0 * s) ** pw
    elif ser[c, S_LIN] > 0.0:
        hi = s / ser[c, S_LIN]
    else:
        t = int(ser[c, S_TAB])
        hi = s / tab[t, T_M, 0] if t >= 0 else s / ser[c, S_LOGB]
        for _ in range(200):
            d, dd, ce = _series_deflection(hi, k0, pw, ser, c, tab)
            if d >= s:
                break
            lo = hi
            hi *= 2.0
    f = f0 if lo < f0 < hi else hi
    for _ in range(200):
        d, dd, ce = _series_deflection(f, k0, pw, ser, c, tab)
        g = d - s
        if g > 0.0:
            hi = f
        elif g < 0.0:
            lo = f
        else:
            return f, 1.0 / dd, f * s - ce
        fn = f - g / dd
        if not (fn > lo and fn < hi):
            fn = 0.5 * (lo + hi)
        elif abs(fn - f) <= 1e-9 * fn:
            f = fn
            break
        if hi - lo <= 4e-16 * hi:
            f = fn
            break
        f = fn
    d, dd, ce = _series_deflection(f, k0, pw, ser, c, tab)
    return f, 1.0 / dd, f * s - ce


@njit(**_JIT)
def _zero_load_stiffness(k0, pw, gap, ser, c, tab):
    """Tangent stiffness of a radial contact at zero deflection: nonzero only for a linear law without
    dead zone (doc 000's linear sun support, a linearised bearing)."""
    if gap != 0.0 or pw != 1.0:
        return 0.0
    if ser[c, S_ON] == 0.0:
        return k0
    if ser[c, S_LOGB] > 0.0:
        return 0.0
    comp = ser[c, S_LIN] + (1.0 / k0 if k0 > 0.0 else 0.0)
    t = int(ser[c, S_TAB])
    if t >= 0:
        comp += tab[t, T_M, 0]
    return 1.0 / comp if comp > 0.0 else 0.0


# --------------------------------------------------------------------------- forces
@njit(**_JIT)
def contact_forces(q, kind, idx, coef, off, k0, pw, gap, ser, tab, F, fc, kt):
    """Internal generalised forces ``F = Σ Gᵀ f`` and, per contact, force and tangent terms.

    ``fc[c]``: signed force of a scalar contact, resultant of a bearing (on entry: the previous evaluation's,
    the starting guess of a series law's inversion).
    ``kt[c]``: scalar contacts ``(k, 0, 0)``; bearings the 2×2 tangent ``(Kxx, Kxy, Kyy)`` — the normal
    stiffness of a contact that unloads since the entry ``fc`` is the secant instead (:func:`_slope`; with
    ``fc`` zero on entry, the tangent).
    Returns the elastic energy ``Σ ∫ f`` (``F`` is its gradient; the Newton line search uses it).
    """
    return _forces(q, kind, idx, coef, off, k0, pw, gap, ser, tab, F, fc, kt, 0)


@njit(inline="always", **_JIT)
def _unilateral(d, k0, pw, ser, c, tab, f0):
    """Force, tangent and energy of a one-sided contact at deflection ``d > 0`` (``f0``: a guess of the force,
    for a series law)."""
    if ser[c, S_ON] != 0.0:
        return series_law(d, k0, pw, ser, c, tab, f0)
    f = (k0 * d) ** pw
    return f, pw * f / d, f * d / (pw + 1.0)


@njit(**_JIT)
def _slope(f, d, k_tangent, f_prev):
    """The stiffness Newton uses for a contact of force ``f`` at deflection ``d > 0``: its tangent, or the
    secant ``f/d`` while it unloads (``f < UNLOADING·f_prev``, ``f_prev`` the previous evaluation's force).

    Why: a body that carries no load at an equilibrium (a crank whose mesh and bearings all go slack at
    some positions) sits where its contacts' forces reach zero, at the foot of a power law f = (k0 d)^p
    whose slope vanishes there.  Newton toward that root multiplies d only by 1 − 1/p per iteration
    (= 0.1 for doc 000's p = 1/(1 − 0.1)) — measured: a residual falling 13× per iteration for six
    iterations at such positions.  The secant is the exact slope to zero force for a power law (one step);
    a contact that keeps its load keeps its tangent, so Newton stays quadratic near the solution.  Any
    positive stiffness keeps the line search on the convex potential convergent (:func:`newton`): the
    equilibrium is the same, only the path to it changes.  "Previous evaluation" is the last call of
    :func:`_forces` for this contact, a rejected line-search trial included: the slope is a choice of the
    path, any choice keeps the equilibria.
    """
    if f < UNLOADING * f_prev:
        return f / d
    return k_tangent


@njit(**_JIT)
def _forces(q, kind, idx, coef, off, k0, pw, gap, ser, tab, F, fc, kt, npin):
    """:func:`contact_forces`; the last ``npin`` contacts are *pins*: one-sided contacts on three
    consecutive DOFs ``idx[c, 0, 0] + (0, 1, 2)`` (the reducer's cycloid–pin contacts, see
    :func:`.contacts.static_table`), evaluated in a loop of their own (no index rows)."""
    F[:] = 0.0
    energy = 0.0
    nc = kind.size
    for c in range(nc - npin, nc):
        i0 = idx[c, 0, 0]
        g0 = coef[c, 0, 0]
        g1 = coef[c, 0, 1]
        g2 = coef[c, 0, 2]
        d = off[c, 0] + g0 * q[i0] + g1 * q[i0 + 1] + g2 * q[i0 + 2]
        kt[c, 1] = 0.0
        kt[c, 2] = 0.0
        if d > 0.0:
            f, kk, e_c = _unilateral(d, k0[c], pw[c], ser, c, tab, fc[c])
            energy += e_c
            kt[c, 0] = _slope(f, d, kk, fc[c])
            fc[c] = f
            F[i0] += g0 * f
            F[i0 + 1] += g1 * f
            F[i0 + 2] += g2 * f
        else:
            fc[c] = 0.0
            kt[c, 0] = 0.0
    for c in range(nc - npin):
        kd = kind[c]
        if kd == RADIAL:
            dx = off[c, 0]
            dy = off[c, 1]
            for m in range(NZ):
                ix = idx[c, 0, m]
                if ix < 0:
                    break
                dx += coef[c, 0, m] * q[ix]
            for m in range(NZ):
                iy = idx[c, 1, m]
                if iy < 0:
                    break
                dy += coef[c, 1, m] * q[iy]
            r = math.sqrt(dx * dx + dy * dy)
            s = r - gap[c]
            if s <= 0.0 or r == 0.0:
                fc[c] = 0.0
                k_zero = _zero_load_stiffness(k0[c], pw[c], gap[c], ser, c, tab)
                kt[c, 0] = k_zero
                kt[c, 1] = 0.0
                kt[c, 2] = k_zero
                continue
            if ser[c, S_ON] != 0.0:
                f, ktan, e_c = series_law(s, k0[c], pw[c], ser, c, tab, fc[c])
                energy += e_c
            else:
                f = (k0[c] * s) ** pw[c]
                energy += f * s / (pw[c] + 1.0)
                ktan = pw[c] * f / s
            ktan = _slope(f, s, ktan, fc[c])
            nx = dx / r
            ny = dy / r
            ksec = f / r
            kt[c, 0] = ktan * nx * nx + ksec * ny * ny
            kt[c, 1] = (ktan - ksec) * nx * ny
            kt[c, 2] = ktan * ny * ny + ksec * nx * nx
            fc[c] = f
            fx = f * nx
            fy = f * ny
            for m in range(NZ):
                ix = idx[c, 0, m]
                if ix < 0:
                    break
                F[ix] += coef[c, 0, m] * fx
            for m in range(NZ):
                iy = idx[c, 1, m]
                if iy < 0:
                    break
                F[iy] += coef[c, 1, m] * fy
        else:
            d = off[c, 0]
            for m in range(NZ):
                ix = idx[c, 0, m]
                if ix < 0:
                    break
                d += coef[c, 0, m] * q[ix]
            if kd == LINEAR:
                f = k0[c] * d
                kk = k0[c]
                energy += 0.5 * f * d
            elif d > 0.0:
                f, kk, e_c = _unilateral(d, k0[c], pw[c], ser, c, tab, fc[c])
                kk = _slope(f, d, kk, fc[c])
                energy += e_c
            else:
                f = 0.0
                kk = 0.0
            fc[c] = f
            kt[c, 0] = kk
            kt[c, 1] = 0.0
            kt[c, 2] = 0.0
            if f != 0.0:
                for m in range(NZ):
                    ix = idx[c, 0, m]
                    if ix < 0:
                        break
                    F[ix] += coef[c, 0, m] * f
    return energy


@njit(**_JIT)
def tangent_matrix(kind, idx, coef, kt, K):
    """``K = Σ Gᵀ (∂f/∂d) G`` from the per-contact tangents of :func:`contact_forces` (rows of ``idx`` are
    filled from the left: the first −1 ends a row)."""
    _tangent(kind, idx, coef, kt, K, 0)


@njit(**_JIT)
def _tangent(kind, idx, coef, kt, K, npin):
    """:func:`tangent_matrix` with the last ``npin`` contacts as pins (see :func:`_forces`)."""
    K[:, :] = 0.0
    nc = kind.size
    for c in range(nc - npin, nc):
        kk = kt[c, 0]
        if kk == 0.0:
            continue
        i0 = idx[c, 0, 0]
        for a in range(3):
            ga = kk * coef[c, 0, a]
            for b in range(3):
                K[i0 + a, i0 + b] += ga * coef[c, 0, b]
    for c in range(nc - npin):
        if kind[c] == RADIAL:
            kxx = kt[c, 0]
            kxy = kt[c, 1]
            kyy = kt[c, 2]
            if kxx == 0.0 and kyy == 0.0:
                continue
            for r in range(2):
                for a in range(NZ):
                    ia = idx[c, r, a]
                    if ia < 0:
                        break
                    ga = coef[c, r, a]
                    for s in range(2):
                        kc = ga * ((kxx if s == 0 else kxy) if r == 0 else (kxy if s == 0 else kyy))
                        if kc == 0.0:
                            continue
                        for b in range(NZ):
                            ib = idx[c, s, b]
                            if ib < 0:
                                break
                            K[ia, ib] += kc * coef[c, s, b]
        else:
            kk = kt[c, 0]
            if kk == 0.0:
                continue
            for a in range(NZ):
                ia = idx[c, 0, a]
                if ia < 0:
                    break
                ga = kk * coef[c, 0, a]
                for b in range(NZ):
                    ib = idx[c, 0, b]
                    if ib < 0:
                        break
                    K[ia, ib] += ga * coef[c, 0, b]


# --------------------------------------------------------------------------- linear algebra
@njit(**_JIT)
def cholesky_factor(A):
    """Cholesky factor ``A = L Lᵀ`` in place (L in the lower triangle; only the lower triangle of the
    symmetric ``A`` is read), by rows: dot products over contiguous rows.  False if not PD."""
    n = A.shape[0]
    for j in range(n):
        s = A[j, j]
        for k in range(j):
            s -= A[j, k] * A[j, k]
        if not s > 0.0:
            return False
        d = math.sqrt(s)
        A[j, j] = d
        r = 1.0 / d
        for i in range(j + 1, n):
            t = A[i, j]
            for k in range(j):
                t -= A[i, k] * A[j, k]
            A[i, j] = t * r
    return True


@njit(**_JIT)
def cholesky_back(L, b, x):
    """Solve ``L Lᵀ x = b`` with the factor of :func:`cholesky_factor` (rows of L only)."""
    n = b.size
    for i in range(n):            # L y = b
        t = b[i]
        for k in range(i):
            t -= L[i, k] * x[k]
        x[i] = t / L[i, i]
    for i in range(n - 1, -1, -1):   # Lᵀ x = y, by rows of L
        t = x[i] / L[i, i]
        x[i] = t
        for k in range(i):
            x[k] -= L[i, k] * t


@njit(**_JIT)
def cholesky_solve(A, b, x):
    """Solve A x = b for symmetric positive definite A (A is overwritten). False if not PD."""
    if not cholesky_factor(A):
        return False
    cholesky_back(A, b, x)
    return True


# --------------------------------------------------------------------------- Newton
@njit(**_JIT)
def workspace(nd, nc):
    """Work arrays of the Newton solver: ``(F, K, fc, kt, R, dq, qprev, Rt, dlt)``."""
    return (np.zeros(nd), np.zeros((nd, nd)), np.zeros(nc), np.zeros((nc, 3)), np.zeros(nd), np.zeros(nd),
            np.zeros(nd), np.zeros(nd), np.zeros(nd))


@njit(**_JIT)
def sweep_arrays(prm, err, pin_cs, idx, nd, nc):
    """What every sweep over crank positions allocates once: the contact table (``coef``, ``off``), the table's
    constants of this reducer, the pin work array and the Newton solver's :func:`workspace`."""
    return (np.zeros((nc, 2, idx.shape[2])), np.zeros((nc, 2)), table_constants(prm, err),
            np.empty((NPINW, pin_cs.shape[1])), workspace(nd, nc))


@njit(**_JIT)
def _merit(q, kind, idx, coef, off, k0, pw, gap, ser, tab, npin, Q, D, gv, dyn, qpred, F, fc, kt, R, dlt):
    """Total potential Π(q) and its gradient R = ∂Π/∂q (the residual).

    Quasi-static: Π = Σ contact energies − Q·q.  Newmark step (``dyn``): plus
    ½ Δᵀ D Δ + gᵀ Δ with Δ = q − qpred, D = c0 M + c1 C and g = C vpred (C symmetric), whose
    gradient D Δ + g = M a(q) + C v(q).  Π is convex (monotone contact laws, affine
    kinematics), so Newton with a line search on Π converges from anywhere.
    """
    n = q.size
    e = _forces(q, kind, idx, coef, off, k0, pw, gap, ser, tab, F, fc, kt, npin)
    for a in range(n):
        R[a] = F[a] - Q[a]
        e -= Q[a] * q[a]
    if dyn:
        for a in range(n):
            dlt[a] = q[a] - qpred[a]
        for a in range(n):
            acc = 0.0
            for b in range(n):
                acc += D[a, b] * dlt[b]
            R[a] += acc + gv[a]
            e += dlt[a] * (0.5 * acc + gv[a])
    return e


@njit(**_JIT)
def newton(q, kind, idx, coef, off, k0, pw, gap, ser, tab, npin, Q, D, gv, dyn, qpred, xs, tol_f, maxit, maxstep,
           ws):
    """Solve ``F(q) + [D (q − qpred) + g] − Q = 0`` for q in place; returns (status, iterations).

    Quasi-static unless ``dyn`` (D, g, qpred ignored); a Newmark step otherwise (see :func:`_merit`).
    Residuals are scaled to forces (torques divided by the DOF's arc radius ``xs``), steps to
    arc lengths; convergence when the largest scaled residual is below
    ``tol_f`` (N).  Each Newton step (at most ``maxstep`` mm long) is halved
    until the potential Π decreases enough (Armijo; see :func:`_merit`).  ``npin``: see
    :func:`_forces`; ``ws``: :func:`workspace`.
    """
    F, K, fc, kt, R, dq, qprev, Rt, dlt = ws
    n = q.size
    e = _merit(q, kind, idx, coef, off, k0, pw, gap, ser, tab, npin, Q, D, gv, dyn, qpred, F, fc, kt, R, dlt)
    for it in range(maxit + 1):
        rmax = 0.0
        for a in range(n):
            r = abs(R[a]) / xs[a]
            if r > rmax:
                rmax = r
        if not (math.isfinite(rmax) and math.isfinite(e)):
            return ST_NONFINITE, it
        if rmax <= tol_f:
            return ST_OK, it
        if it == maxit:
            break
        _tangent(kind, idx, coef, kt, K, npin)
        for a in range(n):
            K[a, a] += REG * 1e5 * xs[a] * xs[a]
        if dyn:
            for a in range(n):
                for b in range(a + 1):
                    K[a, b] += D[a, b]
        if not cholesky_factor(K):
            return ST_SINGULAR, it
        for a in range(n):
            Rt[a] = -R[a]
        cholesky_back(K, Rt, dq)
        smax = 0.0
        for a in range(n):
            s = abs(dq[a]) * xs[a]
            if s > smax:
                smax = s
        if not math.isfinite(smax):
            return ST_NONFINITE, it
        if smax > maxstep:
            for a in range(n):
                dq[a] *= maxstep / smax
        slope = 0.0
        for a in range(n):
            qprev[a] = q[a]
            slope += R[a] * dq[a]
        lam = 1.0
        for ls in range(40):
            for a in range(n):
                q[a] = qprev[a] + lam * dq[a]
            et = _merit(q, kind, idx, coef, off, k0, pw, gap, ser, tab, npin, Q, D, gv, dyn, qpred, F, fc, kt, R,
                        dlt)
            if et <= e + 1e-4 * lam * slope + 1e-12 * (abs(e) + 1.0) or not math.isfinite(et):
                break
            lam *= 0.5
        e = et
        for a in range(n):
            if abs(q[a]) * xs[a] > Q_MAX:
                return ST_DIVERGED, it
    return ST_MAXITER, maxit


@njit(**_JIT)
def linearised_laws(kind, k0, pw, gap, ser, tab):
    """Contact laws for the cold-start guess: every Hertz (or series) law linearised at ``P_LINEARISE``
    (secant), pins bilateral, bearings without clearance (one linear solve gives a guess near the answer)."""
    kind_l = kind.copy()
    k0_l = k0.copy()
    pw_l = pw.copy()
    gap_l = np.zeros_like(gap)
    ser_l = np.zeros_like(ser)
    for c in range(kind.size):
        if kind[c] != LINEAR:
            if ser[c, S_ON] != 0.0:
                d, dd, ce = _series_deflection(P_LINEARISE, k0[c], pw[c], ser, c, tab)
                k0_l[c] = P_LINEARISE / d
            else:
                k0_l[c] = k0[c] * P_LINEARISE ** (1.0 - 1.0 / pw[c])   # secant k0·P^h of f = (k0 d)^pw at P
            pw_l[c] = 1.0
            if kind[c] == UNILATERAL:
                kind_l[c] = LINEAR
    return kind_l, k0_l, pw_l, gap_l, ser_l


@njit(**_JIT)
def solve_cold(q, kind, idx, coef, off, k0, pw, gap, ser, tab, npin, Q, D, gv, dyn, qpred, xs, tol_f, maxit, maxstep,
               ws):
    """Equilibrium from no prior solution: a linearised solve (pins bilateral: no pin block), then Newton
    on the real laws."""
    kind_l, k0_l, pw_l, gap_l, ser_l = linearised_laws(kind, k0, pw, gap, ser, tab)
    st, it0 = newton(q, kind_l, idx, coef, off, k0_l, pw_l, gap_l, ser_l, tab, 0, Q, D, gv, dyn, qpred, xs, tol_f,
                     maxit, 1e300, ws)
    if st != ST_OK:
        q[:] = 0.0
    st, it1 = newton(q, kind, idx, coef, off, k0, pw, gap, ser, tab, npin, Q, D, gv, dyn, qpred, xs, tol_f, maxit,
                     maxstep, ws)
    return st, it0 + it1


# --------------------------------------------------------------------------- records
@njit(**_JIT)
def record(kind, fc, prm, tol_f, rec):
    """Per-position outputs from the contact forces of a converged state.  A pin counts as loaded when its
    force exceeds the solver's force resolution ``tol_f``: a pin that only touches at the level of the
    residual (a 2e-6 N contact was counted before) is not load-bearing.  The count stays a property of the
    converged state, not of the equilibrium alone: a pin whose force lies near ``tol_f`` can count on one
    Newton path and not on another (measured: one pin in 960 when issue 15's predictor, 28355af, changed the
    path; up to 2 in 2880 across 48 spec samples when the next predictor did), and a
    large ``tol_f`` near zero torque can leave no pin counted (``ST_LOST_CONTACT``)."""
    zb = int(prm[P_ZB])
    pmax = 0.0
    for j in range(N_DISC):
        npin = 0
        for k in range(zb):
            f = fc[C_PIN + j * zb + k]
            if f > tol_f:
                npin += 1
                if f > pmax:
                    pmax = f
        rec[R_NPIN0 + j] = npin
    rec[R_PIN_MAX] = pmax
    m = 0.0
    for c in range(C_CAM, C_CAM + N_DISC * N_CRANK):
        m = max(m, fc[c])
    rec[R_CAM_MAX] = m
    m = 0.0
    for c in range(C_CRANK, C_CRANK + N_CRANK):
        m = max(m, fc[c])
    rec[R_CRANK_MAX] = m
    rec[R_HOUSING] = fc[C_HOUSING]
    t = 0.0
    for i in range(N_CRANK):
        t += prm[P_RBS] * fc[C_MESH + i]
    rec[R_TORQUE_IN] = t


# --------------------------------------------------------------------------- quasi-static sequence
@njit(**_JIT)
def static_position(q, cold, torque, kind, idx, coef, off, k0, pw, gap, ser, tab, npin, Q, D, prm, xs, tol_f, maxit,
                    maxstep, ws, rec):
    """The static equilibrium of one position (contact table ``coef``/``off``, generalised forces ``Q``, carrier
    torque ``torque``) from the guess ``q`` (solved in place; ``cold``: from no guess), with a cold retry on
    failure; its forces in ``rec`` (:func:`record`).  A loaded reducer in which no pin carries load has lost
    contact.  Returns (status, Newton iterations)."""
    if cold:
        st, it = solve_cold(q, kind, idx, coef, off, k0, pw, gap, ser, tab, npin, Q, D, Q, False, q, xs, tol_f,
                            maxit, maxstep, ws)
    else:
        st, it = newton(q, kind, idx, coef, off, k0, pw, gap, ser, tab, npin, Q, D, Q, False, q, xs, tol_f, maxit,
                        maxstep, ws)
        if st != ST_OK:
            q[:] = 0.0
            st, it2 = solve_cold(q, kind, idx, coef, off, k0, pw, gap, ser, tab, npin, Q, D, Q, False, q, xs,
                                 tol_f, maxit, maxstep, ws)
            it += it2
    if st == ST_OK:
        record(kind, ws[2], prm, tol_f, rec)
        if torque != 0.0 and rec[R_NPIN0] + rec[R_NPIN1] == 0:
            st = ST_LOST_CONTACT
    return st, it


@njit(**_JIT)
def qs_sequence(theta_c, dth_s, torque, load, prm, err, pin_err, disc_h, pin_cs, kind, idx, k0, pw, gap, ser, tab,
                xs, q_start, cold, tol_f, maxit, maxstep, period, out_q, out_status, out_iter, out_rec):
    """A sequence of static equilibria, each warm-started from the previous ones.

    Position n has nominal carrier angle ``theta_c[n]``, input deviation
    ``dth_s[n]`` and external carrier torque ``torque[n]`` (N·mm about +z; a
    load resisting forward rotation is negative), plus the constant generalised
    forces ``load`` (e.g. the discs' centrifugal force).  A rotation sweep varies
    ``theta_c``; a locked-input torsion sweep keeps it and varies ``torque``.
    The first position starts from ``q_start`` (or cold); later ones from a
    linear extrapolation of the last two solutions — or, in a sweep whose
    contact pattern repeats every ``period`` positions (a rotation sweep: one
    crank revolution), from the solution one period earlier plus the change
    since then, ``q[p] ≈ q[p−P] + D(p)`` with ``D(p) = q[p] − q[p−P]`` (the pins
    engage and let go at the same crank angles each revolution: the linear
    extrapolation cannot foresee that).  D(p) is estimated by the mean of the
    two changes already known beside it: at the previous position,
    ``D(p−1)``, and at the same crank angle one revolution earlier, ``D(p−P)``
    (``D(p−1)`` alone for P < p < 2P; the first P + 1 positions extrapolate
    linearly).  Against ``D(p−1)`` alone the mean halves the variance of the
    independent part of their errors — measured on the benchmark's spec
    sample (largest coordinate error in arc length, median over the
    positions): 1.70 → 1.47e-4 mm, Newton iterations 4.22 → 3.73 per position
    (``studies/transmission_error.md`` §5).  A cold retry on failure.
    Stops at the first failure; returns its index or −1.
    """
    n = theta_c.size
    nd = q_start.size
    nc = kind.size
    coef, off, aux, w, ws = sweep_arrays(prm, err, pin_cs, idx, nd, nc)
    Q = np.zeros(nd)
    D = np.zeros((1, 1))
    npin = nc - C_PIN
    q = q_start.copy()
    for p in range(n):
        update_table_fast(theta_c[p], dth_s[p], prm, err, aux, pin_err, disc_h, pin_cs, coef, off, w)
        Q[:] = load
        Q[THCA] += torque[p]
        if period > 0 and p > period:
            for a in range(nd):
                change = out_q[p - 1, a] - out_q[p - 1 - period, a]                      # D(p−1)
                if p >= 2 * period:
                    change = 0.5 * (change + (out_q[p - period, a] - out_q[p - 2 * period, a]))   # and D(p−P)
                q[a] = out_q[p - period, a] + change
        elif p >= 2:
            for a in range(nd):
                q[a] = 2.0 * out_q[p - 1, a] - out_q[p - 2, a]
        st, it = static_position(q, p == 0 and cold, torque[p], kind, idx, coef, off, k0, pw, gap, ser, tab, npin,
                                 Q, D, prm, xs, tol_f, maxit, maxstep, ws, out_rec[p])
        out_iter[p] = it
        out_status[p] = st
        out_q[p, :] = q
        if st != ST_OK:
            return p
    return -1


# --------------------------------------------------------------------------- Coulomb friction (torsion curve)
@njit(**_JIT)
def friction_jacobian(c, fr, coef, idx, prm, ji, jv):
    """The sliding motion of friction contact ``c`` as a row of the coordinates: its DOFs ``ji[:n]`` and
    coefficients ``jv[:n]``; returns n (:mod:`.friction`).

    A pin (``FR_PIN``): the tangential slip of the disc's contact point, ``t·u_C`` with ``t = (−sin α, cos α)``
    in the eccentric frame (u_e, t_e): ``−sin α η + e cos α θ_do + (R_d cos α + λ) θ_d``, λ = |PC| the distance
    from the pitch point P to the contact point, ``λ = −z_b e cos α + √(R_p² − (z_b e sin α)²) − r_rp`` (the pin
    centre lies on the normal through P at distance √(R_p² − …) − z_b e cos α); cos α and sin α are read from the
    pin's contact row (``coef[c, 0, :]`` = (cos α, e sin α, R_d sin α)).  A relative rotation (``FR_ROTATION``):
    ``+1`` on DOF a, ``−1`` on DOF b (none when b < 0: against the ground).
    """
    k = int(fr[c, FR_KIND])
    if k == FR_PIN:
        e = prm[P_ECC]
        h = prm[P_ZB] * e
        cal = coef[c, 0, 0]
        sal = coef[c, 0, 1] / e
        lam = -h * cal + math.sqrt(prm[P_RP] * prm[P_RP] - (h * sal) * (h * sal)) - prm[P_RRP]
        i0 = idx[c, 0, 0]
        ji[0] = i0
        ji[1] = i0 + 1
        ji[2] = i0 + 2
        jv[0] = -sal
        jv[1] = e * cal
        jv[2] = prm[P_ZC] * e * cal + lam
        return 3
    if k == FR_ROTATION:
        ji[0] = int(fr[c, FR_A])
        jv[0] = 1.0
        b = int(fr[c, FR_B])
        if b >= 0:
            ji[1] = b
            jv[1] = -1.0
            return 2
        return 1
    return 0


@njit(**_JIT)
def friction_torque(q, kind, idx, coef, off, k0, pw, gap, ser, tab, fr, prm, xs, npin, ws, v, parts):
    """The friction torque at the output of the equilibrium ``q`` (contact table ``coef``/``off``; :mod:`.friction`):
    every friction contact's force or moment ``m_c = μ_c (F_c + P0_c) arm_c`` (``F_c`` its normal force at
    ``q``) times its sliding motion per unit output rotation, ``|J_c v| / |v_θ|`` with ``v = K⁻¹ e_θ`` the
    motion of the reducer per unit output torque (the tangent ``K`` at ``q``, regularised as :func:`newton`;
    ``e_θ`` the output's unit torque): ``T_f = Σ_c m_c |J_c v| / |v_θ|`` — the work the contacts dissipate
    while the output turns, per unit output angle.  ``parts[g]``: the share of each group (0 pins, 1 needle
    rows, 2 crank-support pairs).  Returns ``T_f`` (N·mm; NaN where the tangent is singular)."""
    F, K, fc, kt = ws[0], ws[1], ws[2], ws[3]
    n = q.size
    fc[:] = 0.0                           # tangents, not the secants of unloading contacts (:func:`_slope`)
    _forces(q, kind, idx, coef, off, k0, pw, gap, ser, tab, F, fc, kt, npin)
    _tangent(kind, idx, coef, kt, K, npin)
    for a in range(n):
        K[a, a] += REG * 1e5 * xs[a] * xs[a]
    e = np.zeros(n)
    e[THCA] = 1.0
    parts[:] = 0.0
    if not cholesky_solve(K, e, v):
        return np.nan
    vt = abs(v[THCA])
    if not vt > 0.0:
        return np.nan
    ji = np.zeros(3, np.int64)
    jv = np.zeros(3)
    total = 0.0
    for c in range(kind.size):
        if fr[c, FR_KIND] == 0.0:
            continue
        m = fr[c, FR_MU] * (fc[c] + fr[c, FR_P0]) * fr[c, FR_ARM]
        if m == 0.0:
            continue
        nj = friction_jacobian(c, fr, coef, idx, prm, ji, jv)
        s = 0.0
        for t in range(nj):
            s += jv[t] * v[ji[t]]
        tc = m * abs(s) / vt
        total += tc
        grp = 0 if int(fr[c, FR_KIND]) == FR_PIN else (1 if c < C_CRANK else 2)
        parts[grp] += tc
    return total


@njit(**_JIT)
def friction_torques(theta_c, dth_s, q_path, prm, err, pin_err, disc_h, pin_cs, kind, idx, k0, pw, gap, ser, tab, fr,
                     xs, out_tf, out_parts):
    """:func:`friction_torque` at every equilibrium of a sweep (``q_path[n, 20]`` at ``theta_c[n]``)."""
    n = theta_c.size
    nd = q_path.shape[1]
    nc = kind.size
    coef, off, aux, w, ws = sweep_arrays(prm, err, pin_cs, idx, nd, nc)
    v = np.zeros(nd)
    parts = np.zeros(3)
    npin = nc - C_PIN
    for p in range(n):
        update_table_fast(theta_c[p], dth_s[p], prm, err, aux, pin_err, disc_h, pin_cs, coef, off, w)
        out_tf[p] = friction_torque(q_path[p], kind, idx, coef, off, k0, pw, gap, ser, tab, fr, prm, xs, npin, ws, v,
                                    parts)
        out_parts[p, :] = parts


# --------------------------------------------------------------------------- extremes of a periodic sweep
@njit(**_JIT)
def interval_bound(ta, tb, ga, gb, chord_before, chord_after, kappa):
    """Lower bound of a curve g over the interval [ta, tb] whose ends are (ta, ga), (tb, gb).

    The curve's slope over the interval is taken to be at most ``S = kappa·c``, ``c`` the steepest chord
    slope |Δg|/Δθ of the interval and of its two neighbours (``chord_before``, ``chord_after``): a local
    Lipschitz constant estimated from the samples.  A curve of slope ≤ S through both ends stays above
    ``(ga + gb)/2 − S·w/2`` (w = tb − ta).  Why the chords bound the slope and when they do not:
    :mod:`rvtol.models.transmission_error.extremes`."""
    w = tb - ta
    c = max(abs(gb - ga) / w, chord_before, chord_after)
    return 0.5 * (ga + gb) - 0.5 * kappa * c * w


@njit(**_JIT)
def _chord(th, g, nxt, k, period):
    """|Δg|/Δθ of the interval from point k to the next (the ring closes over one ``period``)."""
    kn = nxt[k]
    w = th[kn] - th[k]
    if w <= 0.0:
        w += period
    return abs(g[kn] - g[k]) / w


@njit(**_JIT)
def _bound(th, g, nxt, prv, k, period, kappa):
    """:func:`interval_bound` of the interval from point k to the next on the ring."""
    kn = nxt[k]
    tb = th[kn]
    if tb <= th[k]:
        tb += period
    return interval_bound(th[k], tb, g[k], g[kn], _chord(th, g, nxt, prv[k], period),
                          _chord(th, g, nxt, kn, period), kappa)


@njit(**_JIT)
def _grown(a, cap):
    """``a`` in a larger array of ``cap`` rows (the rows beyond ``a``'s zero)."""
    out = np.zeros((cap,) + a.shape[1:], a.dtype)
    out[:a.shape[0]] = a
    return out


@njit(**_JIT)
def _meas(theta, meas):
    """``Σ_k a_k cos(n_k θ) + b_k sin(n_k θ)`` of the rows ``meas[k] = (n, a, b)``."""
    v = 0.0
    for k in range(meas.shape[0]):
        v += meas[k, 1] * math.cos(meas[k, 0] * theta) + meas[k, 2] * math.sin(meas[k, 0] * theta)
    return v


@njit(**_JIT)
def qs_extreme(sign, theta_c, q_sweep, dth_s, torque, load, prm, err, pin_err, disc_h, pin_cs, kind, idx, k0, pw, gap,
               ser, tab, xs, tol_f, maxit, maxstep, kappa, tol_te, max_levels):
    """:func:`qs_extreme_curve` of Δθ_ca itself (no measurement terms)."""
    return qs_extreme_curve(sign, theta_c, q_sweep, dth_s, torque, load, prm, err, pin_err, disc_h, pin_cs, kind, idx,
                            k0, pw, gap, ser, tab, xs, tol_f, maxit, maxstep, kappa, tol_te, max_levels,
                            np.zeros((0, 3)))


@njit(**_JIT)
def qs_extreme_curve(sign, theta_c, q_sweep, dth_s, torque, load, prm, err, pin_err, disc_h, pin_cs, kind, idx, k0, pw,
                     gap, ser, tab, xs, tol_f, maxit, maxstep, kappa, tol_te, max_levels, meas):
    """The smallest value of ``sign·Δθ_ca`` over one output revolution, refined from a rotation sweep
    (``theta_c`` increasing over [0, 2π), its equilibria ``q_sweep``; ``sign`` −1: the largest TE).

    Branch and bound (:mod:`rvtol.models.transmission_error.extremes`): every interval whose lower bound
    (:func:`interval_bound`) lies below the best value found less ``tol_te`` is halved — its midpoint's equilibrium
    solved from a guess interpolated between its neighbours' —, level by level, until no interval can hold a value
    more than ``tol_te`` below the best.  The points form a ring (``nxt``/``prv``); a level rechecks only the
    intervals whose bound can have changed — the halves and the neighbours of a halved interval (the best value only
    falls, so an interval that was not a candidate stays one only through its neighbours' chords). Input deviation
    ``dth_s`` and carrier torque ``torque`` are those of the sweep.  ``meas[k] = (n, a, b)``: terms
    ``a cos(n θ_c) + b sin(n θ_c)`` added to Δθ_ca — the measurement chain of a test rig
    (:mod:`rvtol.models.transmission_error.rig`): the curve refined is then the TE the rig reads (no rows: Δθ_ca
    itself, bit for bit).  Returns (status, θ_c of the extreme, the curve's value there, equilibria solved, Newton
    iterations); status ≠ ST_OK: an equilibrium between the sweep's positions failed, or ``max_levels`` halvings left
    an interval whose bound is still below the best (ST_UNRESOLVED).
    """
    n, nd = q_sweep.shape
    nc = kind.size
    coef, off, aux, w, ws = sweep_arrays(prm, err, pin_cs, idx, nd, nc)
    Q = np.zeros(nd)
    Q[:] = load
    Q[THCA] += torque
    D = np.zeros((1, 1))
    rec = np.zeros(NREC)
    npin = nc - C_PIN
    cap = n + 64                    # points: the sweep's and room for the first halvings (grown as needed)
    th = np.empty(cap)
    g = np.empty(cap)
    q = np.empty((cap, nd))
    nxt = np.empty(cap, np.int64)
    prv = np.empty(cap, np.int64)
    th[:n] = theta_c
    nm = meas.shape[0]
    for k in range(n):
        g[k] = sign * (q_sweep[k, THCA] + _meas(theta_c[k], meas) if nm > 0 else q_sweep[k, THCA])
    q[:n] = q_sweep
    for k in range(n):
        nxt[k] = k + 1 if k + 1 < n else 0
        prv[k] = k - 1 if k > 0 else n - 1
    size = n
    best = g[:n].min()
    check = np.arange(n)            # intervals (by their first point) whose bound is to be checked
    nchk = n
    split = np.empty(cap, np.int64)
    mark = np.zeros(cap, np.int64)  # level at which an interval was last queued (dedupe)
    nev = 0
    nit = 0
    for level in range(1, max_levels + 1):
        ns = 0
        for c in range(nchk):
            k = check[c]
            if _bound(th, g, nxt, prv, k, TWO_PI, kappa) < best - tol_te:
                split[ns] = k
                ns += 1
        if ns == 0:
            k = int(np.argmin(g[:size]))
            return ST_OK, th[k], sign * g[k], nev, nit
        if size + ns > cap:
            cap = 2 * (size + ns)
            th, g, q, nxt, prv = _grown(th, cap), _grown(g, cap), _grown(q, cap), _grown(nxt, cap), _grown(prv, cap)
            mark, split = _grown(mark, cap), _grown(split, cap)
        for c in range(ns):
            k = split[c]
            kn = nxt[k]
            tb = th[kn]
            if tb <= th[k]:
                tb += TWO_PI
            x = 0.5 * (th[k] + tb)
            update_table_fast(x, dth_s, prm, err, aux, pin_err, disc_h, pin_cs, coef, off, w)
            j = size
            # the guess: the cubic through the interval's ends and their outer neighbours (angles from θ_k,
            # unwrapped); 10 % fewer Newton iterations than the ends' mean (spec samples, 12 positions per crank
            # revolution: 3.52 → 3.16 per equilibrium)
            kp, knn = prv[k], nxt[kn]
            t0 = th[kp] - th[k]
            if t0 > 0.0:
                t0 -= TWO_PI
            t3 = th[knn] - th[k]
            if t3 <= tb - th[k]:
                t3 += TWO_PI
            ts = (t0, 0.0, tb - th[k], t3)
            lw = np.ones(4)
            for r in range(4):
                for r2 in range(4):
                    if r2 != r:
                        lw[r] *= (x - th[k] - ts[r2]) / (ts[r] - ts[r2])
            for a in range(nd):
                q[j, a] = lw[0] * q[kp, a] + lw[1] * q[k, a] + lw[2] * q[kn, a] + lw[3] * q[knn, a]
            st, it = static_position(q[j], False, torque, kind, idx, coef, off, k0, pw, gap, ser, tab, npin, Q, D,
                                     prm, xs, tol_f, maxit, maxstep, ws, rec)
            nev += 1
            nit += it
            if st != ST_OK:
                return st, x, q[j, THCA] + (_meas(x, meas) if nm > 0 else 0.0), nev, nit
            th[j] = x
            g[j] = sign * (q[j, THCA] + _meas(x, meas) if nm > 0 else q[j, THCA])
            if g[j] < best:
                best = g[j]
            nxt[j], prv[j] = kn, k
            nxt[k], prv[kn] = j, j
            size += 1
        # the next level checks the halves and their neighbours
        need = 4 * ns
        if check.size < need:
            check = np.empty(need, np.int64)
        nchk = 0
        for c in range(ns):
            k = split[c]
            for t in (prv[k], k, nxt[k], nxt[nxt[k]]):
                if mark[t] != level:
                    mark[t] = level
                    check[nchk] = t
                    nchk += 1
    k = int(np.argmin(g[:size]))
    return ST_UNRESOLVED, th[k], sign * g[k], nev, nit


# --------------------------------------------------------------------------- Newmark-β
@njit(**_JIT)
def newmark_run(theta_c0, omega_c, h, nsteps, nskip, rv, prm, err, pin_err, disc_h, pin_cs, kind, idx, coef, off,
                k0, pw, gap, ser, tab, xs, M, C, Q0, Q1, omega_f, q0, v0, tol_f, maxit, maxstep,
                out_q, out_v, out_status, out_iter, out_rec):
    """Implicit Newmark-β (γ = 1/2, β = 1/4, average acceleration) with Newton at every step.

    ``M q̈ + C q̇ + F(q, t) = Q0 + Q1 sin(omega_f t)``.  With ``rv`` the contact
    table follows the nominal motion θ_c(t) = theta_c0 + omega_c t (constant
    input speed); otherwise ``coef``/``off`` are used as given (test systems).
    Steps ``nskip .. nsteps`` are recorded (index n − nskip).  Returns the
    first failing step or −1.  The step's dynamic stiffness D = c0 M + c1 C is formed once, the
    damping force of the predicted velocity once per step (``C`` symmetric).
    """
    gamma = 0.5
    beta = 0.25
    nd = q0.size
    nc = kind.size
    ws = workspace(nd, nc)
    F, fc, kt, R = ws[0], ws[2], ws[3], ws[4]
    Q = np.zeros(nd)
    q = q0.copy()
    v = v0.copy()
    a = np.zeros(nd)
    qpred = np.zeros(nd)
    vpred = np.zeros(nd)
    gv = np.zeros(nd)
    Mw = M.copy()
    rec = np.zeros(NREC)
    c0 = 1.0 / (beta * h * h)
    c1 = gamma / (beta * h)
    D = np.empty((nd, nd))
    for i in range(nd):
        for b in range(nd):
            D[i, b] = c0 * M[i, b] + c1 * C[i, b]
    aux = table_constants(prm, err)
    w = np.empty((NPINW, pin_cs.shape[1]))
    npin = nc - C_PIN if rv else 0
    # initial acceleration from the equation of motion
    if rv:
        update_table_fast(theta_c0, 0.0, prm, err, aux, pin_err, disc_h, pin_cs, coef, off, w)
    _forces(q, kind, idx, coef, off, k0, pw, gap, ser, tab, F, fc, kt, npin)
    for i in range(nd):
        acc = Q0[i] - F[i]
        for b in range(nd):
            acc -= C[i, b] * v[b]
        R[i] = acc
    if not cholesky_solve(Mw, R, a):
        out_status[0] = ST_SINGULAR
        return 0
    for n in range(1, nsteps + 1):
        t = n * h
        if rv:
            update_table_fast(theta_c0 + omega_c * t, 0.0, prm, err, aux, pin_err, disc_h, pin_cs, coef, off, w)
        sf = math.sin(omega_f * t)
        for i in range(nd):
            Q[i] = Q0[i] + Q1[i] * sf
            qpred[i] = q[i] + h * v[i] + h * h * (0.5 - beta) * a[i]
            vpred[i] = v[i] + h * (1.0 - gamma) * a[i]
            q[i] = qpred[i] + beta * h * h * a[i]      # guess: unchanged acceleration
        for i in range(nd):
            acc = 0.0
            for b in range(nd):
                acc += C[i, b] * vpred[b]
            gv[i] = acc
        st, it = newton(q, kind, idx, coef, off, k0, pw, gap, ser, tab, npin, Q, D, gv, True, qpred, xs, tol_f,
                        maxit, maxstep, ws)
        for i in range(nd):
            a[i] = c0 * (q[i] - qpred[i])
            v[i] = vpred[i] + c1 * (q[i] - qpred[i])
        r = n - nskip
        if st == ST_OK and rv:
            record(kind, fc, prm, tol_f, rec)
            if Q0[THCA] != 0.0 and rec[R_NPIN0] + rec[R_NPIN1] == 0:
                st = ST_LOST_CONTACT
        if r >= 0:
            out_q[r, :] = q
            out_v[r, :] = v
            out_iter[r] = it
            out_status[r] = st
            if rv and st == ST_OK:
                out_rec[r, :] = rec
        if st != ST_OK:
            if r < 0:
                out_status[0] = st
            return max(r, 0)
    return -1
