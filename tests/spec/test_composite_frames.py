"""Composite position frames (issue 42 item 2, :mod:`rvtol.patterns`): a pattern-locating zone ⌀T₁ and a
feature-relating zone ⌀T₂ read as the pattern's shared translation plus each feature's own deviation."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize

from conftest import assert_refused, write
from rvtol.errors import InputError
from rvtol.inputs.notation import zone_level
from rvtol.models.formula.model import FormulaModel
from rvtol.inputs.table_spec import write_table_spec
from rvtol.patterns import Pattern, PatternModel, feature_spec, frame_extreme, patterns, with_patterns
from rvtol.spec import load_spec
from rvtol.study import load_study, run_study

T1, T2 = 0.5, 0.1        # mm: the frame ⌀0.5 | A | B | C over ⌀0.1 | A


def _feature(name, zone, extra=""):
    return (f'[[factor]]\nname = "{name}"\nunit = "mm"\ntolerance = "⌀{T1}"\nzone = "{zone}"\npattern = "bolts"\n'
            f'feature_relating = "⌀{T2}"\n{extra}\n')


SPEC = "".join(_feature(f"h{k}.{a}", f"h{k}") for k in (1, 2) for a in "xy")
STUDY = """[study]
name = "composite"
spec = "spec.toml"
[sampling]
n = 40000
seed = 3
[model]
kind = "formula"
[[model.output]]
name = "spacing"
unit = "mm"
formula = "h2.x - h1.x"
[[model.output]]
name = "to_datum"
unit = "mm"
formula = "h1.x"
[[model.output]]
name = "mixed"
unit = "mm"
formula = "h1.x + 0.7 * h2.y - 0.4 * h2.x"
[[analysis]]
kind = "stack_conventions"
outputs = "all"
true_worst_case = false
second_order = false
"""


def _exact_by_scipy(a, t1, t2, basic=None):
    """max Σ a_i·p_i over |p_i| ≤ t1/2, |p_i − c − θ J r_i| ≤ t2/2 (θ = 0 without ``basic``, r_i the features' basic
    positions from their centroid) by SLSQP with exact gradients from four starts — independent of cvxpy."""
    a = np.asarray(a, dtype=float)
    n = len(a)
    if basic is None:
        turn = np.zeros((n, 2))
    else:
        r = np.asarray(basic, float) - np.mean(basic, axis=0)
        turn = np.column_stack([-r[:, 1], r[:, 0]]) / np.abs(r).max()      # θ scaled to the farthest feature

    def cons(i):
        def own(z):
            d = z[2 * i:2 * i + 2] - z[2 * n:2 * n + 2] - z[-1] * turn[i]
            return d, (t2 / 2) ** 2 - d @ d

        def own_jac(z):
            d = own(z)[0]
            g = np.zeros(2 * n + 3)
            g[2 * i:2 * i + 2], g[2 * n:2 * n + 2], g[-1] = -2 * d, 2 * d, 2 * d @ turn[i]
            return g

        def loc_jac(z):
            g = np.zeros(2 * n + 3)
            g[2 * i:2 * i + 2] = -2 * z[2 * i:2 * i + 2]
            return g
        return [{"type": "ineq", "fun": lambda z: (t1 / 2) ** 2 - z[2 * i:2 * i + 2] @ z[2 * i:2 * i + 2],
                 "jac": loc_jac}, {"type": "ineq", "fun": lambda z: own(z)[1], "jac": own_jac}]

    constraints = [c for i in range(n) for c in cons(i)]
    rng = np.random.default_rng(0)
    best = -np.inf
    for _ in range(4):
        r = minimize(lambda z: -float(a.ravel() @ z[:2 * n]), rng.normal(scale=t2 / 8, size=2 * n + 3),
                     jac=lambda z: np.r_[-a.ravel(), 0.0, 0.0, 0.0], constraints=constraints, method="SLSQP",
                     options={"ftol": 1e-14, "maxiter": 1000})
        if r.success:
            best = max(best, -r.fun)
    return best


def test_a_composite_frame_is_the_patterns_translation_plus_each_features_own_zone(tmp_path):
    spec = load_spec(write(tmp_path / "spec.toml", SPEC))
    assert spec.names == ("h1.x", "h1.y", "h2.x", "h2.y", "bolts.x", "bolts.y")
    own, shift = spec.factor("h1.x"), spec.factor("bolts.x")
    assert own.limits == pytest.approx((-T2 / 2, T2 / 2)) and own.locating == T1
    assert own.dist.std == pytest.approx(T2 / 2 / zone_level(), rel=1e-12)
    assert shift.zone == "bolts" and shift.limits == pytest.approx((-(T1 - T2) / 2, (T1 - T2) / 2))
    assert shift.dist.std == pytest.approx((T1 - T2) / 2 / zone_level(), rel=1e-12)
    (p,) = patterns(spec.factors)
    assert (p.zones, p.locating, p.relating, p.shift) == (("h1", "h2"), T1, pytest.approx(T2), ("bolts.x", "bolts.y"))
    assert feature_spec(spec).names == spec.names[:4]


def test_the_model_reads_each_feature_at_the_translation_plus_its_own_deviation_and_its_gradient_by_the_chain_rule(
        tmp_path):
    spec = load_spec(write(tmp_path / "spec.toml", SPEC))
    inner = FormulaModel([("y", "h1.x * h2.y + 3 * h2.x", "1")], spec.names[:4], ["1"] * 4)
    model = with_patterns(inner, spec)
    assert isinstance(model, PatternModel) and model.inputs == spec.names
    X = np.random.default_rng(1).normal(scale=0.05, size=(7, 6))
    e1x, e1y, e2x, e2y, sx, sy = X.T
    np.testing.assert_allclose(model.evaluate(X)[:, 0], (e1x + sx) * (e2y + sy) + 3 * (e2x + sx), rtol=1e-13)
    h = 1e-6
    fd = np.stack([(model.evaluate(X + h * np.eye(6)[j]) - model.evaluate(X - h * np.eye(6)[j]))[:, 0] / (2 * h)
                   for j in range(6)], axis=1)
    np.testing.assert_allclose(model.gradient(X)[:, 0, :], fd, rtol=1e-7, atol=1e-9)
    assert model.dependencies() == {"y": frozenset({"h1.x", "h2.x", "h2.y", "bolts.x", "bolts.y"})}   # not h1.y
    with pytest.raises(InputError, match="without the pattern's translation"):
        with_patterns(inner, feature_spec(spec))


def test_the_study_reproduces_the_handbook_rules_and_the_frames_own_extreme(tmp_path):
    write(tmp_path / "spec.toml", SPEC)
    st = load_study(write(tmp_path / "study.toml", STUDY), executor="serial", progress=False, pdf=False)
    res = run_study(st)
    se, ss = T2 / 2 / zone_level(), (T1 - T2) / 2 / zone_level()
    Y = res.mc.Y
    # Monte Carlo: two features of one pattern vary by their own zones only; a feature to the datums by both
    assert Y[:, 0].std() == pytest.approx(math.sqrt(2) * se, rel=0.02)
    assert Y[:, 1].std() == pytest.approx(math.hypot(se, ss), rel=0.02)
    rows = {o: {c["convention"]: c for c in s["conventions"]}
            for o, s in next(s for s in res.sections if s.key == "stack_conventions").summary.items()}
    # the worst case: feature to feature ±T₂ (the FRTZF), feature to datums ±T₁/2 (the PLTZF) — Drake 1999 ch. 5
    for out, half in (("spacing", T2), ("to_datum", T1 / 2)):
        for conv in ("worst case (arithmetic)", "worst case (GD&T domains)"):
            assert (rows[out][conv]["low"], rows[out][conv]["high"]) == pytest.approx((-half, half), abs=1e-7)
    # a mixed combination: the frame admits more than its decomposition; the row is the frame's extreme
    a = np.array([[1.0, 0.0], [-0.4, 0.7]])
    exact = _exact_by_scipy(a, T1, T2)
    decomposed = (T1 - T2) / 2 * np.linalg.norm(a.sum(0)) + T2 / 2 * np.linalg.norm(a, axis=1).sum()
    assert exact > decomposed * 1.05
    assert rows["mixed"]["worst case (arithmetic)"]["high"] == pytest.approx(decomposed, rel=1e-12)
    assert rows["mixed"]["worst case (GD&T domains)"]["high"] == pytest.approx(exact, rel=1e-6)
    assert rows["mixed"]["worst case (GD&T domains)"]["low"] == pytest.approx(-exact, rel=1e-6)


@pytest.mark.parametrize("seed", range(4))
def test_the_frames_extreme_is_an_independent_optimisers(seed):
    rng = np.random.default_rng(seed)
    n = 2 + seed % 3
    a = rng.normal(size=(n, 2))
    p = Pattern("p", tuple(f"z{i}" for i in range(n)), 0.8, 0.25, "mm")
    frame, decomposition = frame_extreme(p, a)
    assert frame == pytest.approx(_exact_by_scipy(a, 0.8, 0.25), rel=1e-6)
    assert decomposition == pytest.approx(0.275 * np.linalg.norm(a.sum(0)) + 0.125 * np.linalg.norm(a, axis=1).sum())
    assert frame >= decomposition


def test_a_spreadsheets_composite_frame_is_the_tomls_and_survives_an_export(tmp_path):
    toml = load_spec(write(tmp_path / "spec.toml", SPEC))
    rows = ["name,unit,tolerance,zone,pattern,feature relating"] + [
        f"h{k}.{a},mm,⌀{T1},h{k},bolts,⌀{T2}" for k in (1, 2) for a in "xy"]
    csv = load_spec(write(tmp_path / "spec.csv", "\n".join(rows) + "\n"))
    assert csv.factors == toml.factors
    write_table_spec(toml, tmp_path / "out.xlsx")
    back = load_spec(tmp_path / "out.xlsx")
    assert back.factors == toml.factors and back.names == toml.names


BAD = [
    ('feature_relating = "⌀0.1"\n', "", "factor[0].feature_relating", "needs both pattern"),
    ('pattern = "bolts"\n', "", "factor[0].pattern", "needs both pattern"),
    ('feature_relating = "⌀0.1"', 'feature_relating = "⌀0.5"', "factor[0].feature_relating", "must be smaller"),
    ('feature_relating = "⌀0.1"', 'feature_relating = "⌀0.1 (M)"', "factor[0].feature_relating",
     "different material conditions"),
    ('feature_relating = "⌀0.1"', 'feature_relating = "±0.05"', "factor[0].feature_relating", "not a position zone"),
    ('feature_relating = "⌀0.1"', 'feature_relating = 0.1', "factor[0].feature_relating", "expected a position zone"),
    ('pattern = "bolts"', 'pattern = "h2"', "factor.pattern", "also the name of a position zone"),
    ('pattern = "bolts"', 'pattern = "b*lts"', "factor[0].pattern", "invalid pattern name"),
]


@pytest.mark.parametrize("old,new,key,words", BAD)
def test_a_composite_frame_written_wrong_is_one_located_line(tmp_path, capsys, old, new, key, words):
    p = write(tmp_path / "spec.toml", SPEC.replace(old, new))      # every feature alike: the first one read is refused
    assert_refused(p, write(tmp_path / "study.toml", STUDY), capsys, key, words)


def test_one_pattern_with_two_frames_and_a_clashing_translation_name_are_refused(tmp_path):
    two = SPEC.replace('name = "h2.x"\nunit = "mm"\ntolerance = "⌀0.5"', 'name = "h2.x"\nunit = "mm"\ntolerance = "⌀0.6"')
    two = two.replace('name = "h2.y"\nunit = "mm"\ntolerance = "⌀0.5"', 'name = "h2.y"\nunit = "mm"\ntolerance = "⌀0.6"')
    with pytest.raises(InputError, match="carry different frames"):
        load_spec(write(tmp_path / "a.toml", two))
    clash = SPEC + '[[factor]]\nname = "bolts.x"\nunit = "mm"\nnominal = 0\ntolerance = "±0.1"\n'
    with pytest.raises(InputError, match="already a factor's name") as ei:
        load_spec(write(tmp_path / "b.toml", clash))
    assert ei.value.key == "factor.pattern"


def _mmc_pattern(extra=""):
    """The independent audit's case: two holes ⌀10 +0.1/0 under ⌀0.5 (M) | A | B (M) | C over ⌀0.1 (M) A B, datum bore
    B ⌀20 +0.2/0 at MMB (its departure shifts the pattern by up to 0.1)."""
    rows = ['[[factor]]\nname = "B.d"\nunit = "mm"\ntolerance = "20 +0.2/0"\n']
    for k in (1, 2):
        rows.append(f'[[factor]]\nname = "h{k}.d"\nunit = "mm"\ntolerance = "10 +0.1/0"\n')
        for a in "xy":
            rows.append(f'[[factor]]\nname = "h{k}.{a}"\nunit = "mm"\ntolerance = "⌀0.5 (M)"\nzone = "h{k}"\n'
                        f'pattern = "P"\nfeature_relating = "⌀0.1 (M) A B"\nsize = "h{k}.d"\nfeature_type = "internal"\n'
                        f'datum_size = "B.d"\ndatum_type = "internal"\n{extra}')
    return "".join(rows)


@pytest.mark.parametrize("extra", ["", "separate = true\n"], ids=["simultaneous", "SEP REQT"])
def test_a_composite_frame_on_a_datum_at_mmb_takes_the_shift_once(tmp_path, extra):
    """The audit's D1: the pattern's translation carried the datum shift a second time (h1.x ±0.5). By hand: a hole to
    the datums moves by its locating zone's radius with its bonus, 0.25 + 0.05, plus the shift 0.1 — ±0.4, what the
    same zone without a pattern gives; two holes of the frame to each other by 2 × (0.05 + 0.05) — the shift moves the
    frame as one, a separate requirement of the whole frame too."""
    from rvtol.spec import datum_shifts
    from rvtol.stacking import stack_conventions
    from rvtol.stacking.slopes import one_sided_slopes

    spec = load_spec(write(tmp_path / "s.toml", _mmc_pattern(extra)))
    assert [(d.zones, d.separate) for d in datum_shifts(spec)] == [(("h1", "h2"), "P" if extra else "")]
    x0 = spec.nominal_base()
    for formula, half in (("h1.x", 0.4), ("h2.x - h1.x", 0.2)):
        inner = FormulaModel.from_spec(feature_spec(spec), {"y": (formula, "mm")})
        m = with_patterns(inner, spec)
        sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], 0.0, x0, out_unit="mm",
                               slopes=one_sided_slopes(m, spec, "y"))
        wc = sc.row("worst case (arithmetic)")
        assert (wc["low"], wc["high"]) == (pytest.approx(-half, abs=1e-9), pytest.approx(half, abs=1e-9)), formula


def test_the_frames_lower_line_keeps_its_datums_and_a_framework_free_to_rotate_is_said(tmp_path):
    held = SPEC.replace('feature_relating = "⌀0.1"', 'feature_relating = "⌀0.1 A|B"')
    spec = load_spec(write(tmp_path / "held.toml", held))
    assert spec.factor("h1.x").datums == ("A", "B") and not patterns(spec.factors)[0].may_rotate
    write_table_spec(spec, tmp_path / "held.csv")
    assert load_spec(tmp_path / "held.csv").factors == spec.factors
    write(tmp_path / "spec.toml", SPEC.replace('feature_relating = "⌀0.1"', 'feature_relating = "⌀0.1 A"'))
    res = run_study(load_study(write(tmp_path / "study.toml", STUDY.replace("n = 40000", "n = 500")),
                               executor="serial", progress=False, pdf=False))
    notes = next(s for s in res.sections if s.key == "stack_conventions").summary["mixed"]["notes"]
    assert any("pattern bolts's feature-relating line references A: its framework may also rotate" in n for n in notes)
    write(tmp_path / "spec.toml", held)
    res = run_study(load_study(tmp_path / "study.toml", executor="serial", progress=False, pdf=False))
    notes = next(s for s in res.sections if s.key == "stack_conventions").summary["mixed"]["notes"]
    assert not any("may also rotate" in n for n in notes)


def test_one_frame_written_in_mm_and_in_micrometres_is_one_frame(tmp_path):
    """The audit's test 10: the same frame, ⌀500/⌀100 µm on one hole's rows, ⌀0.5/⌀0.1 mm on the other's."""
    rows = ["name,unit,tolerance,zone,pattern,feature relating", "h1.x,mm,⌀0.5,h1,P,⌀0.1 A B",
            "h1.y,mm,⌀0.5,h1,P,⌀0.1 A B", "h2.x,um,⌀500,h2,P,⌀100 A B", "h2.y,um,⌀500,h2,P,⌀100 A B"]
    spec = load_spec(write(tmp_path / "s.csv", "\n".join(rows) + "\n"))
    (p,) = patterns(spec.factors)
    assert p.zones == ("h1", "h2") and spec.factor("P.x").unit == "mm"
    m = with_patterns(FormulaModel.from_spec(feature_spec(spec), {"y": ("h2.x - h1.x", "mm")}), spec)
    X = np.zeros((1, len(spec)))
    X[0, spec.index("P.x")] = 0.02               # the translation moves both holes alike (base units, mm)
    X[0, spec.index("h2.x")] = 0.003
    assert m.evaluate(X)[0, 0] == pytest.approx(0.003, abs=1e-15)


