"""Shared fixtures: the repository's property tables (Tables I and II of the paper), and one default workflow run."""

from pathlib import Path

import pytest
import yaml

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


@pytest.fixture
def raw():
    """The default config/config.yaml as written (not validated): a fresh copy for each test to edit."""
    return yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


@pytest.fixture(scope="module")
def schema():
    """The config schema (workflow/schemas/config.schema.yaml)."""
    return yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())


@pytest.fixture(scope="session")
def balls():
    return load_balls(ROOT / "config" / "balls.csv")


@pytest.fixture(scope="session")
def bats():
    return load_bats(ROOT / "config" / "bats.csv")


@pytest.fixture(scope="session")
def default_run(tmp_path_factory):
    """A copy of the workflow run once with the default config (`snakemake -c2`), shared by the tests that read it.

    The only build of the default workflow in the suite: a test that changes a run works on a
    copy of this one (:func:`workflow_helpers.copy_run`), where Snakemake has nothing to redo.
    """
    from workflow_helpers import make_workdir, snakemake

    work = make_workdir(tmp_path_factory.mktemp("default_run"))
    snakemake(work, "-c2")
    return work


@pytest.fixture(scope="session")
def default_report(default_run, tmp_path_factory):
    """A copy of the default run with its report (`snakemake --report results/report.html`)."""
    from workflow_helpers import copy_run, snakemake

    work = copy_run(default_run, tmp_path_factory.mktemp("default_report") / "run")
    snakemake(work, "--report", "results/report.html")
    return work


@pytest.fixture(scope="session")
def small_run(tmp_path_factory):
    """One finished run of a small config, shared (through copies) by test_workflow and test_redteam_guards.

    The package's source is copied too (tests edit it to see what reruns). Config: the
    dataset ``small`` (36 impacts, direct noise), the paper scenario with 26 offsets and e_x
    from ``small``, a ``flyballs`` scenario (2 exit speeds x 3 launch angles, 11 points), and a
    2-replicate calibration study of ``small``; built with ``snakemake -c2 all studies``.
    """
    from workflow_helpers import SMALL_SYNTHETIC, make_workdir, snakemake, write_config

    def edit(cfg):
        cfg["datasets"] = {"small": {"synthetic": SMALL_SYNTHETIC}}
        paper = cfg["implications"]["scenarios"]["paper"]
        paper["sweep"]["D_in"]["num"] = 26
        paper["e_x_from_dataset"] = "small"
        cfg["implications"]["scenarios"]["flyballs"] = {
            "ball": "baseball",
            "launch": {"exit_speed_mph": [95, 105], "launch_deg": [15, 25, 35], "backspin_rpm": 2200},
            "flight": {"n_points": 11},
        }
        cfg["studies"] = {
            "calibration": {"dataset": "small", "seed": 1, "replicates": 2, "batch_size": 1, "truth_impacts": 40}
        }

    work = make_workdir(tmp_path_factory.mktemp("small_run"), copy_package=True)
    write_config(work, edit)
    snakemake(work, "-c2", "all", "studies")
    return work


@pytest.fixture(scope="session")
def maple_run(tmp_path_factory):
    """One finished run of the example measured dataset (config/examples/maple.yaml) beside the small
    synthetic dataset ``tiny`` (no scenarios, no studies), shared through copies by test_byod and test_faults.
    """
    from workflow_helpers import TINY_SYNTHETIC, make_workdir, snakemake, write_config

    def edit(cfg):
        cfg["datasets"] = {"tiny": {"synthetic": TINY_SYNTHETIC}}
        cfg["studies"] = {}
        cfg["implications"]["scenarios"] = {}

    work = make_workdir(tmp_path_factory.mktemp("maple_run"))
    write_config(work, edit)
    snakemake(work, "-c2", "--configfile", "config/examples/maple.yaml")
    return work


#: The shared runs above: under pytest-xdist (`make test`: ``-n 2 --dist loadgroup``) every test
#: that uses one goes to the same worker, so each run is still built once in the whole suite.
SHARED_RUNS = {"default_run": "default_run", "default_report": "default_run", "small_run": "small_run"}
SHARED_RUNS["maple_run"] = "maple_run"


def pytest_collection_modifyitems(config, items):
    """Group the tests of each shared run onto one xdist worker (a no-op without xdist)."""
    for item in items:
        groups = {SHARED_RUNS[f] for f in item.fixturenames if f in SHARED_RUNS}
        if groups:
            item.add_marker(pytest.mark.xdist_group("+".join(sorted(groups))))
