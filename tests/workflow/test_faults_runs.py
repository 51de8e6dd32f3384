"""Results that never outlive their inputs (issue 10): a job killed while writing, a missing input
file beside a good dataset, a measured file's warnings, on the real workflow's small measured dataset
(maple, in a copy of conftest.lab_run). The rest of the fault tests: test_faults.py; two modules so
that the two pytest-xdist processes (``make test``, a module per process) share the reruns.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time

import pytest
import yaml

from ballbat.pipeline.atomic import hostname
from workflow_helpers import MAPLE_DATA as DATA
from workflow_helpers import maple_data_files as data_files
from workflow_helpers import snakemake

pytestmark = pytest.mark.slow


def test_job_killed_while_writing(maple_copy):
    """Kill the run while jobs run: the rerun cleans the temporaries and ends as a clean run."""
    wd, reference = maple_copy
    for p in (wd / "results" / "maple").glob("*.nc"):
        p.unlink()
    env = dict(os.environ)
    proc = subprocess.Popen(
        [sys.executable, "-m", "snakemake", "-c1", *DATA],
        cwd=wd,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    deadline = time.time() + 60
    while time.time() < deadline and not (wd / "results" / "maple" / "normalize.nc").exists():
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)
    # as a job killed mid-write leaves it: a temporary file beside its output
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = wd / "results" / "maple" / f".fit_ex.nc.{dead.pid}@{hostname()}.abc12345.tmp"  # its owner is dead
    stale.write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 4096)
    shutil.rmtree(wd / ".snakemake" / "locks", ignore_errors=True)  # the killed run's lock
    out = snakemake(wd, "-c2", *DATA, "--rerun-incomplete")
    assert f"{stale}".split("/results/")[1] in out.stderr.replace(str(wd) + "/", "")
    assert not list((wd / "results").rglob("*.tmp"))
    assert data_files(wd) == reference


def test_missing_input_stops_only_its_dataset(maple_copy, tmp_path):
    """A dataset whose file is missing, or a directory, fails its own job with --keep-going; the
    others complete (before, a missing file stopped every dataset when the DAG was built).
    """
    wd, reference = maple_copy
    (wd / "missing.yaml").write_text(
        yaml.safe_dump(
            {
                "datasets": {
                    "gone": {"impacts": "nothere.csv", "bats": "config/examples/maple_bats.csv"},
                    "folder": {"impacts": "config", "bats": "config/examples/maple_bats.csv"},
                }
            }
        )
    )
    for product in ("paper_comparison.csv", "results.xlsx"):  # the good dataset has jobs to run
        (wd / "results" / "maple" / product).unlink()
    out = snakemake(wd, "-c2", "--keep-going", "--configfile", "missing.yaml", check=False)
    assert out.returncode != 0
    assert data_files(wd) == reference  # the good dataset is whole: its jobs ran beside the failing ones
    assert "nothere.csv: file not found" in (wd / "results" / "gone" / "logs" / "ingest.log").read_text()
    assert "config: is a directory, not a CSV file" in (wd / "results" / "folder" / "logs" / "ingest.log").read_text()
    assert not list((wd / "results" / "gone").rglob("*.nc"))


def test_warnings_reach_every_product_and_the_end_of_the_run(maple_copy, tmp_path):
    """A measured file's warnings are in fit_ex.nc, stronge.nc, the comparison and the workbook,
    and the run prints them when it ends.
    """
    wd, _ = maple_copy
    lines = (wd / "config" / "examples" / "maple_impacts.csv").read_text().splitlines()
    head = lines[0].split(",")
    keep = [i for i, h in enumerate(head) if h != "theta_deg_err"]  # 3 of the 4 uncertainty columns
    (wd / "warn.csv").write_text("\n".join(",".join(c.split(",")[i] for i in keep) for c in lines) + "\n")
    (wd / "warn.yaml").write_text(
        yaml.safe_dump({"datasets": {"warn": {"impacts": "warn.csv", "bats": "config/examples/maple_bats.csv"}}})
    )
    out = snakemake(wd, "-c2", "--configfile", "warn.yaml")
    assert "warnings of this run" in out.stderr and "only v_bat_mph_err" in out.stderr
    import openpyxl
    import xarray as xr

    res = wd / "results" / "warn"
    for name in ("fit_ex.nc", "stronge.nc"):
        with xr.open_dataset(res / name) as ds:
            assert ds.attrs["n_warnings"] == 1 and "only v_bat_mph_err" in ds.attrs["ingest_warnings"], name
    assert "## Warnings" in (res / "paper_comparison.md").read_text()
    assert "n_warnings,,,,,1," in (res / "paper_comparison.csv").read_text()
    book = openpyxl.load_workbook(res / "results.xlsx")
    assert "only v_bat_mph_err" in str(book["warnings"]["A3"].value)
    # the report's front page lists it once, with the log that has it (escaped for reStructuredText)
    front = (wd / "results" / "report" / "front.rst").read_text()
    assert front.count("only v\\_bat\\_mph\\_err") == 1 and "results/warn/logs/ingest.log" in front