def test_a_framework_free_to_rotate_turns_in_the_worst_case_over_the_frame(tmp_path):
    """The audit's D4: the cover's frame ⌀0.5 | A | B | C over ⌀0.1 | A lets the framework rotate about A. With the
    holes' basic positions (the 80 mm square) the GD&T-domains row takes a small rotation about the pattern's centre
    too: the tilt h2.y − h1.y reaches far more than the translation alone allows — checked against SLSQP."""
    rows = ["name,unit,tolerance,zone,pattern,feature relating,basic"]
    square = {1: (-40, -40), 2: (40, -40), 3: (40, 40), 4: (-40, 40)}
    for k, (bx, by) in square.items():
        rows += [f"h{k}.x,mm,⌀0.5,h{k},P,⌀0.1 A,{bx}", f"h{k}.y,mm,⌀0.5,h{k},P,⌀0.1 A,{by}"]
    spec = load_spec(write(tmp_path / "s.csv", "\n".join(rows) + "\n"))
    (p,) = patterns(spec.factors)
    assert p.may_rotate and p.basic == tuple(square[k] for k in (1, 2, 3, 4))
    write_table_spec(spec, tmp_path / "out.xlsx")
    assert load_spec(tmp_path / "out.xlsx").factors == spec.factors
    a = np.zeros((4, 2))
    a[0] = (0.25, -1.0)
    a[1] = (0.25, 1.0)
    a[2:, 0] = 0.25                                      # the study's centre_offset: mean x plus the tilt
    frame, decomposition = frame_extreme(p, a)
    assert frame == pytest.approx(_exact_by_scipy(a, T1, T2, basic=list(square.values())), rel=1e-6)
    held = Pattern("P", p.zones, T1, T2, "mm", ("A", "B"), p.basic)
    assert frame > frame_extreme(held, a)[0] * 1.2      # the rotation: 0.434 against the translation's 0.347
    with pytest.raises(InputError, match="basic is given for some features") as ei:
        load_spec(write(tmp_path / "t.csv", "\n".join(rows[:-1] + ["h4.y,mm,⌀0.5,h4,P,⌀0.1 A,"]) + "\n"))
    assert ei.value.key == "factor.basic"


