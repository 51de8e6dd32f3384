"""Report text (ballbat.reporting): the stick period, the comparison table as HTML."""

from __future__ import annotations

import numpy as np
import pytest

from ballbat import reporting
from ballbat.pipeline.checked import sealed_csv


def test_stick_period():
    t = np.linspace(0, 1.6, 17)
    stick = np.where(t < 1.4, 1.0, np.where(t <= 1.5, 0.0, np.nan))
    assert reporting.stick_period(t, stick) == (0.0, pytest.approx(1.4))
    assert reporting.stick_period(t, np.zeros_like(t)) == (None, None)
    late = np.where((t > 0.2) & (t < 0.5), 1.0, 0.0)  # initial slip, then stick
    assert reporting.stick_period(t, late) == (pytest.approx(0.3), pytest.approx(0.5))


def test_comparison_html(tmp_path):
    csv = tmp_path / "t.csv"
    csv.write_text(
        sealed_csv(  # as the workflow writes its tables: with their check line
            "quantity,ball,bat,paper,paper_uncertainty,value,uncertainty,truth,unit\n"
            "e_x,baseball,wood,0.464,0.014,0.47,0.02,,1\n"
        )
    )
    text = reporting.comparison_html(csv, tmp_path / "t.html", title="A & B")
    assert "<td>0.464</td>" in text and "A &amp; B" in text
    assert (tmp_path / "t.html").read_text() == text
