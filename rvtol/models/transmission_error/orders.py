"""Which error families produce which orders of the transmission-error spectrum.

Orders are per output revolution (the carrier angle θ_c).  Over one output
revolution the bodies turn, absolutely: housing 0, carrier and discs 1,
cranks and their eccentrics 1 − z_b = −z_c, sun i (doc 000's nominal motion,
:mod:`rvtol.models.reducer_20dof.geometry`).  Two exact symmetries of the 20-DOF model fix the orders
(a shift of θ_c that maps the reducer onto itself leaves the TE unchanged):

* **carrier side** — errors of the discs, cranks, planets and carrier, with a
  perfect pin ring: after Δθ_c = 2π/z_b the eccentric has turned −z_c·2π/z_b
  = +2π/z_b (mod 2π), i.e. everything has turned rigidly by one pin pitch,
  and the pin ring looks the same.  The TE is periodic in 2π/z_b: **only
  multiples of z_b** (the sun too when its turns relative to the carrier per
  2π/z_b, z_p/z_s, are whole: multiples of gcd(z_b, i − 1));
* **housing side** — errors of the pin ring and housing-fixed offsets (A_c,
  A_s), with a perfect carrier side (three identical cranks, discs symmetric
  under 120°): the TE is a function of the eccentric's angle −z_c θ_c and of
  the carrier angle modulo 2π/3, so its orders are **|a·z_c − 3b|** — for
  the RV-80E (z_c = 39 = 13·3) the multiples of 3;
* errors that keep both symmetries (pin-circle radius, uniform pin clearance,
  profile modification, identical crank patterns on all three cranks, the
  carrier–housing clearance) show only at common multiples: lcm(z_b, 3) =
  120 for the RV-80E, the strongest at the mesh order Z = z_b·z_c.

Which members of a lattice are strong follows from the relative rotation of the
error's body and the mesh (the loaded pins sit near φ0 = arccos K1 from the
eccentric): an order-n pattern fixed in the housing meets the mesh at n·z_c, one
fixed in a disc at n·z_b; crank-fixed errors act through the carrier-fixed crank
holes at z_b; the sun through three planets at 3(i − 1); the ±3b sidebands of the
housing side come from the three cranks turning once relative to the housing.
Disc 2 meets the pins with the side opposite to disc 1 (eccentrics 180° apart),
so it sees an order-n pattern shifted by n·180°: an error common to both discs
(the pin ring, a carrier bore, the same field on both discs) cancels at odd n
to first order and shows at 2n (a single pin: 2·z_c; A_c: 2·z_c; E_ca: 2·z_b).

Errors of both sides together break both symmetries; their products in the
nonlinear contacts give sums and differences of the families' orders, e.g.
order z_b − z_c = 1 from a housing-fixed error with a disc- or crank-fixed one.

**Crank phase and order 3.**  A crank's phase (its planet's clocking on the
crank, a planet's tooth thickness: ``phi_p[i]``, ``s_p[i]``) turns with the
crank: a carrier-side error, multiples of z_b only — it cannot give order 3.
To first order it is both cams of the crank moved e·φ at right angles to the
eccentric; the two discs' compromise rotations ±e·φ·cos(z_b θ_c)/(3a') cancel,
so one crank's phase shows at 2·z_b; a phase common to the three cranks only
shifts the TE by the kinematic angle −φ z_p/(z_s i).  Order 3 is a housing-side
order: the three cranks passing a housing-fixed error (carrier offset A_c,
pin-ring patterns); the input orders i and 2·i come from the input shaft's turn
against the housing (a sun-support offset A_s; a test rig's input encoder).
A spectrum of N positions per revolution shows an order t > N/2 aliased at
|t − N·round(t/N)| (off the lattice unless N is a multiple of its step).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ...errors import InputError
from ..reducer_20dof import layout as L
from ..reducer_20dof.geometry import RVGeometry
from ..reducer_20dof.quasistatic import MIN_PER_CRANK_REV


@dataclass(frozen=True)
class Family:
    """An error family: which symmetry its errors break (``side``) and where its strongest orders are."""

    key: str
    short: str
    label: str
    side: str        # "housing", "carrier", "sun" or "uniform" (see the module doc)
    strongest: str


FAMILIES = {f.key: f for f in (
    Family("pin_ring", "pin ring", "pin ring (housing-fixed: pin positions, diameters, pin-ring patterns)", "housing",
           "n·z_c for an even pattern order n, 2n·z_c for an odd one; a single pin: 2·z_c, 4·z_c, …"),
    Family("carrier_offset", "carrier offset", "carrier axis offset in the housing (A_c)", "housing",
           "2·z_c (an order-1 housing pattern, common to both discs), 3"),
    Family("input_support", "sun support", "sun support offset (A_s, housing-fixed)", "housing",
           "i (the sun's rotation), 3"),
    Family("disc_profile", "disc profile", "disc profile and pitch (disc-fixed)", "carrier",
           "n·z_b on one disc; the same field on both discs: n·z_b for even n, 2n·z_b for odd n"),
    Family("disc_holes", "disc holes", "disc crank holes (disc-fixed)", "carrier", "z_b"),
    Family("crank", "cranks", "cranks: cams, planets, needle and crank-bearing clearances (crank-fixed)", "carrier",
           "z_b (3·z_b for a pattern identical on all three cranks)"),
    Family("crank_phase", "crank phase",
           "crank phase: a planet's clocking on its crank and its tooth thickness (crank-fixed)", "carrier",
           "z_b, 2·z_b; a phase common to the three cranks only shifts the mean (and 3·z_b)"),
    Family("carrier_bores", "carrier bores", "carrier crank bores (carrier-fixed)", "carrier",
           "2·z_b (a bore moves the crank under both discs alike)"),
    Family("sun", "sun", "sun eccentricity (sun-fixed)", "sun", "3(i − 1): three planets on a floating sun"),
    Family("uniform", "uniform",
           "uniform (pin circle, uniform pin clearance, profile modification, carrier–housing clearance)", "uniform",
           "Z = z_b·z_c; changes the mean and the nominal ripple"),
    Family("nominal", "nominal", "nominal reducer (no error)", "uniform", "Z (below 0.001 arcsec for the RV-80E)"),
)}

#: factor base name -> family key (phase and direction factors have none: they act through their amplitude)
FAMILY_OF = {
    **dict.fromkeys(("R_pin", "AP_pin", "R_pin_h", "AP_pin_h", "R_pin_c", "R_pin_s", "AP_pin_c", "AP_pin_s"),
                    "pin_ring"),
    "A_c": "carrier_offset",
    "A_s": "input_support",
    **dict.fromkeys(("R_pc", "equidistance_mod", "moved_distance_mod", "delta_ca"), "uniform"),
    **dict.fromkeys(("R_cyc", "AP_cyc", "R_cyc_h", "AP_cyc_h", "R_cyc_c", "R_cyc_s", "AP_cyc_c", "AP_cyc_s"),
                    "disc_profile"),
    "E_h": "disc_holes",
    **dict.fromkeys(("E_c", "E_p", "delta_b", "delta_oc"), "crank"),
    **dict.fromkeys(("phi_p", "s_p"), "crank_phase"),
    "E_ca": "carrier_bores",
    "E_s": "sun",
}


def family_of(binding) -> str | None:
    """The family key of a factor binding (:class:`rvtol.models.reducer_20dof.factors.ErrorFactors`), or None
    (phases, directions).

    ``delta_pin``/``delta_th`` belong to the pin ring with an index (one pin) and are uniform without.
    """
    if binding.base in ("delta_pin", "delta_th"):
        return "pin_ring" if binding.index else "uniform"
    return FAMILY_OF.get(binding.base)


def order_spectrum(te: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(orders, amplitude)`` of a signal sampled uniformly over one output revolution.

    Amplitude of order k ≥ 1 is 2|X_k|/N (a sinusoid of amplitude A gives A);
    order 0 is the mean.
    """
    n = te.size
    X = np.fft.rfft(te)
    amp = np.abs(X) / n
    amp[1:] *= 2.0
    if n % 2 == 0:
        amp[-1] /= 2.0
    return np.arange(amp.size), amp


