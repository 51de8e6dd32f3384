"""The maple example's paper comparison, from the suite's lab run (issue 37, section 5)."""

from __future__ import annotations

import pytest


@pytest.mark.slow
def test_the_maple_examples_table(lab_run):
    """The lab run's maple dataset (config/examples/maple.yaml): its Markdown and HTML tables."""
    res = lab_run / "results" / "maple"
    md = (res / "paper_comparison.md").read_text()
    html = (res / "paper_comparison.html").read_text()
    for text in (md, html):
        assert "softball: this dataset has no impacts of it" in text
        assert "e_x of baseball on wood, metal_rough, metal_smooth: bats this dataset did not test" in text
    assert "| softball |" not in md and "<td>softball</td>" not in html
    assert "| e_x | baseball | maple |" in md
