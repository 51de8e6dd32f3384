"""The numbers a lab reads: e_x with its calibration systematic (summary, workbook, captions),
rounded as the field does, and the workbook's formats, units, dates and provenance (issue 21).
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr

import ballbat
from ballbat.compare import format_measurement, uncertainty_decimals
from ballbat.pipeline.provenance import commit_time, sha256_file
from ballbat.workbook import _number_format


@pytest.fixture(scope="module")
def fit(default_run):
    return xr.open_dataset(default_run / "results" / "synthetic" / "fit_ex.nc").load()


@pytest.mark.slow
def test_summary_shows_the_systematic(default_run, fit):
    """`ballbat summary` of a tracked dataset prints e_x with statistical, systematic and total errors."""
    out = subprocess.run(
        [str(Path(sys.executable).parent / "ballbat"), "summary", "results/synthetic"],
        cwd=default_run,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    assert "± syst" in out.stdout and "± total" in out.stdout
    f = fit.sel(ball="baseball", bat="wood")
    stat, syst = float(f.e_x_err), float(f.e_x_err_scale)
    assert syst > 0.003  # the default tracks' pixel scale gives ~0.005
    expected = format_measurement(float(f.e_x), stat, syst, math.hypot(stat, syst))
    assert any(line.split()[:6] == ["baseball", "wood", *expected] for line in out.stdout.splitlines())


@pytest.mark.slow
def test_workbook_e_x_sheet(default_run, fit):
    """The e_x sheet: value, statistical, systematic and total at full precision; number formats
    that show them rounded as the field does; no "1" as a unit anywhere.
    """
    import openpyxl

    book = openpyxl.load_workbook(default_run / "results" / "synthetic" / "results.xlsx")
    ws = book["e_x"]
    names = [c.value for c in ws[1]]
    assert names[:6] == ["ball", "bat", "e_x", "e_x_err", "e_x_syst", "e_x_err_total"]
    assert not any(str(c.value).endswith(")") and "(" not in str(c.value)[:-1] for c in ws[2])
    assert [c.value for c in ws[2]][2].startswith("tangential coefficient of restitution")  # words, no unit
    rows = {(r[0].value, r[1].value): r for r in ws.iter_rows(min_row=3)}
    row = rows[("baseball", "wood")]
    f = fit.sel(ball="baseball", bat="wood")
    stat, syst = float(f.e_x_err), float(f.e_x_err_scale)
    # full precision: openpyxl writes numbers with 16 significant digits ("%.16g"; Excel keeps 15)
    full = [float(f.e_x), stat, syst, math.hypot(stat, syst)]
    assert [c.value for c in row[2:6]] == pytest.approx(full, rel=1e-15, abs=0)
    fmt = _number_format(uncertainty_decimals(stat, syst))
    assert [c.number_format for c in row[2:8]] == [fmt] * 6
    assert row[names.index("e_x_n")].number_format == "0"
    pooled = rows[("softball", "pooled")]
    assert pooled[4].value == pytest.approx(float(fit.e_x_pooled_err_scale.sel(ball="softball")), rel=1e-15, abs=0)
    for sheet in book.worksheets:
        assert "1" not in [c.value for c in sheet[2]], sheet.title
    impacts = book["impacts"]
    assert impacts.cell(3, 5).number_format != "General"  # v_bat, mph


@pytest.mark.slow
def test_workbook_dates_and_provenance(default_run, fit):
    """Document properties carry the date of the commit the results were made with; custom
    properties carry every input's sha256, the version and the source hashes.
    """
    import json

    import openpyxl

    res = default_run / "results" / "synthetic"
    book = openpyxl.load_workbook(res / "results.xlsx")
    commit = json.loads(fit.attrs["provenance_git"])["commit"]
    when = commit_time(commit)
    assert when is not None and when.year >= 2026
    assert book.properties.created == when and book.properties.modified == when
    props = {p.name: p.value for p in book.custom_doc_props.props}
    assert props["input fit_ex.nc"].endswith(f"sha256:{sha256_file(res / 'fit_ex.nc')}")
    assert props["input paper_comparison.csv"].endswith(f"sha256:{sha256_file(res / 'paper_comparison.csv')}")
    assert props["ballbat version"] == ballbat.__version__
    assert props["git commit"] == commit
    assert len(props["workflow source sha256"]) == 64


@pytest.mark.slow
def test_caption_shows_the_systematic(default_run, fit):
    """Fig. 5's caption numbers give e_x with the systematic and the total."""
    text = (default_run / "results" / "synthetic" / "figures" / "fig5.rst").read_text()
    f = fit.sel(ball="baseball", bat="wood")
    stat, syst = float(f.e_x_err), float(f.e_x_err_scale)
    v, e, s, t = format_measurement(float(f.e_x), stat, syst, math.hypot(stat, syst))
    assert f"baseball, wood: {v} ± {e} (stat) ± {s} (syst) = {v} ± {t} (total)" in text


@pytest.mark.slow
def test_png_figures_carry_their_provenance(default_run):
    """Each figure's PNG text chunks record its rule, its inputs with their sha256, the versions and the commit."""
    import json

    from PIL import Image

    res = default_run / "results" / "synthetic"
    with Image.open(res / "figures" / "fig5.png") as im:
        text = dict(im.text)
    assert text["provenance_rule"] == "plot_fig5"
    inputs = {Path(i["path"]).name: i["sha256"] for i in json.loads(text["provenance_inputs"])}
    assert inputs == {
        "fit_ex.nc": sha256_file(res / "fit_ex.nc"),
        "reconstruct.nc": sha256_file(res / "reconstruct.nc"),
    }
    assert json.loads(text["provenance_software"])["ballbat"] == ballbat.__version__
    assert "Software" not in text  # no matplotlib version stamp: same data, same bytes
    with Image.open(res / "figures" / "tracks_summary.png") as im:
        assert im.text["provenance_rule"] == "tracks_qa"


@pytest.mark.slow
def test_tables_have_a_provenance_sidecar(default_run, fit):
    """paper_comparison.provenance.json names the CSV and Markdown tables with their sha256 and records the
    job's inputs; the Markdown rounds e_x as the field does, the CSV keeps 6 significant digits.
    """
    import json

    res = default_run / "results" / "synthetic"
    side = json.loads((res / "paper_comparison.provenance.json").read_text())
    assert {Path(d["path"]).name: d["sha256"] for d in side["describes"]} == {
        "paper_comparison.csv": sha256_file(res / "paper_comparison.csv"),
        "paper_comparison.md": sha256_file(res / "paper_comparison.md"),
    }
    assert side["rule"] == "compare"
    assert {Path(i["path"]).name: i["sha256"] for i in side["inputs"]}["fit_ex.nc"] == sha256_file(res / "fit_ex.nc")
    f = fit.sel(ball="baseball", bat="wood")
    v, e, s = format_measurement(float(f.e_x), float(f.e_x_err), float(f.e_x_err_scale))
    assert f"| e_x | baseball | wood | 0.464 | 0.014 | {v} | {e} | {s} |" in (res / "paper_comparison.md").read_text()
    assert (
        f",{float(f.e_x):.6g},{float(f.e_x_err):.6g},{float(f.e_x_err_scale):.6g},"
        in (res / "paper_comparison.csv").read_text()
    )
