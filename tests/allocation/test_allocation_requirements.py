"""An allocation's ``[[analysis.requirement]]`` tables are read by the requirement schema (issue 38 item 1): listed by
``rvtol kinds allocation``, checked when the options are read, and made into the same requirements as the study's
own ``[[requirement]]`` tables, located at their place in the analysis table."""
from pathlib import Path

import pytest

from rvtol.allocation.analyses import AllocationAnalysis, _requirements
from rvtol.errors import InputError
from rvtol.model_kind import Where
from rvtol.options import describe, read_options
from rvtol.params import Params
from rvtol.spec import requirements_from_tables
from rvtol.spec.requirements import RequirementTable

TABLES = [{"output": "delta_*", "lower": -1.0, "upper": 1.0, "unit": "arcmin", "min_cpk": 1.0},
          {"output": "y", "lower": 2.0, "upper": 3.0, "statistic": "median", "source": "drawing 12"}]


def _table(requirement):
    return Params({"costs": "c.toml", "assign": {"*": "ground_axis"}, "requirement": requirement}, file="s.toml",
                  key="analysis[1]")


def _read(requirement):
    return read_options(AllocationAnalysis.Options, _table(requirement), Where(Path(".")))


def test_the_requirement_tables_keys_are_listed_with_the_allocations():
    keys = [o.key for o in describe(AllocationAnalysis.Options)]
    assert [f"requirement[].{o.key}" for o in describe(RequirementTable)] == [k for k in keys
                                                                             if k.startswith("requirement[].")]
    assert "requirement[].min_cpk" in keys and "requirement[].statistic" in keys


def test_they_make_the_requirements_the_study_tables_make_at_their_own_keys():
    got = _requirements(_read(TABLES).requirement, _table(TABLES).error)
    want = requirements_from_tables(Params({"requirement": TABLES}, file="s.toml", key="analysis[1]")
                                    .tables("requirement"))
    assert got == want and len(got) == 2
    assert [(r.file, r.key) for r in got] == [("s.toml", "analysis[1].requirement[0]"),
                                              ("s.toml", "analysis[1].requirement[1]")]
    assert (got[0].unit, got[0].min_cpk, got[0].min_yield, got[1].statistic) == ("arcmin", 1.0, None, "median")


@pytest.mark.parametrize("bad, key, reason", [
    ({"min_cpk": -1.0}, "min_cpk", "must be > 0"),
    ({"interval": "exact"}, "interval", "expected one of: clopper-pearson, wilson"),
    ({"lowr": 1.0}, "lowr", "unknown key (known here: basis, bound, confidence"),
    ({"lower": 2.0}, "upper", "limits in the wrong order"),
])
def test_a_bad_requirement_is_one_error_at_its_key(bad, key, reason):
    with pytest.raises(InputError) as e:
        _read([TABLES[0], {**TABLES[0], **bad}])
    assert (e.value.file, e.value.key) == ("s.toml", f"analysis[1].requirement[1].{key}") and reason in e.value.reason
