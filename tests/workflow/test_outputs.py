"""End to end: the suite's lab run (conftest.lab_run: rendered dataset ``small``, the measured
example ``maple``, scenarios paper and flyballs) in a copy of its folder. The rerun of small's chain
(byte-identical): test_workflow_rerun.py, a module of its own so that the other pytest-xdist process
runs it beside this module's tests.
"""

from __future__ import annotations

import base64
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from ballbat.compare import format_measurement, read_csv
from ballbat.pipeline.provenance import sha256_file
from workflow_helpers import ROOT, assert_cf, assert_not_blank, copy_run, make_workdir, planned_jobs, snakemake

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def run_dir(lab_run, tmp_path_factory):
    """A copy of the suite's lab run (conftest.lab_run) for this module's tests to edit."""
    return copy_run(lab_run, tmp_path_factory.mktemp("wf") / "run")


def test_outputs_content(run_dir):
    res = run_dir / "results" / "small"
    for stage in ("simulate", "normalize", "reconstruct", "fit_ex"):
        ds = xr.open_dataset(res / f"{stage}.nc")
        for name, var in {**ds.data_vars, **ds.coords}.items():
            assert "long_name" in var.attrs, (stage, name)
            if var.dtype.kind not in "OSU":
                assert "units" in var.attrs, (stage, name)
        for attr in ("Conventions", "title", "source", "history", "references"):
            assert ds.attrs[attr], (stage, attr)
        # Provenance: rule, inputs with their sha256, config, software, git.
        assert ds.attrs["provenance_rule"] == stage
        for rec in json.loads(ds.attrs["provenance_inputs"]):
            assert rec["sha256"] == sha256_file(run_dir / rec["path"]), rec
        soft = json.loads(ds.attrs["provenance_software"])
        assert {"ballbat", "ballbat_source_sha256", "python", "numpy", "xarray", "scipy"} <= set(soft)
        assert set(json.loads(ds.attrs["provenance_git"])) == {"commit", "dirty"}
        ds.close()
    sim = xr.open_dataset(res / "simulate.nc")
    assert sim.sizes["impact"] == 36
    assert json.loads(sim.attrs["provenance_config"])["settings"]["seed"] == 7
    rec = xr.open_dataset(res / "reconstruct.nc")
    # psi reconstructed from noisy data tracks the truth to within a degree or so.
    ok = rec.flag.values == 0
    assert np.nanmax(np.abs(rec.psi.values[ok] - rec.truth_psi.values[ok])) < np.radians(3)
    fit = xr.open_dataset(res / "fit_ex.nc")
    assert int(fit.e_x_n.sel(ball="baseball", bat="wood")) == 12
    table = read_csv(res / "paper_comparison.csv")
    header = "quantity ball bat paper paper_uncertainty value uncertainty systematic truth unit"
    assert list(table[0]) == header.split()
    rows = {(r["quantity"], r["ball"], r["bat"]): r for r in table}
    wood = rows[("e_x", "baseball", "wood")]
    assert float(wood["paper"]) == 0.464 and float(wood["truth"]) == 0.464
    assert abs(float(wood["value"]) - 0.464) < 3 * float(wood["uncertainty"])
    assert rows[("e_x", "softball", "wood")]["value"] == ""  # not in this dataset: empty, not invented
    for q in "e_x_pooled spin_theta_slope speed_theta_slope tan_ratio_slope e_y_implied mu_k_lower_bound".split():
        assert rows[(q, "baseball", "")]["value"] != "", q
    assert (res / "paper_comparison.md").read_text().startswith("# Dataset small")


