"""The adjustment / allocation / reproduction analyses inside a study, and their bad inputs."""
import json
import math
import textwrap

import numpy as np
import pytest

from rvtol.models.adjustment import AdjustedAssemblyModel, load_assembly
from rvtol.errors import InputError
from rvtol.study import load_study, run_study

from conftest import BX40E_STUDY_HEAD, needs_wing, write

STUDY = BX40E_STUDY_HEAD + textwrap.dedent("""
    [[analysis]]
    kind = "adjustment"
    part_errors = "example.part_errors"
    sweep_points = 5
    [[analysis]]
    kind = "allocation"
    key = "alloc3d"
    costs = "{root}/data/costs/bx40e_angular.toml"
    spec = "{root}/data/specs/bx40e_assembly_3d.toml"
    groups = ["Crankshaft 1", "Cycloid Gear 1", "Crankshaft 2", "Cycloid Gear 2"]
    assign = { "*" = "ground_axis" }
    [analysis.model]
    kind = "adjusted_assembly"
    assembly = "{root}/data/assemblies/bx40e_3d.toml"
    [[analysis.requirement]]
    output = "delta_*"
    lower = -1.0
    upper = 1.0
    unit = "arcmin"
    min_cpk = 1.0
    [analysis.ga]
    n = 200
    population = 8
    parents = 4
    generations = 3
    [analysis.verify]
    n = 300
    [analysis.pareto]
    scales = [1.0, 2.0]
    [[analysis]]
    kind = "adjustment_reproduction"
    printed = "{root}/data/reproduction/doc002_adjustment.toml"
    assembly_3d = "{root}/data/assemblies/bx40e_3d.toml"
    allocation = "alloc3d"
""")


#: the study without the wing's analysis (adjustment_reproduction): what the allocation's own checks need
CORE_STUDY = STUDY[:STUDY.index('[[analysis]]\nkind = "adjustment_reproduction"')]


def _path(tmp_path, root, text):
    return write(tmp_path / "s.toml", text.replace("{root}", str(root)))


@needs_wing
def test_small_study_runs_and_its_summary_is_json(tmp_path, root):
    study = load_study(_path(tmp_path, root, STUDY), executor="serial", progress=False)
    res = run_study(study)
    keys = [s.key for s in res.sections]
    assert keys == ["adjustment", "alloc3d_costs", "alloc3d", "adjustment_reproduction"]
    summ = {s.key: s.summary for s in res.sections}
    json.dumps(summ, allow_nan=False)
    methods = {m["method"]: m for m in summ["alloc3d"]["methods"]}
    assert set(methods) == {"uniform", "convex rss", "GA"}
    assert methods["convex rss"]["total cost [relative]"] <= methods["uniform"]["total cost [relative]"]
    rows = {r["item"]: r for r in summ["adjustment_reproduction"]["rows"]}
    assert rows["P1 coefficient of v1x"]["printed"] == 0.3069
    assert rows["two tightest components"]["reproduced"] == "yes"


