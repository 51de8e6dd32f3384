# Config validation, input functions and code dependencies shared by all rules.
import math
import sys
import time
from argparse import Namespace
from pathlib import Path

import yaml
from snakemake.exceptions import WorkflowError

from ballbat.pipeline.codedeps import module_files
from ballbat.pipeline.config import (
    BYTES_PER_CASE,
    ConfigError,
    STUDY_BYTES_PER_REPLICATE,
    drop_nulls,
    impact_bytes,
    scenario_problems,
    study_impacts,
    validate_config,
)
from ballbat.sweeps import renders
from ballbat.pipeline.guards import (
    damaged_products,
    foreign_outputs,
    remove_temporaries,
    unwritable_folders,
    users_files,
    warnings_summary,
)
from ballbat.pipeline.provenance import sha256_file
from ballbat.tracks.data import camera_block, tool_file_extensions

# A folder the run cannot write: one line naming it, for every invocation (a dry run, --unlock too).
for _line in unwritable_folders(["results", ".snakemake"]):
    sys.exit(f"ballbat: {_line}")

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
    for message in remove_temporaries("results"):
        print(f"ballbat: {message}", file=sys.stderr)
    from ballbat.pipeline.crate import remove_crate

    remove_crate("results")  # the run changes the folder: no crate until it ends (write_crate)


#: When this run started (the crate's run action; no data file records a time).
RUN_STARTED = time.time()


def write_crate(failed=False):
    """Write the run's Provenance Run Crate, results/ro-crate-metadata.json (ballbat.pipeline.crate): after a
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


def code(script):
    """The package modules a script imports (so editing them reruns the rule)."""
    here = Path.cwd()
    files = module_files(str(SCRIPTS / script))
    return [str(Path(f).relative_to(here)) if Path(f).is_relative_to(here) else f for f in files]


def dataset_config(wildcards):
    return config["datasets"][wildcards.dataset]


def get_synthetic_settings(wildcards):
    return dataset_config(wildcards)["synthetic"]


def data_files(wildcards):
    """The dataset's data files as the config names them: impacts (measured), balls, bats."""
    ds = dataset_config(wildcards)
    files = {"balls": ds.get("balls", config["tables"]["balls"]), "bats": ds.get("bats", config["tables"]["bats"])}
    if "impacts" in ds:
        files["impacts"] = ds["impacts"]
    if "tracks" in ds:
        if "file" in ds["tracks"]:
            files["tracks"] = ds["tracks"]["file"]
        files["tracks_impacts"] = ds["tracks"]["impacts"]
    return files


def existing(path):
    """``path`` as an input when it is a file; none when it is missing or not a file, so that only
    this dataset's job fails, with a message that says what the path is (not the whole DAG)."""
    return path if Path(path).is_file() else []


def get_balls_table(wildcards):
    return existing(data_files(wildcards)["balls"])


def get_bats_table(wildcards):
    return existing(data_files(wildcards)["bats"])


def file_hashes(files):
    """Return the sha256 of each of ``files`` (name -> path): a param of the rules that read them, so that
    their jobs rerun when the content changes, even to a copy with an older timestamp (cp -p, tar, rsync -a)."""
    return {k: sha256_file(v) if Path(v).is_file() else "not a file" for k, v in files.items()}


def data_hashes(wildcards):
    """Return the sha256 of each data file of a dataset (:func:`file_hashes`)."""
    return file_hashes(data_files(wildcards))


def tables_hashes(wildcards):
    """Return the sha256 of the property tables of config `tables` (the implications' balls and bats)."""
    return file_hashes(config["tables"])


def is_measured(name):
    """A measured dataset names its impacts file; a synthetic one has `synthetic` settings."""
    return "impacts" in config["datasets"][name]


def get_measured_impacts(wildcards):
    return existing(dataset_config(wildcards)["impacts"])


def dataset_mem_mb(wildcards):
    """Return the memory a dataset's job may need, MB: over a 500 MB base, 4 kB per impact (measured ~1 kB),
    50 kB per impact rendered as camera tracks (measured 35 kB)."""
    d = dataset_config(wildcards)
    syn = d.get("synthetic")
    n = sum(sum(bats.values()) for bats in syn["impacts"].values()) if syn else 10_000
    return 500 + n * impact_bytes(d) // 1_000_000


