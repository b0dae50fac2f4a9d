"""Drawing tolerance notation → limits and a factor table the spec loader understands.

:func:`parse_tolerance` reads what an engineer copies off a drawing::

    ±0.05            +0.10/-0.00        +0.10 -0.05        0/-0.02          (deviations)
    5%               ±2 %               +5%/-2%                              (of the nominal)
    24.95..25.05     24.95 to 25.05     max 0.02           ≤ 0.02           (limits)
    25 H7            Ø7 h5              25 H7/g6                             (ISO 286 class, fit)
    ⌀0.05            Ø0.1 mm                                                 (a circular position zone)
    25 ±0.05 Cp 1.33                    25 ±0.05 Cpk 1.33 k 0.25            (process)
    1.000" ±0.002"   1 in +0.002/-0.001   25 mm +10/-5 um                   (units)
    50 H7 (+0.025/0)                    Ø50 H7 (+0.025/0)                   (class with its deviations)
    ⌀0.4 (M)         ⌀0.4 Ⓜ             ⌀0.4 MMC         ⌀0.4 (L)          (zone at MMC / LMC)
    50 ISO 2768-m    120 ISO 2768-mK                                        (general tolerance)
    30 deg ISO 2768-m (with shorter_side)   2 ISO 2768-m (with broken_edge)  (ISO 2768-1 Tables 3, 2)

Grammar (case-sensitive where ISO 286 is: ``H7`` is a hole, ``h7`` a shaft)::

    text      := [Ø] [nominal [unit]] body [unit] {process}
               | Ø x [unit]                        a circular position zone of diameter x
    body      := "±" x ["%"]                      symmetric deviations
               | d ["%"] [unit] ["/"] d ["%"]      two signed deviations (either order; a
                                                   deviation without a sign must be 0)
               | x "%"                             ±x % of the nominal
               | a [unit] (".." | "to") b          limits of size
               | ("max" | "≤" | "<=") x            a magnitude: limits 0 … x (runout, position)
               | class ["/" class]                 ISO 286 class (nominal needed) or fit
    process   := ("Cp" | "Cpk" | "k") ["=" | "≥" | ">=" | ":"] number

A unit or ``%`` written once after the second deviation applies to both (``+10/-5 um``,
``+5/-2 %``); a ``%`` on one deviation only (``+5 %/-2``) is refused, and so is a second unit
where the grammar has one (``25 ±0.1 um mm``).  Unicode minus signs and dashes, ``+/-``, ``+-``
and decimal commas are accepted; ``"`` is the
inch, ``in``, ``inch``, ``thou`` and every unit of :mod:`rvtol.units` are known.  Exponents
are not (``25e8`` is the ISO class e8 on 25 mm, not 2.5·10⁹).

Process specifications.  ``Cp`` fixes the process spread σ = T / (6·Cp) inside the drawing's
band T; ``k`` is the mean shift as a fraction of the half band (ISO 22514 / the usual
k = |μ − m| / (T/2); signed here: positive toward the upper limit), so Cpk = Cp·(1 − |k|).
Any two of Cp, Cpk, k fix the third (Cpk alone: a centred process, Cp = Cpk; Cp with Cpk:
k = 1 − Cpk/Cp, shifted upward).  **The drawing's limits stay the worst-case limits**: the
process spec only says where the parts fall inside them.  The factor table it produces is a
normal with ``tolerance`` = the drawing band, ``sigma_level`` = 3·Cp (so σ = T/(6·Cp) and the
distribution's ``tolerance`` is still the drawing's T) and ``shift`` = k·T/2.

Position zones.  ``⌀0.05`` (a diameter sign and one unsigned number) is a circular position zone of
diameter t: the feature's axis lies within t/2 of its true position.  It describes one coordinate
of the zone (a factor pair x, y shares it, :mod:`rvtol.spec`), with limits ∓t/2; read as a normal
each coordinate has σ = (t/2)/√(−2 ln(1 − c)) so that the radial deviation √(x² + y²), a Rayleigh,
stays inside the zone with the coverage c of ±``sigma_level``·σ (99.73 % at 3: σ = t/2/3.4393).

A class written with its deviations (``50 H7 (+0.025/0)``, as drawings print it) must agree with the
standard's table to 0.5 µm, else it is refused: one of the two is mistyped.  ``ISO 2768-m`` (f, m, c,
v; a trailing geometric class H/K/L is accepted and ignored here) gives the general tolerance of the
nominal, ±(ISO 2768-1 Table 1), :mod:`rvtol.inputs.iso2768`.  An angle (a nominal in deg, arcmin, rad…)
goes by the length of its shorter side instead (Table 3: ``parse_tolerance(..., shorter_side=35)``, in mm;
refused without it), and a broken edge — a chamfer height, an external radius — by its own table
(Table 2: ``broken_edge=True``); either given where it does not belong is refused with the error's
``key`` set to its name.

Material condition of a position zone.  ``(M)``/``Ⓜ``/``MMC`` and ``(L)``/``Ⓛ``/``LMC`` after ``⌀t``
set ``Tolerance.modifier``; ``(S)``/``RFS`` is the default.  The zone then grows with the bonus of the
feature's actual size (:func:`rvtol.spec.zone_bonus`).

Fits.  ``25 H7/g6`` gives the clearance (hole − shaft, negative = interference) between the
fit's worst-case limits EI − es … ES − ei.  As a factor it is a normal whose σ is the
root-sum-square of the two parts' σ (each part's IT read at ``sigma_level``), placed in the
middle of the worst-case range, whose ``sigma_level`` is set so that its ``tolerance`` is the
worst-case range.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace

import numpy as np

from .. import units
from ..errors import InputError
from . import iso286

#: the accepted forms, quoted in every parse error
FORMS = ("±0.05 | +0.10/-0.05 | +0.10 -0.05 | 0/-0.02 | 5% | ±2 % | +5%/-2% | 24.95..25.05 | "
         "24.95 to 25.05 | max 0.02 | 25 H7 | Ø7 h5 | 25 H7/g6 | 50 H7 (+0.025/0) | 50 ISO 2768-m | ⌀0.4 (M), with an optional nominal first, a unit "
         "(mm, um, in, \", …) and a process spec (Cp 1.33 | Cpk 1.33 k 0.25)")

#: distribution kinds a band can be read as
BAND_KINDS = ("normal", "uniform", "triangular", "truncnorm")
MAGNITUDE_KINDS = ("rayleigh", "weibull")


class NotationError(InputError):
    """Tolerance text that cannot be read."""


@dataclass(frozen=True)
class Process:
    """A process inside the drawing's band: capability Cp, Cpk and signed mean shift k."""

    cp: float
    cpk: float
    k: float