def test_implications_outputs(run_dir):
    imp = run_dir / "results" / "implications"
    paper = xr.open_dataset(imp / "paper.nc")
    fit = xr.open_dataset(run_dir / "results" / "small" / "fit_ex.nc")
    # e_x taken from the dataset's fit of the scenario's bat (wood) with its ball (issue 37: the bat's own
    # e_x, no longer the pooled one), recorded in the file and its inputs, with its bands
    assert paper.attrs["e_x"] == pytest.approx(float(fit.e_x.sel(ball="baseball", bat="wood")), rel=1e-12)
    assert paper.attrs["e_x_source"] == "bat e_x of dataset small"
    assert paper.attrs["e_x_stat"] == pytest.approx(float(fit.e_x_err.sel(ball="baseball", bat="wood")), rel=1e-12)
    assert (paper.carry_low95 <= paper.carry_low68).all() and (paper.carry_high68 <= paper.carry_high95).all()
    assert any(r["name"] == "fit" for r in json.loads(paper.attrs["provenance_inputs"]))
    assert paper.sizes["case"] == 26 and paper.D.attrs["units"] == "m"
    assert set(np.unique(paper.exceeds_mu.values)) <= {0, 1}
    fly = xr.open_dataset(imp / "flyballs.nc")
    assert fly.sizes == {"case": 6, "point": 11}
    assert np.all(fly.carry.values > 50) and "D" not in fly
    rows = {r["quantity"]: r for r in read_csv(imp / "paper_comparison.csv")}
    assert rows["carry_max"]["paper"] == "400" and 350 < float(rows["carry_max"]["value"]) < 450
    assert rows["carry_max"]["unit"] == "ft" and rows["D_at_carry_max"]["unit"] == "in"


#: Two datasets (small and maple) draw the paper's figures; the scenarios draw Fig. 11 (paper) and
#: the launch figure (flyballs); small's tracks have their QA figures.
DATASET_PLOTS = {f"plot_fig{n}": 2 for n in (3, 4, 5, 6, 9, 10)}
ALL_PLOTS = {**DATASET_PLOTS, "plot_fig11": 1, "plot_launch": 1, "tracks_qa": 1, "plot_league": 1}
#: The report's front page follows every product of the run (its warnings are every job's).
FRONT = {"report_front": 1}
#: What follows a fit of both datasets: comparisons (HTML: both datasets' and the scenarios'),
#: workbooks, the paper scenario (it takes small's pooled e_x) and its table and Fig. 11.
AFTER_FIT = {
    "compare": 2,
    "comparison_html": 3,
    "workbook": 2,
    "implications": 1,
    "implications_compare": 1,
    "implications_workbook": 1,
    "plot_fig11": 1,
    "league": 1,  # the bats league table over both datasets (issue 37), its forest plot and workbook
    "plot_league": 1,
    "league_workbook": 1,
}
#: What follows a new reduction of both datasets (small's tracks, maple's ingest) up to the fits.
REDUCED = {"reduce": 1, "tracks_qa": 1, "ingest": 1, "normalize": 2, "reconstruct": 2, "fit_ex": 2, "fit_stronge": 2}


def _jobs_after_edit(run_dir, path):
    """Dry-run job counts after appending a comment to ``path`` (restored afterwards)."""
    text = path.read_text()
    try:
        path.write_text(text + "\n# an edit\n")
        return planned_jobs(run_dir)
    finally:
        path.write_text(text)


