"""Design from a lab's own numbers (issue 37, section 4; src/ballbat/pilot.py): impacts per bat from a pilot's
measured scatter with an interval, ``ballbat design``, and one answer over a design study's sweep.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import forked
import numpy as np
import xarray as xr

from ballbat import pilot
from ballbat.pipeline.ncio import write_dataset

BALLBAT = Path(sys.executable).parent / "ballbat"


def fit(se: dict, n: dict) -> xr.Dataset:
    bats = list(se)
    one, shape = {"units": "1", "long_name": "x"}, (1, len(bats))
    return xr.Dataset(
        {
            "e_x": (("ball", "bat"), np.full(shape, 0.45), one),
            "e_x_err": (("ball", "bat"), [[se[b] for b in bats]], one),
            "e_x_n": (("ball", "bat"), [[n[b] for b in bats]], one),
            "e_x_status": (("ball", "bat"), np.zeros(shape, dtype=np.int8), one),
            "e_x_scatter": (("ball", "bat"), np.zeros(shape), one),
        },
        coords={"ball": ("ball", ["baseball"], {"long_name": "b"}), "bat": ("bat", bats, {"long_name": "b"})},
    )


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