@dataclass(frozen=True)
class Tolerance:
    """A toleranced value: nominal, lower/upper deviations (signed, from the nominal or 0), unit.

    ``lower_limit``/``upper_limit`` are the drawing's worst-case limits, whatever the process.
    """

    text: str
    form: str                 # symmetric | deviations | percent | limits | max | iso | fit | zone
    nominal: float | None     # None: written without (deviations about 0, absolute limits)
    lower: float
    upper: float
    unit: str | None          # canonical unit of every number here; None if none was written
    diameter: bool = False
    iso: iso286.Limits | None = None
    fit: iso286.Fit | None = None
    process: Process | None = None
    modifier: str = ""        # a position zone's material condition: "" (RFS), "MMC", "LMC"

    @property
    def base(self) -> float:
        return 0.0 if self.nominal is None else self.nominal

    @property
    def lower_limit(self) -> float:
        return self.base + self.lower

    @property
    def upper_limit(self) -> float:
        return self.base + self.upper

    @property
    def limits(self) -> tuple[float, float]:
        return self.lower_limit, self.upper_limit

    @property
    def width(self) -> float:
        """The tolerance band T = upper − lower deviation."""
        return self.upper - self.lower

    @property
    def mid(self) -> float:
        """The middle of the band (absolute)."""
        return self.base + 0.5 * (self.lower + self.upper)

    def in_unit(self, unit: str) -> "Tolerance":
        """The same tolerance in another unit of the same dimension."""
        u = units.canonical(unit)
        if self.unit is None or self.unit == u:
            return replace(self, unit=u)
        c = lambda v: None if v is None else float(units.convert(v, self.unit, u))  # noqa: E731
        return replace(self, nominal=c(self.nominal), lower=c(self.lower), upper=c(self.upper), unit=u)

    def describe(self) -> str:
        if self.form == "zone":
            return (f"⌀{fmt(self.width)}" + (f" {units.label(self.unit)}" if self.unit else "")
                    + {"MMC": " (M)", "LMC": " (L)"}.get(self.modifier, ""))
        if self.nominal is None and self.form in ("limits", "max"):
            s = format_limits(self.lower_limit, self.upper_limit)
        else:
            s = format_deviations(self.lower, self.upper)
        if self.nominal is not None:
            s = f"{fmt(self.nominal)} {s}"
        if self.unit:
            s += f" {units.label(self.unit)}"
        if self.process:
            s += f" (Cp {fmt(self.process.cp)}, Cpk {fmt(self.process.cpk)}, k {fmt(self.process.k)})"
        return s

    # -- the factor table --------------------------------------------------------------
    def factor_table(self, dist: str = "normal", sigma_level: float | None = None, **extra) -> dict:
        """Keys for :func:`rvtol.distributions.from_params` (values in ``self.unit``), plus ``nominal``.

        ``dist``: ``normal`` (band read at ±``sigma_level``·σ, 3 by default), ``uniform``,
        ``triangular``, ``truncnorm`` (normal at ``sigma_level`` cut at the limits), or a
        magnitude ``rayleigh``/``weibull`` (``extra`` gives weibull's ``shape``) whose coverage
        quantile is the upper limit above the lower one.
        """
        level = 3.0 if sigma_level is None else float(sigma_level)
        if not level > 0:
            raise NotationError(f"sigma_level must be > 0, got {sigma_level}")
        lo, hi, T, c = self.lower_limit, self.upper_limit, self.width, self.mid
        out: dict = {"dist": dist}
        if self.form == "zone":
            if dist != "normal":
                raise NotationError(f"a position zone's coordinates are normal (their radial deviation is then "
                                    f"Rayleigh), not {dist!r}")
            out.update(mean=c, tolerance=T, sigma_level=zone_level(level))
        elif self.process is not None:
            if dist != "normal":
                raise NotationError(f"a process specification (Cp/Cpk) describes a normal process, "
                                    f"not {dist!r}")
            if sigma_level is not None:
                raise NotationError("a process specification fixes σ through Cp: give no sigma_level")
            out.update(mean=c, tolerance=T, sigma_level=3.0 * self.process.cp,
                       shift=self.process.k * T / 2.0)
        elif self.fit is not None and dist == "normal":
            th, ts = self.fit.hole.width, self.fit.shaft.width
            out.update(mean=c, tolerance=T, sigma_level=level * (th + ts) / math.hypot(th, ts))
        elif dist == "normal":
            out.update(mean=c, tolerance=T)
            if sigma_level is not None:
                out["sigma_level"] = level
        elif dist in ("uniform", "triangular"):
            out.update(lower=lo, upper=hi)
        elif dist == "truncnorm":
            out.update(mean=c, sigma=T / (2.0 * level), lower=lo, upper=hi)
        elif dist in MAGNITUDE_KINDS:
            if not (self.form in ("max", "limits") or (self.form in ("deviations", "percent") and self.lower == 0.0)):
                raise NotationError(
                    f"a {dist} factor is a magnitude (its values start at a point and go up): {self.text!r} is a band "
                    "about the nominal and does not say where they start — write 'max x' (from 0), 'a..b' (from a) "
                    "or '+x/0' (from the nominal)")
            out.update(tolerance=T)
            if lo != 0.0:
                out["shift"] = lo
            if sigma_level is not None:
                out["sigma_level"] = level
        else:
            raise NotationError(f"a tolerance band cannot be read as {dist!r} (use one of: "
                                f"{', '.join(BAND_KINDS + MAGNITUDE_KINDS)})")
        for k, v in extra.items():
            if k in out:
                raise NotationError(f"{k!r} is set by the tolerance; do not give it as well")
            out[k] = v
        if self.nominal is not None:
            out["nominal"] = self.nominal
        return out


