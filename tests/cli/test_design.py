"""``ballbat design`` (ballbat.cli.design): impacts per bat from a pilot folder (issue 37, section 4)."""

from __future__ import annotations

import pytest
from helpers import pilot_fit as fit
from helpers import run_ballbat

from ballbat import pilot
from ballbat.pipeline.ncio import write_dataset


@pytest.mark.slow  # more than 2 s
def test_ballbat_design_from_a_pilot_folder(tmp_path):
    ds = fit({"A": 0.006}, {"A": 25})
    write_dataset(ds, tmp_path / "h01" / "fit_ex.nc", title="t", rule="fit_ex", inputs={}, config={})
    out = run_ballbat("design", str(tmp_path / "h01"), "--delta", "0.02", installed=True)
    assert out.returncode == 0, out.stderr
    n = pilot.pilot_design(ds, 0.02)[0]
    assert f"baseball, pooled over 1 bat(s): {n.n:.0f} (95 %: {n.n_low:.0f} to {n.n_high:.0f})" in out.stdout
    (tmp_path / "empty").mkdir()
    out = run_ballbat("design", str(tmp_path / "empty"), "--delta", "0.02")
    assert out.returncode == 2 and str(tmp_path / "empty") in out.stderr and len(out.stderr.splitlines()) == 1