def test_code_edit_reruns_only_dependents(run_dir):
    """Editing a package module marks the outputs that import it out of date; README does not."""
    pkg = run_dir / "src" / "ballbat"
    # implications use small's pooled e_x, so they follow the fit
    # figures and report tables follow what they draw (one job each)
    # the Sec. IV orchestration: not the Stronge fit, which shares only the line fit and the designs
    stronge_plots = {"plot_fig9", "plot_fig10"}
    assert _jobs_after_edit(run_dir, pkg / "fitting.py") == {
        **FRONT,
        **AFTER_FIT,
        "fit_ex": 2,
        **{k: v for k, v in DATASET_PLOTS.items() if k not in stronge_plots},
    }
    # the line fit: the tracks' fits (small's reduction) and the measured file's checks (maple's ingest) too
    assert _jobs_after_edit(run_dir, pkg / "linefit.py") == {**FRONT, **AFTER_FIT, **REDUCED, **DATASET_PLOTS}
    assert _jobs_after_edit(run_dir, pkg / "kinematics.py") == {
        **FRONT,
        **AFTER_FIT,
        **REDUCED,
        **DATASET_PLOTS,
        "simulate": 1,
        "render_tracks": 1,
        "plot_launch": 1,  # captions quote D through the comparison code (Eq. D)
    }
    assert _jobs_after_edit(run_dir, pkg / "flight.py") == {
        **FRONT,
        "implications": 2,
        "implications_compare": 1,
        "plot_fig11": 1,
        "plot_launch": 1,
        "comparison_html": 1,
        "implications_workbook": 1,
    }
    assert _jobs_after_edit(run_dir, pkg / "workbook.py") == {
        "workbook": 2,
        "implications_workbook": 1,
        "league_workbook": 1,
        **FRONT,
    }
    assert planned_jobs(run_dir) == {}  # restoring the text restores the state
    (run_dir / "README.md").write_text("an unrelated edit\n")
    assert planned_jobs(run_dir) == {}


def test_config_error_names_the_key(tmp_path):
    wd = make_workdir(tmp_path)
    bad = tmp_path / "bad.yaml"
    bad.write_text("normalize:\n  v_ref_mph: fast\n  colour: red\n")
    out = snakemake(wd, "-n", "--configfile", str(bad), check=False)
    assert out.returncode != 0
    text = out.stdout + out.stderr
    assert "normalize.colour: unknown key" in text
    assert "normalize.v_ref_mph: 'fast' is not of type 'number'" in text


