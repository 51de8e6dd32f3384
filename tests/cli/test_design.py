"""``ballbat design`` (ballbat.cli.design): impacts per bat from a pilot folder (issue 37, section 4)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import forked
import pytest
from helpers import pilot_fit as fit

from ballbat import pilot
from ballbat.pipeline.ncio import write_dataset

BALLBAT = Path(sys.executable).parent / "ballbat"


@pytest.mark.slow  # more than 2 s
def test_ballbat_design_from_a_pilot_folder(tmp_path):
    ds = fit({"A": 0.006}, {"A": 25})
    write_dataset(ds, tmp_path / "h01" / "fit_ex.nc", title="t", rule="fit_ex", inputs={}, config={})
    env = {**os.environ, "PYTHONPATH": str(Path(pilot.__file__).parents[1])}
    run = [str(BALLBAT), "design", str(tmp_path / "h01"), "--delta", "0.02"]
    out = subprocess.run(run, capture_output=True, text=True, timeout=60, env=env)
    assert out.returncode == 0, out.stderr
    n = pilot.pilot_design(ds, 0.02)[0]
    assert f"baseball, pooled over 1 bat(s): {n.n:.0f} (95 %: {n.n_low:.0f} to {n.n_high:.0f})" in out.stdout
    run[2] = str(tmp_path)
    (tmp_path / "empty").mkdir()
    out = forked.ballbat(*run[1:2], str(tmp_path / "empty"), *run[3:], cwd=tmp_path, timeout=60)
    assert out.returncode == 2 and str(tmp_path / "empty") in out.stderr and len(out.stderr.splitlines()) == 1
