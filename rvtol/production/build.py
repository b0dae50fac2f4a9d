"""How a reducer is built: selective fits, shim-set preloads and the design choices behind them (issue 23).

A drawing spec says what each part may be; a **build** says how the maker puts the parts together.
It is a transform of every Monte Carlo sample between the drawing factors and the physics (a composed
study's ``[study] build = "build.toml"``, :class:`rvtol.models.composite.model.CompositeModel`): the
reducer the models see is the one the build rules assemble from that sample's parts.

* **Selective fit** (:class:`SelectiveFit`, ``[[fit]]``) — a part comes in classes of known size
  (``sizes``: pin gauge lots, needle-roller gauges).  The fitter measures the mating parts (each reading
  = true value + a *gauge error*, a factor of the study) and takes the **largest part whose measured
  clearance is at least** ``minimum``.  The rule writes that as ``target``: the part size at which the
  measured clearance equals ``minimum`` (an expression of the readings; ``minimum`` is a name in it), and
  the part is the largest size ≤ target — :class:`~rvtol.production.selective.TargetRule` on
  :class:`~rvtol.production.selective.Classes` whose lower limits are the sizes.  The true clearance of
  the fit (``clearance``: an expression of the true sizes and ``part``) is then::

      clearance = minimum + a·(target − part) − a·e        (a = −∂clearance/∂part, e = the target's gauge error)

  i.e. ``minimum`` + a residual within one class step + the gauge's error: uniform on
  [minimum, minimum + a·step) convolved with the gauge's normal error when the demand spreads over
  many classes.  The factor the fit ``sets`` takes ``value`` (an expression of ``part`` and
  ``clearance``): the chosen part size, or the fitted clearance where the drawing spec carries it.
* **Shim-set preload** (:class:`ShimPreload`, ``[[shim]]``) — a tapered roller pair is mounted with a
  shim (``from``/``to``/``step``) chosen from the measured axial end play of its stack so that the
  interference is the one of the target preload (``preload``: a value, or ``{ design = "key" }`` — the
  design's own, so a variant of the design sets its own target; the pair's law, from the study's design);
  the nearest shim leaves the interference within ± step/2 of its target, plus the gauge's error, less the
  stack's ``settling`` during run-in (optional: an expression, e.g. a process factor, base units) — and the
  preload follows the pair's law ``F = Z K sin α (Δ sin α / 2)^(10/9)``
  (:class:`PreloadLaw`; rigid rings, :mod:`rvtol.elements.rolling_bearings`).
* **Design choice** (:class:`DesignChoice`, ``[[choice]]``) — a drawing or design value chosen for the
  build (e.g. the profile modification that puts the nominal demand in the middle of the pin supply).
  It is not applied per sample: the loader checks that the drawing spec's factor means and the design
  hold the value the build file states, so the file and the drawing cannot drift apart.  ``value`` is a
  number, or an expression of the **nominal build** — the reducer with every factor at its mean and no
  gauge error, built by the fits above: the names of the fits' expressions and ``build.<fit>.part``,
  ``build.<fit>.clearance`` (base units) — for a design value that follows from the build (the pins' fit
  in their grooves follows from the pin gauge the nominal housing gets), written in one place.
* **Gauges** (``[[gauge]]``) — each reading's measurement error, a factor table in the spec's format
  (normal, mean 0, σ = the gauge's standard uncertainty u) appended to the study's spec: the gauge
  errors are sampled with the parts, so sensitivity analyses see them like any tolerance.
* **Process spread** (``[[process]]``) — what the build does to a unit beyond its parts and readings (the run-in
  settling of a preloaded stack), factor tables in the spec's format appended to the study's spec like the
  gauges: sampled per unit, seen by sensitivity analyses like any tolerance.

Every rule reads the *as-drawn* values (factors, gauge errors, the composition's quantities that do not
depend on a factor a rule sets); the composition then recomputes its quantities from the as-built
factors.  The build's own outputs (``build.<fit>.clearance``, ``build.<shim>.preload``) are outputs of
the composed model.  Units: every expression is in base units (mm, N, rad), as the composition's.

::

    rules = load_build("data/products/rv80e/build.toml", spec, design, quantity_names)
    set_values, named = rules.apply(env, n)       # env: name -> array (base units) of n samples
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from .. import units
from ..errors import InputError
from ..expressions import Expression
from ..model import Quantity
from ..options import read_options
from ..params import Params, read_toml
from .build_tables import BuildHead, ChoiceTable, FitTable, ShimTable, Steps
from ..spec import Factor, ToleranceSpec, factors_from_params
from .selective import Classes, TargetRule

#: names a rule's expressions may use besides the composition's: the part size, the fitted clearance,
#: the rule's minimum clearance
LOCAL_NAMES = ("part", "clearance", "minimum")
#: prefix of the build's outputs (``build.<rule>.clearance``, ``build.<rule>.preload``)
PREFIX = "build."
#: relative tolerance of the loader's check that the drawing and the design hold a choice's value
CHOICE_RTOL = 1e-9


# --------------------------------------------------------------------------- selective fit
@dataclass(frozen=True)
class FitResult:
    """One fit on ``n`` samples: the target, the part chosen, the true clearance and the set value (base
    units); ``short``: the supply has no part small enough (the clearance is below ``minimum``);
    ``loose``: even the largest part leaves more than one class step above ``minimum``."""

    target: np.ndarray
    part: np.ndarray
    clearance: np.ndarray
    value: np.ndarray
    short: np.ndarray
    loose: np.ndarray


@dataclass(frozen=True)
class SelectiveFit:
    """The largest part whose measured clearance is at least ``minimum`` (module docstring)."""

    name: str
    title: str
    sets: str
    sizes: np.ndarray            # available part sizes, increasing (base units)
    minimum: float               # base units
    target: TargetRule           # the part size at which the MEASURED clearance equals ``minimum``
    clearance: Expression        # the TRUE clearance with part size ``part``
    value: Expression            # the as-built value of ``sets`` (reads ``part``, ``clearance``)
    unit: str                    # display unit of sizes and clearances
    rule: str = ""
    source: str = ""

    @property
    def classes(self) -> Classes:
        """Class c holds the targets in [sizes[c], sizes[c + 1]): its part is ``sizes[c]``."""
        return Classes(np.append(self.sizes, np.inf))

    @property
    def step(self) -> float:
        """The largest gap between neighbouring sizes (base units)."""
        return float(np.max(np.diff(self.sizes))) if self.sizes.size > 1 else np.inf

    @property
    def reads(self) -> set[str]:
        """The composition's names the rule reads."""
        return (set(self.target.names) | set(self.clearance.names) | set(self.value.names)) - set(LOCAL_NAMES)

    def choose(self, env: dict, n: int) -> FitResult:
        local = dict(env)
        local["minimum"] = self.minimum
        cls, target = self.target.wanted(local, self.classes, None, n)
        part = self.sizes[cls]
        local["part"] = part
        c = _column(self.clearance.evaluate(local), n)
        local["clearance"] = c
        value = _column(self.value.evaluate(local), n)
        short = target < self.sizes[0]
        loose = target >= self.sizes[-1] + (self.step if np.isfinite(self.step) else 0.0)
        return FitResult(target, part, c, value, short, loose)

    def describe(self) -> dict:
        u = self.unit
        sizes = units.from_base(self.sizes, u)
        return {"rule": self.name, "what": self.title, "sets": self.sets,
                "how": (f"the largest part of {sizes.size} sizes {_fmt(sizes[0])} … {_fmt(sizes[-1])} {units.label(u)} "
                        f"(step {_fmt(units.from_base(self.step, u))}) whose measured clearance is ≥ "
                        f"{_fmt(units.from_base(self.minimum, u))} {units.label(u)}"),
                "reasoning": self.rule, "source": self.source}