def test_one_composite_pattern_is_one_frame_and_one_frames_zones_are_alike(tmp_path):
    """The second audit's N3 and N1: a composite pattern split over two SEP REQT frames (its spacing then took two
    shifts, ±0.3 for ±0.1) and two zones of one frame with different diameters were accepted."""
    from rvtol.spec import spec_from_table

    split = SPEC.replace('zone = "h1"\npattern = "bolts"', 'zone = "h1"\npattern = "bolts"\nframe = "X"')
    with pytest.raises(InputError, match="its features name different frames") as ei:
        load_spec(write(tmp_path / "split.toml", split))
    assert ei.value.key == "factor.frame"
    zone = lambda n, z, t: {"name": n, "unit": "mm", "tolerance": t, "zone": z, "frame": "F"}  # noqa: E731
    with pytest.raises(InputError, match="differ in diameter or modifier") as ei:
        spec_from_table({"factor": [zone("x1", "h1", "⌀0.5"), zone("y1", "h1", "⌀0.5"), zone("x2", "h2", "⌀0.3"),
                                    zone("y2", "h2", "⌀0.3")]})
    assert ei.value.key == "factor.frame"
    # one frame in mm on one zone, in µm on the other: one frame
    um = {"name": "x2", "unit": "um", "tolerance": "⌀500", "zone": "h2", "frame": "F"}
    spec_from_table({"factor": [zone("x1", "h1", "⌀0.5"), zone("y1", "h1", "⌀0.5"), um, dict(um, name="y2")]})
    # the upper line's datum letters are read and left to datum_size
    assert spec_from_table({"factor": [zone("x", "h", "⌀0.5 A B C"), zone("y", "h", "⌀0.5 A|B|C")]}).factor(
        "x").limits == pytest.approx((-0.25, 0.25))