@pytest.mark.parametrize("old,new,key,reason", [
    ('assign = { "*" = "ground_axis" }', 'assign = { "*" = "diamond" }', "analysis[1].assign.*",
     "unknown cost curve"),
    ('assign = { "*" = "ground_axis" }', 'assign = { "Crankshaft 1" = "ground_axis" }', "analysis[1].assign",
     "no cost curve for factor"),
    ('assign = { "*" = "ground_axis" }', 'assign = { "*" = "ground_axis", "Gearbox" = "ground_axis" }',
     "analysis[1].assign.Gearbox", "neither a factor, a family, a pattern"),
    ('groups = ["Crankshaft 1",', 'groups = ["Crankshaft 9",', "analysis[1].groups", "unknown group"),
    ('output = "delta_*"', 'output = "gamma_*"', "analysis[1].requirement[0].output", "matches no output"),
    ('[analysis.ga]\n', '[analysis.ga]\nconstraint = "never"\n', "analysis[1].ga.constraint", "unknown value"),
    ('[analysis.ga]\n', '[analysis.ga]\nhandling = "ignore"\n', "analysis[1].ga.handling", "unknown value"),
    ('parents = 4', 'parents = 40', "analysis[1].ga.parents", "parents must lie"),
    ('[analysis.ga]\n', '[analysis.ga]\nconstraint = "linearised"\nconfirm = true\n', "analysis[1].ga.confirm",
     "needs the Monte Carlo constraint"),
    ('groups = ["Crankshaft 1",', 'tie = "coordinates"\ngroups = ["Crankshaft 1",', "analysis[1].tie", "unknown value"),
    ('scales = [1.0, 2.0]', 'scales = [1.0, -2.0]', "analysis[1].pareto.scales[1]", "> 0"),
    ('costs = "{root}/data/costs/bx40e_angular.toml"', 'costs = "{root}/data/costs/none.toml"', "-",
     "file not found"),
    # the reproduction's requires = {"allocation": "allocation"}: the key it names is checked
    pytest.param('allocation = "alloc3d"', 'allocation = "alloc9"', "analysis[2].allocation",
                 "no other analysis has the key 'alloc9' (the study's: 'adjustment', 'alloc3d')", marks=needs_wing),
    pytest.param('allocation = "alloc3d"', 'allocation = "adjustment"', "analysis[2].allocation",
                 "analysis 'adjustment' is a 'adjustment' analysis, not 'allocation'", marks=needs_wing),
])
def test_bad_allocation_inputs(tmp_path, root, old, new, key, reason):
    text = STUDY if key.startswith("analysis[2]") else CORE_STUDY
    assert old in text, old
    with pytest.raises(InputError) as ei:
        load_study(_path(tmp_path, root, text.replace(old, new, 1)))
    assert ei.value.key == key, (ei.value.key, ei.value.reason)
    assert reason in ei.value.reason


@needs_wing
def test_an_analysis_runs_after_the_analyses_it_requires_whatever_the_files_order(tmp_path, root):
    head, rest = STUDY.split("[[analysis]]\nkind = \"allocation\"", 1)
    alloc, repro = rest.split("[[analysis]]\nkind = \"adjustment_reproduction\"", 1)
    reordered = head + "[[analysis]]\nkind = \"adjustment_reproduction\"" + repro.rstrip("\n") + "\n" \
        + "[[analysis]]\nkind = \"allocation\"" + alloc
    study = load_study(_path(tmp_path, root, reordered), execute=False)
    assert [a.key for a in study.analyses] == ["adjustment", "alloc3d", "adjustment_reproduction"]


def test_analyses_that_require_each_other_are_a_located_error():
    from dataclasses import dataclass

    from rvtol.analysis import Analysis, CommonOptions, in_dependency_order
    from rvtol.options import option
    from rvtol.params import Params

    class Reader(Analysis):
        kind = "reader"
        requires = {"source": None}

        @dataclass
        class Options(CommonOptions):
            source: str | None = option(None, "the key of the analysis read")

    tables = [Params({"kind": "reader", "key": k, "source": src}, file="s.toml", key=f"analysis[{i}]")
              for i, (k, src) in enumerate([("a", "c"), ("b", "a"), ("c", "b"), ("d", None)])]
    analyses = [Reader(t, None) for t in tables]
    with pytest.raises(InputError) as ei:
        in_dependency_order(analyses, tables)
    assert ei.value.key == "analysis[0].source" and "in a cycle: a → b → c" in ei.value.reason
    chain = [Reader(t, None) for t in tables[1:]]          # b reads a (absent), ...
    with pytest.raises(InputError) as ei:
        in_dependency_order(chain, tables[1:])
    assert ei.value.key == "analysis[1].source" and "no other analysis has the key 'a'" in ei.value.reason


#: the allocation analysis of the small studies below (one cost curve for every factor)
ALLOCATION = """[[analysis]]
kind = "allocation"
costs = "costs.toml"
assign = { "*" = "turning" }
"""