# --------------------------------------------------------------------------------- lexing
_DASHES = dict.fromkeys(map(ord, "\u2212\u2012\u2013\u2014\ufe63\uff0d"), "-")
_DIAMETER = "Ø⌀ø∅"
_UNIT_ALIASES = {'"': "in", "µ": "um", "μ": "um"}
_TOKEN = re.compile(r"""
    (?P<ws>\s+)
  | (?P<range>\.\.)
  | (?P<num>[+-]?\s*(?:\d+(?:\.(?!\.)\d*)?|\.\d+))
  | (?P<pm>±)
  | (?P<slash>/)
  | (?P<pct>%)
  | (?P<cmp>≤|<=|≥|>=|=|:)
  | (?P<word>[A-Za-zµμ°′″"]+(?:\^\d)?)
""", re.VERBOSE)
_ISO_GRADE = re.compile(r"(01|0|1[0-8]|[1-9])(?![\d.])")


@dataclass
class _Tok:
    kind: str
    text: str
    pos: int
    value: float = 0.0
    signed: bool = False


@dataclass(frozen=True)
class _Num:
    """A number of a tolerance's body: its value, whether it is a percentage, the unit written with it."""

    value: float
    pct: bool
    unit: str | None


#: a number as a drawing writes it, with its separators (a decimal comma, thousands separators)
_NUMBER_RUN = re.compile(r"(?<!\d)\d+(?:[.,]\d+)*")


def _decimal_points(s: str, text: str) -> str:
    """``s`` with every number written with a decimal point and no thousands separators: a decimal comma read as
    one, an ambiguous ``1,250`` (1.25 or 1250?) decided by the text's other numbers (``25,011 ±0,005`` writes
    decimal commas) or refused (:func:`rvtol.inputs.sheets.read_number`)."""
    from .sheets import EITHER, NumberFormError, comma_role, fmt_plain, read_number

    runs = _NUMBER_RUN.findall(s)
    if not any("," in r or r.count(".") > 1 for r in runs):
        return s
    role = comma_role(None, runs)

    def plain(m: re.Match) -> str:
        try:
            return fmt_plain(read_number(m.group(), role or EITHER))
        except NumberFormError as exc:
            raise _err(text, str(exc)) from None

    return _NUMBER_RUN.sub(plain, s)


