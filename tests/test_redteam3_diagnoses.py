"""Red team, issue 34 part B: the crate, per-impact quality, diagnoses, early errors and provenance.

Each row of a table below is a case of issue 34 ("Reliability 3") that, on the code before it,
gave a wrong or vague message, a late error or a silently wrong number; the row holds the
expected outcome. Crate-only checks are in tests/test_crate.py.
"""

from __future__ import annotations

import copy
import sys
from pathlib import Path

import pytest
import yaml
from conftest import ROOT

from ballbat.pipeline.config import ConfigError, drop_nulls, scenario_problems, validate_config

MAPLE = ROOT / "config" / "examples" / "maple_impacts.csv"
MAPLE_BATS = ROOT / "config" / "examples" / "maple_bats.csv"


# ---------------------------------------------------------------------------------------
# Early errors: (case, edit of the default config, the one line expected), before any DAG


def _scenario(c, **kw):
    c["implications"]["scenarios"]["paper"].update(kw)


def _maple_only(c):
    c["datasets"] = {"maple": {"impacts": str(MAPLE), "bats": str(MAPLE_BATS)}}
    c["studies"] = {}


EARLY_CASES = [
    (
        "a sweep scenario's misspelt bat",
        lambda c: _scenario(c, bat="wod"),
        "implications.scenarios.paper.bat: 'wod' is not in the bat table config/bats.csv",
    ),
    (
        "a scenario's misspelt ball",
        lambda c: _scenario(c, ball="basebal"),
        "implications.scenarios.paper.ball: 'basebal' is not in the ball table config/balls.csv",
    ),
    (
        "e_x_from_dataset: a measured dataset without the scenario's ball",
        lambda c: (_maple_only(c), _scenario(c, ball="softball", e_x_from_dataset="maple")),
        "implications.scenarios.paper.e_x_from_dataset: dataset 'maple' has no impacts of the scenario's ball "
        "'softball' (its balls: baseball)",
    ),
    (
        "e_x_from_dataset: a synthetic dataset without the scenario's ball",
        lambda c: (
            [c["datasets"]["synthetic"]["synthetic"][k].pop("softball") for k in ("impacts", "e_x", "e_y", "psi_deg")],
            _scenario(c, ball="softball", e_x_from_dataset="synthetic"),
        ),
        "dataset 'synthetic' has no impacts of the scenario's ball 'softball' (its balls: baseball)",
    ),
    (
        "e_x_from_dataset: no such dataset",
        lambda c: _scenario(c, e_x_from_dataset="synthetc"),
        "implications.scenarios.paper.e_x_from_dataset: 'synthetc' is not a dataset (synthetic)",
    ),
]


def _early_problems(cfg, schema) -> list[str]:
    """What common.smk says before the DAG: the schema's lines, else the scenarios' (scenario_problems)."""
    try:
        validate_config(drop_nulls(cfg), schema, available=24 * 2**30)
    except ConfigError as err:
        return str(err).splitlines()[1:]
    return scenario_problems(cfg)


@pytest.mark.parametrize(("case", "edit", "line"), EARLY_CASES, ids=[c[0] for c in EARLY_CASES])
def test_early_errors_name_the_key(case, edit, line, schema, monkeypatch):
    """Each mistake is one line naming the scenario's key, found from the config and tables alone."""
    monkeypatch.chdir(ROOT)
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    edit(cfg)
    problems = _early_problems(cfg, schema)
    assert len(problems) == 1 and line in problems[0], problems


def test_config_null_text_drops_the_dataset(schema):
    """`--config "datasets={synthetic: null}"` passes the text 'null': it drops the dataset as a YAML null does,
    and with no dataset left the message is one line saying so (not two schema lines about 'null')."""
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    cfg["datasets"]["maple"] = {"impacts": str(MAPLE), "bats": str(MAPLE_BATS)}
    cfg["datasets"]["synthetic"] = "null"  # snakemake's --config parser keeps YAML scalars as text
    assert sorted(validate_config(drop_nulls(cfg), schema, available=24 * 2**30)["datasets"]) == ["maple"]
    alone = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    alone["datasets"]["synthetic"] = "null"
    with pytest.raises(ConfigError) as err:
        validate_config(drop_nulls(alone), schema, available=24 * 2**30)
    assert str(err.value).splitlines()[1:] == [
        "  datasets: no dataset is left (each one was set to null or removed); the workflow needs at least one"
    ]


