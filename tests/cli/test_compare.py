"""The bats league table (issue 37, section 2; docs/league.md): every bat's e_x over test sessions,
pairwise differences whose shared systematics cancel within a session and add across sessions,
Holm's adjustment, the consistency test of a bat in several sessions, the equivalence test (TOST),
``ballbat compare FOLDER...`` and the workflow's league rule.

The fit_ex.nc files here are built by hand (the variables the league reads, written by the
workflow's writer), so every expected number is a hand computation.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import forked
import numpy as np
import xarray as xr

from ballbat import league
from ballbat.pipeline.ncio import write_dataset

BALLBAT = Path(sys.executable).parent / "ballbat"
SOURCES = list(league.SHARING)


def fit_file(
    folder: Path, dataset: str, bats: dict, ball: str = "baseball", older: bool = False, sources: list = SOURCES
) -> Path:
    """Write ``folder/dataset/fit_ex.nc`` with ``bats``: name -> (e_x, stat, n, systematic of ``sources[0]``)."""
    names = list(bats)
    shape = (1, len(names))
    val = {k: np.array([[bats[b][i] for b in names]], dtype=float) for i, k in enumerate(("e_x", "err", "n", "s"))}
    per = np.zeros((len(sources), *shape))
    per[0] = val["s"]
    one = {"units": "1", "long_name": "x"}
    ds = xr.Dataset(
        {
            "e_x": (("ball", "bat"), val["e_x"], one),
            "e_x_err": (("ball", "bat"), val["err"], one),
            "e_x_n": (("ball", "bat"), val["n"].astype(np.int64), one),
            "e_x_status": (("ball", "bat"), np.zeros(shape, dtype=np.int8), one),
            "e_x_scatter": (("ball", "bat"), np.zeros(shape), one),
            "e_x_syst_by_source": (("systematic", "ball", "bat"), per, one),
        },
        coords={
            "ball": ("ball", np.array([ball]), {"long_name": "ball"}),
            "bat": ("bat", np.array(names), {"long_name": "bat"}),
            "systematic": ("systematic", np.array(sources), {"long_name": "source"}),
        },
    )
    if older:  # fit_ex.nc before the intrinsic scatter (issue 36) and the systematics by source
        ds = ds.drop_vars(["e_x_scatter", "e_x_syst_by_source", "systematic"])
        ds["e_x_err_scale"] = (("ball", "bat"), val["s"], one)
    path = folder / dataset / "fit_ex.nc"
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_dataset(ds, path, title="test fit_ex", rule="fit_ex", inputs={}, config={})


# ---------------------------------------------------------------------------------------
# ballbat compare, through the installed entry point, and bad input


def run_compare(*args: str, installed: bool = False) -> subprocess.CompletedProcess:
    """`ballbat compare ARGS`: the installed command, or (the default) a process forked with its libraries loaded."""
    if not installed:
        return forked.ballbat("compare", *args, cwd=Path.cwd(), timeout=60)
    env = {**os.environ, "PYTHONPATH": str(Path(league.__file__).parents[1])}
    return subprocess.run([str(BALLBAT), "compare", *args], capture_output=True, text=True, timeout=60, env=env)


def test_ballbat_compare_prints_the_table_the_pairs_and_tost(tmp_path):
    fit_file(tmp_path / "s1", "h01", {"hickory": (0.47, 0.006, 25, 0.004), "wood": (0.46, 0.006, 25, 0.004)})
    fit_file(tmp_path / "s2", "m01", {"maple": (0.38, 0.006, 25, 0.004), "wood": (0.465, 0.006, 25, 0.004)})
    out = run_compare(str(tmp_path / "s1"), str(tmp_path / "s2"), "--reference-bat", "wood", installed=True)
    assert out.returncode == 0, out.stderr
    assert f"2 test session(s): {tmp_path / 's1' / 'h01'}, {tmp_path / 's2' / 'm01'}" in out.stdout
    lines = out.stdout.splitlines()
    wood = next(line for line in lines if line.startswith("baseball  wood "))
    assert "(reference)" in wood and wood.split()[6] == "2"  # two sessions
    maple = next(line for line in lines if line.startswith("baseball  maple "))
    assert maple.split()[2] == "0.380" and maple.endswith("no")
    assert "Pairwise differences (Holm over 3 pairs" in out.stdout


def test_compare_bad_folders_are_one_line_naming_the_folder(tmp_path):
    (tmp_path / "empty").mkdir()
    out = run_compare(str(tmp_path / "empty"))
    assert out.returncode == 2 and out.stdout == ""
    what = "no fit_ex.nc in it or in its dataset folders (run the workflow first)"
    assert out.stderr == f"ballbat compare: error: {tmp_path / 'empty'}: {what}\n"
    fit_file(tmp_path / "old", "d", {"A": (0.45, 0.006, 20, 0.005)}, older=True)
    out = run_compare(str(tmp_path / "old"))
    assert out.returncode == 2 and len(out.stderr.splitlines()) == 1
    assert str(tmp_path / "old" / "d" / "fit_ex.nc") in out.stderr and "older format" in out.stderr
    assert "e_x_scatter" in out.stderr and "Traceback" not in out.stderr
