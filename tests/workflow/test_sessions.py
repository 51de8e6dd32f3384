"""Test sessions through Snakemake (issue 37, section 1): three sessions' folders make one league table, a
rerun keeps a lab's scenario, a results file given after --configfile is named.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers import crate_graph as _graph
from helpers import crate_ids as _ids

from ballbat.pipeline.cratefiles import crate_file_problems
from ballbat.pipeline.provenance import sha256_file

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
