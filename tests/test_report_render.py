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


def test_columns_too_wide_for_a4_are_left_out_of_the_pdf_view_only():
    t = Table(pd.DataFrame({"factor": ["f0", "f1"], "value": [1.0, 2.0], "source": ["drawing RV-80E-001 rev C", "x"],
                            "feature": ["bore Ø40 H6", "y"]}), "Factors", pdf_omit=("feature", "source", "absent"))
    full, pdf = _block_view(t), _block_view(t, PDF_MAX_ROWS)
    assert "drawing RV-80E-001 rev C" in full["html"] and "bore Ø40 H6" in full["html"] and full["caption"] == "Factors"
    assert "drawing RV-80E-001" not in pdf["html"] and "bore Ø40" not in pdf["html"] and ">f1<" in pdf["html"]
    assert "<th>value</th>" in pdf["html"] and "<th>source</th>" not in pdf["html"]
    assert "without the columns feature, source" in pdf["caption"] and "absent" not in pdf["caption"]


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
