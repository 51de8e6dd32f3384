"""Provenance Run Crate of a workflow run: ``results/ro-crate-metadata.json``.

A successful ``snakemake`` run describes itself in the standard that WorkflowHub, Galaxy and
the CWL tools exchange: an RO-Crate (1.1) following the Workflow Run Crate and Provenance Run
Crate profiles (0.5, https://w3id.org/ro/wfrun/provenance/0.5). ``results/`` is the crate:

* the workflow's own files (Snakefile, rules, scripts, schemas), the package source and the
  config files of the run are copied into ``results/workflow.snapshot/`` (the main
  ``ComputationalWorkflow`` is its ``Snakefile``, with the git commit as its version), so the
  crate says what ran even where there is no git;
* one ``CreateAction`` for the run (instrument: the workflow; object: the config files and the
  merged config's values; result: every output) and one per job, i.e. per rule execution
  (instrument: the rule as a ``SoftwareApplication`` with its script and rule file; object: its
  input files and the config values it used, as ``PropertyValue``; result: its output files),
  each tied to its workflow step by a ``ControlAction`` and to Snakemake by an ``OrganizeAction``;
* every file with its sha256, size (bytes) and media type; the versions of ballbat (with the
  sha256 of its source and of the workflow's), Python, Snakemake and the scientific stack.

The job records come from Snakemake's DAG and its own metadata (start and end times, the rule,
the inputs), and the config values each job used from the ``provenance_config`` attribute the
job wrote into its NetCDF output (its params otherwise). Times are in the crate (it is the
record of one run); no data file gets one. The crate is written atomically: the old metadata
file goes first, so a run cut short leaves no crate rather than one that lies.
"""

from __future__ import annotations

import datetime as dt
import json
import os
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .. import __version__
from .atomic import atomic_target
from .cratefiles import EARLIER_NAME, METADATA_NAME, Staleness, folder_files
from .guards import RECORDED_SUFFIXES, written_by_workflow
from .provenance import (
    PACKAGE_DIR,
    git_state,
    package_source_hash,
    package_sources,
    sha256_file,
    software_versions,
    workflow_source_hash,
    workflow_sources,
)

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable, Mapping

#: Where, inside the crate, the workflow, the package source and the config files are copied.
SNAPSHOT = "workflow.snapshot"
#: The snapshot's copies of input data (config files, property tables, impacts, tracks, tool files):
#: each file up to SNAPSHOT_FILE_LIMIT bytes, all of them up to SNAPSHOT_DATA_LIMIT. A file above
#: either is not copied: the crate records it by path, size and sha256 (``#uncopied-...``).
SNAPSHOT_FILE_LIMIT = 20_000_000
SNAPSHOT_DATA_LIMIT = 100_000_000
#: The profiles the crate conforms to (the root dataset's conformsTo), with name and version.
PROFILES = {
    "https://w3id.org/ro/wfrun/process/0.5": ("Process Run Crate", "0.5"),
    "https://w3id.org/ro/wfrun/workflow/0.5": ("Workflow Run Crate", "0.5"),
    "https://w3id.org/ro/wfrun/provenance/0.5": ("Provenance Run Crate", "0.5"),
    "https://w3id.org/workflowhub/workflow-ro-crate/1.0": ("Workflow RO-Crate", "1.0"),
}
#: Terms of the Workflow Run Crate vocabulary used here (https://w3id.org/ro/terms/workflow-run/context),
#: given in the crate's own context so that a reader needs no second remote document.
WFRUN_TERMS = {"sha256": "https://w3id.org/ro/terms/workflow-run#sha256"}
#: Media types by file suffix (IANA where registered).
MEDIA_TYPES = {
    ".nc": "application/x-netcdf",
    ".png": "image/png",
    ".csv": "text/csv",
    ".md": "text/markdown",
    ".html": "text/html",
    ".xlsx": "application/vnd.openxmlformats-officedocument.spreadsheetml.sheet",
    ".log": "text/plain",
    ".txt": "text/plain",
    ".tsv": "text/tab-separated-values",
    ".rst": "text/x-rst",
    ".py": "text/x-python",
    ".smk": "text/x-snakemake",
    ".yaml": "application/yaml",
    ".yml": "application/yaml",
    ".json": "application/json",
    ".toml": "application/toml",
}
LICENSE = "https://spdx.org/licenses/MIT"
SNAKEMAKE_LANGUAGE = "https://w3id.org/workflowhub/workflow-ro-crate#snakemake"


