"""Sec. V.B scenarios: the paper's D sweep shows what the paper reports; launch scenarios.

Trajectories for a lab's own bat (issue 37, section 3; docs/flight.md "A lab's own bat"): a scenario
takes its bat, tables and e_x from a dataset; e_x's stat. and syst. uncertainty gives 68 % and 95 %
bands of exit speed, launch angle, backspin and carry; ``ballbat hit`` runs the same code; the Fig. 11
caption quotes the paper only for Sec. V.B's case.
"""

from __future__ import annotations

import copy

import pytest
import xarray as xr
import yaml
from conftest import ROOT

from ballbat import scenario_bands
from ballbat.config_checks import validate_config
from ballbat.implications import comparison_rows
from ballbat.pipeline.config import checked_block
from ballbat.properties import load_balls, load_bats
from ballbat.stages import implications as stage
from ballbat.stages.implications import ImplicationsSettings
from ballbat.stages.implications import run as run_scenario
from ballbat.units import FOOT


@pytest.fixture(scope="module")
def cfg(config):
    return config["implications"]


@pytest.fixture(scope="module")
def complete(config, root):
    """A scenario as the workflow sees it: checked against the schema, its defaults filled."""
    schema = yaml.safe_load((root / "workflow" / "schemas" / "config.schema.yaml").read_text())

    def fill(sc):
        cfg = copy.deepcopy(config)
        cfg["implications"]["scenarios"] = {"s": sc}
        return validate_config(cfg, schema)["implications"]["scenarios"]["s"]

    return fill


@pytest.fixture(scope="module")
def paper(cfg, balls, bats):
    return run_scenario(ImplicationsSettings(cfg["scenarios"]["paper"], cfg["air"]), balls, bats)


def test_comparison_rows(paper):
    rows = {r["quantity"]: r for r in comparison_rows(paper)}
    assert rows["carry_max"]["unit"] == "ft" and 375 < rows["carry_max"]["value"] < 425
    assert rows["D_at_exit_speed_max"]["value"] == pytest.approx(0.0, abs=0.1)
    assert rows["backspin_at_D0"]["value"] < 0


def test_launch_scenario_flies_calculator_case(cfg, complete, balls, bats):
    # The calculator's published case with our baseball (5.04 oz, r = 1.42 in), not its 5.125 oz:
    # a lighter, smaller ball; only check it flies to the right neighbourhood and is sane.
    sc = complete({"ball": "baseball", "launch": {"exit_speed_mph": 103, "launch_deg": 27.5, "backspin_rpm": 2500}})
    ds = run_scenario(ImplicationsSettings(sc, cfg["air"]), balls, bats)
    assert ds.sizes["case"] == 1
    assert 400 < float(ds.carry[0]) / FOOT < 440
    assert float(ds.trajectory_z[0, -1]) == pytest.approx(0.0, abs=1e-6)


def test_unknown_ball_or_bat(cfg, complete, balls, bats):
    cricket = complete({"ball": "cricket", "launch": {"exit_speed_mph": 90, "launch_deg": 20}})
    with pytest.raises(ValueError, match="scenario ball 'cricket' is not in the ball table"):
        run_scenario(ImplicationsSettings(cricket, cfg["air"]), balls, bats)
    sc = {**cfg["scenarios"]["paper"], "bat": "oak"}
    with pytest.raises(ValueError, match="scenario bat 'oak' is not in the bat table"):
        run_scenario(ImplicationsSettings(sc, cfg["air"]), balls, bats)


HICKORY_BATS = ROOT / "config" / "examples" / "hickory_bats.csv"
SWEEP = {"pitch_mph": 90, "pitch_descent_deg": 6, "pitch_backspin_rpm": 2000, "bat_mph": 70, "attack_deg": 6}


@pytest.fixture(scope="module")
def tables():
    return load_balls(ROOT / "config" / "balls.csv"), load_bats(HICKORY_BATS)


def settings(tables, **sweep) -> stage.ImplicationsSettings:
    sweep = {"D_in": {"start": 0.0, "stop": 1.0, "num": 3}, **sweep}
    block = {"ball": "baseball", "bat": "hickory", "sweep": {**SWEEP, **sweep}}
    imp = checked_block({"scenarios": {"s": block}}, "implications")
    return stage.ImplicationsSettings(scenario=imp["scenarios"]["s"], air=imp["air"])


def test_no_dataset_no_bands_and_the_stage_unchanged(tables):
    s = settings(tables)
    ds = scenario_bands.scenario_with_bands(s, *tables)
    plain = stage.run(s, *tables)
    assert not [v for v in ds.data_vars if v.endswith("68")]
    xr.testing.assert_identical(ds.drop_attrs(), plain.drop_attrs())
