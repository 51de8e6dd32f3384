"""Unit tests of the results folder's guards (ballbat.pipeline.guards), on small files in a temporary folder.
The same guards on a real run: tests/workflow/test_guards.py.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import product_file as product
from helpers import users_netcdf4

from ballbat.pipeline import checked, guards
from ballbat.pipeline.atomic import hostname
from ballbat.pipeline.checked import sealed_csv

SIG = checked.HDF5_SIGNATURE


def dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


# --- written_by_workflow, product_problem ------------------------------------------------


def test_written_by_workflow_netcdf(tmp_path):
    own = product(tmp_path / "own.nc")
    assert guards.written_by_workflow(own)
    with open(own, "r+b") as fh:  # still recognised when cut short: the mark is near the start
        fh.truncate(own.stat().st_size // 2)
    assert guards.written_by_workflow(own)
    assert not guards.written_by_workflow(users_netcdf4(tmp_path / "user.nc"))
    late = tmp_path / "late.nc"  # the mark beyond the first 64 KiB is not looked for
    late.write_bytes(SIG + bytes(guards.MARK_WINDOW) + guards.PROVENANCE_MARK)
    assert not guards.written_by_workflow(late)
    early = tmp_path / "early.nc"
    early.write_bytes(SIG + bytes(guards.MARK_WINDOW - 100) + guards.PROVENANCE_MARK)
    assert guards.written_by_workflow(early)


@pytest.mark.parametrize("header", guards.TABLE_HEADERS)
def test_written_by_workflow_csv_by_its_header(tmp_path, header):
    path = tmp_path / "t.csv"
    path.write_text(header + "x,y\n1,2,3,4,5,6\n")  # an old table without its check line
    assert guards.written_by_workflow(path)


def test_written_by_workflow_csv_by_its_check_line(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text(sealed_csv("a,b\n1,2\n"))
    assert guards.written_by_workflow(path)
    path.write_text("a,b\n1,2\n")
    assert not guards.written_by_workflow(path)
    path.write_text("a,b\n1,2  # ballbat table: 1 rows\n")  # not on a line of its own
    assert not guards.written_by_workflow(path)


def test_product_problem_by_suffix(tmp_path):
    nc = tmp_path / "x.nc"
    nc.write_bytes(b"CDF\x01")
    assert guards.product_problem(nc) == "not a NetCDF-4/HDF5 file (4 bytes, no HDF5 signature)"
    table = tmp_path / "t.csv"
    table.write_text(sealed_csv("a,b\n1,2\n3,4\n"))
    assert guards.product_problem(table) is None
    lines = table.read_text().splitlines(keepends=True)
    table.write_text("".join(lines[:2]))  # the check line and a row cut off
    assert guards.product_problem(table).startswith("no check line ('# ballbat table: ...') at its end (8 bytes)")
    table.write_text("".join([lines[0], lines[1], lines[3]]))  # a row cut out, the check line kept
    assert guards.product_problem(table) == "1 rows, but it was written with 2"
    png = tmp_path / "fig.png"
    png.write_bytes(b"not a png")
    assert guards.product_problem(png) is None  # figures are not judged


# --- damaged_products --------------------------------------------------------------------


def test_damaged_products_names_each_with_what_to_do(tmp_path):
    res = tmp_path / "results"
    own = product(res / "a" / "own.nc")
    with open(own, "r+b") as fh:
        fh.truncate(own.stat().st_size - 10)
    own_csv = res / "a" / "paper_comparison.csv"
    own_csv.write_text("".join(sealed_csv("quantity,ball,bat,paper,\ne_x,,,\n").splitlines(keepends=True)[:1]))
    user = res / "b" / "user.nc"
    user.parent.mkdir()
    user.write_bytes(b"CDF\x01" + bytes(20))
    user_csv = res / "b" / "mine.csv"
    user_csv.write_text("a,b\n1,2\n")
    whole = product(res / "c" / "whole.nc")
    (res / "c" / "fig.png").write_bytes(b"junk")
    (res / "c" / "dir.nc").mkdir()
    before = {p: p.read_bytes() for p in (own, own_csv, user, user_csv, whole)}
    paths = [whole, user_csv, own, user, own_csv, own, res / "absent.nc", res / "c" / "fig.png", res / "c" / "dir.nc"]
    lines = guards.damaged_products(str(p) for p in paths)
    assert {p: p.read_bytes() for p in before} == before  # nothing removed or changed
    size = own.stat().st_size
    assert lines == [
        f"{own}: truncated: {size} bytes, but its HDF5 superblock says it ends at byte {size + 10}; "
        f"rebuild it with: snakemake --forcerun {own}",
        f"{own_csv}: no check line ('# ballbat table: ...') at its end (25 bytes): cut short, or not a table this "
        f"workflow wrote; rebuild it with: snakemake --forcerun {own_csv}",
        f"{user_csv}: no check line ('# ballbat table: ...') at its end (8 bytes): cut short, or not a table this "
        "workflow wrote, and not written by this workflow (no provenance record); it is left alone: "
        "move it out of results/",
        f"{user}: not a NetCDF-4/HDF5 file (24 bytes, no HDF5 signature), and not written by this workflow "
        "(no provenance record); it is left alone: move it out of results/",
    ]  # sorted by path, each once; whole files, figures, folders and absent files not named


def test_damaged_products_of_nothing():
    assert guards.damaged_products([]) == []


# --- foreign_outputs ---------------------------------------------------------------------


def test_foreign_outputs_refuse_only_the_users_files(tmp_path):
    res = tmp_path / "results"
    own = product(res / "own.nc")
    own_csv = res / "paper_comparison.csv"
    own_csv.write_text(sealed_csv("quantity,ball,bat\n"))
    user = users_netcdf4(res / "fit_ex.nc")
    user_csv = res / "coverage.csv"
    user_csv.write_text("my,own,table\n")
    (res / "fig.png").write_bytes(b"a user's picture")  # Snakemake replaces figures; not guarded
    lines = guards.foreign_outputs([own, own_csv, user, user_csv, user, res / "fig.png", res / "absent.nc"])
    why = (
        "not written by this workflow (no provenance record), and this run would replace it; "
        "nothing was changed: move it out of results/ and run again"
    )
    assert lines == [f"{user_csv}: {why}", f"{user}: {why}"]
    assert user_csv.read_text() == "my,own,table\n" and user.is_file()


# --- remove_temporaries ------------------------------------------------------------------


def test_remove_temporaries_message_and_nested_folders(tmp_path):
    host = hostname()
    dead = dead_pid()
    deep = tmp_path / "ds" / "figures"
    deep.mkdir(parents=True)
    gone = deep / f".fig3.png.{dead}@{host}.abcd1234.png"
    gone.write_bytes(b"1234567")
    folder = tmp_path / f".x.nc.{dead}@{host}.abcd1234.tmp"  # a folder of that name: not a temporary file
    folder.mkdir()
    plain = tmp_path / ".hidden"
    plain.write_text("a user's dot file")
    lines = guards.remove_temporaries(tmp_path)
    assert lines == [f"{gone}: temporary file of a job that died (pid {dead}, 7 bytes); removed"]
    assert not gone.exists() and folder.is_dir() and plain.is_file()


def test_remove_temporaries_of_another_host_and_no_folder(tmp_path):
    dead = dead_pid()
    tmp = tmp_path / f".a.nc.{dead}@node17.abcd1234.tmp"
    tmp.write_bytes(b"x")
    assert guards.remove_temporaries(tmp_path) == []  # made on another host: its job may live there
    assert guards.remove_temporaries(tmp_path, host="node17") == [
        f"{tmp}: temporary file of a job that died (pid {dead}, 1 bytes); removed"
    ]
    assert guards.remove_temporaries(tmp_path / "absent") == []


# --- unwritable, unwritable_folders ------------------------------------------------------


@pytest.fixture
def deny(monkeypatch):
    """Make os.access (as guards sees it) refuse writing to the folders added to the returned set."""
    denied: set[Path] = set()
    real = os.access

    def access(path, mode):
        if mode & os.W_OK and Path(path).resolve() in denied:
            return False
        return real(path, mode)

    monkeypatch.setattr(guards.os, "access", access)
    return denied


WHY = "folder is read-only; the workflow writes its results and Snakemake its records here"


def test_unwritable_names_the_first_existing_folder(tmp_path, deny):
    res = tmp_path / "results"
    res.mkdir()
    assert guards.unwritable(res / "new" / "deeper") is None
    deny.add(res.resolve())
    assert guards.unwritable(res / "new" / "deeper") == f"{res}: {WHY}"  # the folder that exists
    assert guards.unwritable(res) == f"{res}: {WHY}"


def test_unwritable_current_folder_by_its_full_path(tmp_path, deny, monkeypatch):
    monkeypatch.chdir(tmp_path)
    deny.add(tmp_path.resolve())
    assert guards.unwritable(".") == f"{Path.cwd()}: {WHY}"
    assert guards.unwritable("results") == f"{Path.cwd()}: {WHY}"  # not there yet: the folder it would go in


def test_unwritable_folders_looks_inside(tmp_path, deny):
    res = tmp_path / "results"
    (res / "a" / "logs").mkdir(parents=True)
    (res / "b").mkdir()
    other = tmp_path / "other"
    other.mkdir()
    assert guards.unwritable_folders([res, other, tmp_path / "absent"]) == []
    deny.update({(res / "a" / "logs").resolve(), (res / "b").resolve()})
    assert guards.unwritable_folders([res, other]) == [f"{res / 'a' / 'logs'}: {WHY}", f"{res / 'b'}: {WHY}"]
    deny.add(res.resolve())  # the top folder itself: one line, not one per folder under it
    assert guards.unwritable_folders([res, other]) == [f"{res}: {WHY}"]


# --- warnings_summary --------------------------------------------------------------------


def test_warnings_summary_collects_every_log(tmp_path):
    res = tmp_path / "results"
    (res / "maple" / "logs").mkdir(parents=True)
    (res / "implications" / "logs").mkdir(parents=True)
    (res / "maple" / "logs" / "ingest.log").write_text(
        "2026-01-01 10:00:00 INFO ballbat.ingest: read 32 rows\n"
        "2026-01-01 10:00:01 WARNING ballbat.ingest: only v_bat_mph_err given\n"
        "WARNING: a line of its own\n"
    )
    (res / "maple" / "logs" / "fit_ex.log").write_text("2026-01-01 10:00:03 WARNING ballbat.fitting: few impacts\n")
    (res / "implications" / "logs" / "paper.log").write_text("2026-01-01 WARNING ballbat.flight: slow\n")
    (res / "other" / "logs").mkdir(parents=True)
    (res / "other" / "logs" / "x.log").write_text("2026-01-01 WARNING not asked for\n")
    lines = guards.warnings_summary(res, ["maple", "absent"], others=["implications"])
    logs = res / "maple" / "logs"
    assert lines == [
        f"{logs / 'fit_ex.log'}: ballbat.fitting: few impacts",
        f"{logs / 'ingest.log'}: ballbat.ingest: only v_bat_mph_err given",
        f"{logs / 'ingest.log'}: a line of its own",
        f"{res / 'implications' / 'logs' / 'paper.log'}: ballbat.flight: slow",
    ]


# -- a target after --configfile -------------------------------------------------------------------


def test_a_results_file_given_as_a_config_file_is_named(tmp_path, monkeypatch):
    """Why (issue 37): `snakemake -c2 --configfile my.yaml TARGET` reads TARGET as a config file. Snakemake
    stops by itself when it is missing or not YAML (before the workflow is read); a results file it can
    read (a provenance sidecar is JSON) is caught here: one line naming it and the right order.
    """
    from ballbat.pipeline.guards import configfile_targets

    monkeypatch.chdir(tmp_path)
    (tmp_path / "results" / "h01").mkdir(parents=True)
    side = tmp_path / "results" / "h01" / "paper_comparison.provenance.json"
    side.write_text("{}")
    assert configfile_targets([str(tmp_path / "my.yaml"), str(tmp_path / "config" / "config.yaml")]) == []
    (line,) = configfile_targets([str(tmp_path / "my.yaml"), str(side)])
    assert line.startswith("--configfile results/h01/paper_comparison.provenance.json: a file of the results")
    assert "snakemake -c2 results/h01/paper_comparison.provenance.json --configfile my.yaml" in line
    session = tmp_path / "sessions" / "s1" / "a.json"  # a session's folder (config results)
    assert configfile_targets([str(session)], "sessions/s1") and not configfile_targets([str(session)])
