# Config validation, the run's guards and crate, and the rules' view of the config: its input
# functions, target lists and resource plans are ballbat.workflow_inputs (Python, tested).
import sys
import time
from pathlib import Path

from snakemake.exceptions import WorkflowError

from ballbat.config_checks import scenario_problems, validate_config
from ballbat.pipeline.codedeps import save_record as save_code_record
from ballbat.pipeline.codedeps import use_record as use_code_record
from ballbat.pipeline.config import ConfigError, drop_nulls
from ballbat.pipeline.guards import (
    configfile_targets,
    damaged_products,
    foreign_outputs,
    remove_temporaries,
    unwritable_folders,
    users_files,
    warnings_summary,
)
from ballbat.pipeline.params_record import serialize_params_lazily
from ballbat.pipeline.validated import load_schema
from ballbat.workflow_inputs import WorkflowInputs

# Snakemake records the rules' params without importing pandas (0.15 s of every start) while no
# param is a pandas object: the same records, so a changed param reruns as before (ballbat.pipeline.params_record).
serialize_params_lazily()

# A results file given to --configfile (a target put after it): one line, before the config is checked.
for _line in configfile_targets(workflow.configfiles, config.get("results") or "results"):
    sys.exit(f"ballbat: {_line}")

SCHEMA = Path(workflow.basedir) / "workflow" / "schemas" / "config.schema.yaml"
# A dataset or scenario set to null (e.g. `datasets: {synthetic: null}` in a --configfile) is dropped.
drop_nulls(config)
# The schema, from its JSON copy where one of the same bytes is kept (ballbat.pipeline.validated).
_schema = load_schema(SCHEMA)
validate_config(
    config,
    _schema,
    source="config (config/config.yaml and --configfile/--config overrides)",
    record=Path(".snakemake") / "ballbat" / "validated",  # a config that passed: its schema checks not run again
)
# A scenario's ball and bat, and the dataset of its e_x, checked before the DAG is built (one line each).
_problems = scenario_problems(config)
if _problems:
    raise ConfigError("config is not valid:\n  " + "\n  ".join(_problems))

# The package modules' imports read at earlier starts (the rules' code inputs; saved at the Snakefile's end).
use_code_record(Path(".snakemake") / "ballbat" / "codedeps.json")
INPUTS = WorkflowInputs(config, workflow.basedir)
#: The run's results folder (config `results`, default `results`): every rule's paths start with it, so a
#: test session written to its own folder (`--config results=results/2026-11-h01`) touches no other.
R = INPUTS.results
# A folder the run cannot write: one line naming it, for every invocation (a dry run, --unlock too).
for _line in unwritable_folders([R, ".snakemake"]):
    sys.exit(f"ballbat: {_line}")
DATASETS, TRACKED = INPUTS.datasets, INPUTS.tracked
#: The datasets whose tracks come from clips (imported by import_clips, with the tracker's quality), and the others.
FILMED, NOT_FILMED = INPUTS.filmed, INPUTS.not_filmed
SCENARIOS, SWEEP_SCENARIOS, LAUNCH_SCENARIOS = INPUTS.scenarios, INPUTS.sweep_scenarios, INPUTS.launch_scenarios
# Replicate studies (studies.smk). STUDIES: those of `snakemake studies` (`make study`); the studies marked
# on_request are built by `snakemake studies_on_request` only.
ALL_STUDIES, STUDIES = INPUTS.all_studies, INPUTS.studies
#: The software environment of every rule (requirements.lock as a conda file; `--sdm conda`).
ENV = "../envs/ballbat.yaml"


wildcard_constraints:
    dataset="|".join(DATASETS),
    scenario="|".join(SCENARIOS) or "^$",
    study="|".join(ALL_STUDIES) or "^$",
    batch=r"\d+",
    point=r"\d+",


