"""A study's truth job: one rule for its size, shared by the job, its plans and the size guard (issue 40)."""

from __future__ import annotations

import copy
import math
import re

import pytest

from ballbat.config_checks import MEMORY_SHARE, impact_bytes, study_impacts, validate_config
from ballbat.pipeline.config import ConfigError
from ballbat.studies import truth as study_truth
from ballbat.studies.settings import StudySettings
from ballbat.studies.sweeps import truth_counts
from ballbat.studies.truth import population_truth

#: The unbalanced design of issue 40: 6 impacts on some bats and 60 on others, the softball bat
#: swung with softballs only (102 of the 204 impacts on three pairs of 60).
UNBALANCED = {
    "baseball": {"wood": 6, "metal_rough": 60, "metal_smooth": 6},
    "softball": {"wood": 60, "metal_rough": 6, "metal_smooth": 60, "softball_composite": 6},
}


def unbalanced(config, **over):
    cfg = copy.deepcopy(config)
    cfg["datasets"]["synthetic"]["synthetic"]["impacts"] = copy.deepcopy(UNBALANCED)
    cfg["studies"]["calibration"].update(over)
    return cfg


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


def test_a_pair_of_no_impacts_stays_empty(config):
    ds = copy.deepcopy(config["datasets"]["synthetic"])
    ds["synthetic"]["impacts"]["baseball"]["wood"] = 0
    k, counts = truth_counts(ds, 1000)
    assert counts["baseball"]["wood"] == 0 and k == math.ceil(6 * 1000 / 88)
    ds["synthetic"]["impacts"] = {"baseball": {"wood": 0}}
    with pytest.raises(ValueError, match="no impacts"):
        truth_counts(ds, 1000)


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


def test_the_unbalanced_design_runs_within_its_plan_on_this_machines_size(raw, schema):
    """At the default truth_impacts the 6-to-60 design is accepted on a 24 GiB machine (its plan: 4.0 GB)."""
    raw["datasets"]["synthetic"]["synthetic"]["impacts"] = copy.deepcopy(UNBALANCED)
    cfg = validate_config(raw, schema, available=23 * 2**30)
    s = StudySettings.from_config(cfg, "calibration")
    assert s.truth_mem_mb(0) * 1e6 <= MEMORY_SHARE * 23 * 2**30
    assert s.truth_mem_mb(0) == 500 + math.ceil(70_176 * 50_000 / 1e6)


def test_a_truth_the_machine_cannot_hold_is_refused_with_its_size(raw, schema):
    """The guard reads the same size: on a 6 GiB machine the 6-to-60 design's truth (70 176 impacts) is refused."""
    raw["datasets"]["synthetic"]["synthetic"]["impacts"] = copy.deepcopy(UNBALANCED)
    with pytest.raises(ConfigError) as err:
        validate_config(raw, schema, available=6 * 2**30)
    assert "studies.calibration.truth_impacts: 70,176 impacts need about 3.3 GiB" in str(err.value)


def test_the_workflow_schedules_each_truth_job_at_its_plan(tmp_path):
    """A dry run of the unbalanced design: every truth job is scheduled with StudySettings.truth_mem_mb of its point."""
    from ballbat.config_checks import load_config
    from workflow_helpers import make_workdir, snakemake, write_config

    wd = make_workdir(tmp_path)

    def edit(cfg):
        cfg["datasets"]["synthetic"]["synthetic"]["impacts"] = copy.deepcopy(UNBALANCED)
        cfg["studies"]["design"]["sweep"]["values"] = [6, 60]

    write_config(wd, edit)
    out = snakemake(wd, "-n", "results/studies/calibration/truth.nc", "results/studies/design/truth.nc")
    jobs = re.findall(
        r"rule study_truth_point:.*?wildcards: study=(\w+), point=(\d+)\n.*?mem_mb=(\d+)", out.stdout, re.S
    )
    planned = {(study, int(point)): int(mem) for study, point, mem in jobs}
    cfg = load_config(wd / "config" / "config.yaml")
    expect = {
        (name, p): StudySettings.from_config(cfg, name).truth_mem_mb(p)
        for name, p in [("calibration", 0), ("design", 0), ("design", 1)]
    }
    assert planned == expect
    assert expect["calibration", 0] == 500 + math.ceil(70_176 * 50_000 / 1e6)  # 344 x 204 impacts
    assert expect["design", 0] == 500 + math.ceil(1667 * 42 * 50_000 / 1e6)  # balanced: ceil(T / n) x 7 n