def positions_for_order(max_order: int, z_b: int) -> int:
    """Positions per crank revolution that resolve the order spectrum up to ``max_order`` (orders per
    output revolution): the fewest ``p ≥ MIN_PER_CRANK_REV`` with ``N = p·z_b > 2·max_order`` samples per
    output revolution (Nyquist: order k is its own alias only below N/2).

    The orders up to ``max_order`` are then free of their own aliases, not of the curve's content
    above N/2, which folds onto them (the TE of a reducer with clearances has kinks where contacts
    change, and a spectrum that decays slowly): subsampling a finer sweep by an integer factor gives
    exactly the fine spectrum summed over each alias set — what
    ``tests/models/transmission_error/test_transmission_resolution.py`` checks.  The positions' own peak-to-peak reads
    lower the fewer they are; the model's Δθ_er is the curve's, refined between them (:mod:`.extremes`).
    """
    if max_order < 1:
        raise InputError(f"max_order must be >= 1, got {max_order}", key="max_order")
    return max(MIN_PER_CRANK_REV, (2 * max_order) // z_b + 1)


def alias(t: int, n_positions: int) -> int:
    """Where order ``t`` shows in the spectrum of ``n_positions`` samples per revolution."""
    return abs(t - n_positions * round(t / n_positions))


def _sun_turns(g: RVGeometry) -> int | None:
    """Turns of the sun relative to the carrier per output revolution, i − 1, if whole."""
    t = g.ratio - 1.0
    return int(round(t)) if abs(t - round(t)) < 1e-9 else None


def lattice_step(g: RVGeometry, side: str) -> int:
    """The orders of a family are the multiples of this step (module doc)."""
    housing = math.gcd(g.z_c, L.N_CRANK)
    if side == "housing":
        return housing
    if side == "carrier":
        return g.z_b
    if side == "sun":
        turns = _sun_turns(g)
        return math.gcd(g.z_b, turns) if turns else 1
    return g.z_b * housing // math.gcd(g.z_b, housing)      # uniform: both symmetries


def _input_multiple(g: RVGeometry, t: int) -> int | None:
    """k where order ``t`` is k·i, the input shaft's k-th harmonic (a whole ratio), else None."""
    i = int(round(g.ratio))
    return t // i if abs(g.ratio - i) < 1e-9 and t % i == 0 else None


def _how(g: RVGeometry, side: str, t: int, key: str | None = None) -> str:
    """The simplest way to write order ``t`` from the family's base orders (the input support's: the input
    shaft's turns, k·i)."""
    if key == "input_support" and _input_multiple(g, t):
        k = _input_multiple(g, t)
        return "i" if k == 1 else f"{k}·i"
    Z = g.z_b * g.z_c
    if side == "housing":          # t = a·z_c ± 3b, smallest |b|
        best = min(((abs(t - a * g.z_c), a) for a in range(t // g.z_c + 2)
                    if abs(t - a * g.z_c) % L.N_CRANK == 0), default=None)
        if best is None:
            return str(t)
        r, a = best
        head = "" if a == 0 else ("z_c" if a == 1 else f"{a}·z_c")
        if r == 0:
            return head
        sign = "+" if t > a * g.z_c else "−"
        return f"{head} {sign} {r}" if head else str(r)
    if side == "sun":
        turns = _sun_turns(g)
        if turns and t % turns == 0:
            return "i − 1" if t == turns else f"{t // turns}·(i − 1)"
    if side == "uniform" and t % Z == 0:
        return "Z" if t == Z else f"{t // Z}·Z"
    if t % g.z_b == 0:
        return "z_b" if t == g.z_b else f"{t // g.z_b}·z_b"
    return str(t)


def expected_orders(g: RVGeometry, key: str, n_positions: int) -> dict[int, str]:
    """Resolved orders (1 … N/2) of the family ``key``, each with how it arises.

    The multiples of :func:`lattice_step` up to Z + N, aliased into the resolved band of N =
    ``n_positions`` samples per revolution: a resolved order is named as such, plus "or Z aliased"
    where the mesh order Z (or 2Z) lands on it; an order reached only by aliasing says from where.
    """
    side = FAMILIES[key].side
    step = lattice_step(g, side)
    half = n_positions // 2
    Z = g.z_b * g.z_c
    out: dict[int, str] = {}
    for t in range(step, Z + n_positions + 1, step):
        k = alias(t, n_positions)
        if 1 <= k <= half and k not in out:
            out[k] = _how(g, side, t, key) + (f" aliased from {t}" if t > half else "")
    for m in (1, 2):
        k = alias(m * Z, n_positions)
        if m * Z > half and (m * Z) % step == 0 and k in out and "aliased" not in out[k]:
            out[k] += f" or {'' if m == 1 else '2·'}Z aliased from {m * Z}"
    return out


def _side_bases(g: RVGeometry) -> dict[str, tuple[tuple[int, str], ...]]:
    """Base orders of each side whose sums and differences give the interactions of two sides."""
    sun = lattice_step(g, "sun")
    return {"housing": ((g.z_c, "z_c"), (L.N_CRANK, str(L.N_CRANK))), "carrier": ((g.z_b, "z_b"),),
            "sun": ((sun, str(sun)),)}


def _interaction_side(g: RVGeometry, key: str) -> str | None:
    side = FAMILIES[key].side
    if side == "uniform":
        return None
    if side == "sun" and lattice_step(g, "sun") % g.z_b == 0:
        return "carrier"           # its orders are multiples of z_b: it mixes like the carrier side
    return side


def _combination(p: int, a: str, sign: str, q: int, b: str) -> str:
    return f"{'' if p == 1 else f'{p}·'}{a} {sign} {'' if q == 1 else f'{q}·'}{b}"


def active_families(bindings, values) -> dict[str, list[str]]:
    """``{family: [factor names]}`` of the factors that are non-zero in ``values`` (plus the nominal ripple)."""
    out: dict[str, list[str]] = {"nominal": []}
    for b, v in zip(bindings, values):
        fam = family_of(b)
        if fam is not None and v != 0.0:
            out.setdefault(fam, []).append(b.name)
    return out


def measurement_orders(measurement, g: RVGeometry, n_positions: int) -> dict[int, str]:
    """The orders a test rig's measurement chain adds (rows ``(n, a, b)`` of :mod:`.rig`), each with what
    makes it: order 1 the output encoder's graduation turning eccentric about the carrier's axis (the rig's
    centring; a ring centred by its fit on the pilot adds the pilot and the main-bearing runout, :mod:`.rig`),
    order i the input encoder's divided by the ratio."""
    out: dict[int, str] = {}
    for n, a, b in np.asarray(measurement, dtype=float).reshape(-1, 3):
        if a == 0.0 and b == 0.0:
            continue
        k = alias(int(round(n)), n_positions)
        if round(n) == 1:
            out[k] = "rig: output encoder eccentricity about the rotation axis (its centring), 1"
        else:
            out[k] = f"rig: input encoder eccentricity ÷ ratio, i = {g.ratio:g}" + (
                f" aliased from {int(round(n))}" if k != round(n) else "")
    return out


def order_sources(g: RVGeometry, o: int) -> str:
    """What can give order ``o`` at all in the 20-DOF model (the lattices of the module doc), for an order an
    order table is asked to list that no active error explains."""
    out = []
    if o % lattice_step(g, "carrier") == 0:
        out.append("carrier-side errors (discs, cranks, crank phase, carrier bores)")
    if o % lattice_step(g, "housing") == 0:
        out.append("the three cranks passing housing-fixed errors (carrier offset A_c, pin-ring patterns)"
                   if o == L.N_CRANK else "housing-fixed errors (pin ring, carrier offset A_c)")
    k = _input_multiple(g, o)
    if k in (1, 2):
        out.append(f"the input shaft's {'once' if k == 1 else 'twice'}-per-turn: a sun-support offset A_s (housing-"
                   "fixed)" + (", a test rig's input encoder eccentricity" if k == 1 else
                               "; a rig's input coupling or encoder ovality (not modelled)"))
    if not out:
        out.append("only beats of errors of two sides (e.g. z_b − z_c = 1)")
    return "; ".join(out)


def order_table(te: np.ndarray, g: RVGeometry, bindings, values, top: int = 12, min_fraction: float = 0.01,
                interactions: int = 4, measurement=None, orders=()) -> pd.DataFrame:
    """The largest orders of a TE curve (uniform over one output revolution) with the families expected there.

    Rows: the ``top`` largest orders ≥ ``min_fraction`` × the largest.  ``expected from``: the active
    families (non-zero factors) whose orders (:func:`expected_orders`) contain it, with how (e.g.
    "pin ring: 2·z_c"), or the nominal ripple where none does; ``interaction`` (for orders no family
    explains alone): active families of two sides (housing: base orders z_c, 3; carrier: z_b) and the
    simplest p·b1 ± q·b2 (p, q ≤ ``interactions``) equal to it — e.g. order 1 = z_b − z_c from a
    housing-fixed and a disc-fixed error.  ``measurement``: the rows of a test rig's measurement chain when ``te``
    is the TE the rig reads (:func:`measurement_orders`: order 1 and order i).  ``orders``: orders listed
    whatever their size (e.g. 3 and the input orders i, 2·i, which a measured spectrum shows), after the largest;
    one no active error explains says what could give it (:func:`order_sources`).
    """
    k, a = order_spectrum(np.asarray(te, dtype=float))
    n_pos = np.asarray(te).size
    rig = measurement_orders(measurement, g, n_pos) if measurement is not None else {}
    fams = active_families(bindings, values)
    expected = {f: expected_orders(g, f, n_pos) for f in fams}
    sides: dict[str, list[str]] = {}
    for f in fams:
        side = _interaction_side(g, f)
        if side and f != "nominal":
            sides.setdefault(side, []).append(_short(f))
    bases = _side_bases(g)
    amp = a[1:]
    biggest = amp.max() if amp.size else 0.0
    rows = []
    largest = [int(o) for o in np.argsort(amp)[::-1][:top] + 1 if biggest > 0 and a[o] >= min_fraction * biggest]
    asked = [int(o) for o in orders if 1 <= int(o) < a.size and int(o) not in largest]
    for o in largest + asked:
        hits = [f"{_label(f, fams[f])}: {expected[f][o]}" for f in fams if f != "nominal" and o in expected[f]]
        if o in rig:
            hits.insert(0, rig[o])
        if not hits and o in expected["nominal"]:
            hits = [f"{_short('nominal')}: {expected['nominal'][o]}"]
        pairs = []
        names = list(sides)
        for x, s1 in enumerate(names if not hits else []):
            for s2 in names[x + 1:]:
                combos = sorted((p + q, _combination(p, n1, sgn, q, n2))
                                for b1, n1 in bases[s1] for b2, n2 in bases[s2]
                                for p in range(1, interactions + 1) for q in range(1, interactions + 1)
                                for sgn in ("+", "−") if abs(p * b1 + (q if sgn == "+" else -q) * b2) == o)
                if combos:
                    pairs.append(f"{', '.join(sides[s1])} × {', '.join(sides[s2])}: {combos[0][1]}")
        shown = "; ".join(hits) if hits else "—"
        if o in asked and not hits and not pairs:
            shown = f"— (no active error; could arise from: {order_sources(g, o)})"
        rows.append({"order [1/rev]": int(o), "amplitude [arcsec]": float(a[o]),
                     "of largest [%]": 100.0 * float(a[o] / biggest) if biggest > 0 else float("nan"),
                     "expected from": shown,
                     "interaction": "; ".join(pairs) if pairs else "—"})
    return pd.DataFrame(rows, columns=["order [1/rev]", "amplitude [arcsec]", "of largest [%]", "expected from",
                                       "interaction"])


def _short(key: str) -> str:
    return FAMILIES[key].short


def _label(key: str, names: list[str]) -> str:
    if not names:
        return _short(key)
    return f"{_short(key)} [" + ", ".join(names[:3]) + (f" +{len(names) - 3}" if len(names) > 3 else "") + "]"


def families_frame(g: RVGeometry) -> pd.DataFrame:
    """The families with their factors, the step of their orders and the strongest orders (reports, notes)."""
    rows = []
    for key, fam in FAMILIES.items():
        factors = sorted(b for b, f in FAMILY_OF.items() if f == key)
        if key == "pin_ring":
            factors += ["R_pin[k]", "AP_pin[k]", "delta_pin[k]", "delta_th[k]"]
        if key == "uniform":
            factors += ["delta_pin", "delta_th"]
        rows.append({"family": fam.label, "factors": ", ".join(factors) or "—",
                     "orders: multiples of": lattice_step(g, fam.side), "strongest": fam.strongest})
    return pd.DataFrame(rows)
