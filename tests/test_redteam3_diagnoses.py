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


_ = copy, sys, Path