# --------------------------------------------------------------------------- shim-set preload
@dataclass(frozen=True)
class PreloadLaw:
    """Axial preload of a pair of identical tapered roller bearings from its axial interference Δ (rigid
    rings, no external load): every roller of both bearings is compressed by ``(Δ/2) sin α`` and carries
    ``K δ^(10/9)`` along the cup normal, so ``F = Z K sin α (Δ sin α / 2)^(10/9)`` (:mod:`rvtol.elements.
    rolling_bearings`: the same Palmgren line-contact law; :meth:`BearingPair.with_preload_force` solves the
    pair's equilibrium for it); Δ ≤ 0 (end play) carries nothing."""

    rollers: int
    K: float                     # N/mm^(10/9)
    alpha: float                 # rad, the cup contact angle

    def force(self, delta) -> np.ndarray:
        d = np.maximum(np.asarray(delta, dtype=float), 0.0)
        s = np.sin(self.alpha)
        return self.rollers * self.K * s * (0.5 * d * s) ** (10.0 / 9.0)

    def interference(self, force: float) -> float:
        s = np.sin(self.alpha)
        return float(2.0 * (force / (self.rollers * self.K * s)) ** 0.9 / s)

    @classmethod
    def from_design(cls, design, key: str = "crank_support_bearing") -> "PreloadLaw":
        """The pair the design's compliance chain uses (:class:`rvtol.elements.rolling_bearings.TaperedRollerBearing`
        from ``<key>.rollers, roller_length, pitch_diameter, cup_angle, cone_angle``)."""
        from ..elements.rolling_bearings import TaperedRollerBearing

        names = ("rollers", "roller_length", "pitch_diameter", "cup_angle", "cone_angle")
        missing = [n for n in names if design is None or f"{key}.{n}" not in design]
        if missing:
            raise InputError(f"a shim rule needs the design's tapered roller pair: {key}.{missing[0]} is missing",
                             file=getattr(design, "file", None), key=f"{key}.{missing[0]}")
        v = {n: float(design[f"{key}.{n}"]) for n in names}
        brg = TaperedRollerBearing(rollers=int(v["rollers"]), alpha=v["cup_angle"], length=v["roller_length"],
                                   pitch_diameter=v["pitch_diameter"], alpha_inner=v["cone_angle"])
        return cls(brg.rollers, float(brg.K), float(brg.alpha))


