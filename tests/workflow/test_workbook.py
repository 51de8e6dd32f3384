"""The default run's workbooks read in words (ballbat.workbook on a real run)."""

from __future__ import annotations

import openpyxl
import pytest
from helpers import sheet_rows as rows

from ballbat import workbook

# ---------------------------------------------------------------------------------------
# Issue 37 §5: a workbook a lab reads (headers in words with units, legends, widths, frozen headers)


def check_readable(path) -> dict[str, list]:
    """Check every sheet of a real workbook; return the legend's rows by (sheet, column).

    Every sheet: code names in row 1 (bold), each column in words in row 2 (with the unit where the
    column has one), both rows frozen, every column's width set; every status and flag column's codes
    that occur in the sheet explained in the legend sheet.
    """
    from openpyxl.utils import get_column_letter

    wb = openpyxl.load_workbook(path)
    legend = {}
    for r in rows(wb["legend"])[2:]:
        legend.setdefault((r[0], r[1]), {})[r[2]] = r[3]
    for ws in wb.worksheets:
        table = rows(ws)
        if not table:
            continue
        names, words = table[0], table[1]
        assert ws.freeze_panes == "A3", ws.title
        for i, (name, word) in enumerate(zip(names, words, strict=True), start=1):
            assert isinstance(name, str) and isinstance(word, str) and word, (ws.title, name)
            assert word != name or "_" not in name, (ws.title, name)  # words, not the code name again
            assert ws.cell(1, i).font.b, (ws.title, name)
            width = ws.column_dimensions[get_column_letter(i)].width
            assert workbook.COLUMN_WIDTH[0] <= width <= workbook.COLUMN_WIDTH[1], (ws.title, name, width)
            if workbook.is_status_column(name):
                codes = {r[i - 1] for r in table[2:] if r[i - 1] is not None}
                assert codes and codes <= set(legend[(ws.title, name)]), (ws.title, name, codes)
    return legend


@pytest.mark.slow
def test_the_default_runs_workbooks_read_in_words(default_run):
    """Why (issue 37): headers were code names, e_x_status = 0 had no legend, no column widths were set."""
    results = default_run / "results"
    legend = check_readable(results / "synthetic" / "results.xlsx")
    assert legend[("e_x", "e_x_status")] == {0: "ok", 1: "no impacts", 2: "too few impacts", 3: "fit failed"}
    assert legend[("impacts", "flag")][0] == "ok" and legend[("impacts", "flag")][3] == "bat behind ball"
    ws = openpyxl.load_workbook(results / "synthetic" / "results.xlsx")["impacts"]
    head = dict(zip(rows(ws)[0], rows(ws)[1], strict=True))
    assert head["v_bat"].endswith("(mph)") and "bat speed" in head["v_bat"]
    assert head["omega"].endswith("(rpm)") and head["D"].endswith("(in)")
    legend = check_readable(results / "implications" / "results.xlsx")
    assert legend[("paper", "exceeds_mu")] == {0: "within friction", 1: "needs more friction than mu"}
    legend = check_readable(results / "league.xlsx")
    assert set(legend) >= {("league", "tost_equivalent"), ("pairs", "pair_differs"), ("sessions", "entry_status")}