def _normalise(text: str) -> tuple[str, bool]:
    s = text.translate(_DASHES).replace("＋", "+").strip()
    s = re.sub(r"\+\s*/\s*-|\+-", "±", s)
    s = _decimal_points(s, text)
    s = s.replace("…", "..")
    diameter = False
    if s[:1] in _DIAMETER:
        diameter, s = True, s[1:].lstrip()
    return s, diameter


def _tokens(s: str, text: str) -> list[_Tok]:
    out, i = [], 0
    while i < len(s):
        m = _TOKEN.match(s, i)
        if not m:
            raise _err(text, f"unexpected {s[i]!r} at position {i + 1}")
        kind = m.lastgroup
        t = m.group()
        if kind == "num":
            digits = t.replace(" ", "")
            out.append(_Tok("num", t, i, float(digits), digits[0] in "+-"))
        elif kind == "word":
            g = _ISO_GRADE.match(s, m.end())
            if g and len(t) <= 2 and t.isascii() and t.isalpha():  # H7, g6, zc11 (checked by iso286)
                out.append(_Tok("iso", t + g.group(), i))
                i = g.end()
                continue
            if t.lower() == "to":
                out.append(_Tok("range", t, i))
            else:
                out.append(_Tok("word", t, i))
        elif kind != "ws":
            out.append(_Tok(kind, t, i))
        i = m.end()
    return out


def _err(text: str, why: str) -> NotationError:
    return NotationError(f"cannot read tolerance {text!r}: {why} (accepted: {FORMS})")


def _unit(word: str) -> str | None:
    """The canonical unit of a word, or None if it is not one of the table's units (:mod:`rvtol.units`): pint would
    read the letters of ISO classes and process specs (``H7``, ``h6``, ``e8``, ``k``) as henry, hour, a charge…"""
    return units.in_table(_UNIT_ALIASES.get(word, word))


# --------------------------------------------------------------------------------- parsing
class _Parser:
    def __init__(self, text: str, toks: list[_Tok]):
        self.text, self.toks, self.i = text, toks, 0

    def peek(self, k: int = 0) -> _Tok | None:
        j = self.i + k
        return self.toks[j] if j < len(self.toks) else None

    def take(self, kind: str | None = None) -> _Tok | None:
        t = self.peek()
        if t is not None and (kind is None or t.kind == kind):
            self.i += 1
            return t
        return None

    def err(self, why: str) -> NotationError:
        return _err(self.text, why)

    def unexpected(self, what: str = "") -> NotationError:
        t = self.peek()
        if t is None:
            return self.err(f"ends too early{(', expected ' + what) if what else ''}")
        return self.err(f"unexpected {t.text!r} at position {t.pos + 1}"
                        f"{(', expected ' + what) if what else ''}")

    def unit(self) -> str | None:
        t = self.peek()
        if t is not None and t.kind == "word":
            u = _unit(t.text)
            if u is not None:
                self.i += 1
                return u
        return None

    def number(self, what: str) -> _Tok:
        t = self.take("num")
        if t is None:
            raise self.unexpected(what)
        return t


_MODIFIER = re.compile(r"\s*(?:\(\s*([MLS])\s*\)|([ⓂⓁⓈ])|\b(MMC|LMC|RFS))\s*$")
_MODIFIERS = {"M": "MMC", "Ⓜ": "MMC", "MMC": "MMC", "L": "LMC", "Ⓛ": "LMC", "LMC": "LMC", "S": "", "Ⓢ": "",
              "RFS": ""}
_PAREN = re.compile(r"^(.*\S)\s*\(([^()]*)\)\s*$")
_ISO2768 = re.compile(r"^\s*(.*?)\s*ISO\s*2768\s*-?\s*([A-Za-z]+?)\s*([HKL])?\s*$")