@dataclass(frozen=True)
class ShimResult:
    shim: np.ndarray
    interference: np.ndarray     # after run-in (less the settling)
    preload: np.ndarray          # after run-in: what the unit runs with
    short: np.ndarray            # the end play needs a shim thinner than the thinnest
    loose: np.ndarray            # … thicker than the thickest
    preload_as_set: np.ndarray | None = None   # at assembly, before the run-in settling


@dataclass(frozen=True)
class ShimPreload:
    """The shim nearest to measured end play + target interference; the preload from the pair's law."""

    name: str
    title: str
    end_play: Expression          # TRUE axial end play of the stack without shim (base units)
    measured: Expression          # the end play as read (with its gauge error)
    shims: np.ndarray             # shim thicknesses in equal steps (base units)
    preload_target: float         # N
    interference_target: float    # mm
    law: PreloadLaw
    unit: str = "um"
    rule: str = ""
    source: str = ""
    settling: Expression | None = None   # axial settling of the stack during run-in (base units)

    @property
    def step(self) -> float:
        return float(self.shims[1] - self.shims[0])

    @property
    def target(self) -> TargetRule:
        """Measured end play + target interference + step/2: the nearest shim is the largest shim ≤ it."""
        return TargetRule(Expression.parse(f"({self.measured.text}) + {self.interference_target + 0.5 * self.step!r}"))

    def with_step(self, step: float) -> "ShimPreload":
        """The same rule with shims in steps of ``step`` (base units) over the same range."""
        return replace(self, shims=self.shims[0] + step * np.arange(int(round((self.shims[-1] - self.shims[0]) / step)) + 1))

    @property
    def reads(self) -> set[str]:
        return set(self.end_play.names) | set(self.measured.names) | set(
            self.settling.names if self.settling is not None else ())

    def choose(self, env: dict, n: int) -> ShimResult:
        classes = Classes(np.append(self.shims, np.inf))
        cls, target = self.target.wanted(env, classes, None, n)
        shim = self.shims[cls]
        delta = shim - _column(self.end_play.evaluate(env), n)
        run = delta - (_column(self.settling.evaluate(env), n) if self.settling is not None else 0.0)
        return ShimResult(shim, run, self.law.force(run), target < self.shims[0], target >= self.shims[-1] + self.step,
                          self.law.force(delta))

    def describe(self) -> dict:
        u = self.unit
        return {"rule": self.name, "what": self.title, "sets": f"{PREFIX}{self.name}.preload",
                "how": (f"the shim nearest to the measured end play + {_fmt(units.from_base(self.interference_target, u))} "
                        f"{units.label(u)} (interference of the {_fmt(self.preload_target)} N target preload), shims "
                        f"{_fmt(units.from_base(self.shims[0], u))} … {_fmt(units.from_base(self.shims[-1], u))} "
                        f"{units.label(u)} in {_fmt(units.from_base(self.step, u))}-{units.label(u)} steps"
                        + (f"; less the run-in settling {self.settling.text}" if self.settling is not None else "")),
                "reasoning": self.rule, "source": self.source}