def test_a_feature_of_size_has_one_type_wherever_it_is_named():
    """The second audit: a size internal for one zone and external for another, or for a zone and an envelope, was
    accepted."""
    from rvtol.spec import spec_from_table

    def zone(n, z, ftype):
        return {"name": n, "unit": "mm", "tolerance": "⌀0.2 (M)", "zone": z, "size": "D", "feature_type": ftype}
    base = [{"name": "D", "unit": "mm", "tolerance": "10 +0.1/0"}]
    with pytest.raises(InputError, match="one feature has one type") as ei:
        spec_from_table({"factor": base + [zone("x1", "h1", "internal"), zone("y1", "h1", "internal"),
                                           zone("x2", "h2", "external"), zone("y2", "h2", "external")]})
    assert ei.value.key == "factor.feature_type"
    form = {"name": "f", "unit": "mm", "tolerance": "⌭0.01", "envelope": "D", "feature_type": "external"}
    with pytest.raises(InputError, match="one feature has one type"):
        spec_from_table({"factor": base + [zone("x1", "h1", "internal"), zone("y1", "h1", "internal"), form]})


def test_a_plain_zone_in_a_composite_patterns_frame_and_modifiers_without_brackets(tmp_path):
    """The third audit: N-a, a plain ⌀0.5 zone in the frame of a composite pattern ⌀0.5/⌀0.1 was refused as 'a different
    diameter' (compared with the features' ⌀0.1); N-b, '⌀0.5 M' read M as a datum letter and dropped the bonus."""
    from rvtol.spec import spec_from_table

    g = ('[[factor]]\nname = "g.x"\nunit = "mm"\ntolerance = "⌀0.5"\nzone = "g"\nframe = "bolts"\n'
         '[[factor]]\nname = "g.y"\nunit = "mm"\ntolerance = "⌀0.5"\nzone = "g"\nframe = "bolts"\n')
    assert "g.x" in load_spec(write(tmp_path / "s.toml", SPEC + g)).names
    zone = lambda t: [{"name": c, "unit": "mm", "tolerance": t, "zone": "h"} for c in "xy"]  # noqa: E731
    for text, words in (("⌀0.5 M", "reads as a datum letter or as a material condition"),
                        ("⌀0.5 M A B", "reads as a datum letter or as a material condition"),
                        ("⌀0.5 A A", "names a datum twice"),
                        ("⌀0.5 (M) A (M) B", "a datum's material condition is not read")):
        with pytest.raises(InputError, match=words.replace("(", r"\(")) as ei:
            spec_from_table({"factor": zone(text)})
        assert ei.value.key == "factor[0].tolerance", text