def parse_tolerance(text: str, *, nominal: float | None = None, unit: str | None = None,
                    shorter_side: float | None = None, broken_edge: bool = False) -> Tolerance:
    """Read drawing tolerance notation (see the module docstring): the forms of :func:`_parse_plain`, and around
    them a zone's material condition, a class with its deviations in parentheses, an ISO 2768 general class — of an
    angle by its ``shorter_side`` (mm), of a ``broken_edge`` (a chamfer height, an external radius).  Both belong to
    an ISO 2768 class only: elsewhere they are refused with the error's key set to their name."""
    if not isinstance(text, str):
        raise NotationError(f"tolerance must be text, got {type(text).__name__}")
    s = text.strip()
    m = _ISO2768.match(s)
    if m:
        return _general_tolerance(text, m, nominal, unit, shorter_side, broken_edge)
    for key, given in (("shorter_side", shorter_side is not None), ("broken_edge", broken_edge)):
        if given:
            raise NotationError(f"{key} belongs to an ISO 2768 general tolerance (e.g. tolerance = \"ISO 2768-m\"), "
                                f"not to {text!r}", key=key)
    m = _MODIFIER.search(s)
    if m and m.start() > 0 and s[:1] not in _DIAMETER:
        raise _err(text, "a material condition (M)/(L)/MMC/LMC belongs to a position zone: ⌀t (M)")
    if m and m.start() > 0:
        tol = _parse_plain(s[:m.start()], nominal=nominal, unit=unit)
        if tol.form != "zone":
            raise _err(text, "a material condition (M)/(L) belongs to a position zone ⌀t")
        return replace(tol, text=text, modifier=_MODIFIERS[next(g for g in m.groups() if g)])
    m = _PAREN.match(s)
    if m:                       # "Ø50 H7 (+0.025/0)": the outer part keeps the diameter sign
        outer, inner = m.group(1), m.group(2)
        a = _parse_plain(outer, nominal=nominal, unit=unit)
        nom = a.nominal if a.nominal is not None else nominal
        b = _parse_plain(inner, nominal=nom, unit=a.unit or unit)
        iso, dev = (a, b) if a.form == "iso" else (b, a) if b.form == "iso" else (None, None)
        if iso is None:
            raise _err(text, "a tolerance in parentheses must pair an ISO 286 class with its deviations, e.g. "
                             "50 H7 (+0.025/0)")
        dev = dev.in_unit(iso.unit)
        tol_mm = float(units.convert(0.0005, "mm", iso.unit))
        if abs(dev.lower - iso.lower) > tol_mm or abs(dev.upper - iso.upper) > tol_mm:
            raise _err(text, f"the deviations written ({format_deviations(dev.lower, dev.upper)}) differ from "
                             f"ISO 286's {iso.iso.cls} at {fmt(iso.nominal)} "
                             f"({format_deviations(iso.lower, iso.upper)}): one of them is mistyped")
        return replace(iso, text=text)
    return _parse_plain(text, nominal=nominal, unit=unit)


def _general_tolerance(text: str, m: re.Match, nominal: float | None, unit: str | None, shorter_side: float | None,
                       broken_edge: bool) -> Tolerance:
    """``50 ISO 2768-m``: ± ISO 2768-1's deviation (:mod:`rvtol.inputs.iso2768`) — of an angle by its shorter side
    (Table 3), of a broken edge (Table 2), else of a linear size (Table 1)."""
    from . import iso2768

    head = m.group(1)
    nom = _parse_plain(head + " ±1", nominal=nominal, unit=unit) if head else None
    base = nom if nom is not None else _parse_plain("±1", nominal=nominal, unit=unit or "mm")
    if base.nominal is None:
        raise _err(text, "ISO 2768 needs the nominal size (e.g. 50 ISO 2768-m)")
    u, cls = base.unit or "mm", m.group(2)
    angle = units.dimension(u) == "angle"
    if angle and shorter_side is None:
        raise NotationError(f"an angle's general tolerance ({text!r}) goes by the length of its shorter side "
                            "(ISO 2768-1 Table 3): give it in mm (e.g. shorter_side = 35; a 'shorter side' column in "
                            "a table)", key="shorter_side")
    if not angle and shorter_side is not None:
        raise NotationError(f"shorter_side is for an angle (ISO 2768-1 Table 3); {text!r} is in {u}, whose general "
                            "tolerance goes by its own size", key="shorter_side")
    if angle and broken_edge:
        raise NotationError(f"broken_edge marks a chamfer height or an external radius (a length, ISO 2768-1 Table 2), "
                            f"not an angle ({text!r} is in {u})", key="broken_edge")
    try:
        if angle:
            dev = units.convert(iso2768.angular(cls, shorter_side), "arcmin", u)
        else:
            table = iso2768.broken_edge if broken_edge else iso2768.linear
            dev = units.convert(table(cls, float(units.convert(base.nominal, u, "mm"))), "mm", u)
    except InputError as exc:
        raise _err(text, exc.reason) from None
    return Tolerance(text, "symmetric", base.nominal, -float(dev), float(dev), u)


