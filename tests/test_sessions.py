"""Issue 37 §1: test sessions. A run's results folder is a setting; a folder's crate carries every run in
it; a folder's workbooks keep every scenario's sheet; three sessions' folders make one league table.
"""

from __future__ import annotations

import copy
import json
from argparse import Namespace

import numpy as np
import pytest

from ballbat.config_checks import validate_config
from ballbat.pipeline import crate as crate_mod
from ballbat.pipeline.config import ConfigError
from ballbat.pipeline.cratefiles import EARLIER_NAME, crate_file_problems, folder_files
from ballbat.pipeline.provenance import sha256_file
from ballbat.workflow_inputs import WorkflowInputs, results_root
from workflow_helpers import ROOT


def _nc(path, note):
    """A small NetCDF file carrying the workflow's provenance mark."""
    import xarray as xr

    path.parent.mkdir(parents=True, exist_ok=True)
    attrs = {"provenance_rule": "r", "provenance_config": json.dumps({"note": note}), "note": note}
    xr.Dataset({"x": ("n", [1.0])}, attrs=attrs).to_netcdf(path, engine="netcdf4")


def _graph(results):
    doc = json.loads((results / "ro-crate-metadata.json").read_text())
    return {e["@id"]: e for e in doc["@graph"]}


def _ids(value):
    refs = value if isinstance(value, list) else [value]
    return sorted(r["@id"] for r in refs)


# -- the results folder is a setting ------------------------------------------------------------------


def test_every_target_starts_with_the_results_folder(config):
    """A session's folder (config ``results``) prefixes every product; the default stays ``results/``."""
    assert results_root(config) == "results" and results_root({}) == "results"
    cfg = copy.deepcopy(config)
    cfg["results"] = "results/2026-11-h01/"
    cfg["studies"]["calibration"]["on_request"] = False
    inputs = WorkflowInputs(cfg, ROOT)
    assert inputs.results == "results/2026-11-h01"
    targets = inputs.final_targets() + inputs.league_targets() + inputs.study_targets()
    assert targets and all(t.startswith("results/2026-11-h01/") for t in targets), targets[:3]
    ds = Namespace(dataset="synthetic")
    assert inputs.get_source(ds) == "results/2026-11-h01/synthetic/reduce.nc"
    assert inputs.get_tracks_inputs(ds) == {"tracks": "results/2026-11-h01/synthetic/tracks.nc"}


def test_the_setting_is_checked(config, schema):
    """The folder is a relative path of plain names: no '..', no hidden part, no absolute path."""
    for bad in ("../elsewhere", "/tmp/x", "results/.hidden", "results/../x", ""):
        cfg = copy.deepcopy(config)
        cfg["results"] = bad
        with pytest.raises(ConfigError, match="results"):
            validate_config(cfg, schema)
    cfg = copy.deepcopy(config)
    cfg["results"] = "results/2026-11-h01"
    validate_config(cfg, schema)


def test_a_session_inside_the_default_folder_is_its_own(tmp_path):
    """The files of results/2026-11-h01 (a crate of its own) are not files of results/'s crate."""
    results = tmp_path / "results"
    _nc(results / "synthetic" / "fit_ex.nc", "default")
    session = results / "2026-11-h01"
    _nc(session / "h01" / "fit_ex.nc", "session")
    assert folder_files(results) == ["2026-11-h01/h01/fit_ex.nc", "synthetic/fit_ex.nc"]  # no crate yet: a folder
    (session / "ro-crate-metadata.json").write_text("{}")
    assert folder_files(results) == ["synthetic/fit_ex.nc"]
    assert folder_files(session) == ["h01/fit_ex.nc"]


# -- the crate of a folder describes every run in it -------------------------------------------------


def _workdir(tmp_path):
    (tmp_path / "Snakefile").write_text("# the workflow\n")
    (tmp_path / "config").mkdir()
    (tmp_path / "config" / "a.csv").write_text("a\n1\n")
    (tmp_path / "config" / "b.csv").write_text("b\n2\n")
    return tmp_path / "results"


def _job(rule, name, inp):
    return crate_mod.JobRecord(
        rule=rule,
        wildcards={"dataset": name},
        inputs=[inp],
        outputs=[f"results/{name}/out.nc"],
        logs=[f"results/{name}/logs/{rule}.log"],
        start=1.0e9,
        end=1.0e9 + 5,
    )


