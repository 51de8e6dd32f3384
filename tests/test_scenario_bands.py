"""Bands of a lab's own bat (ballbat.scenario_bands): a dataset's e_x and its uncertainty give 68 % and 95 %
bands; the Fig. 11 caption quotes the paper only for its case (issue 37, section 3).
"""

from __future__ import annotations

import helpers
import numpy as np
import pytest
import xarray as xr
from helpers import scenario_settings as settings

from ballbat import reporting, scenario_bands
from ballbat.stages import implications as stage

tables = helpers.tables  # a fixture of tests/helpers.py


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


def test_caption_quotes_the_paper_only_for_its_case(tables):
    """Why: the caption compared a 90 mph case with the paper's 85 mph one."""
    ours = scenario_bands.scenario_with_bands(settings(tables), *tables)
    text = reporting.fig11_numbers(ours)
    assert "paper: about 400 ft" not in text and "paper: peaks" not in text
    assert "Not the paper's case (90 mph pitch, 70 mph swing" in text
    paper = settings(tables, pitch_mph=85.0, bat_mph=73.0)
    text = reporting.fig11_numbers(scenario_bands.scenario_with_bands(paper, *tables))
    assert "(paper: about 400 ft)." in text and "Not the paper's case" not in text
