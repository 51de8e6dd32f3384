"""Red team, issue 19: nothing deleted, stale or half-checked behind the user's back.

:data:`RED_TEAM` lists each case with its expected outcome and the tests that hold it (each
fails on the code before issue 19 and passes now). The workflow is built once for the suite
(``conftest.lab_run``: a small rendered dataset, the measured example, the scenarios and small studies);
each workflow test works on its own copy of that finished folder.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from helpers import assert_cases_have_tests

from ballbat import compare
from ballbat.pipeline import guards
from ballbat.pipeline.atomic import atomic_target, hostname, temporary_owner
from ballbat.pipeline.checked import (
    CHECKSUM_ATTR,
    DamagedFileError,
    hdf5_problem,
    netcdf_problem,
    read_sealed_csv,
    sealed_csv,
    verify_netcdf,
)
from ballbat.pipeline.ncio import read_dataset, write_dataset
from ballbat.pipeline.runlog import logged
from ballbat.studies.coverage import COVERAGE_COLUMNS
from ballbat.studies.design import DESIGN_COLUMNS
from workflow_helpers import copy_run, planned_jobs, snakemake

#: case -> (expected outcome, tests)
RED_TEAM = {
    "`snakemake -n` / `--summary` with a user's NetCDF-3 file and a truncated product under results/": (
        "nothing removed or written; each named, the product with the command that rebuilds it",
        ["test_parsing_removes_nothing", "test_damaged_products_only_reads"],
    ),
    "a real run would replace a user's file under results/": (
        "the run stops before any job, naming the file; the file is intact",
        ["test_run_never_replaces_a_users_file"],
    ),
    "two runs in one folder with different targets: run 1's job is writing its temporary": (
        "run 2 leaves it; only a dead job's temporary on this host is removed",
        ["test_live_temporaries_survive_a_second_run", "test_remove_temporaries_only_dead_jobs_on_this_host"],
    ),
    "read-only results folder, with one damaged .nc or none: `-n`, `--unlock`, a run": (
        "one line naming the folder, exit status 1, no traceback",
        ["test_read_only_results_folder", "test_unwritable_names_the_folder"],
    ),
    "config/bats.csv or balls.csv replaced by a copy with an older timestamp": (
        "implications, the datasets and the study's jobs rerun (content, not timestamp)",
        ["test_property_table_content_reruns_implications_and_studies"],
    ),
    "a study's truth.nc or a batch deleted": (
        "rebuilt by `snakemake studies`, identical",
        ["test_deleted_study_products_are_rebuilt"],
    ),
    "mid-file corruption of a NetCDF product (its header whole)": (
        "the job reading it fails naming it (no HDF traceback) and removes it (the workflow wrote it); "
        "the next run rebuilds it",
        ["test_mid_file_corruption_is_found_and_rebuilt", "test_verify_netcdf_reads_every_byte"],
    ),
    "truncated paper_comparison.csv (2 rows of 41)": (
        "named by a dry run; the HTML and the workbook are not built from it; the next run rebuilds it",
        ["test_truncated_table_is_never_used", "test_sealed_csv_refuses_a_truncated_table"],
    ),
    "a job finds a damaged input the user wrote": (
        "refused, never removed",
        ["test_a_job_removes_only_what_the_workflow_wrote"],
    ),
}


def test_every_case_has_its_tests():
    assert_cases_have_tests(RED_TEAM, globals())


# --- unit tests of the guards ----------------------------------------------------------------


def small_dataset():
    return xr.Dataset(
        {"x": ("n", np.linspace(0.0, 1.0, 4000), {"units": "m", "long_name": "a length"})},
        coords={"n": ("n", np.arange(4000), {"units": "1", "long_name": "index"})},
    )


def write_product(path):
    return write_dataset(small_dataset(), path, title="t", rule="r", inputs={}, config={})


def test_verify_netcdf_reads_every_byte(tmp_path):
    path = write_product(tmp_path / "results" / "x.nc")
    assert netcdf_problem(path) is None and CHECKSUM_ATTR not in read_dataset(path).attrs
    data = bytearray(path.read_bytes())
    at = data.find(np.linspace(0.0, 1.0, 4000)[2000:2001].tobytes())  # a value in the middle of the file
    assert 0 < at < len(data) - 1000
    data[at + 3] ^= 0xFF
    path.write_bytes(bytes(data))
    assert hdf5_problem(path) is None  # the header is whole: only the checksum finds it
    with pytest.raises(DamagedFileError, match=r"x\.nc: damaged: its contents differ"):
        read_dataset(path)
    path.write_bytes(bytes(data[: len(data) // 2]))
    with pytest.raises(DamagedFileError, match=r"x\.nc: truncated"):
        verify_netcdf(path)


def test_sealed_files_are_byte_identical_on_rewrite(tmp_path):
    a = write_product(tmp_path / "a" / "x.nc").read_bytes()
    b = write_product(tmp_path / "b" / "x.nc").read_bytes()
    assert a == b


def test_sealed_csv_refuses_a_truncated_table(tmp_path):
    table = compare.to_csv([{c: "1" for c in compare.COLUMNS} | {"quantity": f"q{i}"} for i in range(41)])
    path = tmp_path / "paper_comparison.csv"
    path.write_text(sealed_csv(table))
    assert read_sealed_csv(path) == table and len(compare.read_csv(path)) == 41
    path.write_text("".join(sealed_csv(table).splitlines(keepends=True)[:3]))  # 2 rows of 41
    with pytest.raises(DamagedFileError, match=r"paper_comparison\.csv: no check line"):
        compare.read_csv(path)
    lines = sealed_csv(table).splitlines(keepends=True)
    path.write_text("".join(lines[:3] + lines[-1:]))  # rows cut out, check line kept
    with pytest.raises(DamagedFileError, match="2 rows, but it was written with 41"):
        compare.read_csv(path)


def test_table_headers_are_the_writers(tmp_path):
    """The headers that recognise an unsealed table as the workflow's are those its writers write."""
    assert ",".join(compare.COLUMNS).startswith(guards.TABLE_HEADERS[0])
    assert ",".join(COVERAGE_COLUMNS).startswith(guards.TABLE_HEADERS[1])
    assert ",".join(DESIGN_COLUMNS).startswith(guards.TABLE_HEADERS[2])