# The rules' input, params and resources functions (ballbat.workflow_inputs.WorkflowInputs).
code = INPUTS.code
dataset_config = INPUTS.dataset_config
data_files = INPUTS.data_files
data_hashes = INPUTS.data_hashes
get_synthetic_settings = INPUTS.get_synthetic_settings
get_measured_impacts = INPUTS.get_measured_impacts
get_balls_table = INPUTS.get_balls_table
get_bats_table = INPUTS.get_bats_table
dataset_kind = INPUTS.dataset_kind
get_source = INPUTS.get_source
final_targets = INPUTS.final_targets
get_render_settings = INPUTS.get_render_settings
get_tracks_inputs = INPUTS.get_tracks_inputs
get_tool_files = INPUTS.get_tool_files
tool_file_hashes = INPUTS.tool_file_hashes
get_import_settings = INPUTS.get_import_settings
get_clip_batch_files = INPUTS.get_clip_batch_files
get_batch_clips = INPUTS.get_batch_clips
get_tracker_settings = INPUTS.get_tracker_settings
batch_hashes = INPUTS.batch_hashes
clip_batch_mem_mb = INPUTS.clip_batch_mem_mb
clip_batch_runtime = INPUTS.clip_batch_runtime
get_reduce_settings = INPUTS.get_reduce_settings
get_reduce_where = INPUTS.get_reduce_where
dataset_mem_mb = INPUTS.dataset_mem_mb
scenario_mem_mb = INPUTS.scenario_mem_mb
get_scenario = INPUTS.get_scenario
get_scenario_fit = INPUTS.get_scenario_fit
get_scenario_tables = INPUTS.get_scenario_tables
scenario_hashes = INPUTS.scenario_hashes
get_study_config = INPUTS.get_study_config
study_hashes = INPUTS.study_hashes
get_study_balls = INPUTS.get_study_balls
get_study_bats = INPUTS.get_study_bats
get_study_batches = INPUTS.get_study_batches
get_study_truth_points = INPUTS.get_study_truth_points
study_targets = INPUTS.study_targets
study_batch_mem_mb = INPUTS.study_batch_mem_mb
study_truth_mem_mb = INPUTS.study_truth_mem_mb
study_aggregate_mem_mb = INPUTS.study_aggregate_mem_mb
study_batch_runtime = INPUTS.study_batch_runtime
study_truth_runtime = INPUTS.study_truth_runtime


def report_damaged_products(paths):
    """Name every damaged product among ``paths``, and how to rebuild it. Reads only: this runs while
    Snakemake parses the workflow (dry runs, --lint, --summary and cluster jobs too), so nothing is removed."""
    if workflow.remote_exec or workflow.subprocess_exec:
        return
    for line in damaged_products(paths) + users_files(paths):
        print(f"ballbat: {line}", file=sys.stderr)


def start_run(dag):
    """When a real run starts (Snakemake holds the folder's lock): stop before any file the workflow did
    not write would be replaced, and remove the temporary files of dead jobs on this host."""
    lines = foreign_outputs(f for job in dag.needrun_jobs() for f in job.output)
    if lines:
        raise WorkflowError("\n".join(f"ballbat: {line}" for line in lines))
    for message in remove_temporaries(R):
        print(f"ballbat: {message}", file=sys.stderr)
    from ballbat.pipeline.crate import set_aside_crate

    # the run changes the folder: no crate until it ends (write_crate), which carries over the earlier one's actions
    set_aside_crate(R)


#: When this run started (the crate's run action; no data file records a time).
RUN_STARTED = time.time()


def write_crate(failed=False):
    """Write the run's Provenance Run Crate, {R}/ro-crate-metadata.json (ballbat.pipeline.crate): after a
    success, or after a failure (the run marked failed; files it did not make listed with their staleness)."""
    from ballbat.pipeline.crate import write_crate_of_run

    try:
        path = write_crate_of_run(workflow, config, started=RUN_STARTED, failed=failed)
    except Exception as exc:
        if not failed:
            raise
        print(f"ballbat: no provenance crate after the failed run ({type(exc).__name__}: {exc})", file=sys.stderr)
        return
    what = "of the failed run, marked failed" if failed else "of the run"
    print(f"ballbat: the provenance crate {what}: {path}", file=sys.stderr)


def print_warnings(results, datasets, scenarios):
    """Print every warning of this run's jobs (from their logs) at its end, so no one has to open a log."""
    lines = warnings_summary(results, datasets, ["implications"] if scenarios else [])
    if lines:
        print("\nballbat: warnings of this run (details in the logs named):", *lines, sep="\n  ", file=sys.stderr)


# A damaged product is named, with the command that rebuilds it (nothing is removed here).
report_damaged_products(final_targets() + study_targets() + study_targets(on_request=True))