@dataclass
class JobRecord:
    """One rule execution, as the crate needs it (paths relative to the working directory)."""

    rule: str
    wildcards: dict[str, str]
    inputs: list[str]
    outputs: list[str]
    logs: list[str] = field(default_factory=list)
    benchmarks: list[str] = field(default_factory=list)
    params: dict[str, Any] = field(default_factory=dict)
    script: str | None = None
    snakefile: str | None = None
    start: float | None = None
    end: float | None = None
    #: False for a job of a failed run that did not finish: its action is left out of the crate.
    completed: bool = True
    #: Why Snakemake had to run it (a job that did not finish: its old outputs are outdated).
    why: str = ""

    @property
    def name(self) -> str:
        """The job's readable name: rule and wildcards."""
        wc = ", ".join(f"{k}={v}" for k, v in sorted(self.wildcards.items()))
        return f"{self.rule} ({wc})" if wc else self.rule

    @property
    def key(self) -> str:
        """The job's identifier inside the crate."""
        wc = "-".join(f"{k}={v}" for k, v in sorted(self.wildcards.items()))
        return f"{self.rule}-{wc}" if wc else self.rule


def media_type(path: str | os.PathLike[str]) -> str:
    """Return the media type of a file by its name (``Snakefile`` is a rule file)."""
    p = Path(path)
    if p.name == "Snakefile":
        return MEDIA_TYPES[".smk"]
    return MEDIA_TYPES.get(p.suffix.lower(), "application/octet-stream")


def _iso(t: float | None) -> str | None:
    if t is None:
        return None
    return dt.datetime.fromtimestamp(t, tz=dt.UTC).isoformat(timespec="seconds")


def jobs_from_dag(dag: Any, persistence: Any, workdir: str | os.PathLike[str], failed: bool = False) -> list[JobRecord]:
    """Return a record of every job of Snakemake's DAG (run now or earlier), with times from Snakemake's metadata.

    After a ``failed`` run, a job that had to run and did not finish is marked not ``completed``.
    """
    here = Path(workdir).resolve()

    def rel(p: object) -> str:
        path = Path(str(p))
        if path.is_absolute() and path.is_relative_to(here):
            return path.relative_to(here).as_posix()
        return path.as_posix()

    records = []
    for job in sorted(dag.jobs, key=lambda j: (j.rule.name, sorted(j.wildcards_dict.items()))):
        if not job.output:  # a target rule (all): it runs nothing
            continue
        named = dict(job.input.items())
        code = {str(f) for f in named.get("code", [])} if "code" in named else set()
        inputs = [rel(f) for f in job.input if str(f) not in code]
        outputs = [rel(f) for f in job.output]
        starts, ends = [], []
        for f in job.output:
            meta = persistence.metadata(f) or {}
            if meta.get("starttime") is not None:
                starts.append(meta["starttime"])
            if meta.get("endtime") is not None:
                ends.append(meta["endtime"])
        params = {k: v for k, v in job.params.items()}
        snakefile = Path(str(job.rule.snakefile)) if job.rule.snakefile else None
        script = job.rule.script
        if script and not Path(script).is_absolute() and snakefile is not None:
            script = str(snakefile.parent / script)
        records.append(
            JobRecord(
                rule=job.rule.name,
                wildcards={k: str(v) for k, v in job.wildcards_dict.items()},
                inputs=inputs,
                outputs=outputs,
                logs=[rel(f) for f in job.log],
                benchmarks=[rel(job.benchmark)] if job.benchmark else [],
                params=params,
                script=rel(Path(script).resolve()) if script else None,
                snakefile=rel(snakefile.resolve()) if snakefile else None,
                start=min(starts) if starts else None,
                end=max(ends) if ends else None,
                completed=not failed or not dag.needrun(job) or dag.finished(job),
                why=_reason(dag, job) if failed and dag.needrun(job) else "",
            )
        )
    return records


def _reason(dag: Any, job: Any) -> str:
    """Return Snakemake's reason for running ``job``, in one line ("" when it gives none)."""
    try:
        return " ".join(str(dag.reason(job)).split())
    except Exception:  # the reason is a courtesy: never fail the crate for it
        return ""


def _config_used(job: JobRecord, workdir: Path) -> dict[str, Any]:
    """Return the config values a job used: its NetCDF output's provenance_config, else its params."""
    for out in job.outputs:
        path = workdir / out
        if path.suffix == ".nc" and path.is_file():
            import netCDF4

            with netCDF4.Dataset(path) as nc:
                if "provenance_config" in nc.ncattrs():
                    return json.loads(nc.getncattr("provenance_config"))
    return dict(job.params)


def _value(v: Any) -> Any:
    if isinstance(v, bool | int | float | str):
        return v
    return json.dumps(v, sort_keys=True, default=str)