def _parse_plain(text: str, *, nominal: float | None = None, unit: str | None = None) -> Tolerance:
    """Read drawing tolerance notation (see the module docstring).

    ``nominal`` (in ``unit``) supplies the nominal when the text has none (a table's nominal
    column); if both are given they must agree.  ``unit`` is the unit of the result (default:
    the first unit written, ``mm`` for ISO classes, else none); numbers written with another
    unit of the same dimension are converted; deviations written without a unit are in the
    nominal's unit, other bare numbers in ``unit``.  Raises :class:`NotationError` (an :class:`InputError`).
    """
    if not isinstance(text, str):
        raise NotationError(f"tolerance must be text, got {type(text).__name__}")
    if not text.strip():
        raise _err(text, "it is empty")
    if len(text) > 200:
        raise _err(text[:40] + "…", "longer than 200 characters")
    out_unit = None
    if unit is not None:
        try:
            out_unit = units.canonical(_UNIT_ALIASES.get(unit, unit))
        except InputError as exc:
            raise NotationError(exc.reason) from None
    if nominal is not None and not (isinstance(nominal, (int, float)) and math.isfinite(nominal)):
        raise NotationError(f"nominal must be a finite number, got {nominal!r}")
    s, diameter = _normalise(text)
    p = _Parser(text, _tokens(s, text))
    if not p.toks:
        raise _err(text, "it is empty")

    # ---- nominal -------------------------------------------------------------------------
    nom_t, nom_u = None, None
    t0, t1 = p.peek(), p.peek(1)
    if t0.kind == "num" and not t0.signed:
        nxt = t1
        if nxt is not None and nxt.kind == "word" and _unit(nxt.text) is not None:
            nxt = p.peek(2)
        if nxt is None and diameter:   # ⌀0.05 [unit]: a circular position zone
            x = p.take().value
            zu = p.unit()
            out = (units.canonical(_UNIT_ALIASES.get(unit, unit)) if unit else None) or zu
            if not x > 0:
                raise _err(text, "a position zone needs a positive diameter")
            r = 0.5 * (float(units.convert(x, zu, out)) if zu and out and zu != out else x)
            if nominal is not None:
                raise _err(text, "a position zone is a deviation about the true position: give no nominal")
            return Tolerance(text, "zone", None, -r, r, out, True)
        if nxt is None:
            if t1 is None:
                raise _err(text, "a bare number is ambiguous: write ±x for a symmetric tolerance, "
                                 "+a/-b for deviations or a..b for limits")
            raise _err(text, "a nominal without a tolerance")
        if nxt.kind not in ("range", "slash", "pct"):
            nom_t = p.take().value
            nom_u = p.unit()

    # ---- body ----------------------------------------------------------------------------
    t = p.peek()
    if t is None:
        raise p.unexpected("a tolerance after the nominal")
    nums: list[_Num] = []   # the body's two numbers (deviations or limits), each with its own unit
    form: str
    iso_cls: list[str] = []
    if t.kind == "pm":
        p.take()
        x = p.number("a number after ±")
        if x.signed:
            raise p.err("write ±x with an unsigned x")
        pct = p.take("pct") is not None
        u = p.unit()
        nums = [_Num(-x.value, pct, u), _Num(x.value, pct, u)]
        form = "percent" if pct else "symmetric"
    elif t.kind == "iso":
        iso_cls.append(p.take().text)
        if p.take("slash"):
            t2 = p.take("iso")
            if t2 is None:
                raise p.unexpected("a shaft class after '/' (e.g. H7/g6)")
            iso_cls.append(t2.text)
        form = "fit" if len(iso_cls) == 2 else "iso"
    elif (t.kind == "word" and t.text.lower() == "max") or (t.kind == "cmp" and t.text in ("≤", "<=")):
        p.take()
        x = p.number("a number after 'max'")
        if x.signed:
            raise p.err("'max x' takes an unsigned x (a magnitude)")
        u = p.unit()
        nums, form = [_Num(0.0, False, u), _Num(x.value, False, u)], "max"
    elif t.kind == "num":
        a = p.take()
        a_pct = p.take("pct") is not None
        a_unit = p.unit()
        if p.peek() is not None and p.peek().kind == "range":
            if a_pct:
                raise p.err("limits cannot be percentages")
            p.take()
            b = p.number("the upper limit after '..'")
            b_unit = p.unit()
            nums, form = [_Num(a.value, False, a_unit or b_unit), _Num(b.value, False, b_unit or a_unit)], "limits"
        else:
            slash = p.take("slash") is not None
            b = p.take("num")
            if b is None:
                if a_pct and not a.signed and not slash:
                    nums, form = [_Num(-a.value, True, a_unit), _Num(a.value, True, a_unit)], "percent"
                elif a.signed or slash:
                    raise p.err("write both deviations, e.g. +0.05/0 or 0/-0.02 (or ±x)")
                else:
                    raise p.unexpected()
            else:
                b_pct = p.take("pct") is not None
                a_pct = a_pct or (b_pct and a_unit is None)   # "+5/-2 %": the % belongs to both
                b_unit = p.unit()
                if a_pct != b_pct:
                    raise p.err("one deviation in percent and the other not: write the % on both (+5%/-2%) or "
                                "once after the pair (+5/-2 %)")
                for x in (a, b):
                    if not x.signed and x.value != 0.0:
                        raise p.err(f"the deviation {x.text.strip()!r} needs a sign (+ or -); "
                                    "for limits write a..b")
                if not slash and not (a.signed and b.signed) and 0.0 not in (a.value, b.value):
                    raise p.unexpected()
                nums = [_Num(a.value, a_pct, a_unit or b_unit), _Num(b.value, b_pct, b_unit or a_unit)]
                form = "percent" if (a_pct or b_pct) else "deviations"
    else:
        raise p.unexpected("a tolerance")
    # the unit after the body: every body but a class has read it after its numbers ("±0.05 mm", "+10/-5 um"); a
    # class's is this one ("25 H7 mm") or the nominal's ("25 mm H7") — one more is refused, not ignored
    t = p.peek()
    tail_unit = p.unit()
    if tail_unit is not None and (not iso_cls or nom_u is not None):
        raise p.err(f"a second unit {t.text!r} at position {t.pos + 1}: write the unit once")
    nom_u = nom_u or tail_unit

    # ---- process -------------------------------------------------------------------------
    proc: dict[str, float] = {}
    while p.peek() is not None:
        w = p.take("word")
        if w is None or w.text.lower() not in ("cp", "cpk", "k"):
            if w is not None:
                p.i -= 1
            raise p.unexpected("a unit or a process spec (Cp, Cpk, k)")
        key = w.text.lower()
        if key in proc:
            raise p.err(f"{w.text} is given twice")
        p.take("cmp")
        x = p.number(f"a number after {w.text}")
        proc[key] = x.value

    # ---- units and nominal ---------------------------------------------------------------
    body_written = sorted({n.unit for n in nums if n.unit is not None and not n.pct})
    if nom_t is not None and nom_u is None and out_unit is not None and any(u != out_unit for u in body_written):
        shown = " and ".join(units.label(u) for u in body_written)
        raise _err(text, f"the nominal {fmt(nom_t)} has no unit and the tolerance is in {shown} while the factor is "
                         f"in {units.label(out_unit)}: write the nominal's unit (e.g. {fmt(nom_t)} "
                         f"{units.label(out_unit)} or {fmt(nom_t)} {units.label(body_written[0])})")
    nums = [replace(n, unit=n.unit or nom_u) for n in nums]   # "1 in +0.002/-0.001": the nominal's unit
    written = [u for u in [nom_u, *(n.unit for n in nums)] if u is not None]
    out = out_unit or (written[0] if written else ("mm" if iso_cls else None))

    def conv(v: float, u: str | None) -> float:
        if u is None or out is None or u == out:
            return v
        try:
            return float(units.convert(v, u, out))
        except InputError as exc:
            raise _err(text, exc.reason) from None

    nom = None if nom_t is None else conv(nom_t, nom_u)
    if nominal is not None:
        arg = float(nominal)
        if nom is not None and not math.isclose(nom, arg, rel_tol=1e-9, abs_tol=1e-12):
            raise _err(text, f"its nominal {fmt(nom)} differs from the nominal given with it ({fmt(arg)})")
        nom = arg if nom is None else nom

    iso_lim = fit = None
    if iso_cls:
        if nom is None:
            raise _err(text, "an ISO 286 class needs the nominal size (e.g. 25 H7)")
        if units.dimension(out) != "length":
            raise _err(text, f"an ISO 286 class is a length tolerance, not in {out}")
        mm = float(units.convert(nom, out, "mm"))
        try:
            if form == "fit":
                fit = iso286.fit(iso_cls[0], iso_cls[1], mm)
                lo_um, hi_um = fit.min_clearance, fit.max_clearance
            else:
                iso_lim = iso286.limits(iso_cls[0], mm)
                lo_um, hi_um = iso_lim.lower, iso_lim.upper
        except InputError as exc:
            raise _err(text, exc.reason) from None
        lower, upper = conv(lo_um / 1000.0, "mm"), conv(hi_um / 1000.0, "mm")
        if form == "fit":   # a clearance: nominal 0 (hole and shaft share the nominal)
            nom = None
    else:
        for n in nums:
            if n.pct and (nom is None or nom == 0.0):
                raise _err(text, "a percentage needs a nonzero nominal")
        vals = [n.value / 100.0 * abs(nom) if n.pct else conv(n.value, n.unit) for n in nums]
        base = 0.0 if nom is None else nom
        if form in ("limits", "max"):    # absolute limits: the deviations from the nominal (or 0)
            vals = [v - base for v in vals]
            _check_nominal_near_limits(text, nom, vals, out)
        lower, upper = min(vals), max(vals)
    lower, upper = lower + 0.0, upper + 0.0   # no negative zeros (-0.00 on drawings)
    if not upper > lower:
        raise _err(text, "the tolerance band has zero width")

    process = _process(proc, text, form) if proc else None
    return Tolerance(text, form, nom, lower, upper, out, diameter, iso_lim, fit, process)


