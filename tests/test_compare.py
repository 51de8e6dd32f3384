"""The paper comparison and a lab's numbers (ballbat.compare): the rows that apply to a bat not in the paper,
rounding as the field does, totals in quadrature (issue 37, section 5).
"""

from __future__ import annotations

import math

import pytest

from ballbat.compare import (
    applicable_rows,
    comparison_table,
    format_measurement,
    result_row,
    to_markdown,
    total_uncertainty,
)
from ballbat.published import PUBLISHED


def _maple_rows():
    """Ours for a lab's dataset: baseball on its own maple bat only."""
    return [
        result_row("e_x", "baseball", 0.418, "1", bat="maple", uncertainty=0.011),
        result_row("e_x_pooled", "baseball", 0.418, "1", uncertainty=0.011),
        result_row("spin_theta_slope", "baseball", 173.5, "rpm/deg", uncertainty=4.7),
        result_row("n_impacts", "baseball", 30, "1"),
    ]


def test_a_bat_not_in_the_paper_shows_the_rows_that_apply():
    table = comparison_table(_maple_rows())
    kept, notes = applicable_rows(table)
    softball = [r for r in PUBLISHED if r.ball == "softball"]
    assert len(table) - len(kept) == len(softball) + 3  # every softball row, and e_x of the paper's 3 baseball bats
    assert all(r["ball"] != "softball" for r in kept)
    assert {r["bat"] for r in kept if r["quantity"] == "e_x"} == {"maple"}
    assert (
        notes[0] == f"softball: this dataset has no impacts of it; the paper's {len(softball)} rows of it are left out"
    )
    assert notes[1] == "e_x of baseball on wood, metal_rough, metal_smooth: bats this dataset did not test; left out"
    assert "ours pool the bats maple, the paper's metal_rough, metal_smooth, wood: not the same bats" in notes[2]
    md = to_markdown(table, "Dataset maple")
    assert "| softball |" not in md and "| e_x | baseball | wood |" not in md
    assert "| e_x_pooled | baseball |  | 0.405 |" in md  # kept: with the note that the bats differ
    assert md.index("Rows that do not apply to this dataset") > md.index("| n_impacts | baseball |")


def test_a_dataset_of_the_papers_bats_keeps_every_row():
    """The default run's table (every ball and bat of the paper) is as it was: every row, no note; a bat of
    the paper whose fit failed (NaN) stays, to be seen.
    """
    rows = [
        result_row("e_x", r.ball, r.value if r.bat != "metal_rough" else float("nan"), "1", bat=r.bat)
        for r in PUBLISHED
        if r.quantity == "e_x"
    ]
    table = comparison_table(rows)
    kept, notes = applicable_rows(table)
    assert kept == table and notes == []
    assert "Rows that do not apply" not in to_markdown(table, "Dataset synthetic")


@pytest.mark.parametrize(
    ("value", "errors", "expected"),
    [
        (0.47512, (0.0030, 0.0053), ["0.4751", "0.0030", "0.0053"]),  # the finer error sets the place
        (0.4751, (0.00996,), ["0.475", "0.010"]),  # rounding carries into a new digit
        (123.4, (15.0,), ["123", "15"]),
        (4.6806, (0.0296,), ["4.681", "0.030"]),
        (0.5, (math.nan,), ["0.5", ""]),  # no usable error: three significant digits
    ],
)
def test_rounded_as_the_field_does(value, errors, expected):
    """The uncertainty to two significant digits, the value to the same decimal place."""
    assert format_measurement(value, *errors) == expected


def test_total_in_quadrature():
    assert total_uncertainty(0.003, 0.004) == pytest.approx(0.005)
    assert total_uncertainty(0.003, math.nan) == 0.003
