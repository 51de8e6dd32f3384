"""Bring your own data: the example measured dataset through the real workflow, a bad
dataset beside it under --keep-going, and which jobs a swapped file or table reruns.
"""

from __future__ import annotations

import os
import time

import pytest
import xarray as xr
import yaml

from ballbat.compare import read_csv
from workflow_helpers import copy_run, planned_jobs, planned_logs, snakemake

pytestmark = pytest.mark.slow

BAD_CSV = """impact_id,bat,ball,v_bat_mph,v_ball_mph,theta_deg,omega_rpm
X1,maple,baseball,75,84,10,1900
X2,ash,baseball,75,fast,10,1900
X3,maple,baseball,-75,84,95,1900
"""


@pytest.fixture(scope="module")
def run(lab_run, tmp_path_factory):
    """A copy of the suite's lab run (small, synthetic; maple, the example), then bad beside them (--keep-going)."""
    wd = copy_run(lab_run, tmp_path_factory.mktemp("byod") / "run")
    (wd / "bad.csv").write_text(BAD_CSV)
    (wd / "bad.yaml").write_text(
        yaml.safe_dump({"datasets": {"bad": {"impacts": "bad.csv", "bats": "config/examples/maple_bats.csv"}}})
    )
    front = wd / "results" / "report" / "front.rst"
    assert front.is_file()
    front.unlink()  # so that the run with bad would have to make it
    (
        wd / "results" / "maple" / "paper_comparison.csv"
    ).unlink()  # and a good dataset's, which it must make all the same
    proc = snakemake(wd, "-c2", "--keep-going", "--configfile", "bad.yaml", check=False)
    # the report's front page covers every dataset of a config, so the failed run made none: the good
    # config's (small and maple) is its only job left
    assert not front.exists()
    assert planned_jobs(wd) == {"report_front": 1}
    snakemake(wd, "-c2")
    return wd, proc


def test_example_dataset_end_to_end(run):
    wd, _ = run
    res = wd / "results" / "maple"
    ing = xr.open_dataset(res / "ingest.nc")
    assert ing.attrs["n_excluded"] == 1 and ing.attrs["provenance_rule"] == "ingest"
    rec = xr.open_dataset(res / "reconstruct.nc")
    assert rec.sizes["impact"] == 31  # the excluded impact is kept, flagged
    assert int((rec.flag.values == 4).sum()) == 1
    assert "excluded at ingest" in str(rec.flag_reason.values[rec.flag.values == 4][0])
    fit = xr.open_dataset(res / "fit_ex.nc")
    e_x = fit.sel(ball="baseball", bat="maple")
    assert int(e_x.e_x_n) == 30 and abs(float(e_x.e_x) - 0.42) < 3 * float(e_x.e_x_err)
    rows = {(r["quantity"], r["ball"], r["bat"]): r for r in read_csv(res / "paper_comparison.csv")}
    assert float(rows[("e_x", "baseball", "maple")]["value"]) == pytest.approx(float(e_x.e_x), rel=1e-5)
    assert rows[("n_excluded", "baseball", "")]["value"] == "1"
    assert rows[("n_impacts", "baseball", "")]["value"] == "30"
    log = (res / "logs" / "ingest.log").read_text()
    assert "excluded: impact MP31 (row 32): alpha r omega / v_ball = 1.04" in log


def test_bad_dataset_stops_only_itself(run):
    wd, proc = run
    assert proc.returncode != 0
    assert (wd / "results" / "maple" / "paper_comparison.csv").is_file()  # remade by the run that failed on bad
    bad = wd / "results" / "bad"
    assert sorted(p.name for p in bad.iterdir() if p.is_file()) == []  # no partial files
    assert not list(bad.rglob("*.nc")) and not list(bad.rglob("*.tmp"))
    log = (bad / "logs" / "ingest.log").read_text()
    for msg in (
        "bad.csv: row 3, column bat: bat 'ash' is not in the bat table (known: maple)",
        "bad.csv: row 3, column v_ball_mph: 'fast' is not a number",
        "bad.csv: row 4, column v_bat_mph: -75 mph; a speed must be positive",
        "bad.csv: row 4, column theta_deg: 95 deg is outside the physical range (-90, 90)",
    ):
        assert msg in log, msg


def _restoring(path, new_text):
    """Context: ``path`` holds ``new_text``; afterwards its old text and mtime come back."""

    class Ctx:
        def __enter__(self):
            self.text, self.stat = path.read_text(), path.stat()
            path.write_text(new_text)
            os.utime(path, (time.time() + 60, time.time() + 60))  # newer than every output

        def __exit__(self, *exc):
            path.write_text(self.text)
            os.utime(path, (self.stat.st_atime, self.stat.st_mtime))

    return Ctx()


def _one_dataset(wd, name):
    """The rules of the planned jobs, all of dataset ``name`` (or of what follows every dataset:
    the scenarios that use its fits, the report's front page, the bats league table): no other
    dataset's job is planned.
    """
    logs = planned_logs(wd)
    assert logs, "nothing planned"
    follows_all = (f"results/{name}/", "results/implications/", "results/report/", "results/logs/")
    others = {log for log in logs if not log.startswith(follows_all)}
    assert not others, others
    return {rule for log, rule in logs.items() if log.startswith(f"results/{name}/")}


def test_replacing_a_file_reruns_only_its_dataset(run):
    wd, _ = run
    assert planned_jobs(wd) == {}
    path = wd / "config" / "examples" / "maple_impacts.csv"
    text = path.read_text()
    with _restoring(path, text.replace("MP01,maple,baseball,68.7", "MP01,maple,baseball,68.9")):
        jobs = _one_dataset(wd, "maple")
    assert {"ingest", "normalize", "reconstruct", "fit_ex", "compare"} <= jobs and "simulate" not in jobs
    assert planned_jobs(wd) == {}


def test_changing_a_bat_reruns_only_what_uses_its_table(run):
    wd, _ = run
    own = wd / "config" / "examples" / "maple_bats.csv"
    with _restoring(own, own.read_text().replace(",9.6,", ",9.9,")):
        jobs = _one_dataset(wd, "maple")
    assert {"ingest", "reconstruct", "fit_ex"} <= jobs and "simulate" not in jobs
    shared = wd / "config" / "bats.csv"
    with _restoring(shared, shared.read_text().replace("wood,wood,29.41", "wood,wood,29.50")):
        jobs = _one_dataset(wd, "small")  # maple has its own table
    assert {"simulate", "reconstruct", "fit_ex"} <= jobs and "ingest" not in jobs
    assert planned_jobs(wd) == {}


def test_override_file_merges_and_null_drops(run):
    wd, _ = run
    (wd / "drop.yaml").write_text("datasets:\n  maple: null\n")
    jobs = planned_jobs(wd, "--forceall", "--configfile", "drop.yaml")
    assert "simulate" in jobs and "ingest" not in jobs
    # --configfile merges mappings key by key: a dataset of the same name keeps its old keys
    (wd / "clash.yaml").write_text("datasets:\n  small:\n    impacts: bad.csv\n")
    out = snakemake(wd, "-n", "--configfile", "clash.yaml", check=False)
    assert out.returncode != 0
    assert "datasets.small: give exactly one of synthetic, impacts, tracks, not several" in out.stdout + out.stderr
