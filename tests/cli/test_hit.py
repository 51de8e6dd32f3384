"""``ballbat hit`` (ballbat.cli.hit): the batted ball of a pitch and a swing, with bands from e_x (issue 37 §3)."""

from __future__ import annotations

from pathlib import Path

import helpers
import numpy as np
import pytest
import xarray as xr
from helpers import run_ballbat
from helpers import scenario_settings as settings

from ballbat import scenario_bands
from ballbat.pipeline.ncio import write_dataset
from ballbat.properties import bat_record

tables = helpers.tables  # a fixture of tests/helpers.py


def fit_file(folder: Path, bats: dict, e_x: dict, err: dict, syst: float = 0.004) -> Path:
    """A fit_ex.nc with the variables a scenario reads: e_x per bat (baseball) and pooled, with errors."""
    names = list(e_x)
    one = {"units": "1", "long_name": "x"}
    v = np.array([[e_x[b] for b in names]])
    ds = xr.Dataset(
        {
            "e_x": (("ball", "bat"), v, one),
            "e_x_err": (("ball", "bat"), np.array([[err[b] for b in names]]), one),
            "e_x_syst": (("ball", "bat"), np.full(v.shape, syst), one),
            "e_x_n": (("ball", "bat"), np.full(v.shape, 30), one),
            "e_x_status": (("ball", "bat"), np.zeros(v.shape, dtype=np.int8), one),
            "e_x_scatter": (("ball", "bat"), np.zeros(v.shape), one),
            "e_x_pooled": (("ball",), np.array([0.41]), one),
            "e_x_pooled_err": (("ball",), np.array([0.005]), one),
            "e_x_pooled_syst": (("ball",), np.array([syst]), one),
        },
        coords={"ball": ("ball", ["baseball"], {"long_name": "b"}), "bat": ("bat", names, {"long_name": "b"})},
        attrs={"bat_properties": bat_record(bats)},
    )
    path = folder / "fit_ex.nc"
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_dataset(ds, path, title="test", rule="fit_ex", inputs={}, config={})


@pytest.mark.slow  # more than 2 s
def test_ballbat_hit_prints_the_batted_ball_with_bands(tmp_path, tables):
    """Why: no command gave pitch + bat -> batted ball. Through the installed entry point, the scenario's numbers."""
    fit_file(tmp_path / "h01", {"hickory": tables[1]["hickory"]}, {"hickory": 0.455}, {"hickory": 0.010})
    out = run_ballbat(
        "hit", "--pitch-speed", "90", "--bat-speed", "70", "--bat", "hickory", "--results", str(tmp_path / "h01")
    )
    assert out.returncode == 2 and "--D" in out.stderr  # D is required
    args = ["--pitch-speed", "90", "--bat-speed", "70", "--bat", "hickory", "--results", str(tmp_path / "h01")]
    out = run_ballbat("hit", *args, "--D", "0.5", installed=True)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert "e_x = 0.4550 ± 0.0100 (stat.) ± 0.0040 (syst.), bat e_x of dataset h01" in lines[0]
    carry = next(line for line in lines if line.strip().startswith("carry")).split()
    ex = scenario_bands.DatasetEx(0.455, 0.010, 0.004, "bat", "h01")
    ds = scenario_bands.scenario_with_bands(settings(tables, D_in={"start": 0.5, "stop": 0.5, "num": 1}), *tables, ex)
    ft = 0.3048
    assert float(carry[1]) == pytest.approx(float(ds["carry"][0]) / ft, abs=0.05)
    assert float(carry[5]) == pytest.approx(float(ds["carry_low68"][0]) / ft, abs=0.05)
    assert float(carry[10]) == pytest.approx(float(ds["carry_low95"][0]) / ft, abs=0.05)
    assert float(carry[12]) == pytest.approx(float(ds["carry_high95"][0]) / ft, abs=0.05)
    out = run_ballbat("hit", *args[:-2], "--results", str(tmp_path / "none"), "--D", "0.5")
    assert out.returncode == 2 and out.stderr == f"ballbat hit: error: {tmp_path / 'none'}: no such folder\n"
    out = run_ballbat("hit", *args[:4], "--bat", "wood", "--results", str(tmp_path / "h01"), "--D", "0.5")
    assert out.stderr == f"ballbat hit: error: --bat wood: not a bat of {tmp_path / 'h01'} (its bats: hickory)\n"
