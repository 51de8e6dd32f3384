"""The bats league table of the suite's runs and its place on the report's front page (issue 37, section 2)."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from helpers import league_row as row
from helpers import league_settings as settings

from ballbat import league
from ballbat.pipeline.ncio import read_dataset

# ---------------------------------------------------------------------------------------
# the workflow's league rule (the shared runs)


@pytest.mark.slow
def test_default_run_writes_the_league(default_run):
    """The default has 3 baseball and 4 softball bats: league.nc, .csv and the forest plot, as the module computes."""
    res = default_run / "results"
    ds = read_dataset(res / "league.nc")
    again = league.league(league.read_folder(res), settings())
    for v in ("e_x", "e_x_stat", "e_x_syst", "tost_p"):
        np.testing.assert_allclose(ds[v].values, again[v].values, rtol=1e-12)
    np.testing.assert_allclose(ds["pair_p_holm"].values, again["pair_p_holm"].values, rtol=1e-12)
    fit = read_dataset(res / "synthetic" / "fit_ex.nc")
    assert float(row(ds, "wood")["e_x"]) in fit["e_x"].values  # one session: each bat's e_x is fit_ex.nc's
    assert (res / "league.csv").read_text().startswith("ball,bat,e_x,e_x_stat,e_x_syst,")
    assert (res / "figures" / "league_forest.png").stat().st_size > 10_000
    import openpyxl

    wb = openpyxl.load_workbook(res / "league.xlsx")
    assert wb.sheetnames == ["league", "pairs", "sessions", "legend", "provenance"]
    assert wb["pairs"].max_row == 2 + ds.sizes["pair"]  # names, words, one row per pair
    assert ds.sizes["pair"] == 3 + 6  # pairs of 3 baseball bats and of 4 softball bats


@pytest.mark.slow
def test_lab_run_league_has_both_sessions(lab_run):
    """The lab run (datasets small and maple): one table over both test sessions."""
    ds = read_dataset(lab_run / "results" / "league.nc")
    assert set(ds["entry_dataset"].values) == {"small", "maple"}
    assert {"results/small", "results/maple"} <= set(ds["entry_session"].values)


@pytest.mark.slow
def test_front_page_shows_the_league_table(default_run):
    """Issue 37 §5: a run with more than one bat of a ball has its league table on the front page: each bat's
    e_x from league.nc, highest first per ball, and every pair of bats with its Holm-adjusted p.
    """
    from ballbat.frontpage import round_pm

    front = (default_run / "results" / "report" / "front.rst").read_text()
    assert "Bats league table" in front
    league = xr.open_dataset(default_run / "results" / "league.nc")
    section = front[front.index("Bats league table") :]
    for i in range(league.sizes["row"]):
        v, s, _ = round_pm(float(league["e_x"][i]), float(league["e_x_stat"][i]), float(league["e_x_syst"][i]))
        assert f"**{v}**" in section and f"± {s}" in section
    table = section[: section.index("every pair of bats")].split("   * - ")[2:]  # the header row first
    shown = [(r.split("\n")[0], float(r.split("**")[1])) for r in table]
    for ball in ("baseball", "softball"):
        e_x = [v for b, v in shown if b == ball]
        assert e_x == sorted(e_x, reverse=True) and len(e_x) == int((league["ball"] == ball).sum())
    assert section.count("p (Holm)") == 1 and section.count(" − ") == league.sizes["pair"]