SET_ASIDE = """
[study]
name = "set_aside"

[model]
kind = "linear"

[[model.output]]
name = "y"
unit = "mm"
display_unit = "um"
coefficients = { b = 1.0 }

[[model.output]]
name = "z"
unit = "mm"
display_unit = "um"
coefficients = { a = 1.0 }

[[factor]]
name = "a"
unit = "um"
dist = "normal"
mean = 10.0
tolerance = 6.0

[[factor]]
name = "b"
unit = "um"
dist = "normal"
mean = 0.0
tolerance = 6.0

[[requirement]]
name = "y within ±3 um"
output = "y"
lower = -3.0
upper = 3.0
unit = "um"
min_cpk = 1.0
basis = "estimate"

[[requirement]]
name = "z at most 5 um"
output = "z"
upper = 5.0
unit = "um"
min_cpk = 1.0
basis = "estimate"

""" + ALLOCATION + """[analysis.ga]
constraint = "none"
[analysis.verify]
n = 2000
[analysis.pareto]
scales = [1.0]

[sampling]
n = 200
seed = 3
"""

COSTS = """
[costs]
name = "test"
cost_unit = "relative"
[[curve]]
name = "turning"
kind = "reciprocal_power"
unit = "um"
data = { tolerance = [0.5, 1, 2, 4, 10], cost = [9.0, 5.0, 3.0, 2.0, 1.4] }
bounds = [0.5, 10]
"""


def test_a_requirement_the_nominal_misses_is_set_aside_with_its_levers(tmp_path):
    """z = a with a's mean 10 µm > 5: no tolerance meets it; it is set aside and its lever (by hand: shift a by
    5 − 3σ_a − 10 = −8 µm; tolerance 6 µm is the full band ±3σ, σ_a = 1) reported; y = b is allocated alone: |y| ≤ 3 µm at Cpk 1 gives ±t_b = 3σ_b = 3 µm
    (the constraint's closed form), and a, which y does not see, goes to the curve's loosest 10 µm."""
    write(tmp_path / "costs.toml", COSTS)
    study = load_study(write(tmp_path / "s.toml", SET_ASIDE), executor="serial", progress=False)
    res = run_study(study)
    summ = {s.key: s.summary for s in res.sections}["allocation"]
    assert summ["set_aside"] == [r.label for r in study.requirements if r.output == "z"]
    methods = {m["method"]: m for m in summ["methods"]}
    assert methods["convex rss"]["status"].startswith("optimal")
    t = {row["factor"]: row["t convex rss (±)"] for row in summ["tolerances"]}
    assert t["b"] == pytest.approx(3.0, rel=1e-4) and t["a"] == pytest.approx(10.0, rel=1e-6)
    (lever,) = next(iter(summ["design_levers"].values()))
    # measured from the study's Monte Carlo: 5 − 3σ̂_z − z̄ (z = a exactly, dz/da = 1), ≈ −8 by hand
    z = res.mc.column("z")
    assert lever["lever (mean shift of)"] == "a" and lever["copies shifted alike"] == 1
    assert lever["shift needed alone"] == pytest.approx(5.0 - 3.0 * np.std(z, ddof=1) - np.mean(z), rel=1e-9)
    assert lever["shift needed alone"] == pytest.approx(-8.0, abs=4 * 4 / np.sqrt(200))
    # the check: a fresh Monte Carlo run with a's mean shifted — z̄ moves by the shift (z = a), σ stays
    (chk,) = summ["design_levers_checked"]
    assert chk["lever"] == "a" and chk["n"] == 200
    assert chk["mean after"] == pytest.approx(10.0 + lever["shift needed alone"], abs=4 / np.sqrt(200))
    assert chk["σ after"] == pytest.approx(1.0, rel=0.2)
    # the first page's checked redesign fix: there exactly when the shifted design's Monte Carlo passed
    sec = next(s for s in res.sections if s.key == "allocation")
    redesign = [f for f in sec.fixes if f.kind == "redesign"]
    assert [(f.requirement, f.checked, f.source) for f in redesign] == ([(chk["requirement"], True, "allocation")]
                                                                        if chk["passed"] else [])