def test_damaged_products_only_reads(tmp_path):
    own = write_product(tmp_path / "results" / "own.nc")
    with open(own, "r+b") as fh:
        fh.truncate(own.stat().st_size - 100)
    user = tmp_path / "results" / "user.nc"
    user.write_bytes(b"CDF\x01" + b"\0" * 100)  # a NetCDF-3 file
    before = {p: p.read_bytes() for p in (own, user)}
    lines = guards.damaged_products([own, user, tmp_path / "results" / "absent.nc"])
    assert {p: p.read_bytes() for p in (own, user)} == before
    assert lines[0].startswith(f"{own}: truncated") and f"snakemake --forcerun {own}" in lines[0]
    assert lines[1].startswith(f"{user}: not a NetCDF-4/HDF5 file") and "not written by this workflow" in lines[1]


def test_atomic_temporaries_name_their_owner(tmp_path):
    with atomic_target(tmp_path / "out.nc") as tmp:
        assert temporary_owner(tmp.name) == (os.getpid(), hostname())
        tmp.write_bytes(b"x")
    assert temporary_owner(".out.nc.abc123.tmp") is None  # the old, ownerless names


def dead_pid():
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_remove_temporaries_only_dead_jobs_on_this_host(tmp_path):
    host = hostname()
    names = {
        "live": f".a.nc.{os.getpid()}@{host}.abcd1234.tmp",
        "dead": f".b.nc.{dead_pid()}@{host}.abcd1234.tmp",
        "dead_png": f".fig3.png.{dead_pid()}@{host}.abcd1234.png",
        "other_host": f".c.nc.{dead_pid()}@elsewhere.example.abcd1234.tmp",
        "unowned": ".d.nc.abc123.tmp",
    }
    for name in names.values():
        (tmp_path / name).write_bytes(b"partial")
    lines = guards.remove_temporaries(tmp_path)
    left = {p.name for p in tmp_path.iterdir()}
    assert left == {names["live"], names["other_host"], names["unowned"]}
    assert len(lines) == 2 and all("temporary file of a job that died" in line for line in lines)


@contextlib.contextmanager
def read_only(folder):
    """Make ``folder`` read-only: a read-only bind mount as root (root writes through chmod), chmod else."""
    folder = Path(folder)
    if os.geteuid() == 0:
        done = subprocess.run(["mount", "--bind", "-o", "ro", str(folder), str(folder)], capture_output=True)
        if done.returncode != 0:
            pytest.skip(f"cannot make a read-only folder here: {done.stderr.decode().strip()}")
        try:
            yield folder
        finally:
            subprocess.run(["umount", str(folder)], check=True)
    else:
        mode = folder.stat().st_mode
        folder.chmod(0o555)
        try:
            yield folder
        finally:
            folder.chmod(mode)


READ_ONLY_WHY = "the workflow writes its results and Snakemake its records here"


