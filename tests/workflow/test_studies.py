"""Replicate studies (issue 12) through Snakemake: the study rules' files, the report's study pages."""

from __future__ import annotations

import csv
import io

import numpy as np
import pytest
import xarray as xr

from ballbat.pipeline.ncio import read_table_csv
from ballbat.studies.coverage import COVERAGE_COLUMNS


@pytest.mark.slow
def test_study_rules_through_snakemake(lab_run, tmp_path):
    """`snakemake studies` (the lab run's, conftest.LAB_STUDIES, of dataset small): batches, coverage and
    design files with units and provenance; `all` runs none; the report holds every study's figures.
    """
    from workflow_helpers import assert_cf, assert_not_blank, copy_run, make_workdir, planned_jobs, snakemake

    assert not any(r.startswith("study") for r in planned_jobs(make_workdir(tmp_path)))  # a default run makes no study
    res = lab_run / "results" / "studies"
    assert sorted(p.name for p in (res / "calibration" / "batches").iterdir()) == ["batch0.nc", "batch1.nc"]
    cov = xr.open_dataset(res / "calibration" / "coverage.nc")
    n_q = 3 + 2 * 7  # small: e_x of 3 bats; per ball, pooled e_x, 3 slopes, e_y, the mu_k bound, eta^2
    assert cov.sizes == {"point": 1, "quantity": n_q}
    assert all("units" in cov[v].attrs or cov[v].attrs.get("units_from") == "units" for v in cov.data_vars)
    assert cov.attrs["provenance_rule"] == "study_aggregate"
    truth = xr.open_dataset(res / "calibration" / "truth.nc")
    assert truth.attrs["provenance_rule"] == "study_truth" and truth.attrs["truth_impacts"] == 40
    assert set(truth.quantity.values) == set(cov.quantity.values)
    judged = cov.quantity.values[cov.quantity_name.values != "mu_k_lower_bound"]  # the others: the design's truth
    assert np.allclose(
        truth.truth.sel(quantity=judged).values, cov.mean_truth.sel(quantity=judged).values, rtol=1e-12, equal_nan=True
    )
    assert int(cov.n_replicates.max()) == 4
    rows = list(csv.DictReader(io.StringIO(read_table_csv(res / "calibration" / "coverage.csv"))))
    assert len(rows) == n_q and set(rows[0]) == set(COVERAGE_COLUMNS)
    design = list(csv.DictReader(io.StringIO(read_table_csv(res / "design" / "design.csv"))))
    per_size = len(design) // 2
    assert per_size >= 3 and [r["setting"] for r in design] == ["5"] * per_size + ["8"] * per_size
    assert all(float(r["impacts_required"]) >= 3 for r in design)
    for png in ("calibration/coverage.png", "design/coverage.png", "design/design.png"):
        assert_not_blank(res / png)
    one_per_rule = ["calibration/truth/point0.nc", "calibration/truth.nc", "calibration/batches/batch0.nc"]
    one_per_rule += ["calibration/coverage.nc", "design/design.nc", "robustness/coverage.nc"]  # a grid's columns
    assert_cf([str(res / f) for f in one_per_rule], tmp_path / "cf.json")
    # the report's front page: one line per study (rule report_front_studies), shown when the report holds them
    front = (res / "front.rst").read_text()
    assert f"**calibration** (4 replicates per point, {n_q} quantities): 95 % intervals cover the truth in" in front
    assert "**design** (2 replicates per point" in front and "impacts per bat to tell two bats" in front
    wd = copy_run(lab_run, tmp_path / "wd")
    snakemake(wd, "--report", "results/report.html", "studies", "studies_on_request")
    html = (wd / "results" / "report.html").read_text()
    assert "Replicate studies" in html and "What was run" not in html  # no dataset's target: no run's front page
    assert "grid.png" in html and "Grid study" in html