class _Builder:
    """Collects the crate's entities (``rocrate`` does the JSON-LD and the root dataset)."""

    def __init__(self, results: Path, workdir: Path) -> None:
        from rocrate.rocrate import ROCrate

        self.results = results
        self.workdir = workdir
        self.crate = ROCrate(version="1.1")
        self.crate.metadata.extra_terms.update(WFRUN_TERMS)
        self.files: dict[str, Any] = {}
        self._digests: dict[Path, str] = {}
        #: Input data files not copied into the snapshot (above its limits): path -> why.
        self.uncopied: dict[str, str] = {}

    def context(self, ident: str, props: dict) -> Any:
        from rocrate.model.contextentity import ContextEntity

        return self.crate.add(ContextEntity(self.crate, ident, properties=props))

    def sha256(self, path: Path) -> str:
        """Return a file's sha256, read once per crate (a carried-over result is compared, then listed)."""
        if path not in self._digests:
            self._digests[path] = sha256_file(path)
        return self._digests[path]

    def file(self, crate_path: str, types: list[str] | None = None, **props: Any) -> Any:
        """Return the File entity of ``results/crate_path`` with sha256, size and media type (added once)."""
        if crate_path in self.files:
            return self.files[crate_path]
        path = self.results / crate_path
        base = {
            "@type": ["File", *(types or [])],
            "name": Path(crate_path).name,
            "sha256": self.sha256(path),
            "contentSize": str(path.stat().st_size),
            "encodingFormat": media_type(path),
        }
        entity = self.crate.add_file(dest_path=crate_path, properties={**base, **props})
        self.files[crate_path] = entity
        return entity

    def input_ref(self, path: str) -> dict | None:
        """Return a reference to an input file (added to the crate), or None.

        None when the file is neither in the crate nor an input data file left out of the snapshot
        (:data:`SNAPSHOT_FILE_LIMIT`).
        """
        cp = self.crate_path(path)
        if cp:
            self.file(cp)
            return {"@id": cp}
        if path not in self.uncopied:
            return None
        full = Path(path) if Path(path).is_absolute() else self.workdir / path
        digest = sha256_file(full)
        entity = self.context(
            f"#uncopied-{digest[:16]}",
            {
                "@type": "CreativeWork",
                "name": path,
                "sha256": digest,
                "contentSize": str(full.stat().st_size),
                "encodingFormat": media_type(full),
                "description": f"an input data file not copied into {SNAPSHOT}/: {self.uncopied[path]}",
            },
        )
        return {"@id": entity.id}

    def crate_path(self, path: str) -> str | None:
        """Where a workdir-relative path is inside the crate (``None`` if not there)."""
        p = Path(path)
        full = p if p.is_absolute() else self.workdir / p
        try:
            rel = full.resolve().relative_to(self.results.resolve())
            return rel.as_posix() if full.is_file() else None
        except ValueError:
            pass
        snap = self.snapshot_path(path)
        return snap if (self.results / snap).is_file() else None

    def snapshot_path(self, path: str) -> str:
        """Where a file from outside ``results/`` is copied in the snapshot."""
        p = Path(path)
        if not p.is_absolute():
            return f"{SNAPSHOT}/{p.as_posix()}"
        try:
            return f"{SNAPSHOT}/{p.resolve().relative_to(self.workdir.resolve()).as_posix()}"
        except ValueError:
            return f"{SNAPSHOT}/external/{sha256_file(p)[:16]}/{p.name}"


def _copy_snapshot(results: Path, workdir: Path, extra: Iterable[str], builder: _Builder) -> Path:
    """Copy workflow, package source and ``extra`` files (config, data tables) to a new temporary folder."""
    tmp = Path(tempfile.mkdtemp(prefix=f".{SNAPSHOT}.", dir=results))
    wanted: dict[str, Path] = {}
    root = workdir if (workdir / "Snakefile").is_file() else None
    if root is not None:
        for f in workflow_sources(root):
            wanted[f.relative_to(root).as_posix()] = f
    for f in package_sources():
        wanted[f"src/ballbat/{f.relative_to(PACKAGE_DIR).as_posix()}"] = f
    wanted.update(_data_copies(results, workdir, extra, builder))
    try:
        for rel, src in sorted(wanted.items()):
            dest = tmp / rel
            dest.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(src, dest)
        tmp.chmod(0o777 & ~_umask())
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return tmp