def _run(results, tmp_path, jobs, record=None):
    for job in jobs:
        _nc(tmp_path / job.outputs[0], job.key)
        (tmp_path / job.logs[0]).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / job.logs[0]).write_text("log\n")
    crate_mod.set_aside_crate(results)
    return crate_mod.write_run_crate(
        results, jobs, config={}, configfiles=[], workdir=tmp_path, record=record or (lambda p: None)
    )


def test_a_later_run_adds_its_actions_to_the_earlier_ones(tmp_path):
    """Run 1 makes dataset a (rule ra); run 2, another config, makes b (rule rb). Run 2's crate has both
    jobs: a's action carried with its times, config values, rule and input (its snapshot copy too), its
    results saying they are an earlier run's; the crate checks against the folder and roc-validator.
    """
    from validate_crate import main

    results = _workdir(tmp_path)
    _run(results, tmp_path, [_job("ra", "a", "config/a.csv")])
    first = _graph(results)
    _run(results, tmp_path, [_job("rb", "b", "config/b.csv")])
    graph = _graph(results)
    assert not (results / EARLIER_NAME).exists()
    assert crate_file_problems(results) == []
    a, b = graph["#job-ra-dataset=a"], graph["#job-rb-dataset=b"]
    assert _ids(a["result"]) == ["a/logs/ra.log", "a/out.nc"] and _ids(b["result"]) == ["b/logs/rb.log", "b/out.nc"]
    assert a["startTime"] == first["#job-ra-dataset=a"]["startTime"]
    assert "earlier run" in a["description"]
    assert a["instrument"]["@id"] == "#rule-ra" and "#step-ra" in graph and "#control-ra-dataset=a" in graph
    assert "workflow.snapshot/config/a.csv" in _ids(a["object"])
    assert (results / "workflow.snapshot" / "config" / "a.csv").is_file()  # the earlier input is still copied
    assert graph["#job-ra-dataset=a-config-note"]["value"] == "ra-dataset=a"
    assert graph["a/out.nc"]["description"].startswith("not made by this run: made by an earlier run's job")
    assert _ids(graph["#run"]["result"]) == ["b/out.nc"]
    assert {"#job-ra-dataset=a", "#job-rb-dataset=b"} <= set(_ids(graph["./"]["mentions"]))
    assert main([str(results)]) == 0


def test_an_earlier_result_changed_or_gone_is_not_listed_as_it(tmp_path):
    """An earlier job's output deleted since is not listed at all; one rewritten by hand is no job's result
    (listed as a file not written by the workflow); an action with no result left is dropped; its input,
    changed since, is named with the sha256 it had.
    """
    results = _workdir(tmp_path)
    _run(results, tmp_path, [_job("ra", "a", "config/a.csv"), _job("rc", "c", "config/a.csv")])
    (results / "a" / "out.nc").unlink()
    (results / "a" / "logs" / "ra.log").unlink()
    (results / "c" / "out.nc").write_bytes(b"a user's own file")
    old_digest = sha256_file(tmp_path / "config" / "a.csv")
    (tmp_path / "config" / "a.csv").write_text("a\n3\n")
    _run(results, tmp_path, [_job("rb", "b", "config/b.csv")])
    graph = _graph(results)
    assert crate_file_problems(results) == []
    assert "a/out.nc" not in graph and "#job-ra-dataset=a" not in graph
    c = graph["#job-rc-dataset=c"]
    assert _ids(c["result"]) == ["c/logs/rc.log"]
    assert graph["c/out.nc"]["description"].startswith("not written by this workflow")
    earlier = [graph[i] for i in _ids(c["object"]) if i.startswith("#earlier-input-")]
    assert len(earlier) == 1 and earlier[0]["sha256"] == old_digest


