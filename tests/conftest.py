"""Shared fixtures: the repository's property tables (Tables I and II of the paper), and one default workflow run."""

from pathlib import Path

import pytest

from ballbat.pipeline.config import load_config
from ballbat.properties import load_balls, load_bats

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def root():
    return ROOT


@pytest.fixture(scope="session")
def config():
    """The default config/config.yaml, validated, with the schema's defaults (as the workflow sees it)."""
    return load_config(ROOT / "config" / "config.yaml")


@pytest.fixture(scope="session")
def balls():
    return load_balls(ROOT / "config" / "balls.csv")


@pytest.fixture(scope="session")
def bats():
    return load_bats(ROOT / "config" / "bats.csv")


@pytest.fixture(scope="session")
def default_run(tmp_path_factory):
    """A copy of the workflow run once with the default config (`snakemake -c2`), shared by the tests that read it."""
    from workflow_helpers import make_workdir, snakemake

    work = make_workdir(tmp_path_factory.mktemp("default_run"))
    snakemake(work, "-c2")
    return work
