"""A study's truth (ballbat.studies.truth): the job runs the size its plans use; single points' truths merge."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from helpers import unbalanced

from ballbat.config_checks import impact_bytes, study_impacts
from ballbat.studies import truth as study_truth
from ballbat.studies.settings import StudySettings
from ballbat.studies.truth import (
    merge_truths,
    population_truth,
    truth_dataset,
    truth_scales_from_dataset,
    truths_from_dataset,
)


def test_truth_files_of_single_points_merge_into_the_study_truth(config, balls, bats):
    """One truth job per sweep point (rule study_truth_point), joined by study_truth: the same as all at once."""
    cfg = copy.deepcopy(config)
    cfg["studies"]["robustness"].update(truth_impacts=30)
    cfg["studies"]["robustness"]["sweep"] = {"grid": {"pixel_noise_px": [2.0], "impacts_per_bat": [6, 9]}}
    s = StudySettings.from_config(cfg, "robustness")
    whole = truth_dataset(s, balls, bats)
    parts = [truth_dataset(s, balls, bats, points=[p]) for p in (1, 0)]
    assert [p.point.values.tolist() for p in parts] == [[1], [0]]
    merged = merge_truths(parts)
    np.testing.assert_array_equal(merged.truth.values, whole.truth.values)
    np.testing.assert_array_equal(merged.grid_setting.values, whole.grid_setting.values)
    assert list(merged.quantity.values) == list(whole.quantity.values)
    assert merged.attrs["truth_impacts"] == 30 and merged.attrs["sweep_parameter"] == "pixel_noise_px,impacts_per_bat"
    assert truths_from_dataset(merged) == truths_from_dataset(whole)
    # the truth's experiment repeats the design ceil(30 / 6) = 5 and ceil(30 / 9) = 4 times
    np.testing.assert_array_equal(truth_scales_from_dataset(merged), [5.0, 4.0])
    with pytest.raises(ValueError, match="no truth_scale variable"):
        truth_scales_from_dataset(merged.drop_vars("truth_scale"))
    with pytest.raises(ValueError, match=r"missing \[0\], repeated \[1\]"):
        merge_truths([parts[0], parts[0]])


def test_the_truth_job_runs_the_size_its_plans_use(config, monkeypatch):
    """The truth job simulates exactly StudySettings.truth_counts: what the memory plan and the guard read."""
    seen = {}

    def fake_run_replicate(settings, ds, index, balls, bats, check):
        seen["impacts"] = ds["synthetic"]["impacts"]
        return []

    monkeypatch.setattr(study_truth, "run_replicate", fake_run_replicate)  # where the truth job looks it up
    cfg = unbalanced(config)
    s = StudySettings.from_config(cfg, "calibration")
    population_truth(s, 0, {}, {})
    assert seen["impacts"] == s.truth_counts(0)[1]
    total = sum(n for bats in seen["impacts"].values() for n in bats.values())
    ds = cfg["datasets"]["synthetic"]
    assert study_impacts(ds, None, [], 10_000) == (204, total)
    assert s.truth_mem_mb(0) == 500 + math.ceil(total * impact_bytes(ds) / 1e6)