def scenario_mem_mb(wildcards):
    """Return the memory a scenario's job may need, MB: 60 kB per case (measured 52-59 kB) over 500 MB."""
    sc = get_scenario(wildcards)
    if "sweep" in sc:
        n = int(sc["sweep"]["D_in"]["num"])
    else:
        sizes = [len(v) if isinstance(v, list) else 1 for k, v in sc["launch"].items() if k != "combine"]
        n = math.prod(sizes) if sc["launch"]["combine"] == "grid" else max(sizes)
    return 500 + n * BYTES_PER_CASE // 1_000_000


def uses_tracks(name):
    """Whether a dataset starts from raw camera tracks (reduce.nc is its source)."""
    d = config["datasets"][name]
    return "tracks" in d or renders(d)


TRACKED = [d for d in DATASETS if uses_tracks(d)]


def dataset_kind(name):
    """What a dataset is, in words (the report's front page)."""
    if uses_tracks(name):
        return "camera tracks" if "tracks" in config["datasets"][name] else "synthetic, rendered camera tracks"
    return "measured" if is_measured(name) else "synthetic"


def get_render_settings(wildcards):
    return dataset_config(wildcards)["render"]


def get_tracks_inputs(wildcards):
    """A lab's tracks and impacts files, its imported tool files (imported_tracks.nc and the camera
    settings found in them), or the rendered tracks.nc (both .nc hold their impact table)."""
    d = dataset_config(wildcards)
    if "tracks" in d and "dir" in d["tracks"]:
        out = f"results/{wildcards.dataset}/imported"
        return {"tracks": f"{out}_tracks.nc", "cameras": f"{out}_cameras.yaml"}
    if "tracks" in d:  # a missing file fails this dataset's reduce job only (existing), not the DAG
        return {"tracks": existing(d["tracks"]["file"]), "impacts": existing(d["tracks"]["impacts"])}
    return {"tracks": f"results/{wildcards.dataset}/tracks.nc"}


def get_tool_files(wildcards):
    """The tool files of a dataset whose tracks block names a folder (dir), and its impacts file."""
    t = dataset_config(wildcards)["tracks"]
    exts = tool_file_extensions(t.get("format"))
    found = sorted(str(p) for p in Path(t["dir"]).glob("*") if p.is_file() and p.suffix.lower() in exts)
    return {"files": found, "impacts": existing(t["impacts"])}


def tool_file_hashes(wildcards):
    """The sha256 of every tool file of a `tracks.dir` folder and of the dataset's tables (:func:`file_hashes`):
    a tool file replaced by other content reruns the import, whatever its timestamp."""
    files = {Path(f).name: f for f in get_tool_files(wildcards)["files"]}
    return {**data_hashes(wildcards), **file_hashes(files)}


def get_import_settings(wildcards):
    return dataset_config(wildcards)["tracks"]


def get_reduce_settings(wildcards):
    d = dataset_config(wildcards)
    return camera_block(d["tracks"] if "tracks" in d else d["render"])


def get_reduce_where(wildcards):
    key = "tracks" if "tracks" in dataset_config(wildcards) else "render"
    return f"config datasets.{wildcards.dataset}.{key}"


def get_source(wildcards):
    """The first stage of a dataset: its synthetic experiment or its measured impacts, checked."""
    if uses_tracks(wildcards.dataset):  # raw camera tracks: workflow/rules/tracks.smk
        return f"results/{wildcards.dataset}/reduce.nc"
    stage = "ingest" if is_measured(wildcards.dataset) else "simulate"
    return f"results/{wildcards.dataset}/{stage}.nc"


SCENARIOS = sorted(config.get("implications", {}).get("scenarios", {}))
# A scenario's ball and bat, and the dataset of its e_x, checked before the DAG is built (one line each).
_problems = scenario_problems(config)
if _problems:
    raise ConfigError("config is not valid:\n  " + "\n  ".join(_problems))


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
    targets += [f"results/{d}/figures/tracks_{fig}.png" for d in TRACKED for fig in ("impacts", "summary")]
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