def _check_nominal_near_limits(text: str, nominal: float | None, devs: list[float], unit: str | None) -> None:
    """A nominal beside absolute limits (``24.95..25.05``, ``max x``) that cannot be theirs is refused: one of the two
    is mistyped (nominal 10 with 9.1..9.3).  A band may lie off its nominal (25 g6 is 24.980..24.993) — up to its
    own width, and for a length up to the farthest band of any ISO 286 class at that size
    (:func:`rvtol.inputs.iso286.farthest_band`: 0.3 mm at 25 mm, the a/A fundamental deviation)."""
    if nominal is None:
        return
    lo, hi = min(devs), max(devs)
    off = max(lo, -hi, 0.0)              # how far the nominal lies outside the band (deviations: from 0)
    if off <= hi - lo:
        return
    reach, why = hi - lo, "the band's own width"
    if unit is not None and units.dimension(unit) == "length":
        iso = float(units.convert(iso286.farthest_band(float(units.convert(abs(nominal), unit, "mm"))) / 1000.0,
                                  "mm", unit))
        if iso > reach:
            reach, why = iso, (f"any ISO 286 tolerance class puts a band at this size ({fmt(iso, 6)}"
                               f"{' ' + units.label(unit) if unit else ''})")
        if off <= reach * (1 + 1e-9):
            return
    side = "below" if lo > 0 else "above"
    u = f" {units.label(unit)}" if unit else ""
    raise _err(text, f"the nominal {fmt(nominal)} lies {fmt(off, 6)}{u} {side} its limits "
                     f"{format_limits(nominal + lo, nominal + hi)}, farther than {why}: one of them is mistyped "
                     "(give the nominal the limits deviate from, or none)")


