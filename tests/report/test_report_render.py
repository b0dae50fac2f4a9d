"""The PDF keeps the first PDF_MAX_ROWS rows of a long table and says so; the HTML keeps every row."""
import pandas as pd

from rvtol.report.render import PDF_MAX_ROWS, _block_view
from rvtol.blocks import Table


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


def test_a_table_wider_than_the_page_comes_in_parts_of_columns_in_the_pdf_each_led_by_the_row_names():
    from rvtol.report.render import PDF_WIDTH_CHARS

    outputs = [f"stackup.disc_{i}_axis.tilt" for i in range(40)]           # 40 columns: no A4 page holds them
    frame = pd.DataFrame({"tolerance": ["cycloid disc 1: pitch", "all other"],
                          **{o: [0.04 * i, 0.5] for i, o in enumerate(outputs)}})
    t = Table(frame, "Sobol indices")
    full, pdf = _block_view(t), _block_view(t, PDF_MAX_ROWS)
    assert full["html"].count("<table") == 1 and "stackup.disc_3_axis.tilt" in full["html"]
    parts = pdf["html"].split("</table>")[:-1]
    assert len(parts) > 1 and f"columns in {len(parts)} parts across the page, each led by column tolerance" in pdf["caption"]
    heads = [[h for h in part.split("<thead>")[1].split("</thead>")[0].split("<th>")[1:]] for part in parts]
    names = [h.split("</th>")[0].replace("\u200b", "") for hs in heads for h in hs]
    assert all(hs[0].startswith("tolerance") for hs in heads)                          # each part names its rows
    assert sorted(n for n in names if n != "tolerance") == sorted(outputs)             # every column, once
    # by hand: an output column is 10 characters wide (its longest piece "stackup." and the padding), the lead 23
    # (its 21-character text and the padding): (118 - 23) // 10 = 9 outputs a part, so parts of 9, 9, 9, 9, 4
    assert PDF_WIDTH_CHARS == 118 and [len(hs) - 1 for hs in heads] == [9, 9, 9, 9, 4]
    assert "stackup.\u200bdisc_\u200b3_\u200baxis.\u200btilt" in pdf["html"]          # names wrap at . and _


def test_the_pdf_view_keeps_duplicate_column_names_and_names_the_lead_left_after_omitting():
    frame = pd.DataFrame([["x", "note", *range(30)]], columns=["name", "label", *(["same.value"] * 30)])
    pdf = _block_view(Table(frame, "Dup", pdf_omit=("name",)), PDF_MAX_ROWS)
    assert pdf["html"].count("same.\u200bvalue") == 30 and "each led by column label" in pdf["caption"]


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
