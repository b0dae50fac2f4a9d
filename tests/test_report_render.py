"""The PDF keeps the first PDF_MAX_ROWS rows of a long table and says so; the HTML keeps every row."""
import pandas as pd

from rvtol.report.render import PDF_MAX_ROWS, _block_view
from rvtol.report.sections import Table


def _rows(html: str) -> int:
    return html.split("<tbody>")[1].count("<tr")


def test_a_long_table_is_cut_in_the_pdf_view_only():
    n = PDF_MAX_ROWS + 23
    t = Table(pd.DataFrame({"factor": [f"f{i}" for i in range(n)], "value": range(n)}), "Factors")
    full, pdf = _block_view(t), _block_view(t, PDF_MAX_ROWS)
    assert _rows(full["html"]) == n and full["caption"] == "Factors"
    assert _rows(pdf["html"]) == PDF_MAX_ROWS and f"the first {PDF_MAX_ROWS} of {n} rows" in pdf["caption"]
    assert f"f{PDF_MAX_ROWS - 1}<" in pdf["html"] and f"f{PDF_MAX_ROWS}<" not in pdf["html"]


def test_a_short_table_is_whole_in_both():
    t = Table(pd.DataFrame({"a": range(PDF_MAX_ROWS)}), "Short")
    assert _block_view(t, PDF_MAX_ROWS) == _block_view(t)


def test_the_inputs_list_correlated_pairs_not_the_whole_matrix():
    import numpy as np

    from rvtol.report.standard import correlated_pairs

    names = ["a", "b", "c", "d"]
    C = np.eye(4)
    C[0, 2] = C[2, 0] = 0.8
    C[1, 3] = C[3, 1] = -0.25
    t = correlated_pairs(names, C)
    assert t.to_dict("records") == [{"factor": "a", "with": "c", "ρ": 0.8}, {"factor": "b", "with": "d", "ρ": -0.25}]
    assert correlated_pairs(names, np.eye(4)).empty