# --------------------------------------------------------------------------- design choices
@dataclass(frozen=True)
class DesignChoice:
    """A drawing/design value chosen for the build, checked against the spec's factor means and the design."""

    name: str
    value: float                 # in ``unit``
    unit: str
    factors: tuple[str, ...]     # spec factors whose mean holds the value
    design_keys: tuple[str, ...]  # design keys that hold it
    rule: str = ""
    source: str = ""
    formula: str = ""            # the expression of the nominal build it follows from ('' for a number)

    def describe(self) -> dict:
        where = ", ".join([f"mean of {f}" for f in self.factors] + [f"design {k}" for k in self.design_keys])
        how = f"{_fmt(self.value)} {units.label(self.unit)}" + (f" = {self.formula} (nominal build)" if self.formula
                                                                 else "")
        return {"rule": self.name, "what": "design choice", "sets": where, "how": how, "reasoning": self.rule,
                "source": self.source}


# --------------------------------------------------------------------------- the build
@dataclass(frozen=True)
class BuildRules:
    """Every rule of a build file; :meth:`apply` builds ``n`` reducers at once (vectorised)."""

    name: str
    description: str
    gauges: tuple[Factor, ...]
    fits: tuple[SelectiveFit, ...]
    shims: tuple[ShimPreload, ...]
    choices: tuple[DesignChoice, ...] = ()
    file: str | None = None
    sha256: str | None = None
    process: tuple[Factor, ...] = ()     # the build's process spread (run-in settling), factors of the spec

    @property
    def sets(self) -> tuple[str, ...]:
        """The factors the build gives their as-built values."""
        return tuple(f.sets for f in self.fits)

    @property
    def outputs(self) -> tuple[Quantity, ...]:
        out = [Quantity(f"{PREFIX}{f.name}.clearance", "mm", f.unit, f"{f.title}: fitted clearance (true sizes)")
               for f in self.fits]
        out += [Quantity(f"{PREFIX}{s.name}.preload", "N", "N", f"{s.title}: preload set by the shim")
                for s in self.shims]
        return tuple(out)

    def as_drawn(self) -> dict[str, float]:
        """The build's named values a unit has with no build rule applied (the parts as drawn): each shim-set
        preload at its target (base units, N)."""
        out = {}
        for s in self.shims:
            out[f"{PREFIX}{s.name}.preload"] = out[f"{PREFIX}{s.name}.preload_as_set"] = float(s.preload_target)
        return out

    def reads(self) -> dict[str, set[str]]:
        """Each set factor and build output -> the composition's names its rule reads."""
        out = {}
        for f in self.fits:
            out[f.sets] = f.reads
            out[f"{PREFIX}{f.name}.clearance"] = f.reads
        for s in self.shims:
            out[f"{PREFIX}{s.name}.preload"] = s.reads
        return out

    def apply(self, env: dict, n: int) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        """``(set factor -> as-built values, named build values)`` for the ``n`` samples of ``env`` (the
        as-drawn factors, gauge errors and quantities, base units).  The named values are the outputs and,
        per fit, ``build.<fit>.part`` (the part size chosen); per shim ``build.<shim>.interference``."""
        changed: dict[str, np.ndarray] = {}
        named: dict[str, np.ndarray] = {}
        for f in self.fits:
            r = f.choose(env, n)
            changed[f.sets] = r.value
            named[f"{PREFIX}{f.name}.clearance"] = r.clearance
            named[f"{PREFIX}{f.name}.part"] = r.part
        for s in self.shims:
            r = s.choose(env, n)
            named[f"{PREFIX}{s.name}.preload"] = r.preload
            named[f"{PREFIX}{s.name}.preload_as_set"] = r.preload_as_set
            named[f"{PREFIX}{s.name}.interference"] = r.interference
        return changed, named

    def fit_results(self, env: dict, n: int) -> dict[str, FitResult | ShimResult]:
        """Every rule's full result (for the report's usage table)."""
        out: dict = {f.name: f.choose(env, n) for f in self.fits}
        out.update({s.name: s.choose(env, n) for s in self.shims})
        return out

    def to_frame(self) -> pd.DataFrame:
        """One row per rule: what it sets, how, why, from which source (the report's inputs page)."""
        rows = [r.describe() for r in (*self.fits, *self.shims, *self.choices)]
        return pd.DataFrame(rows, columns=["rule", "what", "sets", "how", "reasoning", "source"])

    def record(self) -> dict:
        """summary.json's ``build``: the rules and the gauges."""
        return {"name": self.name, "file": self.file, "sha256": self.sha256,
                "rules": self.to_frame().to_dict(orient="records"),
                "gauges": [{"name": g.name, "unit": g.unit, "u": g.dist.std, "source": g.source} for g in self.gauges],
                "process": [{"name": f.name, "unit": f.unit, "distribution": f.dist.describe() if hasattr(f.dist, "describe")
                             else f.dist.kind, "source": f.source} for f in self.process]}