def _data_copies(results: Path, workdir: Path, extra: Iterable[str], builder: _Builder) -> dict[str, Path]:
    """Return the input data files to copy into the snapshot (snapshot path -> file), within its limits.

    Each file up to :data:`SNAPSHOT_FILE_LIMIT` bytes, all up to :data:`SNAPSHOT_DATA_LIMIT` (smallest
    first); the others are recorded in ``builder.uncopied`` with the reason.
    """
    found = {}
    for path in dict.fromkeys(extra):
        p = Path(path) if Path(path).is_absolute() else workdir / path
        if p.is_file() and not p.resolve().is_relative_to(results.resolve()):
            found[path] = (p, p.stat().st_size)
    wanted, total = {}, 0
    for path, (p, size) in sorted(found.items(), key=lambda item: (item[1][1], item[0])):
        if size > SNAPSHOT_FILE_LIMIT:
            builder.uncopied[path] = f"{size:,} bytes, above the limit of {SNAPSHOT_FILE_LIMIT:,} per file"
        elif total + size > SNAPSHOT_DATA_LIMIT:
            builder.uncopied[path] = f"{size:,} bytes, past the limit of {SNAPSHOT_DATA_LIMIT:,} for all data copies"
        else:
            total += size
            wanted[builder.snapshot_path(path).removeprefix(f"{SNAPSHOT}/")] = p
    return wanted


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _install_snapshot(results: Path, tmp: Path) -> None:
    """Put the new snapshot in place of the old (renames; the old one is removed after)."""
    target = results / SNAPSHOT
    old = None
    if target.exists():
        old = Path(tempfile.mkdtemp(prefix=f".{SNAPSHOT}.old.", dir=results))
        os.replace(target, old / "x")
    os.replace(tmp, target)
    if old is not None:
        shutil.rmtree(old)


def build_crate(
    results: Path,
    workdir: Path,
    jobs: list[JobRecord],
    *,
    config: Mapping[str, Any],
    configfiles: list[str],
    started: float | None,
    ended: float,
    record: Callable[[str], Any] | None = None,
    uncopied: Mapping[str, str] | None = None,
    earlier: list[dict] | None = None,
) -> dict:
    """Return the crate's JSON-LD (a dict), the snapshot already in ``results/workflow.snapshot``.

    ``record`` returns Snakemake's metadata of an output (None: none): the staleness of the files of
    the folder that are not results of this run. ``uncopied``: input data left out of the snapshot.
    ``earlier``: the graph of the folder's earlier crate, whose job actions this run did not redo are
    carried over (:func:`_carry_earlier`).
    """
    b = _Builder(results, workdir)
    b.uncopied.update(uncopied or {})
    git = git_state(str(workdir))
    versions = software_versions()
    smk_version = versions.get("snakemake", "unknown")
    soft_ids, engine = _software(b, versions, smk_version)
    _profiles(b)
    main = _workflow_files(b, results, git, soft_ids, smk_version)
    done = [j for j in jobs if j.completed]
    tools, steps = _rules(b, done, soft_ids, main)
    job_actions, controls, all_results = _job_actions(b, done, workdir, tools, steps)
    state = Staleness(workdir, record or (lambda path: None))
    made = {r for action in job_actions for r in _ids(action["result"])}
    parts = (tools, steps, main, soft_ids)
    carried = _carry_earlier(b, earlier or [], ({f"#job-{j.key}" for j in jobs}, made), parts, state)
    run = _run(b, config, configfiles, main, all_results, engine, controls, started, ended)
    if len(done) < len(jobs):
        _failed(run, [j for j in jobs if not j.completed])
    pending = {out: j.why for j in jobs if not j.completed for out in j.outputs}
    others = _other_files(b, results, workdir, state, pending)
    _root(b, main, run, [*job_actions, *carried], ended, others)
    _ = package_source_hash, workflow_source_hash  # recorded through software_versions()
    return _single_values(b.crate.metadata.generate())


def _software(b: _Builder, versions: dict, smk_version: str) -> tuple[list[dict], dict]:
    """Add ballbat (with its source hashes), Python and the stack, and Snakemake (the engine).

    Returns the references to the software (without Snakemake) and the engine's entity.
    """
    soft_ids = []
    for name, version in versions.items():
        if name.endswith("_sha256"):
            continue
        ident = f"#software-{name}"
        props = {"@type": "SoftwareApplication", "name": name, "softwareVersion": str(version)}
        if name == "ballbat":
            props["description"] = (
                f"sha256 of the package source: {versions['ballbat_source_sha256']}; "
                f"of the workflow's own files: {versions['workflow_source_sha256']}"
            )
            props["url"] = "https://pypi.org/project/ballbat/"
        if name == "snakemake":
            continue
        b.context(ident, props)
        soft_ids.append({"@id": ident})
    engine = b.context(
        "#snakemake",
        {
            "@type": "SoftwareApplication",
            "name": "Snakemake",
            "softwareVersion": smk_version,
            "url": "https://snakemake.readthedocs.io",
        },
    )
    return soft_ids, engine


def _profiles(b: _Builder) -> None:
    """Add the profiles the crate conforms to."""
    for ident, (name, version) in PROFILES.items():
        b.context(ident, {"@type": "CreativeWork", "name": name, "version": version})
    b.crate.metadata["conformsTo"] = [
        {"@id": "https://w3id.org/ro/crate/1.1"},
        {"@id": "https://w3id.org/workflowhub/workflow-ro-crate/1.0"},
    ]


