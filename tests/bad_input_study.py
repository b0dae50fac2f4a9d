"""The valid study the bad-input tests break one thing of (tests/cli/test_bad_input.py; also
tests/verdict/test_demonstration.py): the gap study as four files in a folder — study.toml, spec.toml, req.toml and
design.toml — and its run through the real CLI."""
from rvtol.cli import main

from conftest import GAP_MODEL, gap_factors

SPEC = '[spec]\nname = "s"\n' + gap_factors(30.0, mean=0.0)

REQ = """
[[requirement]]
output = "gap"
upper = 40.0
unit = "um"
"""

DESIGN = """
[design]
name = "d"
[pin]
radius = { value = 3.0, unit = "mm", source = "doc 000 Table 1" }
"""

STUDY = """
[study]
name = "t"
spec = "spec.toml"
requirements = "req.toml"
design = "design.toml"
""" + GAP_MODEL + """[sampling]
n = 2000
method = "lhs"
seed = 1
"""


def setup(tmp_path, study=STUDY, spec=SPEC, req=REQ, design=DESIGN):
    for name, text in (("study.toml", study), ("spec.toml", spec), ("req.toml", req), ("design.toml", design)):
        if text is not None:
            (tmp_path / name).write_bytes(text.encode("utf-8", "surrogateescape"))
    return tmp_path / "study.toml"


def run(tmp_path, capsys, path, *extra):
    out = tmp_path / "out"
    rc = main(["run", str(path), "--out", str(out), "--no-pdf", "--executor", "serial", "--quiet", *extra])
    err = capsys.readouterr().err.strip().splitlines()
    return rc, err, out
