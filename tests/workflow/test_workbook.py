"""Unit tests of the results workbooks (ballbat.workbook) on small in-memory results.

Each workbook is written to a real .xlsx file and read back with openpyxl: the sheets, the two
header rows, every cell's value in the field's units, the number formats that round it, the
provenance sheet, the custom document properties and the fixed document time.
"""

from __future__ import annotations

import json

import numpy as np
import openpyxl
import pytest
import xarray as xr

from ballbat import workbook
from ballbat.kinematics import ImpactFlag
from ballbat.pipeline.products import flag_attrs
from ballbat.units import DEGREE, INCH, MPH, RPM

PROVENANCE = {
    "provenance_rule": "reconstruct",
    "provenance_inputs": json.dumps([{"name": "normalize", "path": "results/t/normalize.nc", "sha256": "ab12"}]),
    "provenance_config": json.dumps({"v_ref_mph": 77.0}),
    "provenance_software": json.dumps({"ballbat": "9.9"}),
    "provenance_git": json.dumps({"commit": "unknown", "dirty": False}),
}


def impacts() -> xr.Dataset:
    """Three impacts as reconstruct.nc holds them (SI), one with a missing spin and one flagged."""
    n = 3
    return xr.Dataset(
        {
            "impact_id": ("impact", np.array(["A1", "A2", "A3"])),
            "ball": ("impact", np.array(["baseball", "baseball", "softball"])),
            "bat": ("impact", np.array(["wood", "wood", "metal"])),
            "v_bat": ("impact", np.array([70.0, 75.0, 80.0]) * MPH),
            "v_bat_err": ("impact", np.array([0.5, 0.5, 0.25]) * MPH),
            "theta": ("impact", np.array([10.0, -5.5, 20.25]) * DEGREE),
            "omega": ("impact", np.array([1900.0, np.nan, 2500.4]) * RPM),
            "D": ("impact", np.array([0.5, 1.25, -0.75]) * INCH),
            "r_x": ("impact", np.full(n, 0.2)),
            "flag": ("impact", np.array([0, 0, 4], dtype=np.int8), flag_attrs(ImpactFlag)),
            "flag_reason": ("impact", np.array(["ok", "ok", "excluded at ingest"])),
        },
        coords={"impact": ("impact", np.arange(n))},
        attrs={**PROVENANCE, "title": "reconstruct", "ingest_warnings": "first warning\nsecond warning\n"},
    )


def rows(ws) -> list[list]:
    return [[c.value for c in row] for row in ws.iter_rows()]


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