def _workflow_files(b: _Builder, results: Path, git: dict, soft_ids: list[dict], smk_version: str):
    """Add the snapshot's files: the main workflow (returned) first, then every other copied file."""
    snap = results / SNAPSHOT
    language = b.context(
        SNAKEMAKE_LANGUAGE,
        {
            "@type": "ComputerLanguage",
            "name": "Snakemake",
            "identifier": {"@id": "https://doi.org/10.1093/bioinformatics/bts480"},
            "url": {"@id": "https://snakemake.readthedocs.io"},
            "version": smk_version,
        },
    )
    main_id = f"{SNAPSHOT}/Snakefile"
    main = b.file(
        main_id,
        ["SoftwareSourceCode", "ComputationalWorkflow", "HowTo"],
        name="ballbat workflow",
        description=(
            "Oblique ball-bat collisions, end to end (Kensrud, Nathan & Smith, Am. J. Phys. 85, 503 (2017)): "
            "the Snakefile with its rules, scripts and config schema (workflow.snapshot/workflow/)"
        ),
        programmingLanguage=language,
        version=str(git["commit"]),
        softwareVersion=__version__,
        softwareRequirements=soft_ids,
        license={"@id": LICENSE},
    )
    if git["dirty"] is True:
        main["description"] += "; the git tree had uncommitted changes at the run"
    for f in sorted(p for p in snap.rglob("*") if p.is_file()):
        rel = f.relative_to(results).as_posix()
        b.file(rel, ["SoftwareSourceCode"] if f.suffix in (".py", ".smk") or f.name == "Snakefile" else None)
    return main


def _rules(b: _Builder, jobs: list[JobRecord], soft_ids: list[dict], main) -> tuple[dict, dict]:
    """Add one tool and one step per rule (parts and steps of ``main``); return both by rule."""
    rule_ids = sorted({j.rule for j in jobs})
    tools, steps = {}, {}
    for pos, rule in enumerate(rule_ids):
        some = next(j for j in jobs if j.rule == rule)
        parts = [p for p in (some.script, some.snakefile) if p]
        has_part = [{"@id": cp} for p in parts if (cp := b.crate_path(p))]
        tools[rule] = b.context(
            f"#rule-{rule}",
            {
                "@type": "SoftwareApplication",
                "name": f"rule {rule}",
                "description": f"the workflow's rule {rule} (its script and rule file), ballbat {__version__}",
                "softwareVersion": __version__,
                "hasPart": has_part,
                "softwareRequirements": soft_ids,
            },
        )
        steps[rule] = b.context(
            f"#step-{rule}",
            {"@type": "HowToStep", "name": f"rule {rule}", "position": str(pos), "workExample": tools[rule]},
        )
    main["hasPart"] = list(tools.values())
    main["step"] = list(steps.values())
    return tools, steps


def _job_actions(b: _Builder, jobs: list[JobRecord], workdir: Path, tools: dict, steps: dict):
    """Add one CreateAction (and ControlAction) per job; return them and every job's outputs."""
    job_actions, controls, all_results = [], [], []
    for job in jobs:
        ident = f"#job-{job.key}"
        objects = [ref for p in job.inputs if (ref := b.input_ref(p))]
        for key, value in sorted(_config_used(job, workdir).items()):
            pv = b.context(
                f"#job-{job.key}-config-{key}",
                {"@type": "PropertyValue", "name": key, "value": _value(value)},
            )
            objects.append(pv)
        result = []
        for p in [*job.outputs, *job.logs, *job.benchmarks]:
            cp = b.crate_path(p)
            if cp and _made_by_workflow(b.results / cp):
                b.file(cp)
                result.append({"@id": cp})
        all_results += [r for r in result if r["@id"] in {b.crate_path(p) for p in job.outputs}]
        props = {
            "@type": "CreateAction",
            "name": f"job {job.name}",
            "description": f"one execution of rule {job.rule}: its inputs and config values in, its outputs out",
            "instrument": tools[job.rule],
            "object": objects,
            "result": result,
            "actionStatus": {"@id": "http://schema.org/CompletedActionStatus"},
        }
        if job.start is not None:
            props["startTime"] = _iso(job.start)
        if job.end is not None:
            props["endTime"] = _iso(job.end)
        job_actions.append(b.context(ident, props))
        controls.append(
            b.context(
                f"#control-{job.key}",
                {
                    "@type": "ControlAction",
                    "name": f"orchestrate {job.name}",
                    "instrument": steps[job.rule],
                    "object": {"@id": ident},
                },
            )
        )
    return job_actions, controls, all_results