def test_a_stale_earlier_output_says_so(tmp_path):
    """An earlier output whose input has changed since is listed as that job's result, and stale."""
    results = _workdir(tmp_path)
    _run(results, tmp_path, [_job("ra", "a", "config/a.csv")])
    records = {"results/a/out.nc": {"rule": "ra", "input": ["config/a.csv"], "input_checksums": {"config/a.csv": "0"}}}
    _run(results, tmp_path, [_job("rb", "b", "config/b.csv")], record=records.get)
    graph = _graph(results)
    assert "a/out.nc" in _ids(graph["#job-ra-dataset=a"]["result"])
    assert "stale: its input config/a.csv has changed since (sha256)" in graph["a/out.nc"]["description"]


def test_a_run_cut_short_keeps_the_earlier_crate_aside(tmp_path):
    """A run that starts sets the crate aside (no crate in the folder while it runs); a second start (the
    first cut short) keeps it, and the next crate still carries the first run's actions.
    """
    results = _workdir(tmp_path)
    _run(results, tmp_path, [_job("ra", "a", "config/a.csv")])
    crate_mod.set_aside_crate(results)
    assert not (results / "ro-crate-metadata.json").exists() and (results / EARLIER_NAME).is_file()
    crate_mod.set_aside_crate(results)
    assert (results / EARLIER_NAME).is_file()
    _run(results, tmp_path, [_job("rb", "b", "config/b.csv")])
    assert "#job-ra-dataset=a" in _graph(results)


# -- real runs: sessions in their own folders, a folder's workbook and crate over two configs ---------

#: A third test session drawn with known e_x (direct noise: no render block, quick): wood as the default's
#: truth (Table II, 0.464), metal_rough 0.106 below it (0.356 in the default session).
H03 = {
    "results": "results/2026-11-h03",
    "datasets": {
        "h03": {
            "synthetic": {
                "seed": 11,
                "impacts": {"baseball": {"wood": 16, "metal_rough": 16}},
                "e_x": {"baseball": {"wood": 0.464, "metal_rough": 0.25}},
                "e_y": {"baseball": 0.45},
            },
        }
    },
}


