"""The implications stage (ballbat.stages.implications): the paper's comparison rows, launch scenarios, a
scenario's bat from a dataset, unknown balls and bats (Sec. V.B; issue 37, section 3).
"""

from __future__ import annotations

import helpers
import pytest
import xarray as xr
from helpers import scenario_settings as settings

from ballbat import scenario_bands
from ballbat.implications import comparison_rows
from ballbat.stages import implications as stage
from ballbat.stages.implications import ImplicationsSettings
from ballbat.stages.implications import run as run_scenario
from ballbat.units import FOOT

paper = helpers.paper  # a fixture of tests/helpers.py

complete = helpers.complete  # a fixture of tests/helpers.py

cfg = helpers.cfg  # a fixture of tests/helpers.py

tables = helpers.tables  # a fixture of tests/helpers.py


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


def test_no_dataset_no_bands_and_the_stage_unchanged(tables):
    s = settings(tables)
    ds = scenario_bands.scenario_with_bands(s, *tables)
    plain = stage.run(s, *tables)
    assert not [v for v in ds.data_vars if v.endswith("68")]
    xr.testing.assert_identical(ds.drop_attrs(), plain.drop_attrs())
