"""A study's batches (ballbat.studies.batch): a grid replicate records its systematic (issue 22)."""

from __future__ import annotations

import copy

import numpy as np

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
