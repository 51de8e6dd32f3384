"""``ballbat compare`` (ballbat.cli.compare): the bats league table of results folders, printed; bad folders
named in one line (issue 37, section 2; docs/league.md).
"""

from __future__ import annotations

import pytest
from helpers import league_fit_file as fit_file
from helpers import run_ballbat

# ---------------------------------------------------------------------------------------
# ballbat compare, through the installed entry point, and bad input


@pytest.mark.slow  # more than 2 s
def test_ballbat_compare_prints_the_table_the_pairs_and_tost(tmp_path):
    fit_file(tmp_path / "s1", "h01", {"hickory": (0.47, 0.006, 25, 0.004), "wood": (0.46, 0.006, 25, 0.004)})
    fit_file(tmp_path / "s2", "m01", {"maple": (0.38, 0.006, 25, 0.004), "wood": (0.465, 0.006, 25, 0.004)})
    out = run_ballbat("compare", str(tmp_path / "s1"), str(tmp_path / "s2"), "--reference-bat", "wood", installed=True)
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
    out = run_ballbat("compare", str(tmp_path / "empty"))
    assert out.returncode == 2 and out.stdout == ""
    what = "no fit_ex.nc in it or in its dataset folders (run the workflow first)"
    assert out.stderr == f"ballbat compare: error: {tmp_path / 'empty'}: {what}\n"
    fit_file(tmp_path / "old", "d", {"A": (0.45, 0.006, 20, 0.005)}, older=True)
    out = run_ballbat("compare", str(tmp_path / "old"))
    assert out.returncode == 2 and len(out.stderr.splitlines()) == 1
    assert str(tmp_path / "old" / "d" / "fit_ex.nc") in out.stderr and "older format" in out.stderr
    assert "e_x_scatter" in out.stderr and "Traceback" not in out.stderr