def usage(rules: BuildRules, env: dict, n: int) -> pd.DataFrame:
    """Per rule on ``n`` samples: the fitted clearance (or preload) mean, σ, min, max, the share of samples
    the supply could not fit (short/loose) and the parts used per size."""
    rows = []
    for f in rules.fits:
        r = f.choose(env, n)
        c = units.from_base(r.clearance, f.unit)
        parts = units.from_base(r.part, f.unit)
        sizes, counts = np.unique(np.round(parts, 9), return_counts=True)
        rows.append({"rule": f.name, "quantity": f"fitted clearance ({units.label(f.unit)})",
                     "mean": float(c.mean()), "std": float(c.std(ddof=1)) if n > 1 else 0.0,
                     "min": float(c.min()), "max": float(c.max()),
                     "no part small enough": float(r.short.mean()), "largest part too small": float(r.loose.mean()),
                     "parts used": ", ".join(f"{_fmt(s)}: {k}" for s, k in zip(sizes, counts))})
    for s in rules.shims:
        r = s.choose(env, n)
        rows.append({"rule": s.name, "quantity": "preload (N)", "mean": float(r.preload.mean()),
                     "std": float(r.preload.std(ddof=1)) if n > 1 else 0.0, "min": float(r.preload.min()),
                     "max": float(r.preload.max()), "no part small enough": float(r.short.mean()),
                     "largest part too small": float(r.loose.mean()),
                     "parts used": (f"interference {_fmt(units.from_base(r.interference.mean(), s.unit))} ± "
                                    f"{_fmt(units.from_base(r.interference.std(), s.unit))} {units.label(s.unit)}")})
    return pd.DataFrame(rows)


