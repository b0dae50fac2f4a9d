"""Error factors of doc 000 §1.2 (and the part errors of real reducers) as model inputs.

A factor name either sets one error element, or a *group* with the pattern the
document uses in its sensitivity study (Table 3; magnitude = the factor's
value, usually called e).  Errors that are *set* (eccentricities, clearances,
the profile modification) cannot be given as a group and as an element in one
spec; errors that *add* (per-pin errors, the pin circle, the harmonic fields
of the pin ring and of the discs) can: every factor adds its term, e.g.
``R_pc`` + ``R_pin_h[2]`` + ``R_pin[k]`` (pin-circle radius + ovality +
per-pin residuals).  Phase factors override the default (Table 3) phase of
their element.

Doc 000 errors and the Table 3 patterns:

=================  ==========================================================  ======
name               meaning (doc 000 symbol)                                    unit
=================  ==========================================================  ======
``E_s``            sun base-circle eccentricity E_s (phase ``beta_s``, def. 0)  length
``E_p`` ``E_p[i]`` planet base-circle eccentricity E_pi (``beta_p[i]``, 0)      length
``E_h``            cycloid crank-hole eccentricity E_hji, all six, β_hji =      length
                   60°, 210°, 180° (holes 1–3, both discs); ``E_h[j,i]``,
                   ``beta_h[j,i]`` one hole of one disc (per-disc errors)
``E_c``            crank cam eccentricity error E_cji, all six, β_cji =         length
                   90°, 0°, 270° (disc 1), 270°, 180°, 90° (disc 2);
                   ``E_c[j,i]``, ``beta_c[j,i]``
``E_ca``           carrier crank-hole eccentricity E_cai, β = 60°, 300°, 180°;  length
                   ``E_ca[i]``, ``beta_ca[i]``
``A_s`` ``A_c``    sun / carrier assembly error (``gamma_s``, ``gamma_c``, 0)   length
``R_pin``          pin tooth-space deviation R_jk = e·sin(n θ_k + ``R_pin_phase``)  length
``AP_pin``         pin cumulative pitch deviation AP_jk = e·sin(n θ_k + phase)  length
``R_cyc``          cycloid tooth-space deviation R_djk = e·sin(n θ_d + phase),  length
                   the same field on both discs
``AP_cyc``         cycloid cumulative pitch deviation AP_djk = e·sin(n θ_d + …) length
``R_pin[k]``       radial position error of pin k alone (``AP_pin[k]`` pitch)   length
``delta_pin``      pin diameter error δ_jk as a normal clearance, all pins      length
                   (``delta_pin[k]`` one pin; positive = undersize pin)
``delta_th``       pin radius error δ_thjk, all pins (``delta_th[k]``)          length
``delta_b``        cycloid–crank bearing clearance δ_bji, pattern (e, e, 0)     length
                   disc 1, (e, 0, e) disc 2; ``delta_b[j,i]``
``delta_oc``       crank–carrier bearing clearance (all three; ``delta_oc[i]``) length
``delta_ca``       carrier–housing bearing clearance δ_ca                       length
=================  ==========================================================  ======

Part errors beyond the document (issue 12):

==================================  ===========================================================  ======
name                                meaning                                                      unit
==================================  ===========================================================  ======
``R_pc``                            pin-circle radius error δR: every pin moved radially by the  length
                                    same amount (+ = larger circle, opens); adds to ``R_pin``,
                                    ``R_pin_h[n]``, ``R_pin[k]``
``R_pin_h[n]``, ``R_pin_h_phase[n]``   pin-ring radial pattern of order n (n = 1 … z_b/2),        length,
                                    R_k += a·sin(n θ_k + phase) (phase default 0)                angle
``AP_pin_h[n]``, ``AP_pin_h_phase[n]`` the same for the tangential (pitch) position, + = counter-  length,
                                    clockwise                                                    angle
``R_pin_c[n]``, ``R_pin_s[n]``      the same pattern as Fourier components: R_k += c·cos(n θ_k)  length
                                    + s·sin(n θ_k); ``AP_pin_c[n]``, ``AP_pin_s[n]`` pitch
``R_cyc_h[j,n]``,                   radial profile error of disc j alone, order n of the disc-   length,
``R_cyc_h_phase[j,n]``              fixed angle (n = 1 … NH−1 = 4): R_dj(θ_d) += a·sin(n θ_d +   angle
                                    phase); + = profile point moved radially outward (material
                                    added: closes on the loaded flanks)
``AP_cyc_h[j,n]``,                  tangential (pitch) profile error of disc j, order n, + =     length,
``AP_cyc_h_phase[j,n]``             flank moved counter-clockwise                                angle
``R_cyc_c[j,n]``, ``R_cyc_s[j,n]``  disc j's order-n field as Fourier components c·cos(n θ_d) +  length
                                    s·sin(n θ_d); ``AP_cyc_c[j,n]``, ``AP_cyc_s[j,n]`` pitch
``equidistance_mod``,               cycloid profile modification of disc j (both discs without   length
``equidistance_mod[j]``             the index), equidistance Δr_j, and moved distance ΔR_j in
``moved_distance_mod``,             doc 004's sign: normal clearance at a pin at angle φ from
``moved_distance_mod[j]``           the eccentric n_j(φ) = Δr_j − ΔR_j (1 − K1 cos φ)/√S,
                                    S = 1 − 2 K1 cos φ + K1² (``stiffness.cycloid_contact``);
                                    e.g. −15 / −30 µm give n = 3.61 µm at φ0 = arccos K1 and
                                    15 µm at φ = 0, 180°
``phi_p[i]``, ``phi_p``             crank phase (clocking) of crank i: its eccentrics turned     angle
                                    φ_i counter-clockwise ahead of its planet's teeth (the
                                    planet's timing on the crank's spline); all three without
                                    the index.  Mesh i sees the planet's teeth −r_bp φ_i along
                                    its line of action — the same as both cams of crank i moved
                                    e·φ_i at right angles to the eccentric (E_c[j,i] with
                                    β_c = 90°, to first order)
``s_p[i]``, ``s_p``                 tooth-thickness deviation of planet i on its driving flank   length
                                    (the flank the sun pushes when it drives forward, as in a
                                    TE run; + = thicker): mesh i closes by (s_i/2)·cos α.  The
                                    sun–planet mesh is bilateral (no first-stage backlash), so
                                    this holds for one drive direction only: a torsion curve
                                    (load reversed) must not take it
``crank_support_preload``,          axial preload of crank i's tapered support pair as this unit  force
``crank_support_preload[i]``        was built (shims, end-play reading, run-in: build.toml), N;
                                    without it the design's preload.  Each crank's pair law is
                                    then its own (:meth:`.compliance.ContactChain.crank_law`)
==================================  ===========================================================  ======

Indices are 1-based as in the document (i crank/hole 1–3, j disc 1–2, k pin
1–z_b with pin k at θ_k = 2π(k−1)/z_b, n harmonic order).  The Table 3
pattern harmonic n is 2 unless the model's ``harmonic`` parameter says
otherwise.  The document's separate crank–carrier clearances δ_xi, δ_yi are one
radial clearance ``delta_oc[i]`` here (a rolling bearing's radial clearance is
isotropic).

Frames and signs (what a mapping from drawing tolerances needs):

* θ_d is the disc-fixed angle of a contact point measured from the carrier's x
  axis, the same frame for both discs (the discs turn with the carrier): θ_d =
  absolute angle − θ_c.  Disc 2 meets the pins with the side opposite to disc
  1 (its eccentric is 180° away), so a field of order n on disc 2 acts like the
  same field on disc 1 times (−1)^n: the same odd-order error on both discs
  (e.g. the same profile eccentricity, n = 1) cancels to first order, the same
  even-order error adds (``studies/transmission_error.md`` §7).  If disc 2 is
  disc 1's twin turned by 180° about the reducer axis, its field is disc 1's
  with phase + n·180°; if it is turned over, the field is mirrored.
* A profile eccentricity — disc j's whole profile moved by a vector d against
  its crank holes — is an order-1 radial field plus an order-1 pitch field a
  quarter turn ahead: ``R_cyc_h[j,1] = AP_cyc_h[j,1] = |d|``,
  ``AP_cyc_h_phase[j,1] = R_cyc_h_phase[j,1] + 90°``, d pointing at 90° −
  ``R_cyc_h_phase[j,1]`` from the carrier's x axis.  It is the same as moving
  the three crank holes by −d (``E_h[j,i] = |d|``, ``beta_h[j,i]`` = direction
  of −d − φ_i; a test holds the two equal).  The radial field alone (what a
  radial-runout reading of the profile gives) is not an eccentricity.
* Two stack-ground discs: give each disc its own factors and correlate them in
  the spec (``[[correlation]]``).  The Fourier components ``R_cyc_c``/``_s`` are
  the natural variables for that: independent normal components give a
  Rayleigh amplitude and a uniform phase, and a correlation ρ between the two
  discs' components is the shared part of the grinding error; correlating
  amplitudes and uniform phases instead breaks at the 0/360° wrap.
* Pins are common to both discs (every pin factor acts on both); pin k at
  θ_k = 2π(k−1)/z_b counter-clockwise from the housing's x axis; R + = outward
  (opens), AP + = counter-clockwise, δ + = clearance.  A pin undersize by Δd
  on its diameter opens Δd/2 if held at its centre, Δd if it is pushed into
  its groove (product mapping, data/products/rv80e/mapping.md §1).
* Crank-hole (``E_h``), cam (``E_c``) and carrier-hole (``E_ca``) errors are
  per element already (per disc, per crank).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from . import layout as L

DEG = math.pi / 180.0
TABLE3_BETA_H = ((60.0, 210.0, 180.0), (60.0, 210.0, 180.0))
TABLE3_BETA_C = ((90.0, 0.0, 270.0), (270.0, 180.0, 90.0))
TABLE3_BETA_CA = (60.0, 300.0, 180.0)
TABLE3_DELTA_B = ((1.0, 1.0, 0.0), (1.0, 0.0, 1.0))

#: the factor groups of the document's Table 3 / section 4, in its order
TABLE3_GROUPS = ("R_pin", "AP_pin", "R_cyc", "AP_cyc", "E_c", "delta_b", "E_h", "E_ca", "A_c", "delta_ca",
                 "E_s", "E_p")

_PATTERNS = ("R_pin", "AP_pin", "R_cyc", "AP_cyc")
_SCALARS = {"E_s": L.E_S, "beta_s": L.BETA_S, "A_s": L.A_S, "gamma_s": L.GAMMA_S, "A_c": L.A_C,
            "gamma_c": L.GAMMA_C, "delta_ca": L.DELTA_CA}
# name -> (err offset, shape, is_angle); set (not added): a group and its elements cannot be mixed
_ARRAYS = {"E_p": (L.E_P, (3,), False), "beta_p": (L.BETA_P, (3,), True),
           "E_h": (L.E_H, (2, 3), False), "beta_h": (L.BETA_H, (2, 3), True),
           "E_c": (L.E_C, (2, 3), False), "beta_c": (L.BETA_C, (2, 3), True),
           "E_ca": (L.E_CA, (3,), False), "beta_ca": (L.BETA_CA, (3,), True),
           "delta_b": (L.DELTA_B, (2, 3), False), "delta_oc": (L.DELTA_OC, (3,), False),
           "equidistance_mod": (L.MOD_EQ, (2,), False), "moved_distance_mod": (L.MOD_MOVED, (2,), False),
           "phi_p": (L.PHI_P, (3,), True), "s_p": (L.S_P, (3,), False)}
# per-pin rows of pin_err (added): element [k] one pin; the uniform groups below all pins
_PER_PIN = {"R_pin": L.PIN_R, "AP_pin": L.PIN_AP, "delta_pin": L.PIN_GAP, "delta_th": L.PIN_GAP}
_UNIFORM_PIN = {"R_pc": L.PIN_R, "delta_pin": L.PIN_GAP, "delta_th": L.PIN_GAP}
# harmonic fields (added): name -> (body, field row, form); pins: [n], discs: [j, n]
_HARMONIC = {}
for _pre, _pin_row, _disc_row in (("R", L.PIN_R, L.DISC_R), ("AP", L.PIN_AP, L.DISC_AP)):
    for _suffix, _form in (("_h", "amp"), ("_h_phase", "phase"), ("_c", "cos"), ("_s", "sin")):
        _HARMONIC[f"{_pre}_pin{_suffix}"] = ("pin", _pin_row, _form)
        _HARMONIC[f"{_pre}_cyc{_suffix}"] = ("disc", _disc_row, _form)
#: crank support preloads (N, set): the group sets all three cranks
_PRELOAD = "crank_support_preload"
_ELEMENT = re.compile(r"^([A-Za-z_]+)\[(\d+)(?:,\s*(\d+))?\]$")


@dataclass
class ErrorState:
    """Errors of one reducer in kernel layout (base units)."""

    err: np.ndarray       # [NERR]
    pin_err: np.ndarray   # [3, N_DISC, z_b]
    disc_h: np.ndarray    # [N_DISC, 2, NH, 2]
    preload: np.ndarray = None   # [N_CRANK] crank support preloads (N); NaN: the design's

    def __post_init__(self):
        if self.preload is None:
            self.preload = np.full(L.N_CRANK, np.nan)

    @classmethod
    def zero(cls, z_b: int) -> "ErrorState":
        return cls(np.zeros(L.NERR), np.zeros((3, L.N_DISC, z_b)), np.zeros((L.N_DISC, 2, L.NH, 2)))

    @property
    def own_preload(self) -> bool:
        """True when a crank's support preload is set (not the design's)."""
        return bool(np.any(np.isfinite(self.preload)))


def negative_clearance(st: ErrorState) -> bool:
    """True when a bearing clearance of the error state is negative (the needle rows δ_b, the crank supports
    δ_oc, the main bearing δ_ca): the 20-DOF contacts take clearances ≥ 0 (a preload is a zero clearance)."""
    clear = np.concatenate([st.err[L.DELTA_B:L.DELTA_B + 6], st.err[L.DELTA_OC:L.DELTA_OC + 3],
                            st.err[L.DELTA_CA:L.DELTA_CA + 1]])
    return bool(np.any(clear < 0))


@dataclass(frozen=True)
class _Binding:
    name: str
    base: str            # e.g. "E_c"
    index: tuple         # () for a group / scalar, (j, i) / (i,) / (k,) / (n,) / (j, n) zero-based (n as is)
    unit: str            # base unit: "mm" or "rad"


def _is_phase(base: str) -> bool:
    return base.endswith("_phase")


class ErrorFactors:
    """Maps factor names (the Model's inputs) to an :class:`ErrorState`."""

    def __init__(self, names, z_b: int, harmonic: int = 2):
        if not 1 <= harmonic < L.NH:
            raise InputError(f"harmonic must lie in 1..{L.NH - 1}, got {harmonic}", key="harmonic")
        self.z_b = z_b
        self.harmonic = harmonic
        self.bindings = tuple(self._parse(n) for n in names)
        seen = {}
        for b in self.bindings:
            if b.name in seen:
                raise InputError(f"factor {b.name!r} given twice", key="factor")
            seen[b.name] = b
        groups = {b.base for b in self.bindings if not b.index}
        keys = {(b.base, b.index) for b in self.bindings}
        for b in self.bindings:
            if b.index and b.base in groups and (b.base in _ARRAYS or b.base == _PRELOAD) and \
                    not b.base.startswith(("beta", "gamma")):
                raise InputError(f"factor {b.name!r} and the group factor {b.base!r} set the same error; "
                                 f"give one or the other", key="factor")
            if _is_phase(b.base) and (b.base[:-6], b.index) not in keys:
                amp = b.base[:-6] + ("[" + ",".join(str(v) for v in self._one_based(b)) + "]" if b.index else "")
                raise InputError(f"phase factor {b.name!r} needs its amplitude factor {amp!r}", key="factor")

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(b.name for b in self.bindings)

    @property
    def units(self) -> tuple[str, ...]:
        return tuple(b.unit for b in self.bindings)

    @staticmethod
    def _one_based(b: _Binding) -> tuple:
        if b.base in _HARMONIC:     # the order n is written as is
            return tuple(v + 1 for v in b.index[:-1]) + (b.index[-1],)
        return tuple(v + 1 for v in b.index)

    def _parse(self, name: str) -> _Binding:
        n = name.strip()
        if n in _SCALARS:
            return _Binding(name, n, (), "rad" if n.startswith(("beta", "gamma")) else "mm")
        if n in _ARRAYS:
            if n.startswith("beta"):
                raise InputError(f"phase factor {name!r} needs an index, e.g. {n}[1,2]", key="factor")
            return _Binding(name, n, (), "rad" if _ARRAYS[n][2] else "mm")
        if n in _PATTERNS or n in _UNIFORM_PIN:
            return _Binding(name, n, (), "mm")
        if n == _PRELOAD:
            return _Binding(name, n, (), "N")
        if _is_phase(n) and n[:-6] in _PATTERNS:
            return _Binding(name, n, (), "rad")
        m = _ELEMENT.match(n)
        if m:
            base, a, b = m.group(1), int(m.group(2)), m.group(3)
            if base == _PRELOAD:
                if b is not None or not 1 <= a <= L.N_CRANK:
                    raise InputError(f"bad index in factor {name!r} (expected {base}[i] with i = 1..{L.N_CRANK})",
                                     key="factor")
                return _Binding(name, base, (a - 1,), "N")
            if base in _ARRAYS:
                off, shape, is_angle = _ARRAYS[base]
                ix = (a - 1,) if b is None else (a - 1, int(b) - 1)
                if len(ix) != len(shape) or any(not 0 <= v < s for v, s in zip(ix, shape)):
                    want = {1: "[i] with i = 1..3", 2: "[j,i] with j = 1..2, i = 1..3"}[len(shape)]
                    if shape == (2,):
                        want = "[j] with j = 1..2"
                    raise InputError(f"bad index in factor {name!r} (expected {base}{want})", key="factor")
                return _Binding(name, base, ix, "rad" if is_angle else "mm")
            if base in _PER_PIN and b is None:
                if not 1 <= a <= self.z_b:
                    raise InputError(f"pin index out of range in factor {name!r} (1..{self.z_b})", key="factor")
                return _Binding(name, base, (a - 1,), "mm")
            if base in _HARMONIC:
                body = _HARMONIC[base][0]
                unit = "rad" if _HARMONIC[base][2] == "phase" else "mm"
                if body == "pin":
                    if b is not None or not 1 <= a <= self.z_b // 2:
                        raise InputError(f"bad index in factor {name!r} (expected {base}[n], pattern order "
                                         f"n = 1..{self.z_b // 2})", key="factor")
                    return _Binding(name, base, (a,), unit)
                if b is None or not 1 <= a <= L.N_DISC or not 1 <= int(b) < L.NH:
                    raise InputError(f"bad index in factor {name!r} (expected {base}[j,n] with disc j = 1..2 and "
                                     f"order n = 1..{L.NH - 1})", key="factor")
                return _Binding(name, base, (a - 1, int(b)), unit)
        raise InputError(f"unknown error factor {name!r} for the transmission-error model "
                         f"(see rvtol.models.reducer_20dof.factors)", key="factor")

    # -- building the state ----------------------------------------------------------------
    def state(self, x) -> ErrorState:
        """The error state for one row ``x`` (base units, in the order of ``names``)."""
        s = ErrorState.zero(self.z_b)
        err = s.err
        # default phases: Table 3
        err[L.BETA_H:L.BETA_H + 6] = np.ravel(TABLE3_BETA_H) * DEG
        err[L.BETA_C:L.BETA_C + 6] = np.ravel(TABLE3_BETA_C) * DEG
        err[L.BETA_CA:L.BETA_CA + 3] = np.array(TABLE3_BETA_CA) * DEG
        amp = {}     # (base, index) -> amplitude of a sine pattern; phases below
        phase = {}
        th = 2.0 * np.pi * np.arange(self.z_b) / self.z_b
        for b, v in zip(self.bindings, np.asarray(x, dtype=float)):
            base = b.base
            if base == _PRELOAD:
                if not (math.isfinite(v) and v >= 0):
                    raise InputError(f"factor {b.name!r}: a preload must be >= 0 N, got {v!r}", key="factor")
                s.preload[b.index[0] if b.index else slice(None)] = v
            elif base in _SCALARS:
                err[_SCALARS[base]] = v
            elif base in _ARRAYS:
                off, shape, _ = _ARRAYS[base]
                if b.index:
                    err[off + int(np.ravel_multi_index(b.index, shape))] = v
                elif base == "delta_b":
                    err[off:off + 6] = v * np.ravel(TABLE3_DELTA_B)
                else:
                    err[off:off + int(np.prod(shape))] = v
            elif _is_phase(base):
                phase[base[:-6], b.index] = v
            elif base in _PATTERNS and not b.index:
                amp[base, ()] = v
            elif base in _HARMONIC:
                body, row, form = _HARMONIC[base]
                if form == "amp":
                    amp[base, b.index] = v
                else:
                    self._add_harmonic(s, body, row, b.index, v * (form == "cos"), v * (form == "sin"), th)
            elif b.index:    # one pin
                s.pin_err[_PER_PIN[base], :, b.index[0]] += v
            else:            # every pin alike
                s.pin_err[_UNIFORM_PIN[base]] += v
        for (base, index), v in amp.items():
            ph = phase.get((base, index), 0.0)
            if base in _PATTERNS:          # Table 3: the pin ring / both discs alike, order = self.harmonic
                n = self.harmonic
                if base in ("R_pin", "AP_pin"):
                    s.pin_err[_PER_PIN[base]] += v * np.sin(n * th + ph)
                else:
                    f = L.DISC_R if base == "R_cyc" else L.DISC_AP
                    for j in range(L.N_DISC):
                        self._add_harmonic(s, "disc", f, (j, n), v * math.sin(ph), v * math.cos(ph), th)
                continue
            body, row, _ = _HARMONIC[base]
            if body == "pin":
                s.pin_err[row] += v * np.sin(index[0] * th + ph)
            else:   # v sin(nθ + ph) = v sin(ph) cos(nθ) + v cos(ph) sin(nθ)
                self._add_harmonic(s, body, row, index, v * math.sin(ph), v * math.cos(ph), th)
        return s

    @staticmethod
    def _add_harmonic(s: ErrorState, body: str, row: int, index: tuple, c: float, si: float, th) -> None:
        """Add c·cos(nθ) + si·sin(nθ): to every pin (θ = θ_k, both discs) or to disc j's field (θ = θ_d)."""
        if body == "pin":
            (n,) = index
            s.pin_err[row] += c * np.cos(n * th) + si * np.sin(n * th)
        else:
            j, n = index
            s.disc_h[j, row, n, 0] += c
            s.disc_h[j, row, n, 1] += si
