"""The rules' view of the config (ballbat.workflow_inputs): inputs, params, resources and targets, as Python.

Issue 37 §1: test sessions. A run's results folder is a setting; a folder's crate carries every run in
it; a folder's workbooks keep every scenario's sheet; three sessions' folders make one league table.
"""

from __future__ import annotations

import copy
from argparse import Namespace

import pytest

from ballbat.config_checks import impact_bytes
from ballbat.workflow_inputs import DATASET_FIGURES, WorkflowInputs, existing, file_hashes, results_root
from workflow_helpers import ROOT


@pytest.fixture
def inputs(config):
    return WorkflowInputs(copy.deepcopy(config), ROOT)


def test_default_targets(inputs):
    targets = inputs.final_targets()
    assert len(targets) == len(set(targets))
    assert targets[0] == "results/synthetic/reduce.nc"  # the default renders camera tracks
    per = [t for t in targets if t.startswith("results/synthetic/")]
    # the source, 2 track figures, 4 intermediate files, 3 tables and the workbook, 7 figures
    assert len(per) == 1 + 2 + 4 + 3 + len(DATASET_FIGURES)
    assert "results/implications/paper.nc" in targets and "results/implications/paper_comparison.csv" in targets
    assert inputs.datasets == ["synthetic"] and inputs.tracked == ["synthetic"]
    assert inputs.dataset_kind("synthetic") == "synthetic, rendered camera tracks"


def test_a_measured_and_a_tool_file_dataset(config, tmp_path):
    cfg = copy.deepcopy(config)
    cfg["datasets"]["lab"] = {"impacts": "lab.csv", "bats": "lab_bats.csv"}
    cfg["datasets"]["trk"] = {"tracks": {"dir": str(tmp_path), "impacts": "imp.csv"}}
    inputs = WorkflowInputs(cfg, ROOT)
    lab, trk = Namespace(dataset="lab"), Namespace(dataset="trk")
    assert inputs.get_source(lab) == "results/lab/ingest.nc" and inputs.dataset_kind("lab") == "measured"
    assert inputs.data_files(lab) == {"balls": cfg["tables"]["balls"], "bats": "lab_bats.csv", "impacts": "lab.csv"}
    assert inputs.get_bats_table(lab) == []  # missing: this dataset's job fails, not the DAG
    assert inputs.get_tracks_inputs(trk) == {
        "tracks": "results/trk/imported_tracks.nc",
        "cameras": "results/trk/imported_cameras.yaml",
    }
    assert (
        inputs.get_source(trk) == "results/trk/reduce.nc"
        and inputs.get_reduce_where(trk) == "config datasets.trk.tracks"
    )


def test_only_a_dataset_of_clips_gets_the_clips_qa_figures(config, tmp_path):
    """A folder of clips: import_clips (the tracker's quality) and the clips' figures; tool files: neither."""
    cfg = copy.deepcopy(config)
    cfg["datasets"]["trk"] = {"tracks": {"dir": str(tmp_path), "impacts": "imp.csv"}}
    cfg["datasets"]["vid"] = {"tracks": {"dir": str(tmp_path), "impacts": "imp.csv", "format": "video"}}
    inputs = WorkflowInputs(cfg, ROOT)
    assert inputs.filmed == ["vid"] and inputs.not_filmed == ["synthetic", "trk"]
    clips = sorted(t for t in inputs.final_targets() if "/figures/clips_" in t)
    assert clips == ["results/vid/figures/clips_contact_sheet.png", "results/vid/figures/clips_quality.png"]


def test_tool_file_content_is_in_the_params(config, tmp_path):
    """A tool file replaced by other content changes the import's params, whatever its timestamp."""
    cfg = copy.deepcopy(config)
    (tmp_path / "W01_swing.trk").write_text("a")
    (tmp_path / "notes.txt").write_text("not a tool file")
    cfg["datasets"]["trk"] = {"tracks": {"dir": str(tmp_path), "impacts": "imp.csv"}}
    inputs = WorkflowInputs(cfg, ROOT)
    trk = Namespace(dataset="trk")
    assert inputs.get_tool_files(trk)["files"] == [str(tmp_path / "W01_swing.trk")]
    before = inputs.tool_file_hashes(trk)
    (tmp_path / "W01_swing.trk").write_text("b")
    after = inputs.tool_file_hashes(trk)
    assert before["W01_swing.trk"] != after["W01_swing.trk"] and before["balls"] == after["balls"]
    assert file_hashes({"x": str(tmp_path / "none")}) == {"x": "not a file"}
    assert existing(str(tmp_path)) == []  # a folder is no input file


def test_memory_plans(inputs, config):
    synthetic = Namespace(dataset="synthetic")
    n = 108  # Table I: 58 baseball and 50 softball impacts
    assert inputs.dataset_mem_mb(synthetic) == 500 + n * impact_bytes(config["datasets"]["synthetic"]) // 1_000_000
    sweep = inputs.get_scenario(Namespace(scenario="paper"))["sweep"]["D_in"]["num"]
    assert inputs.scenario_mem_mb(Namespace(scenario="paper")) >= 500 and sweep > 1


def test_study_targets(inputs):
    """Every product of each study, its truth points and batches included; on_request ones apart."""
    calibration = [t for t in inputs.study_targets() if "/calibration/" in t]
    s = inputs.study_settings("calibration")
    assert len([t for t in calibration if "/batches/" in t]) == s.n_batches == -(-s.replicates // s.batch_size)
    assert "results/studies/calibration/coverage.png" in calibration
    assert "results/studies/design/design.nc" in inputs.study_targets()
    on_request = inputs.study_targets(on_request=True)
    assert "results/studies/robustness/grid.png" in on_request
    assert not any("/robustness/" in t for t in inputs.study_targets())


def test_code_lists_the_modules_a_script_imports(inputs):
    files = inputs.code("simulate.py")
    assert any(f.endswith("src/ballbat/stages/simulate.py") for f in files)
    assert not any(f.endswith("src/ballbat/plotting.py") for f in files)


def test_league_targets(config):
    """The league is made when there is something to compare: several datasets, or several bats of a ball."""
    cfg = copy.deepcopy(config)
    assert "results/league.nc" in WorkflowInputs(cfg, ROOT).league_targets()  # 3 baseball, 4 softball bats
    cfg["datasets"]["synthetic"]["synthetic"]["impacts"] = {"baseball": {"wood": 20}}
    assert WorkflowInputs(cfg, ROOT).league_targets() == []
    cfg["datasets"]["lab"] = {"impacts": "lab.csv"}
    assert len(WorkflowInputs(cfg, ROOT).league_targets()) == 4


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
