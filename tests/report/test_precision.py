"""Issue 37, item 9: numbers shown to the precision their tolerance needs, not four significant digits — a mean of
19.994 mm on a 12-µm band read 19.99; a baseline diff of a 5-µm shift read "μ=42.01 → μ=42"."""
import json
import re

import pandas as pd
import pytest

from rvtol.cli import main
from rvtol.precision import Scaled, decimals, output_scale, shown


@pytest.mark.parametrize("scale,d", [(0.012, 4), (0.1, 3), (1.0, 2), (100.0, 0), (2500.0, 0), (0.0004, 6),
                                     (None, None), (0.0, None), (-1.0, None), (float("nan"), None)])
def test_decimals_resolve_a_hundredth_of_the_scale(scale, d):
    """By hand: 10^-d ≤ scale/100 < 10^-(d-1) — 0.012/100 = 1.2e-4 needs 4 decimals (1e-4); 0.1/100 = 1e-3 exactly 3."""
    assert decimals(scale) == d
    if d:
        assert 10.0 ** -d <= scale / 100 * (1 + 1e-12) and scale / 100 < 10.0 ** -(d - 1)


def test_shown_resolves_the_band_and_never_shows_fewer_than_four_digits():
    assert shown(19.994, 0.012) == "19.9940" and f"{19.994:.4g}" == "19.99"       # what 4 digits gave
    assert shown(0.01667, 0.1) == "0.01667"                       # σ keeps its four digits (0.017 would lose some)
    assert shown(60.0, 0.1) == "60.000" and shown(0.0031, 5.8) == "0.00310"        # 4 digits, 3 decimals more...
    assert shown(-1e-15, 0.1) == "0.000000"                                      # ... at most: round-off reads 0
    assert shown(123456.7, None) == "1.235e+05" and shown(None, 1.0) == "—" and shown(float("inf"), 1) == "—"
    assert output_scale([(19.988, 20.0), (None, 20.5), (19.9, 20.1)], 0.5) == pytest.approx(0.012)
    assert output_scale([(None, 20.5)], 0.0007) == 0.0007 and output_scale([], 0.0) is None
    x = Scaled(42.005, 0.02)
    assert (f"{x:.4g}", f"{x:+.3g}", f"{x:g}", f"{x:.2f}") == ("42.0050", "+42.0050", "42.0050", "42.01")


STUDY = """[study]
name = "mu"
[[factor]]
name = "l"
unit = "mm"
nominal = {nominal}
tolerance = "±0.002"
[model]
kind = "formula"
[[model.output]]
name = "length"
formula = "l"
unit = "mm"
[[requirement]]
name = "length"
output = "length"
lower = 19.988
upper = 20.000
unit = "mm"
min_yield = 0.9
[sampling]
n = 400
seed = 1
[execution]
executor = "serial"
[report]
pdf = false
"""


def test_a_mean_of_19_994_mm_on_a_12_um_band_reads_19_9940_everywhere(tmp_path, capsys):
    p = tmp_path / "mu.toml"
    p.write_text(STUDY.format(nominal=19.994), encoding="utf-8")
    out = tmp_path / "r"
    assert main(["run", str(p), "--out", str(out)]) == 0
    cli = capsys.readouterr().out
    mean = pd.read_parquet(out / "samples.parquet")["length [mm]"].mean()       # the reference: the samples' mean
    assert abs(mean - 19.994) < 2e-4
    text = f"{mean:.4f}"                                                         # 12 µm / 100 → 4 decimals
    assert text == "19.9940" and f"{mean:.4g}" == "19.99"
    assert re.search(rf"^length +mm +{text} ", cli, re.M)                        # the CLI's statistics line
    html = (out / "report.html").read_text(encoding="utf-8")
    first = html[:html.index('id="verdict"')]
    assert re.search(rf"<td>{text}</td>", first)                                 # the first page (and summary.pdf)
    results = html[html.index('id="results"'):]
    assert re.search(rf"<td>{text} \[", results)                                 # the statistics table: mean [CI]
    assert "19.99 " not in cli and "<td>19.99</td>" not in html


def test_a_5_um_shift_of_a_42_mm_part_shows_in_the_baseline_diff(tmp_path, capsys):
    """Base: nominal 42.005 mm, new: 42.000 mm, both ±0.01 mm (a 20-µm band: 4 decimals)."""
    runs = {}
    for tag, nominal in (("base", 42.005), ("new", 42.0)):
        p = tmp_path / f"{tag}.toml"
        p.write_text(STUDY.format(nominal=nominal).replace('"±0.002"', '"±0.01"')
                     .replace("lower = 19.988\nupper = 20.000", "lower = 41.98\nupper = 42.02"), encoding="utf-8")
        runs[tag] = tmp_path / tag
        assert main(["run", str(p), "--out", str(runs[tag]), "--quiet"]) == 0
    capsys.readouterr()
    md = tmp_path / "cmp.md"
    main(["compare", str(runs["base"]), str(runs["new"]), "--markdown", str(md)])
    text = capsys.readouterr().out
    spec = [line for line in text.splitlines() if line.startswith("  spec: l changed")]
    assert len(spec) == 1 and "μ=42.0050" in spec[0].split("→")[0] and "μ=42.0000" in spec[0].split("→")[1]
    base = json.loads((runs["base"] / "summary.json").read_text())["outputs"]["length"]["mean"]
    new = json.loads((runs["new"] / "summary.json").read_text())["outputs"]["length"]["mean"]
    assert base - new == pytest.approx(0.005, abs=2e-4)                          # the reference: the two means
    line = next(x for x in text.splitlines() if x.startswith("  length mean:"))
    assert line.startswith(f"  length mean: {base:.4f} → {new:.4f} mm, change {new - base:.6f}")
    assert f"{base:.4f} → {new:.4f} mm" in md.read_text(encoding="utf-8")