def _run(b: _Builder, config, configfiles, main, all_results, engine, controls, started, ended):
    """Add the run (config files and the merged config in, every output out) and its orchestration."""
    run_objects = []
    for cf in configfiles:
        cp = b.crate_path(cf)
        if cp:
            b.file(cp, description=f"config file of the run ({cf}), merged in this order")
        if ref := b.input_ref(cf):
            run_objects.append(ref)
    for key, value in sorted(config.items()):
        run_objects.append(
            b.context(f"#run-config-{key}", {"@type": "PropertyValue", "name": key, "value": _value(value)})
        )
    run = b.context(
        "#run",
        {
            "@type": "CreateAction",
            "name": f"snakemake run of the ballbat workflow {__version__}",
            "description": "the run: the config files and the merged config in, every job's outputs out",
            "instrument": main,
            "object": run_objects,
            "result": all_results,
            "endTime": _iso(ended),
            "actionStatus": {"@id": "http://schema.org/CompletedActionStatus"},
            **({"startTime": _iso(started)} if started is not None else {}),
        },
    )
    b.context(
        "#orchestration",
        {
            "@type": "OrganizeAction",
            "name": "Snakemake orchestrating the run",
            "instrument": engine,
            "object": controls,
            "result": run,
            "endTime": _iso(ended),
            **({"startTime": _iso(started)} if started is not None else {}),
        },
    )
    return run


def _made_by_workflow(path: Path) -> bool:
    """Whether a job's output is the workflow's (a kind with a record: :func:`.guards.written_by_workflow`)."""
    return path.suffix not in RECORDED_SUFFIXES or written_by_workflow(path)


def _failed(run: Any, unfinished: list[JobRecord]) -> None:
    """Mark the run's action failed, naming the jobs that did not finish (their actions are not in the crate)."""
    names = ", ".join(j.name for j in unfinished[:10]) + (", ..." if len(unfinished) > 10 else "")
    run["actionStatus"] = {"@id": "http://schema.org/FailedActionStatus"}
    run["error"] = (
        f"the run failed: {len(unfinished)} job(s) did not finish ({names}); their old outputs, if any, "
        "are listed as files not made by this run"
    )


def _other_files(b: _Builder, results: Path, workdir: Path, state: Staleness, pending: Mapping[str, str]) -> list:
    """Add every file of the folder that is not yet in the crate, each saying why and whether it is stale.

    ``pending``: the outputs of the jobs a failed run had to run and did not finish, with Snakemake's
    reason; such a file is outdated whatever its inputs say (its config values may have changed).
    """
    top = results.resolve()
    prefix = top.relative_to(workdir.resolve()).as_posix() if top.is_relative_to(workdir.resolve()) else str(results)
    paths = [f"{prefix}/{rel}" for rel in folder_files(results)]
    others = []
    for path in paths:
        rel = path.removeprefix(f"{prefix}/")
        if rel in b.files:
            continue
        if not _made_by_workflow(results / rel):
            why = "not written by this workflow (no provenance record, or changed since): a file put here by hand"
        elif path in pending:
            reason = pending[path] or "no reason given"
            why = f"not made by this run: outdated, its job had to run and did not finish ({reason}); an earlier run's"
        else:
            why = f"not made by this run; {state.describe(path, paths)}"
        others.append(b.file(rel, description=why))
    return others


def _root(b: _Builder, main, run, job_actions: list, ended: float, others: list) -> None:
    """Describe the crate's root dataset: the results of one run, its workflow and actions."""
    root = b.crate.root_dataset
    root["name"] = "ballbat results"
    root["description"] = (
        "The products of the runs of the ballbat workflow in this results folder, described as a Provenance "
        "Run Crate: the workflow, every job with its inputs, config values and outputs (the last run's, and "
        "an earlier run's whose outputs are still here unchanged), every file's sha256."
    )
    if others:
        root["description"] += (
            f" {len(others)} file(s) of the folder are not results of this run; each File says why, and "
            "whether it is stale against the inputs recorded for it."
        )
    b.context(LICENSE, {"@type": "CreativeWork", "name": "MIT License", "identifier": "MIT"})
    root["license"] = {"@id": LICENSE}
    root["datePublished"] = _iso(ended)
    root["conformsTo"] = [{"@id": ident} for ident in PROFILES]
    root["mainEntity"] = main
    root["mentions"] = [run, *job_actions]


def _single_values(doc: dict) -> dict:
    """Return the JSON-LD with one-element lists as single values (RO-Crate 1.1's recommendation)."""
    for entity in doc["@graph"]:
        for key, value in list(entity.items()):
            if key != "@type" and isinstance(value, list) and len(value) == 1:
                entity[key] = value[0]
    return doc