# --------------------------------------------------------------------------- loading
def load_build(path, spec: ToleranceSpec, design=None, quantities=()) -> BuildRules:
    """Read and check a build file (module docstring).  ``quantities``: the composition's quantities (objects
    with ``name`` and ``expression``, design numbers included, in order): a rule may read them, but not one
    that depends on a factor the build sets; ``design``: the study's design (shim rules read their bearing
    pair from it; choices are checked against it).  Raises :class:`InputError` naming the file and key."""
    data, sha = read_toml(path)
    file = str(path)
    root = Params(data, file=file)
    head = root.sub("build", {})
    h = read_options(BuildHead, head)
    head.finish()
    name, desc = h.name, h.description
    gauges = [g for t in root.tables("gauge") for g in factors_from_params(t)]
    process = [f for t in root.tables("process") for f in factors_from_params(t)]
    for kind, added in (("gauge", gauges), ("process", process)):
        clash = {g.name for g in added} & set(spec.names)
        if clash:
            raise InputError(f"{kind} {sorted(clash)[0]!r} has the name of a factor of the spec", file=file, key=kind)
    both = [g.name for g in gauges + process]
    if len(set(both)) != len(both):
        raise InputError(f"{sorted({n for n in both if both.count(n) > 1})[0]!r} is given twice among the gauges and "
                         "process factors", file=file, key="process")
    nominal, deps = _nominal(spec, gauges + process, quantities, design)
    known = set(nominal)
    fits = [_fit(t, spec, known, nominal) for t in root.tables("fit")]
    shims = [_shim(t, known, design) for t in root.tables("shim")]
    built = _nominal_build(fits, nominal)
    choices = [_choice(t, spec, design, {**nominal, **built}) for t in root.tables("choice")]
    root.finish()
    if not fits and not shims and not choices:
        raise InputError("a build needs at least one [[fit]], [[shim]] or [[choice]]", file=file, key="fit")
    names = [r.name for r in (*fits, *shims)]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise InputError(f"two rules are named {sorted(dup)[0]!r}", file=file, key="fit")
    sets = [f.sets for f in fits]
    if len(set(sets)) != len(sets):
        raise InputError(f"two fits set {sorted({s for s in sets if sets.count(s) > 1})[0]!r}", file=file, key="fit")
    for i, r in enumerate((*fits, *shims)):
        key = f"fit[{i}]" if i < len(fits) else f"shim[{i - len(fits)}]"
        for m in sorted(r.reads):
            bad = deps.get(m, set()) & set(sets)
            if bad:
                what = "a factor a fit sets" if m in sets else f"a quantity that depends on {sorted(bad)[0]!r}"
                raise InputError(f"rule {r.name!r} reads {m!r}, {what} (rules read the parts as drawn)",
                                 file=file, key=key)
    return BuildRules(name, desc, tuple(gauges), tuple(fits), tuple(shims), tuple(choices), file, sha, tuple(process))


def _nominal(spec: ToleranceSpec, gauges, quantities, design) -> tuple[dict, dict]:
    """Every name a rule may read at the spec's means (gauge and process factors at their nominal), and the factors
    each depends on: factors, gauges, process factors, the design's numbers (``design.<key>``, base units) and the
    quantities."""
    env = {f.name: np.atleast_1d(f.nominal_base) for f in spec.factors}
    env.update({g.name: np.atleast_1d(g.nominal_base) for g in gauges})
    deps = {n: {n} for n in env}
    for k in (design.params if design is not None else ()):
        v = design[k]
        if isinstance(v, float):
            env[f"design.{k}"] = np.atleast_1d(v)
            deps[f"design.{k}"] = set()
    for q in quantities:
        env[q.name] = np.atleast_1d(np.asarray(q.expression.evaluate(env), dtype=float))
        deps[q.name] = set().union(set(), *(deps.get(m, set()) for m in q.expression.names))
    return env, deps


def extended_spec(spec: ToleranceSpec, rules: BuildRules) -> ToleranceSpec:
    """The spec with the build's gauge errors and process factors appended (independent of every factor)."""
    added = tuple(rules.gauges) + tuple(rules.process)
    if not added:
        return spec
    corr = spec.correlation
    if corr is not None:
        k, g = len(spec), len(added)
        c = np.eye(k + g)
        c[:k, :k] = corr
        corr = c
    return replace(spec, factors=spec.factors + added, correlation=corr)


