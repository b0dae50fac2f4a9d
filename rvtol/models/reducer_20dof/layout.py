"""Index layout shared by the numba kernels, the NumPy twin and the Python wrappers.

Plain integers only (numba reads them as compile-time constants).

Generalised coordinates (20 DOF, small deviations from the nominal motion;
translations in mm, rotations in rad, all angles counter-clockwise positive)::

    0, 1                      X_s, Y_s            sun centre
    2 + 3i, 3 + 3i, 4 + 3i    X_pi, Y_pi, θ_pi    planet/crank i (θ: absolute rotation deviation)
    11 + 3j, 12 + 3j, 13 + 3j η_dj, θ_doj, θ_dj   cycloid disc j: radial (along the eccentric),
                                                   orbital angle of its centre, spin
    17, 18, 19                X_ca, Y_ca, θ_ca    output carrier (θ_ca = Δθ_ca, the transmission error)

Contacts (one row of the contact table each)::

    0, 1          sun support x, y                      linear
    2 .. 4        sun–planet mesh i                     linear (bilateral)
    5 .. 10       cycloid j – crank i bearing (5+3j+i)  radial, dead zone δ_bji, Hertz
    11 .. 13      crank i – carrier bearing             radial, dead zone δ_oci, Hertz
    14            carrier – housing bearing             radial, dead zone δ_ca, Hertz
    15 + j·z_b + k  cycloid j – pin k                   unilateral (pins only push), Hertz
"""
NDOF = 20
XS, YS = 0, 1
PLANET0 = 2      # + 3 i: X, Y, θ
DISC0 = 11       # + 3 j: η, θ_do, θ_d
XCA, YCA, THCA = 17, 18, 19

# contact kinds
LINEAR = 0       # scalar, bilateral: f = k0·δ
UNILATERAL = 1   # scalar, one-sided power law: f = (k0·max(δ, 0))^pw
RADIAL = 2       # 2-D bearing with a radial dead zone g: f = (k0·max(|d| - g, 0))^pw along d/|d|
NZ = 5           # max non-zero coefficients per contact row

# series law of a contact (row `ser[c]`, see .compliance and _kernels.series_law): the deflection of the
# force f is the sum of the kind's power law (absent when k0 = 0), c_lin·f, the log law f·(a − b ln f)
# (linear beyond f_cap) and a tabulated law (row `tab[id]`); S_ON = 0: the kind's power law alone
S_ON, S_LIN, S_LOGA, S_LOGB, S_LOGCAP, S_TAB = 0, 1, 2, 3, 4, 5
NSER = 6
# rows of a law table tab[id]: knots f, deflection δ, slope dδ/df, cumulative ∫δ df
T_F, T_D, T_M, T_C = 0, 1, 2, 3

C_SUN = 0
C_MESH = 2
C_CAM = 5
C_CRANK = 11
C_HOUSING = 14
C_PIN = 15
N_CRANK = 3
N_DISC = 2

# geometry/stiffness vector `prm`
P_ZS, P_ZP, P_ZC, P_ZB = 0, 1, 2, 3
P_ECC, P_RP, P_RRP = 4, 5, 6          # eccentricity e (= R_e), pin circle radius, pin radius
P_RDC, P_ALPHAW, P_RBS, P_RBP = 7, 8, 9, 10   # crank circle radius R_dc = a', α', base radii
P_RATIO = 11
P_KS, P_KSP = 12, 13                  # linear stiffnesses (N/mm)
P_K0DC, P_K0OC, P_K0PIN, P_K0CA = 14, 15, 16, 17   # Hertz base coefficients (k = k0·P^h)
P_PW = 18                             # force exponent 1/(1-h)
P_OMEGA_C = 19                        # nominal carrier speed (rad/s), Newmark only
P_COSA = 20                           # cos α of the reference pressure angle (a tooth thickness → line of action)
NPRM = 21

# error vector `err` (base units mm, rad)
E_S, BETA_S, A_S, GAMMA_S, A_C, GAMMA_C, DELTA_CA = 0, 1, 2, 3, 4, 5, 6
E_P, BETA_P = 7, 10                   # [3]
E_H, BETA_H = 13, 19                  # [2, 3] -> + 3j + i
E_C, BETA_C = 25, 31                  # [2, 3]
DELTA_B = 37                          # [2, 3]
E_CA, BETA_CA = 43, 46                # [3]
DELTA_OC = 49                         # [3]
MOD_EQ, MOD_MOVED = 52, 54            # [2]: cycloid profile modification per disc, equidistance Δr_j and
                                      # moved distance ΔR_j (doc 004's normal clearance n(φ) at every pin)
PHI_P, S_P = 56, 59                   # [3]: crank i's phase (clocking: its eccentrics ahead of its planet's teeth,
                                      # rad) and planet i's tooth-thickness deviation on the driving flank (mm):
                                      # an offset of mesh i along its line of action, −r_bp φ_i + (s_i/2) cos α
NERR = 62

# pin_err[3, N_DISC, z_b]: radial position (R_jk), tangential position (AP_jk), normal clearance
# (δ_jk + δ_thjk) of pin k as seen by disc j
PIN_R, PIN_AP, PIN_GAP = 0, 1, 2
# disc_h[N_DISC, 2, NH, 2]: Fourier coefficients (cos, sin) of order n of the disc's radial (0)
# and tangential (1) profile-error fields, functions of the disc-fixed angle
DISC_R, DISC_AP = 0, 1
NH = 5

# kernel status codes (0 = ok); the Model maps them to reasons
ST_OK = 0
ST_MAXITER = 2
ST_LOST_CONTACT = 3
ST_DIVERGED = 4
ST_SINGULAR = 5
ST_NONFINITE = 6
ST_BAD_CLEARANCE = 7       # a sample with a negative bearing clearance: refused by the models before solving
ST_UNRESOLVED = 8

# friction table `fr[nc, NFR]` (see .friction): per contact the kind of its sliding motion, the friction
# coefficient, the arm turning μ·P into a moment (1 for a force), a load-independent normal load P0 (N: a
# bearing's preload) and, for a relative rotation, the two rotation DOFs (b = −1: the ground)
FR_KIND, FR_MU, FR_ARM, FR_P0, FR_A, FR_B = 0, 1, 2, 3, 4, 5
NFR = 6
FR_NONE = 0      # no friction
FR_PIN = 1       # a pin: tangential slip of the disc's contact point (Jacobian from the pin's contact row)
FR_ROTATION = 2  # a bearing: relative rotation of DOF a against DOF b

STATUS_REASONS = {
    ST_MAXITER: "Newton iteration did not converge (equilibrium not found within the iteration limit)",
    ST_LOST_CONTACT: "contact lost everywhere: no pin of either cycloid disc carries load",
    ST_DIVERGED: "solution diverged (a displacement exceeded the model's small-deviation range)",
    ST_SINGULAR: "singular tangent stiffness (a body is free: no contact restrains it)",
    ST_NONFINITE: "non-finite force or displacement in the solver",
    ST_UNRESOLVED: "TE extreme not resolved: intervals of the sweep still admitted a larger extreme after the "
                   "refinement's limit of halvings",
}


def planet(i: int) -> int:
    return PLANET0 + 3 * i


def disc(j: int) -> int:
    return DISC0 + 3 * j


def n_contacts(zb: int) -> int:
    return C_PIN + N_DISC * zb
