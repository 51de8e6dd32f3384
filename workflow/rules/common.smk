# Config validation, input functions and code dependencies shared by all rules.
from pathlib import Path

import yaml

from ballbat.pipeline.codedeps import module_files
from ballbat.pipeline.config import validate_config

SCHEMA = Path(workflow.basedir) / "workflow" / "schemas" / "config.schema.yaml"
# A dataset set to null (e.g. `datasets: {synthetic: null}` in a --configfile) is dropped.
if isinstance(config.get("datasets"), dict):
    config["datasets"] = {k: v for k, v in config["datasets"].items() if v is not None}
with open(SCHEMA) as _fh:
    # the C loader (libyaml, shipped in the PyYAML wheel) parses the schema ~10x faster
    _schema = yaml.load(_fh, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    validate_config(config, _schema, source="config (config/config.yaml and --configfile/--config overrides)")

DATASETS = sorted(config["datasets"])
SCRIPTS = Path(workflow.basedir) / "workflow" / "scripts"


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
    if uses_tracks(wildcards.dataset):  # raw camera tracks: workflow/rules/tracks.smk
        return f"results/{wildcards.dataset}/reduce.nc"
    stage = "ingest" if is_measured(wildcards.dataset) else "simulate"
    return f"results/{wildcards.dataset}/{stage}.nc"


#: Final products; each rule file appends its own (rule all asks for all of them).
TARGETS = []


def rule_writes(pattern):
    """Whether a rule included so far writes ``pattern`` (lets optional stages switch figures on)."""
    from snakemake.io import strip_wildcard_constraints

    return any(strip_wildcard_constraints(str(f)) == pattern for r in workflow.rules for f in r.output)


SCENARIOS = sorted(config.get("implications", {}).get("scenarios", {}))
for _name, _sc in config.get("implications", {}).get("scenarios", {}).items():
    if "e_x_from_dataset" in _sc and _sc["e_x_from_dataset"] not in DATASETS:
        raise ValueError(
            f"config: implications.scenarios.{_name}.e_x_from_dataset: "
            f"{_sc['e_x_from_dataset']!r} is not a dataset ({', '.join(DATASETS)})"
        )


wildcard_constraints:
    scenario="|".join(SCENARIOS) or "^$",


def get_scenario(wildcards):
    return config["implications"]["scenarios"][wildcards.scenario]


def get_scenario_fit(wildcards):
    """fit_ex.nc of the dataset whose pooled e_x the scenario uses (none by default)."""
    name = get_scenario(wildcards).get("e_x_from_dataset")
    return {"fit": f"results/{name}/fit_ex.nc"} if name else {}