@pytest.mark.parametrize(
    "script",
    [
        "simulate",
        "ingest",
        "normalize",
        "reconstruct",
        "fit_ex",
        "fit_stronge",
        "compare",
        "comparison_html",
        "implications",
        "implications_compare",
    ],
)
def test_jobs_import_only_what_they_use(script):
    """No job but the plot jobs imports matplotlib, and none imports lmfit before it fits (start-up time)."""
    from ballbat.pipeline.codedeps import module_names

    mods = module_names(str(ROOT / "workflow" / "scripts" / f"{script}.py"))
    code = (
        "import sys\n"
        + "".join(f"import {m}\n" for m in mods)
        + "print(sorted(m for m in ('lmfit', 'matplotlib') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", (script, out.stdout)


def test_results_pass_the_cf_checker(run_dir):
    """A NetCDF file of every rule of a run passes the IOOS compliance-checker's CF 1.10 suite (issue 9)."""
    res = run_dir / "results"
    # the checker's time grows as the square of a file's variables: normalize .. fit_ex of maple (the
    # same rules as small's, with fewer variables), the rest of small's, the scenarios' (studies': test_studies)
    files = [res / "maple" / f"{name}.nc" for name in ("ingest", "normalize", "reconstruct", "fit_ex")]
    files += [res / "small" / f"{name}.nc" for name in ("simulate", "tracks", "reduce", "stronge")]
    files.append(res / "implications" / "paper.nc")
    assert all(f.is_file() for f in files)
    assert_cf([str(f) for f in files], run_dir / "cf.json")


def test_the_remembering_cf_checker_reports_as_the_checker_does(tmp_path):
    """tests/cf_check.py (the checker with its dataset queries remembered) gives the installed checker's report,
    and names a unit that is not one and a standard name that is not CF's.
    """
    from workflow_helpers import run_cf_checker

    x = xr.DataArray(np.arange(4.0), dims="impact", attrs={"units": "m", "long_name": "distance"})
    good = xr.Dataset({"x": x, "t": x.copy().assign_attrs(units="s", long_name="time of flight")})
    good.attrs["Conventions"] = "CF-1.10"
    bad = good.assign(y=x.copy().assign_attrs(units="furlongs per fortnightly", standard_name="bat_speediness"))
    files = [str(tmp_path / "good.nc"), str(tmp_path / "bad.nc")]
    good.to_netcdf(files[0])
    bad.to_netcdf(files[1])
    fast, slow = (run_cf_checker(files, tmp_path / f"{k}.json", remembering=k) for k in (True, False))
    for name in files:
        fast[name]["cf:1.10"].pop("report_timestamp")
        slow[name]["cf:1.10"].pop("report_timestamp")
    assert fast == slow
    msgs = {
        Path(n).name: " ".join(
            str(c["msgs"])
            for level in ("high_priorities", "medium_priorities", "low_priorities")
            for c in r["cf:1.10"][level]
        )
        for n, r in fast.items()
    }
    assert "bat_speediness" in msgs["bad.nc"] and "furlongs" in msgs["bad.nc"], msgs["bad.nc"]
    assert "bat_speediness" not in msgs["good.nc"] and "furlongs" not in msgs["good.nc"]


def test_workbook_in_the_fields_units(run_dir):
    """results.xlsx (issue 13): one sheet per table, names then units in the header, the values of
    the NetCDF files in mph/deg/rpm/in, and the provenance of every file; read by two real readers.
    """
    import openpyxl
    import pandas as pd

    res = run_dir / "results" / "small"
    book = openpyxl.load_workbook(res / "results.xlsx")
    sheets = "impacts e_x sec4 eta2 systematics paper_comparison warnings legend provenance"
    assert book.sheetnames == sheets.split()
    names, words = ([c.value for c in row] for row in (book["impacts"][1], book["impacts"][2]))
    head = dict(zip(names, words, strict=True))
    assert head["v_bat"].endswith("(mph)") and head["v_ball"].endswith("(mph)")  # words with units: row 2
    assert not head["impact_id"].endswith(")")  # text: no unit
    rec = xr.open_dataset(res / "reconstruct.nc")
    fit = xr.open_dataset(res / "fit_ex.nc")
    imp = pd.read_excel(res / "results.xlsx", sheet_name="impacts", header=[0, 1]).droplevel(1, axis=1)
    assert {"v_bat", "psi", "D"} <= set(imp.columns) and head["psi"].endswith("(deg)") and head["D"].endswith("(in)")
    assert len(imp) == rec.sizes["impact"]
    np.testing.assert_allclose(imp["v_bat"], rec.v_bat.values / 0.44704, rtol=1e-12)
    np.testing.assert_allclose(imp["omega"], rec.omega.values * 60 / (2 * np.pi), rtol=1e-12)
    np.testing.assert_allclose(imp["D"], rec.D.values / 0.0254, rtol=1e-12)
    assert set(imp["flag_reason"]) == {"ok"}
    ex = pd.read_excel(res / "results.xlsx", sheet_name="e_x", header=0, skiprows=[1])  # dimensionless: no unit
    wood = ex[(ex["ball"] == "baseball") & (ex["bat"] == "wood")]
    assert float(wood["e_x"].iloc[0]) == pytest.approx(float(fit.e_x.sel(ball="baseball", bat="wood")))
    pooled = ex[(ex["ball"] == "softball") & (ex["bat"] == "pooled")]
    assert int(pooled["e_x_n"].iloc[0]) == int(fit.e_x_pooled_n.sel(ball="softball"))
    sec4 = pd.read_excel(res / "results.xlsx", sheet_name="sec4", header=[0, 1])
    (words,) = [w for name, w in sec4.columns if name == "spin_theta_slope"]
    assert words.endswith("(rpm/deg)")
    slope = float(fit.spin_theta_slope.sel(ball="baseball")) * 60 / (2 * np.pi) * np.pi / 180
    assert float(sec4.droplevel(1, axis=1)["spin_theta_slope"].iloc[0]) == pytest.approx(slope, rel=1e-12)
    prov = pd.read_excel(res / "results.xlsx", sheet_name="provenance", header=0).iloc[1:]
    inputs = prov[prov["record"] == "input"]
    normalize = inputs[inputs["key"].str.endswith("normalize.nc")]
    assert normalize["value"].iloc[0] == sha256_file(res / "normalize.nc")
    assert set(prov["record"]) >= {"title", "rule", "input", "config", "software", "git"}
    paper = xr.open_dataset(run_dir / "results" / "implications" / "paper.nc")
    sweep = pd.read_excel(run_dir / "results" / "implications" / "results.xlsx", sheet_name="paper", header=[0, 1])
    assert next(w for name, w in sweep.columns if name == "carry").endswith("(ft)")
    np.testing.assert_allclose(sweep.droplevel(1, axis=1)["carry"], paper.carry.values / 0.3048, rtol=1e-12)
    with pd.ExcelFile(run_dir / "results" / "implications" / "results.xlsx") as book:
        assert set(book.sheet_names) == {"paper", "flyballs", "legend", "provenance"}


def test_summary_command(run_dir):
    """`ballbat summary` (issue 13) prints the dataset's e_x per bat and pooled, and eta^2, from its files;
    a dataset without camera tracks (maple) has no pixel-scale systematic to show.
    """

    def summary(name):
        out = subprocess.run(
            [str(Path(sys.executable).parent / "ballbat"), "summary", f"results/{name}"],
            cwd=run_dir,
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert out.returncode == 0, out.stderr
        return out.stdout

    out = summary("small")
    fit = xr.open_dataset(run_dir / "results" / "small" / "fit_ex.nc")
    st = xr.open_dataset(run_dir / "results" / "small" / "stronge.nc")
    f = fit.sel(ball="baseball", bat="wood")
    e = format_measurement(float(f.e_x), float(f.e_x_err))[0]  # rounded to its error
    assert any(line.split()[:3] == ["baseball", "wood", e] for line in out.splitlines())
    f = fit.sel(ball="softball")
    p = format_measurement(float(f.e_x_pooled), float(f.e_x_pooled_err))[0]
    assert any(line.split()[:3] == ["softball", "pooled", p] for line in out.splitlines())
    assert f"{float(st.eta2.sel(ball='baseball')):.3f}" in out
    assert out.startswith("small: 36 impacts, 0 not used")
    out = summary("maple")
    assert "e_x_err_scale" not in xr.open_dataset(run_dir / "results" / "maple" / "fit_ex.nc")
    assert "± syst" not in out and out.startswith("maple: 31 impacts, 1 not used")


def test_figures_drawn(run_dir):
    """Every figure of the paper that the data support is drawn, is not blank, and has its caption numbers."""
    figs = run_dir / "results" / "small" / "figures"
    for name in ("fig3", "fig4", "fig5", "fig6", "fig9a", "fig9b", "fig10"):
        assert_not_blank(figs / f"{name}.png")
    imp = run_dir / "results" / "implications" / "figures"
    for name in ("paper_fig11a", "paper_fig11b", "flyballs_launch"):
        assert_not_blank(imp / f"{name}.png")
    assert not (imp / "flyballs_fig11a.png").exists() and not (imp / "paper_launch.png").exists()
    # The caption numbers are the fitted ones, in the paper's units.
    fit = xr.open_dataset(run_dir / "results" / "small" / "fit_ex.nc")
    slope = float(fit.spin_theta_slope.sel(ball="baseball")) * 60 / (2 * np.pi) * np.pi / 180
    text3 = (figs / "fig3.rst").read_text()
    assert f"baseball: {slope:.3g} ± " in text3 and "paper 179 rpm/deg" in text3
    assert "Impacts shown: 36 of 36 (0 flagged" in text3
    maple = xr.open_dataset(run_dir / "results" / "maple" / "fit_ex.nc").sel(ball="baseball")
    e_x, err = format_measurement(float(maple.e_x_pooled), float(maple.e_x_pooled_err))  # no tracks: no systematic
    assert f"e_x = {e_x} ± {err} (n = " in (run_dir / "results" / "maple" / "figures" / "fig5.rst").read_text()
    assert "Longest carry" in (imp / "paper_fig11.rst").read_text()
    eta2 = float(xr.open_dataset(run_dir / "results" / "small" / "stronge.nc").eta2.sel(ball="baseball"))
    assert f"baseball: η² = {eta2:.3g} ± " in (figs / "fig9.rst").read_text()
    assert "<td>e_x_pooled</td>" in (run_dir / "results" / "small" / "paper_comparison.html").read_text()


def _report_results(html: str) -> dict:
    """The report's table of results: path -> entry (its labels, caption, MIME type and data URI)."""
    at = html.index("results = {") + len("results = ")
    return json.JSONDecoder().raw_decode(html, at)[0]


def test_report_builds(run_dir):
    """`snakemake --report` embeds every figure, table and workbook byte for byte, each figure with
    its caption numbers, and the run's config.
    """
    snakemake(run_dir, "--report", "results/report.html")
    html = (run_dir / "results" / "report.html").read_text()
    results = _report_results(html)
    products = []
    for d in ("small", "maple", "implications"):  # the config's (not the tool files' datasets of tools.yaml)
        for pattern in ("figures/*.png", "paper_comparison.html", "results.xlsx"):
            products += [str(p.relative_to(run_dir)) for p in run_dir.glob(f"results/{d}/{pattern}")]
    products.append("results/figures/league_forest.png")  # the league table's forest plot (issue 37)
    assert (
        len(products) == 9 + 7 + 3 + 3 + 3 + 1
    )  # small 9, maple 7, implications 3 figures; a table and a workbook each
    assert sorted(results) == sorted(products)
    for path in products:
        head, data = results[path]["data_uri"].split(",", 1)
        assert head.endswith(";base64"), path
        assert base64.b64decode(data) == (run_dir / path).read_bytes(), path  # the file, whole
    assert results["results/small/figures/fig3.png"]["mime_type"] == "image/png"
    assert results["results/small/figures/fig3.png"]["labels"]["figure"] == "Fig. 3"
    assert results["results/small/results.xlsx"]["labels"] == {"table": "results.xlsx"}  # issue 13
    e_x = float(xr.open_dataset(run_dir / "results" / "small" / "fit_ex.nc").e_x_pooled.sel(ball="baseball"))
    # the fitted number, rounded as the field does (to its error's second significant digit)
    shown = re.search(r"baseball: e_x = (-?[0-9.]+) ±", results["results/small/figures/fig5.png"]["caption"])
    assert shown, "Fig. 5's caption has no pooled e_x of baseballs"
    digits = len(shown.group(1).split(".")[1])
    assert float(shown.group(1)) == round(e_x, digits) and digits >= 3, (shown.group(1), e_x)
    assert "v_ref_mph" in html  # the run's config


def test_plot_edit_reruns_only_plots(run_dir):
    """Restyling a figure (editing plotting.py) never reruns a fit: only the plot jobs are planned."""
    pkg = run_dir / "src" / "ballbat"
    assert _jobs_after_edit(run_dir, pkg / "plotting.py") == {**ALL_PLOTS, **FRONT}
    assert _jobs_after_edit(run_dir, pkg / "reporting.py") == {**ALL_PLOTS, "comparison_html": 3, **FRONT}
    assert _jobs_after_edit(run_dir, pkg / "frontpage.py") == FRONT  # the front page alone
    assert _jobs_after_edit(run_dir, run_dir / "workflow" / "report" / "fig3.rst") == {}  # captions: report only
    assert planned_jobs(run_dir) == {}
