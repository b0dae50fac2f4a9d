"""Composite position frames: a pattern's locating zone and its features' relating zone.

A composite feature control frame on a pattern of features (ASME Y14.5-2018 §10.5.1; ISO 5458:2018)::

    ⌀0.5 (M) | A | B | C      the pattern-locating tolerance zone framework (PLTZF), ⌀T₁
    ⌀0.1 (M) | A              the feature-relating tolerance zone framework (FRTZF), ⌀T₂ < T₁

requires each feature's axis to lie in its ⌀T₁ zone at true position from the datums **and** in its ⌀T₂ zone of a
framework that keeps the pattern's basic spacing but may move as a whole.  A spec writes it on each feature's two
coordinates (:mod:`rvtol.spec`)::

    [[factor]]
    name = "hole1.x"            # and hole1.y with the same zone; hole2.x/.y … likewise
    nominal = 0
    tolerance = "⌀0.5"          # the first line: PLTZF
    zone = "hole1"
    pattern = "bolts"           # the features the frame locates
    feature_relating = "⌀0.1"   # the second line: FRTZF

and rvtol reads a feature's position as the pattern's translation s plus the feature's own deviation e_i::

    p_i = s + e_i,   |s| ≤ (T₁ − T₂)/2,   |e_i| ≤ T₂/2

The spec then holds, for each pattern, two more factors ``NAME.x`` and ``NAME.y``: the translation s, a position
zone ⌀(T₁ − T₂) read as every zone is (normal coordinates, 99.73 % of the radius inside at 3σ); each feature's own
coordinates are read in its ⌀T₂ zone.  The model sees the features' positions p_i (:class:`PatternModel` adds s to
each feature's coordinates, the first coordinate of a zone to ``.x``, the second to ``.y``: the features' coordinates
must share their axes), so every convention, the Monte Carlo and the sensitivities take the pattern's shared
translation as the factor it is: a feature to the datums moves by s + e_i (worst case T₁/2, as the PLTZF allows), two
features of one pattern to each other by e_i − e_j (worst case T₂, as the FRTZF allows: s cancels).

What the decomposition leaves out (it admits only conforming patterns, not every one):

- the framework's centre may lie further than (T₁ − T₂)/2 from true position when every feature sits toward that
  side of its PLTZF; such patterns conform and are not generated — the worst-case rows are those of the
  decomposition, exact for a feature to the datums and for features to each other, within a few per cent of the
  frame's own extreme for mixed combinations;
- a FRTZF whose line references fewer than two datums (``feature_relating = "⌀0.1 A"``: orientation to the primary
  only) may also **rotate** about the primary's axis; the decomposition translates it only — exact for ``"⌀0.1 A B"``
  (the framework held in rotation by B), an understatement otherwise for an output that turns with the pattern, and
  the stack-up's notes say so for every output that reads such a pattern.  Given every feature's basic position
  (``basic`` on each coordinate), the worst case over the frame (:func:`frame_extreme`) turns the framework too (a
  small rotation about the pattern's centre: the cover's tilt 0.4345 where the translation alone gives 0.3475); the
  Monte Carlo still translates it only.

In ``samples.parquet`` and the factor tables a feature's coordinate (``hole1.x``) is its own deviation within the
framework; the model's ``hole1.x`` is the feature's position, the translation added.

The material condition is the zones': a frame at MMC on both lines gives each feature's own zone ⌀T₂ its bonus
(:func:`rvtol.spec.zone_bonus`) and the difference T₁ − T₂, the translation's zone, stays; a datum feature of size
at MMB shifts the pattern as one (:func:`rvtol.spec.datum_shifts`).  The two lines must carry the same modifier.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from . import units
from .distributions import from_params
from .errors import InputError, SpecError
from .inputs.notation import zone_level
from .model import Model
from .params import Params

AXES = ("x", "y")


@dataclass(frozen=True)
class Pattern:
    """One composite frame's pattern: its name, its features' zones (in the spec's order), the two zones' diameters
    in ``unit`` and the names of its translation's two coordinates."""

    name: str
    zones: tuple[str, ...]
    locating: float
    relating: float
    unit: str
    datums: tuple[str, ...] = ()       # the feature-relating line's datums
    basic: tuple | None = None         # the features' basic (true) positions, base units, (x, y) per zone

    @property
    def may_rotate(self) -> bool:
        """A feature-relating framework that references fewer than two datums may rotate about the primary's axis."""
        return len(self.datums) < 2

    @property
    def shift(self) -> tuple[str, str]:
        return tuple(f"{self.name}.{a}" for a in AXES)


def drawn_zone(f) -> tuple:
    """A zone coordinate's zone as the frame draws it — dimension, diameter in base units (a composite feature's: its
    locating zone) and modifier — to compare frames written in different units (⌀0.5 mm is ⌀500 µm)."""
    lo, hi = f.limits
    width = hi - lo if f.locating is None else f.locating
    return units.dimension(f.unit), round(float(units.to_base(width, f.unit)), 12), f.modifier


def patterns(factors) -> list[Pattern]:
    """The composite frames' patterns among ``factors`` (each feature coordinate carries ``pattern``)."""
    out: dict[str, list] = {}
    for f in factors:
        if f.pattern and f.zone != f.pattern:
            out.setdefault(f.pattern, []).append(f)
    result = []
    for name, fs in out.items():
        zones = tuple(dict.fromkeys(f.zone for f in fs))
        lo, hi = fs[0].limits
        given = [f.basic for f in fs]
        basic = None
        if all(b is not None for b in given):
            coords = {z: [float(units.to_base(f.basic, f.unit)) for f in fs if f.zone == z] for z in zones}
            basic = tuple(tuple(coords[z]) for z in zones)
        result.append(Pattern(name, zones, float(fs[0].locating), float(hi - lo), fs[0].unit, tuple(fs[0].datums),
                              basic))
    return result


def expand(factors: list, file: str | None) -> list:
    """``factors`` with each pattern's translation (:class:`Pattern`.shift) written after its last feature; every
    feature of a pattern checked to carry the same frame."""
    factors = list(factors)
    names = {f.name for f in factors}
    zones = {f.zone for f in factors if f.zone}
    for pat in patterns(factors):
        fs = [f for f in factors if f.pattern == pat.name]
        def frame_of(f):    # both lines in base units: one frame may be written in mm on one row, in µm on another
            lo, hi = f.limits
            return drawn_zone(f), round(float(units.to_base(hi - lo, f.unit)), 12), f.datums

        for f in fs:
            if frame_of(f) != frame_of(fs[0]):
                raise SpecError(f"pattern {pat.name!r}: {f.name} and {fs[0].name} carry different frames (one "
                                "composite frame locates a pattern: the same unit, zones and modifier on every "
                                "feature)", file=file, key="factor.pattern")
        if len({f.frame for f in fs}) > 1:
            raise SpecError(f"pattern {pat.name!r}: its features name different frames ({', '.join(sorted({f.frame for f in fs}))}) "
                            "— a composite frame is one frame: leave frame out (the pattern's) or give them one",
                            file=file, key="factor.frame")
        if any(f.basic is None for f in fs) and any(f.basic is not None for f in fs):
            raise SpecError(f"pattern {pat.name!r}: basic is given for some features and not for others — every "
                            "feature's two coordinates, or none", file=file, key="factor.basic")
        if pat.name in zones:
            raise SpecError(f"pattern {pat.name!r} is also the name of a position zone: name the pattern otherwise",
                            file=file, key="factor.pattern")
        taken = [n for n in pat.shift if n in names]
        if taken:
            raise SpecError(f"pattern {pat.name!r}: its translation's coordinate {taken[0]!r} is already a factor's "
                            "name: name the pattern otherwise", file=file, key="factor.pattern")
        width = pat.locating - pat.relating
        table = {"dist": "normal", "mean": 0.0, "tolerance": width, "sigma_level": zone_level()}
        dist = from_params(Params(table, file=file, key="factor.pattern"))
        first = fs[0]
        where = max(factors.index(f) for f in fs) + 1
        # the translation carries no bonus and no datum shift of its own: a datum feature at MMB shifts the pattern
        # through its features (one shift, every feature alike), which the translation would count a second time
        shift = [replace(first, name=n, dist=dist, nominal=0.0, limits=(-width / 2, width / 2), zone=pat.name,
                         feature="pattern translation", size="", feature_type="", modifier="", locating=None,
                         datum_size="", datum_type="", separate=False, frame="", datums=(), direction=None,
                         family="",
                         description=f"translation of pattern {pat.name}'s feature-relating framework within the "
                                     f"pattern-locating zone (composite frame ⌀{pat.locating:g}/⌀{pat.relating:g} "
                                     f"{units.label(pat.unit)}: ⌀{width:g})")
                 for n in pat.shift]
        factors[where:where] = shift
        names.update(pat.shift)
    return factors


def feature_spec(spec):
    """``spec`` without its patterns' translations: what a model of the features' positions reads."""
    shifts = {n for p in patterns(spec.factors) for n in p.shift}
    if not shifts:
        return spec
    keep = [i for i, n in enumerate(spec.names) if n not in shifts]
    corr = None if spec.correlation is None else np.asarray(spec.correlation)[np.ix_(keep, keep)]
    return replace(spec, factors=tuple(spec.factors[i] for i in keep), correlation=corr)


def with_patterns(model: Model, spec) -> Model:
    """``model`` (of the features' positions) reading ``spec``'s factors: unchanged without a composite frame,
    else a :class:`PatternModel`."""
    pats = patterns(spec.factors)
    if not pats:
        return model
    for p in pats:
        if not set(p.shift) <= set(spec.names):
            raise InputError(f"pattern {p.name!r}: its features are read without the pattern's translation "
                             f"({', '.join(p.shift)}): the features' positions need both", key="factor.pattern")
    return PatternModel(model, spec, pats)


class PatternModel(Model):
    """A model of the features' positions p_i fed with the spec's factors: each feature coordinate of a pattern
    plus its pattern's translation (module docstring).  Its inputs are the spec's factors; its outputs, status and
    structure the model's."""

    def __init__(self, inner: Model, spec, pats: list[Pattern]):
        self.inner = inner
        self.patterns = tuple(pats)
        self.inputs = tuple(spec.names)
        self.outputs = inner.outputs
        self.status_reasons = inner.status_reasons
        missing = [n for n in inner.inputs if n not in spec.names]
        if missing:
            raise InputError(f"the model reads {missing[0]!r}, which the spec does not hold", key="factor")
        self._take = np.array([spec.index(n) for n in inner.inputs])
        units_of = dict(zip(inner.inputs, inner.input_units))
        self.input_units = tuple(units_of.get(f.name, f.base_unit) for f in spec.factors)
        pos = {n: j for j, n in enumerate(inner.inputs)}
        self._add: list[tuple[int, int]] = []       # (inner column, spec column of the translation added to it)
        for p in pats:
            for z in p.zones:
                coords = [f.name for f in spec.factors if f.zone == z]
                for name, shift in zip(coords, p.shift):
                    if name in pos:
                        self._add.append((pos[name], spec.index(shift)))
        self.warnings = list(getattr(inner, "warnings", []))
        if hasattr(inner, "gradient"):
            self.gradient = self._gradient
        if hasattr(inner, "probe"):
            self.probe = self._probe

    @property
    def label(self) -> str:
        names = ", ".join(p.name for p in self.patterns)
        return f"{type(self.inner).__name__} with composite frames ({names})"

    def positions(self, X: np.ndarray) -> np.ndarray:
        """The model's inputs (features at p_i = s + e_i) from the spec's columns ``X``."""
        X = self.check_input(X)
        P = X[:, self._take].copy()
        for j, k in self._add:
            P[:, j] += X[:, k]
        return P

    def evaluate(self, X):
        return self.inner.evaluate(self.positions(X))

    def evaluate_with_status(self, X):
        return self.inner.evaluate_with_status(self.positions(X))

    def dependencies(self):
        deps = self.inner.dependencies()
        if deps is None:
            return None
        adds: dict[str, set] = {}
        for j, k in self._add:
            adds.setdefault(self.inner.inputs[j], set()).add(self.inputs[k])
        return {o: frozenset(ins | {s for n in ins for s in adds.get(n, ())}) for o, ins in deps.items()}

    def _probe(self, spec, seed):
        """The model's own probe (:mod:`rvtol.models.formula.probe`) over the features' positions: each feature of a
        pattern anywhere in its pattern-locating zone ⌀T₁ (what the translation and its own deviation reach)."""
        located = []
        for f in feature_spec(spec).factors:
            if f.locating is not None:
                lo, hi = f.limits
                f = f.scaled(f.locating / (hi - lo))
            located.append(f)
        return self.inner.probe(replace(feature_spec(spec), factors=tuple(located)), seed)

    def _gradient(self, X) -> np.ndarray:
        """∂Y/∂X by the chain rule: a translation's column is the sum of its features' columns."""
        G_in = np.asarray(self.inner.gradient(self.positions(X)), dtype=float)
        G = np.zeros(G_in.shape[:2] + (len(self.inputs),))
        G[:, :, self._take] += G_in
        for j, k in self._add:
            G[:, :, k] += G_in[:, :, j]
        return G


def frame_extreme(pattern: Pattern, gradients: np.ndarray) -> tuple[float, float]:
    """The largest change of a linear output Σ a_i·p_i over the composite frame itself and over rvtol's decomposition
    of it (module docstring), in the output's base unit per the pattern's base unit: ``(frame, decomposition)``.

    ``gradients[i] = a_i``, the output's gradient by feature i's two coordinates (the pattern's zones' order).  The
    frame: max Σ a_i·p_i subject to |p_i| ≤ T₁/2 and |p_i − c − θ J r_i| ≤ T₂/2 for a common framework centre c and,
    where the framework may rotate (:attr:`Pattern.may_rotate`) and the features' basic positions are given, a common
    small rotation θ about the pattern's centroid (r_i: feature i's basic position from it, J a quarter turn; θ = 0
    otherwise) — a second-order cone programme (cvxpy); its lower extreme is the negative (the domain is symmetric).
    The decomposition: (T₁ − T₂)/2 |Σ a_i| + T₂/2 Σ |a_i| (the arithmetic worst case's discs)."""
    import cvxpy as cp

    a = np.asarray(gradients, dtype=float).reshape(len(pattern.zones), 2)
    t1, t2 = (float(units.to_base(v, pattern.unit)) for v in (pattern.locating, pattern.relating))
    decomposition = 0.5 * (t1 - t2) * float(np.linalg.norm(a.sum(axis=0))) + 0.5 * t2 * float(
        np.linalg.norm(a, axis=1).sum())
    scale = float(np.abs(a).max())
    if scale == 0.0:
        return 0.0, 0.0
    p, c = cp.Variable((len(a), 2)), cp.Variable(2)
    rows = range(len(a))
    turn = np.zeros((len(a), 2))
    theta = cp.Variable()
    if pattern.may_rotate and pattern.basic is not None:
        b = np.asarray(pattern.basic, dtype=float)
        r = b - b.mean(axis=0)
        turn = np.column_stack([-r[:, 1], r[:, 0]])          # J r_i: a small turn's displacement per radian
    framework = [c + theta * turn[i] for i in rows]
    problem = cp.Problem(cp.Maximize(cp.sum(cp.multiply(a / scale, p))),
                         [cp.norm(p[i]) <= t1 / 2 for i in rows]
                         + [cp.norm(p[i] - framework[i]) <= t2 / 2 for i in rows])
    problem.solve()
    if problem.status != "optimal":
        raise RuntimeError(f"the composite frame's extreme was not found ({problem.status})")
    return max(float(problem.value) * scale, decomposition), decomposition
