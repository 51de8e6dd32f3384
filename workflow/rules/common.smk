# Config validation, input functions and code dependencies shared by all rules.
from argparse import Namespace
from pathlib import Path

import yaml

from ballbat.pipeline.codedeps import module_files
from ballbat.pipeline.config import drop_nulls, validate_config

SCHEMA = Path(workflow.basedir) / "workflow" / "schemas" / "config.schema.yaml"
# A dataset or scenario set to null (e.g. `datasets: {synthetic: null}` in a --configfile) is dropped.
drop_nulls(config)
with open(SCHEMA) as _fh:
    # the C loader (libyaml, shipped in the PyYAML wheel) parses the schema ~10x faster
    _schema = yaml.load(_fh, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    validate_config(config, _schema, source="config (config/config.yaml and --configfile/--config overrides)")

DATASETS = sorted(config["datasets"])
SCRIPTS = Path(workflow.basedir) / "workflow" / "scripts"
#: The software environment of every rule (requirements.lock as a conda file; `--sdm conda`).
ENV = "../envs/ballbat.yaml"


wildcard_constraints:
    dataset="|".join(DATASETS),


def code(script):
    """The package modules a script imports (so editing them reruns the rule)."""
    here = Path.cwd()
    files = module_files(str(SCRIPTS / script))
    return [str(Path(f).relative_to(here)) if Path(f).is_relative_to(here) else f for f in files]


def dataset_config(wildcards):
    return config["datasets"][wildcards.dataset]


def get_synthetic_settings(wildcards):
    return dataset_config(wildcards)["synthetic"]


def get_balls_table(wildcards):
    return dataset_config(wildcards).get("balls", config["tables"]["balls"])


def get_bats_table(wildcards):
    return dataset_config(wildcards).get("bats", config["tables"]["bats"])


def is_measured(name):
    """A measured dataset names its impacts file; a synthetic one has `synthetic` settings."""
    return "impacts" in config["datasets"][name]


def get_measured_impacts(wildcards):
    return dataset_config(wildcards)["impacts"]


def get_source(wildcards):
    """The first stage of a dataset: its synthetic experiment or its measured impacts, checked."""
    stage = "ingest" if is_measured(wildcards.dataset) else "simulate"
    return f"results/{wildcards.dataset}/{stage}.nc"


SCENARIOS = sorted(config.get("implications", {}).get("scenarios", {}))
for _name, _sc in config.get("implications", {}).get("scenarios", {}).items():
    if "e_x_from_dataset" in _sc and _sc["e_x_from_dataset"] not in DATASETS:
        raise ValueError(
            f"config: implications.scenarios.{_name}.e_x_from_dataset: "
            f"{_sc['e_x_from_dataset']!r} is not a dataset ({', '.join(DATASETS)})"
        )


wildcard_constraints:
    scenario="|".join(SCENARIOS) or "^$",


SWEEP_SCENARIOS = [s for s in SCENARIOS if "sweep" in config["implications"]["scenarios"][s]]
LAUNCH_SCENARIOS = [s for s in SCENARIOS if s not in SWEEP_SCENARIOS]


def final_targets():
    """Everything a default run makes: every dataset's intermediate files, fits, figures and tables, and
    every scenario's (rule all asks for these; an intermediate deleted by hand is therefore rebuilt)."""
    per_dataset = ["normalize.nc", "reconstruct.nc", "fit_ex.nc", "stronge.nc"]
    per_dataset += ["paper_comparison.csv", "paper_comparison.html", "results.xlsx"]
    per_dataset += [f"figures/{fig}.png" for fig in ("fig3", "fig4", "fig5", "fig6", "fig9a", "fig9b", "fig10")]
    targets = [get_source(Namespace(dataset=d)) for d in DATASETS]
    targets += [f"results/{d}/{f}" for d in DATASETS for f in per_dataset]
    targets += [f"results/implications/{s}.nc" for s in SCENARIOS]
    targets += ["results/implications/results.xlsx"] if SCENARIOS else []
    targets += [f"results/implications/figures/{s}_fig11{p}.png" for s in SWEEP_SCENARIOS for p in "ab"]
    targets += [f"results/implications/figures/{s}_launch.png" for s in LAUNCH_SCENARIOS]
    if "paper" in SWEEP_SCENARIOS:  # the paper's own scenario is compared with Sec. V.B
        targets += ["results/implications/paper_comparison.csv", "results/implications/paper_comparison.html"]
    return targets


def get_scenario(wildcards):
    return config["implications"]["scenarios"][wildcards.scenario]


def get_scenario_fit(wildcards):
    """fit_ex.nc of the dataset whose pooled e_x the scenario uses (none by default)."""
    name = get_scenario(wildcards).get("e_x_from_dataset")
    return {"fit": f"results/{name}/fit_ex.nc"} if name else {}