def _expression(p: Params, key: str, text, known: set[str], local: tuple[str, ...]) -> Expression:
    """The expression ``text`` of the key ``key`` of ``p``: names only what the rule may read, or the located error."""
    try:
        e = Expression.parse(text, what=key)
    except InputError as exc:
        raise p.error(key, exc.reason) from None
    unknown = [m for m in e.names if m not in known and m not in local]
    if unknown:
        raise p.error(key, f"unknown name {unknown[0]!r} in {e.text!r} (a factor of the spec, a gauge, a quantity "
                           f"of the mapping, or {', '.join(local) or 'no local name'})")
    return e


def _sizes(p: Params, key: str, given: list[float] | Steps, unit: str) -> np.ndarray:
    """The sizes of the key ``key`` (a list, or from/to/step) in base units."""
    if isinstance(given, Steps):
        lo, hi, step = given.start, given.stop, given.step
        if not hi > lo:
            raise p.error(key, f"'to' ({hi:g}) must exceed 'from' ({lo:g})")
        k = int(round((hi - lo) / step))
        if abs(lo + k * step - hi) > 1e-9 * max(1.0, abs(hi)):
            raise p.error(key, f"'to' − 'from' ({hi - lo:g}) is not a whole number of steps of {step:g}")
        vals = lo + step * np.arange(k + 1)
    else:
        vals = np.asarray(given, dtype=float)
        if not np.all(np.diff(vals) > 0):
            raise p.error(key, "the sizes must increase strictly")
    return units.to_base(vals, unit)


def _fit(p: Params, spec: ToleranceSpec, known: set[str], nominal: dict) -> SelectiveFit:
    o = read_options(FitTable, p)
    p.finish()
    name, title, sets = o.name, o.name if o.title is None else o.title, o.sets
    if sets not in spec.names:
        raise p.error("sets", f"{sets!r} is not a factor of the spec")
    unit = p.canonical_unit("unit", o.unit, dimension="length")
    sizes = _sizes(p, "sizes", o.sizes, unit)
    minimum = float(units.to_base(o.minimum, unit))
    target = _expression(p, "target", o.target, known, ("minimum",))
    clearance = _expression(p, "clearance", o.clearance, known, ("part",))
    value = _expression(p, "value", o.value, known, ("part", "clearance"))
    rule, source = o.rule, o.source
    # the target and the clearance must state one rule: at the spec's means (gauge errors 0) the clearance
    # with a part of size ``target`` is ``minimum``, and it falls as the part grows
    t = target.evaluate({**nominal, "minimum": minimum})
    c0 = float(np.ravel(clearance.evaluate({**nominal, "part": t}))[0])
    c1 = float(np.ravel(clearance.evaluate({**nominal, "part": t + 1e-3}))[0])
    if not c1 < c0:
        raise p.error("clearance", "the clearance must fall as the part grows (a larger part fits tighter)")
    if not abs(c0 - minimum) <= 1e-9:
        raise p.error("target", f"at the spec's means the clearance with a part of size 'target' is "
                                f"{units.from_base(c0, unit):.6g} {unit}, not the minimum "
                                f"{units.from_base(minimum, unit):.6g} {unit}: target and clearance disagree")
    return SelectiveFit(name, title, sets, sizes, minimum, TargetRule(target), clearance, value, unit, rule, source)


def _shim(p: Params, known: set[str], design) -> ShimPreload:
    o = read_options(ShimTable, p)
    name, title = o.name, o.name if o.title is None else o.title
    unit = p.canonical_unit("unit", o.unit, dimension="length")
    end_play = _expression(p, "end_play", o.end_play, known, ())
    measured = _expression(p, "measured_end_play", o.measured_end_play, known, ())
    shims = _sizes(p, "shims", o.shims, unit)
    steps = np.diff(shims)
    if not np.allclose(steps, steps[0], rtol=1e-9, atol=0.0):
        raise p.error("shims", "a shim rule needs shims in equal steps (give from, to, step)")
    preload = _preload_target(p, design)
    p.finish()
    settling = _expression(p, "settling", o.settling, known, ()) if o.settling is not None else None
    rule, source, key = o.rule, o.source, o.bearing
    try:
        law = PreloadLaw.from_design(design, key)
    except InputError as exc:
        raise p.error("bearing", exc.reason) from None
    return ShimPreload(name, title, end_play, measured, shims, preload, law.interference(preload), law, unit, rule,
                       source, settling)