@pytest.mark.slow
def test_scenario_bat_is_refused_before_the_dag(tmp_path):
    """`snakemake -n` with a misspelt scenario bat stops while parsing, naming the scenario (no job planned)."""
    from workflow_helpers import make_workdir, snakemake

    work = make_workdir(tmp_path)
    out = snakemake(work, "-n", "--config", "implications={scenarios: {paper: {bat: wod}}}", check=False)
    assert out.returncode != 0
    assert "implications.scenarios.paper.bat: 'wod' is not in the bat table" in out.stdout + out.stderr
    assert "Job stats" not in out.stdout + out.stderr


# ---------------------------------------------------------------------------------------
# Provenance


def test_dirty_when_a_copied_workflow_differs_from_the_commit(tmp_path, monkeypatch):
    """A copied checkout whose workflow script was edited records dirty: True (it recorded False: git status
    looked at the package's clean checkout, not at the workflow that ran)."""
    from workflow_helpers import make_workdir

    from ballbat.pipeline import provenance

    work = make_workdir(tmp_path)
    commit = provenance.git_state(str(ROOT))["commit"]
    assert provenance.workflow_matches_commit(work, str(ROOT), commit) == provenance.workflow_matches_commit(
        ROOT, str(ROOT), commit
    )  # a faithful copy is judged as the checkout itself
    script = work / "workflow" / "scripts" / "fit_ex.py"
    script.write_text(script.read_text() + "# a local edit\n")
    assert not provenance.workflow_matches_commit(work, str(ROOT), commit)
    monkeypatch.chdir(work)
    state = provenance.git_state()
    assert state == {"commit": commit, "dirty": True}
    added = work / "workflow" / "rules" / "extra.smk"
    script.write_text(script.read_text().removesuffix("# a local edit\n"))
    added.write_text("# a rule file the commit does not have\n")
    assert not provenance.workflow_matches_commit(work, str(ROOT), commit)


def test_a_users_workbook_or_notes_at_an_output_path_are_not_the_workflows(tmp_path):
    """A user's own .xlsx or .md at a product's path is named as not the workflow's: never replaced by a run
    (foreign_outputs), and named while parsing (users_files); the workflow's own pass (test_crate.py: the
    crate does not list such a file as the job's result)."""
    import json

    import openpyxl

    from ballbat.pipeline.guards import foreign_outputs, users_files, written_by_workflow
    from ballbat.pipeline.provenance import sha256_file

    book, notes = tmp_path / "results.xlsx", tmp_path / "paper_comparison.md"
    openpyxl.Workbook().save(book)
    notes.write_text("| my | notes |\n")
    assert not written_by_workflow(book) and not written_by_workflow(notes)
    lines = foreign_outputs([book, notes])
    assert len(lines) == 2 and all("not written by this workflow" in line for line in lines)
    assert len(users_files([book, notes])) == 2
    sidecar = tmp_path / "paper_comparison.provenance.json"
    sidecar.write_text(json.dumps({"describes": [{"path": str(notes), "sha256": sha256_file(notes)}]}))
    assert written_by_workflow(notes) and users_files([notes]) == []
    notes.write_text("| edited | by hand |\n")
    assert not written_by_workflow(notes)


@pytest.mark.slow
def test_workflow_products_carry_their_record(default_run):
    """Every workbook, Markdown table and figure of a default run is recognised as the workflow's."""
    from ballbat.pipeline.guards import users_files, written_by_workflow

    results = default_run / "results"
    products = [p for p in results.rglob("*") if p.suffix in (".xlsx", ".md", ".png") and "snapshot" not in str(p)]
    assert len(products) > 10 and all(written_by_workflow(p) for p in products)
    assert users_files(products) == []


_ = copy, sys, Path
