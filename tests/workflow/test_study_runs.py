"""Studies through Snakemake: the robustness study's DAG and a small run, each truth job at its plan's memory
(issues 22, 40).
"""

from __future__ import annotations

import copy
import csv
import io
import math
import re

import pytest
import xarray as xr
from helpers import UNBALANCED

from ballbat.studies.settings import StudySettings


@pytest.mark.slow
def test_the_robustness_figure_is_in_the_dag(tmp_path):
    """`snakemake -n studies_on_request` plans the grid figure; `studies` (make study) plans no robustness job."""
    from workflow_helpers import make_workdir, snakemake

    wd = make_workdir(tmp_path)
    out = snakemake(wd, "-n", "studies_on_request").stdout
    assert "rule study_grid:" in out and "results/studies/robustness/grid.png" in out
    assert "results/studies/robustness/batches/batch107.nc" in out  # 27 points x 400 replicates in 100s
    assert "results/studies/robustness/" not in snakemake(wd, "-n", "studies").stdout


@pytest.mark.slow
def test_a_small_robustness_study_runs_through_snakemake(lab_run):
    """The on-request grid study through Snakemake (the lab run's, conftest.LAB_STUDIES: 2 points of dataset
    small): a truth job per point, coverage with the grid's columns and combined intervals, the
    grid figure (in the report: test_studies.test_study_rules_through_snakemake).
    """
    from ballbat.pipeline.ncio import read_table_csv
    from workflow_helpers import assert_not_blank

    res = lab_run / "results" / "studies" / "robustness"
    assert sorted(p.name for p in (res / "truth").iterdir()) == ["point0.nc", "point1.nc"]
    truth = xr.open_dataset(res / "truth.nc")
    assert truth.attrs["provenance_rule"] == "study_truth" and truth.sizes["point"] == 2
    rows = list(csv.DictReader(io.StringIO(read_table_csv(res / "coverage.csv"))))
    assert len(rows) == 2 * truth.sizes["quantity"]
    assert rows[-1]["setting"] == "pixel_noise_px=5 impacts_per_bat=6 contact_ms=1"
    assert (rows[-1]["pixel_noise_px"], rows[-1]["contact_ms"]) == ("5", "1")
    ex = [r for r in rows if r["quantity"] == "e_x"]
    assert len(ex) == 2 * 3 and all(
        float(r["mean_systematic"]) > 0 for r in ex
    )  # drawn calibration: e_x's pixel-scale systematic
    assert_not_blank(res / "grid.png")
    assert not (res / "design.csv").exists()  # a grid has no design table


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