def _tree(folder):
    return {p.relative_to(folder).as_posix(): sha256_file(p) for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.slow
def test_three_sessions_in_three_folders_make_one_league(default_run, lab_run, tmp_path, capsys):
    """Done when (issue 37): the default run (results/), the maple example (the lab run's results/maple)
    and a third session drawn with known e_x, run into its own folder results/2026-11-h03, give one league
    table with its pairwise tests (`ballbat compare F1 F2 F3`) and its forest plot. The session's run
    leaves the default folder's files as they were, and each folder's crate checks against its folder.
    """
    import yaml
    from validate_crate import main as validate

    from ballbat.cli import main as cli
    from workflow_helpers import copy_run, snakemake

    work = copy_run(default_run, tmp_path / "run")
    before = _tree(work / "results")
    (work / "h03.yaml").write_text(yaml.safe_dump(H03))
    snakemake(work, "-c2", "results/2026-11-h03/h03/fit_ex.nc", "--configfile", "h03.yaml")
    session = work / "results" / "2026-11-h03"
    assert {k: v for k, v in _tree(work / "results").items() if not k.startswith("2026-11-h03/")} == before
    assert crate_file_problems(work / "results") == [] and crate_file_problems(session) == []
    assert validate([str(session)]) == 0
    folders = [work / "results", lab_run / "results" / "maple", session]
    assert cli(["compare", *map(str, folders)]) == 0
    out = capsys.readouterr().out
    assert "3 test session(s)" in out and "Pairwise differences (Holm over 12 pairs" in out
    # the same table as ballbat compare's (its code: read_folder, league), and its forest plot
    from ballbat.league import LeagueSettings, league, read_folder
    from ballbat.plotting_league import save_forest

    ds = league([s for f in folders for s in read_folder(f)], LeagueSettings.from_config({}))
    sessions = {str(s) for s in ds["entry_session"].values}
    assert len(sessions) == 3, sessions
    save_forest(ds, tmp_path / "league_forest.png")
    assert (tmp_path / "league_forest.png").stat().st_size > 10_000
    # the known truth: each of the session's e_x within its 95 % interval (2 sigma of stat. and syst.)
    for bat, truth in H03["datasets"]["h03"]["synthetic"]["e_x"]["baseball"].items():
        (i,) = [k for k in range(ds.sizes["entry"]) if ds["entry_bat"].values[k] == bat and "h03" in sessions_of(ds, k)]
        total = float(np.hypot(ds["entry_e_x_stat"].values[i], ds["entry_e_x_syst"].values[i]))
        assert abs(float(ds["entry_e_x"].values[i]) - truth) < 2 * total, (bat, float(ds["entry_e_x"].values[i]))
    # the consistency test of a bat in two sessions: wood drawn with the same e_x in both agrees (a 95 %
    # event at this seed), metal_rough drawn 0.106 apart (about 12 standard errors of the difference) does not
    rows = {(str(b), str(t)): i for i, (b, t) in enumerate(zip(ds["ball"].values, ds["bat"].values, strict=True))}
    assert ds["consistency_p"].values[rows[("baseball", "wood")]] > 0.05
    assert ds["consistency_p"].values[rows[("baseball", "metal_rough")]] < 1e-3
    # every pair of baseball bats has its test (default's 3, maple, and h03's two: 4 bats, 6 pairs)
    ball = [str(b) for b in ds["pair_ball"].values]
    assert ball.count("baseball") == 6 and np.all(np.isfinite(ds["pair_p_holm"].values))


def sessions_of(ds, k):
    return f"{ds['entry_session'].values[k]} {ds['entry_folder'].values[k]}"


#: A lab's own scenario, run into the default folder beside the paper's (a launch scenario: quick).
MYLAB = {
    "implications": {
        "scenarios": {
            "mylab": {
                "ball": "baseball",
                "launch": {"exit_speed_mph": 100, "launch_deg": [20, 30], "backspin_rpm": 2000},
                "flight": {"n_points": 11},
            }
        }
    }
}


@pytest.mark.slow
def test_rerunning_the_default_keeps_a_labs_scenario(default_run, tmp_path):
    """Why (issue 37): rerunning the default dropped a user's scenario sheet from implications/results.xlsx,
    and the crate then described only the last run. Now the workbook keeps the sheet, and the crate of the
    rerun carries the scenario's jobs from the earlier run, their results unchanged.
    """
    import openpyxl
    import yaml
    from validate_crate import main as validate

    from workflow_helpers import copy_run, snakemake

    work = copy_run(default_run, tmp_path / "run")
    results = work / "results"
    (work / "mylab.yaml").write_text(yaml.safe_dump(MYLAB))
    snakemake(work, "-c2", "--configfile", "mylab.yaml")
    xlsx = results / "implications" / "results.xlsx"
    assert openpyxl.load_workbook(xlsx, read_only=True).sheetnames[:2] == ["mylab", "paper"]
    scenario = sha256_file(results / "implications" / "mylab.nc")
    snakemake(work, "-c2")  # the default config again: the front page reruns (its scenarios changed)
    assert openpyxl.load_workbook(xlsx, read_only=True).sheetnames[:2] == ["mylab", "paper"]
    graph = _graph(results)
    action = graph["#job-implications-scenario=mylab"]
    assert "implications/mylab.nc" in _ids(action["result"]) and "earlier run" in action["description"]
    assert graph["implications/mylab.nc"]["sha256"] == scenario
    assert graph["implications/mylab.nc"]["description"].startswith("not made by this run: made by an earlier run")
    assert "#job-plot_launch-scenario=mylab" in graph and "#job-report_front" in _ids(graph["./"]["mentions"])
    assert crate_file_problems(results) == [] and validate([str(results)]) == 0


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


@pytest.mark.slow
def test_snakemake_names_a_target_after_configfile(tmp_path):
    """The workflow stops with one line (main printed the sidecar's keys as unknown config keys)."""
    from workflow_helpers import make_workdir, snakemake

    work = make_workdir(tmp_path)
    (work / "my.yaml").write_text("analysis: {mu_k_example: 0.4}\n")
    (work / "results" / "synthetic").mkdir(parents=True)
    (work / "results" / "synthetic" / "paper_comparison.provenance.json").write_text('{"rule": "compare"}')
    out = snakemake(
        work, "-n", "--configfile", "my.yaml", "results/synthetic/paper_comparison.provenance.json", check=False
    )
    assert out.returncode != 0
    assert (
        "ballbat: --configfile results/synthetic/paper_comparison.provenance.json: a file of the results" in out.stderr
    )
    assert "Traceback" not in out.stderr and "unknown key" not in out.stderr
