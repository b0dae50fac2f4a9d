"""Error factors of doc 000 §1.2 as model inputs, with the patterns of Table 3.

A factor name either sets one error element or a *group* with the pattern the
document uses in its sensitivity study (Table 3; magnitude = the factor's
value, usually called e).  Group and element names of the same error cannot
be mixed in one spec; phase factors override the default (Table 3) phase of
their element.

=================  ==========================================================  ======
name               meaning (doc 000 symbol)                                    unit
=================  ==========================================================  ======
``E_s``            sun base-circle eccentricity E_s (phase ``beta_s``, def. 0)  length
``E_p`` ``E_p[i]`` planet base-circle eccentricity E_pi (``beta_p[i]``, 0)      length
``E_h``            cycloid crank-hole eccentricity E_hji, all six, β_hji =      length
                   60°, 210°, 180° (holes 1–3, both discs); ``E_h[j,i]``,
                   ``beta_h[j,i]``
``E_c``            crank cam eccentricity error E_cji, all six, β_cji =         length
                   90°, 0°, 270° (disc 1), 270°, 180°, 90° (disc 2);
                   ``E_c[j,i]``, ``beta_c[j,i]``
``E_ca``           carrier crank-hole eccentricity E_cai, β = 60°, 300°, 180°;  length
                   ``E_ca[i]``, ``beta_ca[i]``
``A_s`` ``A_c``    sun / carrier assembly error (``gamma_s``, ``gamma_c``, 0)   length
``R_pin``          pin tooth-space deviation R_jk = e·sin(n θ_k + ``R_pin_phase``)  length
``AP_pin``         pin cumulative pitch deviation AP_jk = e·sin(n θ_k + phase)  length
``R_cyc``          cycloid tooth-space deviation R_djk = e·sin(n θ_d + phase)   length
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

Indices are 1-based as in the document (i crank/hole 1–3, j disc 1–2, k pin
1–z_b with pin k at θ_k = 2π(k−1)/z_b).  The pattern harmonic n is 2 (Table 3)
unless the model's ``harmonic`` parameter says otherwise; θ_d is the
disc-fixed angle of the contact point.  The document's separate crank–carrier
clearances δ_xi, δ_yi are one radial clearance ``delta_oc[i]`` here (a rolling
bearing's radial clearance is isotropic).
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
# name -> (err offset, shape, is_angle)
_ARRAYS = {"E_p": (L.E_P, (3,), False), "beta_p": (L.BETA_P, (3,), True),
           "E_h": (L.E_H, (2, 3), False), "beta_h": (L.BETA_H, (2, 3), True),
           "E_c": (L.E_C, (2, 3), False), "beta_c": (L.BETA_C, (2, 3), True),
           "E_ca": (L.E_CA, (3,), False), "beta_ca": (L.BETA_CA, (3,), True),
           "delta_b": (L.DELTA_B, (2, 3), False), "delta_oc": (L.DELTA_OC, (3,), False)}
_PER_PIN = {"R_pin": L.PIN_R, "AP_pin": L.PIN_AP, "delta_pin": L.PIN_GAP, "delta_th": L.PIN_GAP}
_ELEMENT = re.compile(r"^([A-Za-z_]+)\[(\d+)(?:,\s*(\d+))?\]$")


@dataclass
class ErrorState:
    """Errors of one reducer in kernel layout (base units)."""

    err: np.ndarray       # [NERR]
    pin_err: np.ndarray   # [3, N_DISC, z_b]
    disc_h: np.ndarray    # [N_DISC, 2, NH, 2]

    @classmethod
    def zero(cls, z_b: int) -> "ErrorState":
        return cls(np.zeros(L.NERR), np.zeros((3, L.N_DISC, z_b)), np.zeros((L.N_DISC, 2, L.NH, 2)))


@dataclass(frozen=True)
class _Binding:
    name: str
    base: str            # e.g. "E_c"
    index: tuple         # () for a group / scalar, (j, i) / (i,) / (k,) zero-based
    unit: str            # base unit: "mm" or "rad"


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
        for b in self.bindings:
            if b.index and b.base in groups and not b.base.startswith(("beta", "gamma")):
                raise InputError(f"factor {b.name!r} and the group factor {b.base!r} set the same error; "
                                 f"give one or the other", key="factor")
            if b.base.endswith("_phase") and b.base[:-6] not in groups:
                raise InputError(f"phase factor {b.name!r} needs its amplitude factor {b.base[:-6]!r}",
                                 key="factor")

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(b.name for b in self.bindings)

    @property
    def units(self) -> tuple[str, ...]:
        return tuple(b.unit for b in self.bindings)

    def _parse(self, name: str) -> _Binding:
        n = name.strip()
        if n in _SCALARS:
            return _Binding(name, n, (), "rad" if n.startswith(("beta", "gamma")) else "mm")
        if n in _ARRAYS:
            if _ARRAYS[n][2]:
                raise InputError(f"phase factor {name!r} needs an index, e.g. {n}[1,2]", key="factor")
            return _Binding(name, n, (), "mm")
        if n in _PATTERNS or n in ("delta_pin", "delta_th"):
            return _Binding(name, n, (), "mm")
        if n.endswith("_phase") and n[:-6] in _PATTERNS:
            return _Binding(name, n, (), "rad")
        m = _ELEMENT.match(n)
        if m:
            base, a, b = m.group(1), int(m.group(2)), m.group(3)
            if base in _ARRAYS:
                off, shape, is_angle = _ARRAYS[base]
                ix = (a - 1,) if b is None else (a - 1, int(b) - 1)
                if len(ix) != len(shape) or any(not 0 <= v < s for v, s in zip(ix, shape)):
                    want = "[i] with i = 1..3" if len(shape) == 1 else "[j,i] with j = 1..2, i = 1..3"
                    raise InputError(f"bad index in factor {name!r} (expected {base}{want})", key="factor")
                return _Binding(name, base, ix, "rad" if is_angle else "mm")
            if base in _PER_PIN and b is None:
                if not 1 <= a <= self.z_b:
                    raise InputError(f"pin index out of range in factor {name!r} (1..{self.z_b})", key="factor")
                return _Binding(name, base, (a - 1,), "mm")
        raise InputError(f"unknown error factor {name!r} for the transmission-error model "
                         f"(see rvtol.models.transmission.factors)", key="factor")

    # -- building the state ----------------------------------------------------------------
    def state(self, x) -> ErrorState:
        """The error state for one row ``x`` (base units, in the order of ``names``)."""
        s = ErrorState.zero(self.z_b)
        err = s.err
        # default phases: Table 3
        err[L.BETA_H:L.BETA_H + 6] = np.ravel(TABLE3_BETA_H) * DEG
        err[L.BETA_C:L.BETA_C + 6] = np.ravel(TABLE3_BETA_C) * DEG
        err[L.BETA_CA:L.BETA_CA + 3] = np.array(TABLE3_BETA_CA) * DEG
        amp = {}
        phase = {}
        for b, v in zip(self.bindings, np.asarray(x, dtype=float)):
            base = b.base
            if base in _SCALARS:
                err[_SCALARS[base]] = v
            elif base in _ARRAYS:
                off, shape, _ = _ARRAYS[base]
                if b.index:
                    err[off + int(np.ravel_multi_index(b.index, shape))] = v
                elif base == "delta_b":
                    err[off:off + 6] = v * np.ravel(TABLE3_DELTA_B)
                else:
                    err[off:off + int(np.prod(shape))] = v
            elif base in _PATTERNS and not b.index:
                amp[base] = v
            elif base.endswith("_phase"):
                phase[base[:-6]] = v
            else:  # per-pin arrays, all pins or one
                row = _PER_PIN[base]
                if b.index:
                    s.pin_err[row, :, b.index[0]] += v
                else:
                    s.pin_err[row] += v
        n = self.harmonic
        th = 2.0 * np.pi * np.arange(self.z_b) / self.z_b
        for base, v in amp.items():
            ph = phase.get(base, 0.0)
            if base in ("R_pin", "AP_pin"):
                s.pin_err[_PER_PIN[base]] += v * np.sin(n * th + ph)
            else:   # v sin(nθ + ph) = v sin(ph) cos(nθ) + v cos(ph) sin(nθ)
                f = L.DISC_R if base == "R_cyc" else L.DISC_AP
                s.disc_h[:, f, n, 0] = v * math.sin(ph)
                s.disc_h[:, f, n, 1] = v * math.cos(ph)
        return s
