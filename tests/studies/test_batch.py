"""A study's batches (ballbat.studies.batch): a grid replicate records its systematic (issue 22)."""

from __future__ import annotations

import copy

import numpy as np
import pytest
import xarray as xr
from helpers import study_settings as settings

from ballbat.studies import batch as study_batch
from ballbat.studies.settings import StudySettings


def test_a_grid_replicate_records_a_systematic(config, balls, bats):
    """One replicate of a grid point with drawn calibration: every quantity gets its calibration systematic
    (the tracks reduced again at +-1 sigma of the swing camera's pixel scale, as the workflow's reduce does).
    """
    cfg = copy.deepcopy(config)
    cfg["studies"]["robustness"].update(replicates=1, batch_size=1)
    cfg["studies"]["robustness"]["sweep"] = {"grid": {"pixel_noise_px": [3.0], "contact_ms": [0.9]}}
    s = StudySettings.from_config(cfg, "robustness")
    batch = study_batch.run(s, 0, balls, bats)
    assert batch.attrs["sweep_parameter"] == "pixel_noise_px,contact_ms"
    names = batch.quantity_name.values
    syst = batch.systematic.values[0]
    for q in ("e_x", "e_x_pooled", "tan_ratio_slope", "spin_theta_slope", "e_y_implied", "eta2"):
        assert np.all(np.isfinite(syst[names == q])) and np.all(syst[names == q] > 0), q


@pytest.mark.slow  # about 3 s: 8 replicates in two batchings
def test_replicates_do_not_depend_on_the_batch_size(config, balls, bats):
    """Replicate k is the same experiment whether it runs in batch 0 of 4 or batch 1 of 3."""
    three = settings(config, replicates=4, batch_size=3, truth_impacts=60)
    b = xr.concat([study_batch.run(three, i, balls, bats) for i in (0, 1)], "replicate")
    one = study_batch.run(settings(config, replicates=4, batch_size=4, truth_impacts=60), 0, balls, bats)
    np.testing.assert_array_equal(one.value.values, b.value.values)