# Replicate studies (studies.smk). STUDIES: those of `snakemake studies` (`make study`); the studies marked
# on_request are built by `snakemake studies_on_request` only.
ALL_STUDIES = sorted(config.get("studies") or {})
STUDIES = [s for s in ALL_STUDIES if not config["studies"][s]["on_request"]]


wildcard_constraints:
    study="|".join(ALL_STUDIES) or "^$",
    batch=r"\d+",
    point=r"\d+",


def study_settings(name):
    from ballbat.study_settings import StudySettings

    return StudySettings.from_config(config, name)


def get_study_config(wildcards):
    """Everything a study's results depend on: its settings, its dataset's and the chain's (StudySettings.from_block)."""
    from ballbat.study_settings import study_block

    return study_block(config, wildcards.study)


def _study_dataset(wildcards):
    return Namespace(dataset=config["studies"][wildcards.study]["dataset"])


def study_hashes(wildcards):
    """The sha256 of a study's property tables (:func:`file_hashes`: a changed table reruns the study)."""
    return data_hashes(_study_dataset(wildcards))


def get_study_balls(wildcards):
    return get_balls_table(_study_dataset(wildcards))


def get_study_bats(wildcards):
    return get_bats_table(_study_dataset(wildcards))


def get_study_batches(wildcards):
    n = study_settings(wildcards.study).n_batches
    return [f"results/studies/{wildcards.study}/batches/batch{b}.nc" for b in range(n)]


def _study_impacts(s):
    """Impacts of the largest replicate of a study, and of its noise-free design (per point)."""
    return study_impacts(s.dataset, s.parameter, s.values, s.truth_impacts)


def study_batch_mem_mb(wildcards):
    """A batch holds one replicate at a time (measured ~180 MB for the paper-sized experiment)."""
    s = study_settings(wildcards.study)
    return 500 + math.ceil(_study_impacts(s)[0] * impact_bytes(s.dataset) / 1e6)


def study_truth_mem_mb(wildcards):
    """The truth job of one sweep point holds the design's large noise-free experiment (StudySettings.truth_mem_mb)."""
    return study_settings(wildcards.study).truth_mem_mb(int(wildcards.point))


def study_aggregate_mem_mb(wildcards):
    """The aggregate holds every replicate's table (:data:`STUDY_BYTES_PER_REPLICATE`) over a 500 MB base."""
    s = study_settings(wildcards.study)
    return 500 + math.ceil(s.total * STUDY_BYTES_PER_REPLICATE / 1e6)


def study_batch_runtime(wildcards):
    """Minutes: about a second per replicate of the paper's size, with room."""
    s = study_settings(wildcards.study)
    return max(10, math.ceil(s.batch_size * 2 / 60) + 5)


def get_study_truth_points(wildcards):
    n = study_settings(wildcards.study).n_points
    return [f"results/studies/{wildcards.study}/truth/point{p}.nc" for p in range(n)]


def study_truth_runtime(wildcards):
    """Minutes (StudySettings.truth_runtime_min)."""
    return study_settings(wildcards.study).truth_runtime_min(int(wildcards.point))


def study_targets(on_request=False):
    """Every product of every study (of `studies`, or with on_request those of `studies_on_request`), its truth
    and batches included (so that one deleted by hand is rebuilt: Snakemake does not rebuild a missing
    intermediate whose consumers are up to date). A one-parameter sweep has a design, a grid its grid figure."""
    targets = []
    for name in STUDIES if not on_request else sorted(set(ALL_STUDIES) - set(STUDIES)):
        targets += [f"results/studies/{name}/coverage.{ext}" for ext in ("nc", "csv", "png")]
        sweep = config["studies"][name].get("sweep") or {}
        if "grid" in sweep:
            targets += [f"results/studies/{name}/grid.png"]
        elif sweep:
            targets += [f"results/studies/{name}/design.{ext}" for ext in ("nc", "csv", "png")]
        targets += [f"results/studies/{name}/truth.nc"] + get_study_truth_points(Namespace(study=name))
        targets += get_study_batches(Namespace(study=name))
    return targets


# A damaged product is named, with the command that rebuilds it (nothing is removed here).
report_damaged_products(final_targets() + study_targets() + study_targets(on_request=True))
