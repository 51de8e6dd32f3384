"""Trajectories for a lab's own bat (issue 37, section 3; docs/flight.md "A lab's own bat"): a scenario
takes its bat, tables and e_x from a dataset; e_x's stat. and syst. uncertainty gives 68 % and 95 %
bands of exit speed, launch angle, backspin and carry; ``ballbat hit`` runs the same code; the Fig. 11
caption quotes the paper only for Sec. V.B's case.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import forked
import numpy as np
import pytest
import xarray as xr
import yaml
from conftest import ROOT

from ballbat import reporting, scenario_bands
from ballbat.config_checks import scenario_problems, validate_config
from ballbat.pipeline.config import checked_block
from ballbat.pipeline.ncio import write_dataset
from ballbat.properties import bat_record, load_balls, load_bats
from ballbat.stages import implications as stage

HICKORY_BATS = ROOT / "config" / "examples" / "hickory_bats.csv"
HICKORY_IMPACTS = ROOT / "config" / "examples" / "hickory_impacts.csv"
BALLBAT = Path(sys.executable).parent / "ballbat"
SWEEP = {"pitch_mph": 90, "pitch_descent_deg": 6, "pitch_backspin_rpm": 2000, "bat_mph": 70, "attack_deg": 6}


def hickory_config(**scenario) -> dict:
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    cfg["datasets"]["h01"] = {"impacts": str(HICKORY_IMPACTS), "bats": str(HICKORY_BATS)}
    sweep = {**SWEEP, "D_in": {"start": 0.0, "stop": 1.0, "num": 5}}
    cfg["implications"]["scenarios"] = {"mine": {"ball": "baseball", "bat": "hickory", "sweep": sweep, **scenario}}
    return cfg


def test_a_scenario_takes_its_bat_from_its_dataset(schema, monkeypatch):
    """Why: `bat: hickory` with `e_x_from_dataset: h01` was refused (hickory is in h01's bat table only)."""
    monkeypatch.chdir(ROOT)
    cfg = validate_config(hickory_config(e_x_from_dataset="h01"), schema, available=24 * 2**30)
    assert scenario_problems(cfg) == []


def test_a_bat_in_no_table_suggests_tables_bats(schema, monkeypatch):
    monkeypatch.chdir(ROOT)
    cfg = validate_config(hickory_config(), schema, available=24 * 2**30)
    (line,) = scenario_problems(cfg)
    assert line.startswith("implications.scenarios.mine.bat: 'hickory' is not in the bat table config/bats.csv")
    assert "tables.bats" in line and "e_x_from_dataset" in line


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


@pytest.fixture(scope="module")
def tables():
    return load_balls(ROOT / "config" / "balls.csv"), load_bats(HICKORY_BATS)


def settings(tables, **sweep) -> stage.ImplicationsSettings:
    sweep = {"D_in": {"start": 0.0, "stop": 1.0, "num": 3}, **sweep}
    block = {"ball": "baseball", "bat": "hickory", "sweep": {**SWEEP, **sweep}}
    imp = checked_block({"scenarios": {"s": block}}, "implications")
    return stage.ImplicationsSettings(scenario=imp["scenarios"]["s"], air=imp["air"])


def test_dataset_e_x_is_the_bats_own_else_pooled():
    fit = xr.Dataset(
        {
            "e_x": (("ball", "bat"), [[0.455, np.nan]]),
            "e_x_err": (("ball", "bat"), [[0.010, np.nan]]),
            "e_x_syst": (("ball", "bat"), [[0.004, np.nan]]),
            "e_x_pooled": (("ball",), [0.43]),
            "e_x_pooled_err": (("ball",), [0.006]),
        },
        coords={"ball": ["baseball"], "bat": ["hickory", "ash"]},
    )
    own = scenario_bands.dataset_e_x(fit, "baseball", "hickory", "h01")
    assert (own.value, own.stat, own.syst, own.source) == (0.455, 0.010, 0.004, "bat")
    assert own.sigma == pytest.approx(np.hypot(0.010, 0.004))
    pooled = scenario_bands.dataset_e_x(fit, "baseball", "ash", "h01")  # no value for ash: the pooled one
    assert (pooled.value, pooled.stat, pooled.syst, pooled.source) == (0.43, 0.006, 0.0, "pooled")
    with pytest.raises(ValueError, match="dataset h01: no e_x for ball 'softball'"):
        scenario_bands.dataset_e_x(fit, "softball", "hickory", "h01")


def test_bands_are_the_scenario_at_e_x_plus_minus_its_sigma(tables):
    """Carry, exit speed, launch angle and backspin are monotone in e_x here: the 68 % band is the runs at
    e_x -+ sigma, the 95 % band at e_x -+ 1.96 sigma; nominal inside 68 % inside 95 %.
    """
    ex = scenario_bands.DatasetEx(0.455, 0.010, 0.004, "bat", "h01")
    s = settings(tables, D_in={"start": 0.25, "stop": 0.75, "num": 3})
    ds = scenario_bands.scenario_with_bands(s, *tables, ex)
    lo, hi = (stage.run(s, *tables, e_x=0.455 + z * ex.sigma) for z in (-1.0, 1.0))
    lo95, hi95 = (stage.run(s, *tables, e_x=0.455 + z * ex.sigma) for z in (-scenario_bands.Z95, scenario_bands.Z95))
    for q, units in scenario_bands.BANDED.items():
        assert ds[f"{q}_low68"].attrs["units"] == units == ds[q].attrs["units"]
        ends = np.sort(np.stack([lo[q].values, hi[q].values]), axis=0)
        np.testing.assert_allclose(ds[f"{q}_low68"].values, ends[0], rtol=1e-12)
        np.testing.assert_allclose(ds[f"{q}_high68"].values, ends[1], rtol=1e-12)
        ends95 = np.sort(np.stack([lo95[q].values, hi95[q].values]), axis=0)
        np.testing.assert_allclose(ds[f"{q}_low95"].values, ends95[0], rtol=1e-12)
        assert (ds[f"{q}_low95"] <= ds[f"{q}_low68"]).all() and (ds[f"{q}_low68"] <= ds[q]).all()
        assert (ds[q] <= ds[f"{q}_high68"]).all() and (ds[f"{q}_high68"] <= ds[f"{q}_high95"]).all()
    assert (ds["backspin_high68"] - ds["backspin_low68"]).min() > 0  # e_x moves the spin: a band, not a line
    assert ds.attrs["e_x_source"] == "bat e_x of dataset h01" and ds.attrs["paper_case"] == 0


def test_no_dataset_no_bands_and_the_stage_unchanged(tables):
    s = settings(tables)
    ds = scenario_bands.scenario_with_bands(s, *tables)
    plain = stage.run(s, *tables)
    assert not [v for v in ds.data_vars if v.endswith("68")]
    xr.testing.assert_identical(ds.drop_attrs(), plain.drop_attrs())


def test_caption_quotes_the_paper_only_for_its_case(tables):
    """Why: the caption compared a 90 mph case with the paper's 85 mph one."""
    ours = scenario_bands.scenario_with_bands(settings(tables), *tables)
    text = reporting.fig11_numbers(ours)
    assert "paper: about 400 ft" not in text and "paper: peaks" not in text
    assert "Not the paper's case (90 mph pitch, 70 mph swing" in text
    paper = settings(tables, pitch_mph=85.0, bat_mph=73.0)
    text = reporting.fig11_numbers(scenario_bands.scenario_with_bands(paper, *tables))
    assert "(paper: about 400 ft)." in text and "Not the paper's case" not in text


def run_hit(*args: str, installed: bool = False) -> subprocess.CompletedProcess:
    """`ballbat hit ARGS`: the installed command, or (the default) a process forked with its libraries loaded."""
    if not installed:
        return forked.ballbat("hit", *args, cwd=Path.cwd(), timeout=60)
    env = {**os.environ, "PYTHONPATH": str(Path(scenario_bands.__file__).parents[1])}
    return subprocess.run([str(BALLBAT), "hit", *args], capture_output=True, text=True, timeout=60, env=env)


def test_ballbat_hit_prints_the_batted_ball_with_bands(tmp_path, tables):
    """Why: no command gave pitch + bat -> batted ball. Through the installed entry point, the scenario's numbers."""
    fit_file(tmp_path / "h01", {"hickory": tables[1]["hickory"]}, {"hickory": 0.455}, {"hickory": 0.010})
    out = run_hit("--pitch-speed", "90", "--bat-speed", "70", "--bat", "hickory", "--results", str(tmp_path / "h01"))
    assert out.returncode == 2 and "--D" in out.stderr  # D is required
    args = ["--pitch-speed", "90", "--bat-speed", "70", "--bat", "hickory", "--results", str(tmp_path / "h01")]
    out = run_hit(*args, "--D", "0.5", installed=True)
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
    out = run_hit(*args[:-2], "--results", str(tmp_path / "none"), "--D", "0.5")
    assert out.returncode == 2 and out.stderr == f"ballbat hit: error: {tmp_path / 'none'}: no such folder\n"
    out = run_hit(*args[:4], "--bat", "wood", "--results", str(tmp_path / "h01"), "--D", "0.5")
    assert out.stderr == f"ballbat hit: error: --bat wood: not a bat of {tmp_path / 'h01'} (its bats: hickory)\n"