def zone_level(sigma_level: float = 3.0) -> float:
    """The radius of a circular zone in σ of each coordinate, for the radial (Rayleigh) coverage of
    ±``sigma_level``·σ of a normal: √(−2 ln(1 − c)), 3.4393 at 3."""
    from ..distributions import coverage

    return math.sqrt(-2.0 * math.log(1.0 - coverage(sigma_level)))


def _process(proc: dict[str, float], text: str, form: str) -> Process:
    if form in ("max", "fit"):
        raise _err(text, f"a process spec needs a two-sided drawing tolerance, not a {form}")
    cp, cpk, k = proc.get("cp"), proc.get("cpk"), proc.get("k")
    for name, v in (("Cp", cp), ("Cpk", cpk)):
        if v is not None and not v > 0:
            raise _err(text, f"{name} must be > 0")
    if k is not None and not -1.0 < k < 1.0:
        raise _err(text, "k (the mean shift over the half tolerance) must lie in (-1, 1)")
    if cp is None and cpk is None:
        raise _err(text, "k needs Cp or Cpk")
    if cp is not None and cpk is not None:
        if cpk > cp * (1 + 1e-9):
            raise _err(text, f"Cpk ({fmt(cpk)}) cannot exceed Cp ({fmt(cp)})")
        kk = 1.0 - cpk / cp
        if k is not None and not math.isclose(abs(k), kk, rel_tol=1e-6, abs_tol=1e-9):
            raise _err(text, f"Cp {fmt(cp)}, Cpk {fmt(cpk)} and k {fmt(k)} disagree "
                             f"(Cpk = Cp·(1 − |k|) gives k = {fmt(kk)})")
        k = kk if k is None else k
    elif cp is None:
        k = 0.0 if k is None else k
        cp = cpk / (1.0 - abs(k))
    else:
        k = 0.0 if k is None else k
        cpk = cp * (1.0 - abs(k))
    return Process(float(cp), float(cpk), float(k))


# --------------------------------------------------------------------------------- formatting
def fmt(x: float, digits: int = 12) -> str:
    """A number in plain positional notation (no exponent), ``digits`` significant digits."""
    if x == 0:
        return "0"
    return np.format_float_positional(float(x), precision=digits, fractional=False, trim="-")


def format_deviations(lower: float, upper: float, digits: int = 12) -> str:
    """``±x`` when symmetric, else ``+upper/-lower`` (a zero is written ``0``)."""
    if math.isclose(-lower, upper, rel_tol=1e-12, abs_tol=0.0):
        return f"±{fmt(upper, digits)}"

    def signed(v: float) -> str:
        s = fmt(v, digits)
        return s if s == "0" or s.startswith("-") else f"+{s}"

    return f"{signed(upper)}/{signed(lower)}"


def format_limits(lower: float, upper: float, digits: int = 12) -> str:
    return f"{fmt(lower, digits)}..{fmt(upper, digits)}"