def write_run_crate(
    results: str | os.PathLike[str],
    jobs: list[JobRecord],
    *,
    config: Mapping[str, Any],
    configfiles: list[str],
    started: float | None = None,
    workdir: str | os.PathLike[str] | None = None,
    record: Callable[[str], Any] | None = None,
) -> Path:
    """Copy the snapshot and write ``results/ro-crate-metadata.json`` (atomically); return its path.

    The old metadata file is removed first, so if anything fails the folder holds no crate rather
    than a crate describing files that have changed. ``record``: Snakemake's metadata of an output
    (:func:`build_crate`).
    """
    import time

    results = Path(results)
    work = Path(workdir or Path.cwd()).resolve()
    earlier = earlier_graph(results)
    target = remove_crate(results)
    for stale in results.glob(f".{SNAPSHOT}.*"):  # left by a crate cut short (we hold Snakemake's lock)
        if stale.is_dir():
            shutil.rmtree(stale, ignore_errors=True)
    builder = _Builder(results, work)
    extra = [*configfiles, *(p for j in jobs for p in j.inputs), *_earlier_inputs(earlier)]
    tmp = _copy_snapshot(results, work, extra, builder)
    try:
        _install_snapshot(results, tmp)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    doc = build_crate(
        results,
        work,
        jobs,
        config=config,
        configfiles=configfiles,
        started=started,
        ended=time.time(),
        record=record,
        uncopied=builder.uncopied,
        earlier=earlier,
    )
    with atomic_target(target) as out:
        out.write_text(json.dumps(doc, indent=1, sort_keys=True, ensure_ascii=False) + "\n", encoding="utf-8")
    (results / EARLIER_NAME).unlink(missing_ok=True)  # its actions are in the new crate
    return target


def set_aside_crate(results: str | os.PathLike[str]) -> Path:
    """When a real run starts: move the folder's crate aside (``.ro-crate-metadata.earlier.json``); return its path.

    The folder then holds no crate until the run ends (a run cut short leaves none rather than one that
    lies), and the crate written then carries over the job actions of the earlier runs that this run did
    not redo (:func:`_carry_earlier`). An earlier crate already set aside (a run cut short) is kept.
    """
    results = Path(results)
    target = results / METADATA_NAME
    if target.is_file():
        os.replace(target, results / EARLIER_NAME)
    return target


def earlier_graph(results: str | os.PathLike[str]) -> list[dict]:
    """Return the entities of the folder's earlier crate (set aside, else still in place); none if unreadable."""
    for name in (EARLIER_NAME, METADATA_NAME):
        path = Path(results) / name
        if path.is_file():
            try:
                graph = json.loads(path.read_text(encoding="utf-8"))["@graph"]
            except (ValueError, KeyError, TypeError):
                return []
            return [e for e in graph if isinstance(e, dict) and "@id" in e]
    return []


def _earlier_inputs(earlier: list[dict]) -> list[str]:
    """Return the workdir paths of the snapshot copies the earlier crate's jobs read (copied again if still there)."""
    prefix = f"{SNAPSHOT}/"
    return [
        e["@id"].removeprefix(prefix)
        for e in earlier
        if e["@id"].startswith(prefix) and not e["@id"].startswith(f"{prefix}external/") and "File" in _types(e)
    ]


def _types(entity: dict) -> list[str]:
    t = entity.get("@type", [])
    return t if isinstance(t, list) else [t]


def _ids(value: Any) -> list[str]:
    """Return the ``@id`` of each reference of a property (one reference or a list)."""
    refs = value if isinstance(value, list) else [value] if value else []
    return [r["@id"] for r in refs if isinstance(r, dict) and "@id" in r]


def _carry_earlier(b: _Builder, earlier: list[dict], this_run: tuple, run_parts: tuple, state: Staleness) -> list:
    """Add the earlier crate's job actions that this run did not redo; return them.

    ``this_run``: the ids of this run's jobs (finished or not) and the crate paths of their results.

    A carried action keeps its times, config values and rule; its results are those of its outputs still
    in the folder with the sha256 listed then (a file gone or changed since is not its result; a changed
    one is listed among the files not made by this run). Each carried result says it was made by an
    earlier run, with its staleness now. An action with no result left is dropped. An input file changed
    or gone since is named with the sha256 it had (``#earlier-input-...``).
    """
    graph = {e["@id"]: e for e in earlier}
    redone, made = this_run
    carried = []
    for action in earlier:
        ident = action["@id"]
        if not ident.startswith("#job-") or "CreateAction" not in _types(action) or ident in redone:
            continue
        results = [cp for cp in _ids(action.get("result")) if cp not in made and _unchanged(b, graph.get(cp, {}), cp)]
        if not results:
            continue
        tool, step = _earlier_rule(b, graph, action, run_parts)
        for cp in results:
            what = f"not made by this run: made by an earlier run's job ({action.get('name', ident)})"
            b.file(cp)["description"] = f"{what}; {state.describe(_workdir_path(b, cp), ())}"
        props = {k: v for k, v in action.items() if k not in ("@id", "@type", "instrument", "object", "result")}
        props["description"] = f"{action.get('description', '')} (an earlier run of this folder; not redone since)"
        objects = [_earlier_object(b, graph, ref) for ref in _ids(action.get("object"))]
        carried.append(
            b.context(
                ident,
                {
                    "@type": "CreateAction",
                    **props,
                    "instrument": tool,
                    "object": [o for o in objects if o is not None],
                    "result": [{"@id": cp} for cp in results],
                },
            )
        )
        key = ident.removeprefix("#job-")
        b.context(
            f"#control-{key}",
            {"@type": "ControlAction", "name": f"orchestrate {key}", "instrument": step, "object": {"@id": ident}},
        )
    return carried