def test_unwritable_names_the_folder(tmp_path):
    (tmp_path / "results").mkdir()
    assert guards.unwritable(tmp_path / "results") is None
    with read_only(tmp_path / "results"):
        line = guards.unwritable(tmp_path / "results")
        assert line == f"{tmp_path / 'results'}: folder is read-only; " + READ_ONLY_WHY
        assert guards.unwritable(tmp_path / "results" / "new").startswith(f"{tmp_path / 'results'}: ")


def test_a_job_removes_only_what_the_workflow_wrote(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    own = write_product(Path("results") / "own.nc")
    with open(own, "r+b") as fh:
        fh.truncate(own.stat().st_size // 2)
    user = Path("results") / "user.nc"
    xr.Dataset({"x": ("n", np.arange(3000.0))}).to_netcdf(user, format="NETCDF4")
    assert netcdf_problem(user) is None  # a whole file of the user's is read as it is
    with open(user, "r+b") as fh:
        fh.truncate(user.stat().st_size // 2)
    with pytest.raises(DamagedFileError, match=r"own\.nc: truncated.*removed \(this workflow wrote it\)"):
        with logged("log/own.log", "r"):
            read_dataset(own)
    assert not own.exists()
    with pytest.raises(DamagedFileError, match=r"user\.nc: truncated.*not written by this workflow, so left alone"):
        with logged("log/user.log", "r"):
            read_dataset(user)
    assert user.exists()


# --- the workflow ----------------------------------------------------------------------------


@pytest.fixture(scope="session")
def finished(lab_run):
    """One finished run: datasets small and maple, the scenarios, small studies (conftest.lab_run)."""
    return lab_run


@pytest.fixture
def run(finished, tmp_path):
    """A copy of the finished run (timestamps kept) for one test to change."""
    return copy_run(finished, tmp_path / "wd")


def nc_state(wd):
    """Every NetCDF product's variables (not its provenance attributes)."""
    out = {}
    for p in sorted((wd / "results").rglob("*.nc")):
        with xr.open_dataset(p) as ds:
            out[str(p.relative_to(wd))] = ds.drop_attrs(deep=False).load()
    return out


def assert_same_state(a, b):
    assert sorted(a) == sorted(b)
    for name in a:
        assert a[name].identical(b[name]), name


@pytest.mark.slow
def test_parsing_removes_nothing(run):
    user = run / "results" / "small" / "fit_ex.nc"
    user.write_bytes(b"CDF\x01" + b"\0" * 200)  # the user's NetCDF-3 file where a product goes
    own = run / "results" / "small" / "reconstruct.nc"
    with open(own, "r+b") as fh:
        fh.truncate(own.stat().st_size // 2)
    before = {p: p.read_bytes() for p in (user, own)}
    for args in (["-n"], ["--summary"], ["--lint"]):
        out = snakemake(run, *args)
        assert {p: p.read_bytes() for p in (user, own)} == before, args
        assert "results/small/reconstruct.nc: truncated" in out.stderr, args
        assert "snakemake --forcerun results/small/reconstruct.nc" in out.stderr, args
        assert "results/small/fit_ex.nc: not a NetCDF-4/HDF5 file" in out.stderr, args
        assert "not written by this workflow" in out.stderr and "removed" not in out.stderr, args


@pytest.mark.slow
def test_run_never_replaces_a_users_file(run):
    user = run / "results" / "small" / "fit_ex.nc"
    user.write_bytes(b"CDF\x01" + b"\0" * 200)
    (run / "results" / "small" / "normalize.nc").unlink()  # so that the run would rebuild fit_ex.nc
    out = snakemake(run, "-c2", check=False)
    assert out.returncode != 0
    assert "results/small/fit_ex.nc: not written by this workflow (no provenance record), and this run would" in (
        out.stderr
    )
    assert user.read_bytes() == b"CDF\x01" + b"\0" * 200
    assert not (run / "results" / "small" / "normalize.nc").exists()  # no job ran


@pytest.mark.slow
def test_live_temporaries_survive_a_second_run(run):
    """Run 1's job writes a temporary (a live process owns it); run 2 (another target) leaves it."""
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])
    try:
        res = run / "results" / "small"
        mine = res / f".stronge.nc.{live.pid}@{hostname()}.abcd1234.tmp"
        mine.write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 4096)
        dead = res / f".fit_ex.nc.{dead_pid()}@{hostname()}.abcd1234.tmp"
        dead.write_bytes(b"\x89HDF\r\n\x1a\n")
        (run / "results" / "implications" / "paper_comparison.md").unlink()
        out = snakemake(run, "-c1", "results/implications/paper_comparison.md")
        assert mine.exists() and not dead.exists()
        assert f"{dead.relative_to(run)}: temporary file of a job that died" in out.stderr
    finally:
        live.kill()
        live.wait()


@pytest.mark.slow
def test_read_only_results_folder(run):
    """A damaged .nc in a read-only results folder: every invocation says so in one line, no traceback."""
    own = run / "results" / "small" / "reconstruct.nc"
    with open(own, "r+b") as fh:
        fh.truncate(own.stat().st_size // 2)
    with read_only(run / "results"):
        for args in (["-n"], ["--unlock"], ["-c1"]):
            out = snakemake(run, *args, check=False)
            assert out.returncode == 1, args
            lines = [line for line in out.stderr.splitlines() if line.startswith("ballbat:")]
            assert lines == ["ballbat: results: folder is read-only; " + READ_ONLY_WHY], (args, out.stderr)
            assert "Traceback" not in out.stderr and "PermissionError" not in out.stderr, args


@pytest.mark.slow
def test_property_table_content_reruns_implications_and_studies(run):
    """Bats.csv replaced by a copy with an older timestamp (cp -p, tar, rsync -a): the content decides."""
    assert planned_jobs(run, "all", "studies") == {}
    bats = run / "config" / "bats.csv"
    old = bats.stat().st_mtime - 10 * 86400
    lines = bats.read_text().splitlines(keepends=True)
    bats.write_text("".join(lines) + "\n")  # the same table, other bytes
    os.utime(bats, (old, old))
    jobs = planned_jobs(run, "all", "studies")
    for rule in ("implications", "simulate", "reconstruct", "study_batch", "study_truth", "study_aggregate"):
        assert rule in jobs, (rule, jobs)


@pytest.mark.slow
def test_deleted_study_products_are_rebuilt(run):
    study = run / "results" / "studies" / "calibration"
    before = nc_state(run)
    (study / "truth.nc").unlink()
    (study / "batches" / "batch1.nc").unlink()
    jobs = planned_jobs(run, "studies")
    assert {rule: jobs.get(rule) for rule in ("study_truth", "study_batch", "study_aggregate", "simulate")} == {
        "study_truth": 1,
        "study_batch": 1,
        "study_aggregate": 1,
        "simulate": None,  # nothing else of the run
    }
    snakemake(run, "-c2", "studies")
    assert_same_state(nc_state(run), before)


@pytest.mark.slow
def test_mid_file_corruption_is_found_and_rebuilt(run):
    path = run / "results" / "small" / "fit_ex.nc"
    before = nc_state(run)
    with xr.open_dataset(path) as ds:
        value = ds["e_x_err"].values.ravel()
    data = bytearray(path.read_bytes())
    at = data.find(value[np.isfinite(value)][0:1].astype("<f8").tobytes())
    assert at > 0
    data[at + 2] ^= 0xFF
    path.write_bytes(bytes(data))
    out = snakemake(run, "-c1", "--forcerun", "plot_fig5", "--", "results/small/figures/fig5.png", check=False)
    assert out.returncode != 0
    log = (run / "results" / "small" / "logs" / "plot_fig5.log").read_text()
    assert "results/small/fit_ex.nc: damaged: its contents differ from those it was written with" in log
    assert "removed (this workflow wrote it): run again to rebuild it" in log
    assert "HDF" not in log
    assert not path.exists()
    snakemake(run, "-c2", "results/small/fit_ex.nc")
    assert_same_state(nc_state(run), before)


@pytest.mark.slow
def test_truncated_table_is_never_used(run):
    csv = run / "results" / "small" / "paper_comparison.csv"
    text = csv.read_text()
    csv.write_text("".join(text.splitlines(keepends=True)[:3]))  # 2 rows
    out = snakemake(run, "-n")
    assert "results/small/paper_comparison.csv: no check line" in out.stderr
    logs = run / "results" / "small" / "logs"
    for product, log in (("paper_comparison.html", "comparison_html.log"), ("results.xlsx", "workbook.log")):
        target = run / "results" / "small" / product
        target.unlink()
        csv.write_text("".join(text.splitlines(keepends=True)[:3]))
        out = snakemake(run, "-c1", str(target.relative_to(run)), check=False)
        assert out.returncode != 0 and not target.exists(), product
        assert "results/small/paper_comparison.csv: no check line" in (logs / log).read_text(), log
        assert not csv.exists()  # the workflow wrote it: removed, so that the next run rebuilds it
    snakemake(run, "-c2")
    assert csv.read_text() == text
