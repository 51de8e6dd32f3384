"""A study's settings (ballbat.studies.settings): its truth sized by one rule, shared by the job, its plans
and the size guard (issue 40).
"""

from __future__ import annotations

import copy
import math

import pytest
from helpers import UNBALANCED, unbalanced
from helpers import study_settings as settings

from ballbat.config_checks import MEMORY_SHARE, validate_config
from ballbat.studies.settings import StudySettings


def test_the_truth_keeps_the_designs_proportions_at_about_truth_impacts_a_pair(config):
    s = StudySettings.from_config(unbalanced(config), "calibration")
    k, counts = s.truth_counts(0)
    assert k == math.ceil(7 * 10_000 / 204) == 344
    assert counts == {b: {t: n * k for t, n in bats.items()} for b, bats in UNBALANCED.items()}
    # about truth_impacts a pair on average: the old rule (10000 / 6 = 1667 times) held 340 068
    assert s.truth_size(0) == 204 * 344 == 70_176
    assert 7 * 10_000 <= s.truth_size(0) < 7 * 10_000 + 204


def test_a_balanced_design_keeps_the_old_scale(config):
    # every pair alike: ceil(P T / N) = ceil(T / n), the scale before issue 40 (the design and
    # robustness studies' truths are unchanged)
    s = StudySettings.from_config(config, "design")
    for p, n in enumerate(s.values):
        assert s.truth_counts(p)[0] == math.ceil(10_000 / n)


def test_the_unbalanced_design_runs_within_its_plan_on_this_machines_size(raw, schema):
    """At the default truth_impacts the 6-to-60 design is accepted on a 24 GiB machine (its plan: 4.0 GB)."""
    raw["datasets"]["synthetic"]["synthetic"]["impacts"] = copy.deepcopy(UNBALANCED)
    cfg = validate_config(raw, schema, available=23 * 2**30)
    s = StudySettings.from_config(cfg, "calibration")
    assert s.truth_mem_mb(0) * 1e6 <= MEMORY_SHARE * 23 * 2**30
    assert s.truth_mem_mb(0) == 500 + math.ceil(70_176 * 50_000 / 1e6)


def test_batches_cover_every_replicate_once(config):
    s = settings(config, "design", replicates=7, batch_size=3)
    seen = [g for b in range(s.n_batches) for g in s.batch_range(b)]
    assert seen == list(range(7 * len(s.values)))
    with pytest.raises(ValueError, match="out of range"):
        s.batch_range(s.n_batches)