MAGNITUDE = """
[study]
name = "magnitude"

[model]
kind = "formula"
[[model.output]]
name = "r"
formula = "hypot(u, v)"
unit = "um"

[[factor]]
name = "u"
unit = "um"
dist = "normal"
mean = 0.0
tolerance = 6.0

[[factor]]
name = "v"
unit = "um"
dist = "normal"
mean = 0.0
tolerance = 6.0

[[requirement]]
name = "radial offset at most 3 um"
output = "r"
upper = 3.0
unit = "um"
min_yield = 0.99
basis = "estimate"

""" + ALLOCATION + """[analysis.ga]
constraint = "monte_carlo"
n = 4000
population = 8
parents = 4
generations = 4
[analysis.verify]
n = 2000
all_requirements = true

[sampling]
n = 400
seed = 3
"""


def test_a_magnitude_output_is_not_linearised_and_the_monte_carlo_constraint_remains(tmp_path):
    """r = hypot(u, v) at the nominal (0, 0): five-point derivatives 0, first-order σ 0 against the Monte Carlo's
    σ_r = σ √(2 − π/2) (Rayleigh, σ = 1 µm): the linearised methods are unavailable; the uniform scale on the
    Monte Carlo constraint is the closed form: P(r ≤ 3) = 1 − exp(−9 / 2σ²) ≥ 0.99  ⇔  σ ≤ 3/√(2 ln 100) = 0.9885,
    ±t = 3σ = 2.966 µm (within the constraint's sampling error at n = 4000)."""
    write(tmp_path / "costs.toml", COSTS)
    res = run_study(load_study(write(tmp_path / "s.toml", MAGNITUDE), executor="serial", progress=False))
    sec = next(s for s in res.sections if s.key == "allocation")
    methods = {m["method"]: m for m in sec.summary["methods"]}
    assert methods["convex rss"]["status"] == "not linearisable"
    t = {row["factor"]: row["t uniform (±)"] for row in sec.summary["tolerances"]}
    sigma = 3.0 / math.sqrt(2 * math.log(100))
    # the yield's standard error at n = 4000 is sqrt(0.99·0.01/4000) = 0.0016 (random sampling; LHS is no worse);
    # dP/dσ at the solution = exp(−9/2σ²)·9/σ³ = 0.093 per µm, so σ is good to ± 3 × 0.0016/0.093 ≈ 0.05 µm and
    # ±t = 3σ to ± 0.15 µm
    assert t["u"] == pytest.approx(3 * sigma, abs=0.15) and t["v"] == t["u"]
    (row,) = sec.summary["all_requirements"]["rows"]
    assert row["output"] == "r" and checks_passed(sec, sec.summary["all_requirements"]["method"])
    # beside it, the study's own Monte Carlo at the spec (σ = 1 µm): P(r ≤ 3) = 1 − exp(−4.5), n = 400
    assert row["yield at the spec"] == pytest.approx(1 - math.exp(-4.5), abs=4 * math.sqrt(0.01 * 0.99 / 400))
    # the first page's checked tighten fix: the verified allocation demonstrates the requirement
    (fix,) = sec.fixes
    assert (fix.requirement, fix.kind, fix.checked, fix.source) == ("radial offset at most 3 um", "tighten", True,
                                                                     "allocation")
    allreq = sec.summary["all_requirements"]
    assert allreq["method"] in fix.action and f"n = {allreq['n']}" in fix.effect


def checks_passed(sec, method) -> bool:
    """Whether ``method``'s own independent check passed (the table of checks in the summary)."""
    return next(m for m in sec.summary["methods"] if m["method"] == method)["independent MC"] == "pass"


def test_a_monte_carlo_constraint_too_small_to_demonstrate_the_yield_is_a_one_line_error(tmp_path):
    """yield ≥ 0.99 on the 95 % one-sided Clopper–Pearson bound needs ⌈ln 0.05 / ln 0.99⌉ = 299 samples with no
    failure (success run): n = 200 could never pass, whatever the tolerances."""
    write(tmp_path / "costs.toml", COSTS)
    text = MAGNITUDE.replace('basis = "estimate"', 'basis = "lower_bound"').replace("n = 4000", "n = 200")
    with pytest.raises(InputError) as ei:
        load_study(write(tmp_path / "s.toml", text))
    assert ei.value.key == "analysis[0].ga.n" and "use n ≥ 299" in ei.value.reason
    assert math.ceil(math.log(0.05) / math.log(0.99)) == 299