def _preload_target(p: Params, design) -> float:
    """``preload``: ``{ value, unit }`` or ``{ design = "key" }`` (the design's number, N) — positive."""
    raw = p.raw("preload")
    if isinstance(raw, dict) and "design" in raw:
        sub = p.sub("preload")
        key = sub.str("design")
        sub.finish()
        if design is None or key not in design:
            raise p.error("preload", f"the study's design has no {key!r}")
        v = float(design.value(key, "N"))
        if not v > 0:
            raise p.error("preload", f"the design's {key} is {v:g} N: a preload target must be > 0")
        return v
    return p.quantity("preload", "N", positive=True)


def _nominal_build(fits, nominal: dict) -> dict[str, np.ndarray]:
    """``build.<fit>.part`` and ``build.<fit>.clearance`` of the nominal reducer (every factor at its mean, no
    gauge error), each fit as :meth:`SelectiveFit.choose` makes it."""
    out = {}
    for f in fits:
        r = f.choose(nominal, 1)
        out[f"{PREFIX}{f.name}.part"], out[f"{PREFIX}{f.name}.clearance"] = r.part, r.clearance
    return out


def _choice_value(p: Params, given: float | str, unit: str, built: dict) -> tuple[float, str]:
    """A choice's value in ``unit``: the number written, or its expression of the nominal build (base units)."""
    if not isinstance(given, str):
        return given, ""
    e = _expression(p, "value", given, set(built), ())
    try:
        v = float(np.ravel(e.evaluate(built))[0])
        return float(units.from_base(v, unit)), e.text
    except InputError as exc:
        raise p.error("value", exc.reason) from None


def _choice(p: Params, spec: ToleranceSpec, design, built: dict) -> DesignChoice:
    o = read_options(ChoiceTable, p)
    p.finish()
    name, unit = o.name, p.canonical_unit("unit", o.unit)
    value, formula = _choice_value(p, o.value, unit, built)
    factors, keys = tuple(o.factors), tuple(o.design)
    rule, source = o.rule, o.source
    what = f" = {formula}, the nominal build's" if formula else ""
    if not factors and not keys:
        raise p.error("factors", "a choice names the spec factors and/or design keys that hold its value")
    for f in factors:
        if f not in spec.names:
            raise p.error("factors", f"{f!r} is not a factor of the spec")
        have = units.convert(spec.factor(f).dist.mean, spec.factor(f).unit, unit)
        if not np.isclose(have, value, rtol=CHOICE_RTOL, atol=1e-12):
            raise p.error("value", f"the spec's {f} has the mean {have:.6g} {unit}, not the chosen {value:.6g}{what}")
    for k in keys:
        if design is None or k not in design:
            raise p.error("design", f"the study's design has no {k!r}")
        have = float(design.value(k, unit))
        if not np.isclose(have, value, rtol=CHOICE_RTOL, atol=1e-12):
            raise p.error("value", f"the design's {k} is {have:.6g} {unit}, not the chosen {value:.6g}{what}")
    return DesignChoice(name, value, unit, factors, keys, rule, source, formula)


def _column(v, n: int) -> np.ndarray:
    return np.broadcast_to(np.asarray(v, dtype=float), (n,)).astype(float, copy=True)


def _fmt(x: float) -> str:
    return f"{float(x):.4g}"


__all__ = ["BuildRules", "DesignChoice", "FitResult", "PreloadLaw", "SelectiveFit", "ShimPreload", "ShimResult",
           "extended_spec", "load_build", "usage", "LOCAL_NAMES", "PREFIX"]