def _workdir_path(b: _Builder, crate_path: str) -> str:
    """Return a crate path of the results folder as a path from the working directory (Snakemake's records)."""
    full = (b.results / crate_path).resolve()
    work = b.workdir.resolve()
    return full.relative_to(work).as_posix() if full.is_relative_to(work) else str(full)


def _unchanged(b: _Builder, entity: dict, crate_path: str) -> bool:
    """Whether an earlier result is still in the folder, unchanged (its sha256 then) and the workflow's."""
    path = b.results / crate_path
    if not path.is_file() or "sha256" not in entity:
        return False
    return entity["sha256"] == b.sha256(path) and _made_by_workflow(path)


def _earlier_object(b: _Builder, graph: dict, ident: str) -> Any:
    """Return an earlier action's object in the new crate: a file as it is now, else as it was, or a value."""
    entity = graph.get(ident)
    if entity is None:
        return None
    if "File" not in _types(entity):
        props = {k: v for k, v in entity.items() if k != "@id"}
        return b.context(ident, props) if b.crate.dereference(ident) is None else {"@id": ident}
    path = b.results / ident
    if path.is_file() and entity.get("sha256") == b.sha256(path):
        b.file(ident)
        return {"@id": ident}
    digest = str(entity.get("sha256", ""))
    return b.context(
        f"#earlier-input-{digest[:16]}",
        {
            "@type": "CreativeWork",
            "name": ident,
            "sha256": digest,
            "description": "an input of an earlier run's job, with the sha256 it had then; changed or gone since",
        },
    )


def _earlier_rule(b: _Builder, graph: dict, action: dict, run_parts: tuple) -> tuple[Any, Any]:
    """Return the tool and step of an earlier action's rule: this run's, else copied from the earlier crate."""
    tools, steps, main, soft_ids = run_parts
    tool_id = (_ids(action.get("instrument")) or ["#rule-unknown"])[0]
    rule = tool_id.removeprefix("#rule-")
    if rule not in tools:
        old = graph.get(tool_id, {})
        parts = [{"@id": cp} for cp in _ids(old.get("hasPart")) if cp in b.files]
        tools[rule] = b.context(
            tool_id,
            {
                "@type": "SoftwareApplication",
                "name": old.get("name", f"rule {rule}"),
                "description": f"{old.get('description', f'rule {rule}')} (as an earlier run of this folder ran it)",
                "softwareVersion": old.get("softwareVersion", "unknown"),
                "hasPart": parts,
                "softwareRequirements": soft_ids,
            },
        )
        steps[rule] = b.context(
            f"#step-{rule}",
            {"@type": "HowToStep", "name": f"rule {rule}", "position": str(len(steps)), "workExample": tools[rule]},
        )
        main["hasPart"] = [*_as_list(main.get("hasPart")), tools[rule]]
        main["step"] = [*_as_list(main.get("step")), steps[rule]]
    return tools[rule], steps[rule]


def _as_list(value: Any) -> list:
    return value if isinstance(value, list) else [value] if value else []


def remove_crate(results: str | os.PathLike[str]) -> Path:
    """Remove the crate's metadata file (a run about to change the folder); return its path.

    Called when a real run starts and before a crate is written: a run cut short (killed, a full
    disk) then leaves no crate rather than one listing files that have changed or gone.
    """
    target = Path(results) / METADATA_NAME
    target.unlink(missing_ok=True)
    return target


def write_crate_of_run(
    workflow: Any, config: Mapping[str, Any], started: float | None = None, failed: bool = False
) -> Path:
    """Write the crate of the Snakemake run ``workflow`` (``onsuccess``; ``onerror`` with ``failed``).

    Every file of ``results/`` is in it: the results of this run's jobs, and the others with their
    staleness from Snakemake's records (:mod:`.cratefiles`).
    """
    from snakemake.io import IOFile

    from .guards import results_root

    workdir = Path.cwd()
    jobs = jobs_from_dag(workflow.dag, workflow.persistence, workdir, failed=failed)
    configfiles = [str(f) for f in workflow.configfiles]
    return write_run_crate(
        workdir / results_root(config),
        jobs,
        config=config,
        configfiles=configfiles,
        started=started,
        workdir=workdir,
        record=lambda path: workflow.persistence.metadata(IOFile(path)),
    )
