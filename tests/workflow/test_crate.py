"""The run's Provenance Run Crate (results/ro-crate-metadata.json; ballbat.pipeline.crate)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from validate_crate import seed_cache, validate

from ballbat.pipeline import crate as crate_mod
from ballbat.pipeline.provenance import sha256_file, workflow_source_hash


@pytest.fixture(scope="module")
def run_dir(default_run):
    return default_run


@pytest.fixture(scope="module")
def graph(run_dir):
    doc = json.loads((run_dir / "results" / "ro-crate-metadata.json").read_text())
    return {e["@id"]: e for e in doc["@graph"]}


def ids(value) -> list[str]:
    value = value if isinstance(value, list) else [value]
    return [v["@id"] for v in value]


@pytest.mark.slow
def test_crate_validates_offline(run_dir, capsys):
    """tests/validate_crate.py: the folder's files and roc-validator (offline, its cache seeded from the shipped
    context) pass every required check; a check skipped for an offline cache miss would fail it.
    """
    from validate_crate import PROFILE, main

    assert main([str(run_dir / "results")]) == 0, capsys.readouterr().err
    assert f"the crate passes every check ({PROFILE}, required level" in capsys.readouterr().out


@pytest.mark.slow
def test_validation_needs_the_context(run_dir, tmp_path):
    """Without the shipped context in its cache the offline validator does not pass the crate."""
    result = validate(run_dir / "results", tmp_path / "empty_cache")
    assert not result.passed()


@pytest.mark.slow
def test_validation_fails_a_broken_crate(run_dir, tmp_path):
    """The same validation fails a crate whose run action has lost its workflow (so the pass above means something)."""
    import shutil

    broken = tmp_path / "broken"
    shutil.copytree(run_dir / "results", broken)
    doc = json.loads((broken / "ro-crate-metadata.json").read_text())
    for e in doc["@graph"]:
        if e["@id"] == "#orchestration":
            del e["result"]
    (broken / "ro-crate-metadata.json").write_text(json.dumps(doc))
    result = validate(broken, seed_cache(tmp_path / "http_cache"))
    assert not result.passed()


@pytest.mark.slow
def test_every_result_listed_with_its_hash(run_dir, graph):
    """Every product of the run is a File of the crate whose sha256, size and media type match the file."""
    results = run_dir / "results"
    products = [p for p in results.rglob("*") if p.is_file() and p.name != "ro-crate-metadata.json"]
    assert len(products) > 80
    for p in products:
        rel = p.relative_to(results).as_posix()
        assert rel in graph, f"{rel} not in the crate"
        entity = graph[rel]
        assert entity["sha256"] == sha256_file(p), rel
        assert entity["contentSize"] == str(p.stat().st_size), rel
        assert entity["encodingFormat"] == crate_mod.media_type(p), rel
    assert graph["synthetic/fit_ex.nc"]["encodingFormat"] == "application/x-netcdf"
    assert graph["synthetic/results.xlsx"]["encodingFormat"].endswith("spreadsheetml.sheet")


@pytest.mark.slow
def test_each_netcdf_is_the_result_of_a_job_with_its_inputs(run_dir, graph):
    """Each NetCDF file is the result of one job action whose object lists the inputs the file records,
    and the config values the job used as PropertyValue; the action's instrument is its rule.
    """
    import netCDF4

    results = run_dir / "results"
    actions = [e for e in graph.values() if e.get("@type") == "CreateAction" and e["@id"].startswith("#job-")]
    for nc in sorted(results.rglob("*.nc")):
        rel = nc.relative_to(results).as_posix()
        makers = [a for a in actions if rel in ids(a["result"])]
        assert len(makers) == 1, rel
        action = makers[0]
        with netCDF4.Dataset(nc) as ds:
            recorded = json.loads(ds.getncattr("provenance_inputs"))
            config = json.loads(ds.getncattr("provenance_config"))
            rule = ds.getncattr("provenance_rule")
        objects = ids(action["object"])
        for item in recorded:
            path = Path(item["path"])
            where = (
                path.relative_to("results").as_posix() if path.parts[0] == "results" else f"workflow.snapshot/{path}"
            )
            assert where in objects, (rel, where)
            assert graph[where]["sha256"] == item["sha256"], (rel, where)
        values = {graph[o]["name"] for o in objects if graph[o]["@type"] == "PropertyValue"}
        assert values == set(config), rel
        assert ids(action["instrument"]) == [f"#rule-{rule}"], rel


@pytest.mark.slow
def test_run_action_and_workflow(run_dir, graph):
    """The run's action uses the Snakefile (with its commit), names the config file with its sha256,
    and lists every job output; the snapshot holds the workflow's files and the package source.
    """
    root = graph["./"]
    main = ids(root["mainEntity"])[0]
    assert main == "workflow.snapshot/Snakefile"
    assert "ComputationalWorkflow" in graph[main]["@type"]
    assert graph[main]["sha256"] == sha256_file(run_dir / "Snakefile")
    run = graph["#run"]
    assert ids(run["instrument"]) == [main]
    cfg = "workflow.snapshot/config/config.yaml"
    assert cfg in ids(run["object"])
    assert graph[cfg]["sha256"] == sha256_file(run_dir / "config" / "config.yaml")
    assert "synthetic/fit_ex.nc" in ids(run["result"])
    snap = run_dir / "results" / "workflow.snapshot"
    assert (snap / "workflow" / "rules" / "fit_ex.smk").read_bytes() == (
        run_dir / "workflow/rules/fit_ex.smk"
    ).read_bytes()
    assert (snap / "src" / "ballbat" / "fitting.py").is_file()
    versions = {e["name"]: e.get("softwareVersion") for e in graph.values() if e.get("@type") == "SoftwareApplication"}
    assert versions["Snakemake"] and versions["numpy"] and versions["ballbat"]


@pytest.mark.slow
def test_workflow_hash_recorded(run_dir):
    """The NetCDF provenance records a hash of the workflow's own files (rules, scripts, Snakefile, schema)."""
    import netCDF4

    with netCDF4.Dataset(run_dir / "results" / "synthetic" / "fit_ex.nc") as ds:
        software = json.loads(ds.getncattr("provenance_software"))
    assert software["workflow_source_sha256"] == workflow_source_hash(str(run_dir))
    assert len(software["workflow_source_sha256"]) == 64


# ---------------------------------------------------------------------------------------
# Issue 34: the crate is the folder's truth (target-only and failed runs)


@pytest.mark.slow
def test_target_only_and_failed_runs_tell_the_folders_truth(default_run, tmp_path):
    """Issue 34: a target-only run that changes fit_ex.nc used to rewrite the crate with its own files only
    (31 products unlisted and stale); a failed run left the old crate listing changed files. Now each crate
    lists every file of the folder, the stale ones say so, and a failed run's crate is marked failed.
    """
    from validate_crate import main

    from ballbat.pipeline.cratefiles import crate_file_problems
    from workflow_helpers import copy_run, snakemake

    work = copy_run(default_run, tmp_path / "run")
    (work / "mu.yaml").write_text("analysis:\n  mu_k_example: 0.4\n")
    snakemake(work, "-c1", "results/synthetic/fit_ex.nc", "--configfile", "mu.yaml")
    results = work / "results"
    assert crate_file_problems(results) == []
    graph = {e["@id"]: e for e in json.loads((results / "ro-crate-metadata.json").read_text())["@graph"]}
    assert "synthetic/fit_ex.nc" in ids(graph["#run"]["result"])
    for name in ("synthetic/results.xlsx", "synthetic/figures/fig3.png", "synthetic/paper_comparison.csv"):
        assert "stale: its input results/synthetic/fit_ex.nc has changed since" in graph[name]["description"], name
    assert (
        "stale: its input results/synthetic/paper_comparison.csv is stale"
        in (graph["synthetic/paper_comparison.html"]["description"])
    )
    script = work / "workflow" / "scripts" / "workbook.py"
    script.write_text('raise SystemExit("a deliberate failure")\n' + script.read_text())
    # --keep-going: both workbooks run and fail whichever Snakemake picks first (it stops at the first otherwise)
    out = snakemake(work, "-c1", "--keep-going", "--configfile", "mu.yaml", check=False)
    assert out.returncode != 0 and "the provenance crate of the failed run, marked failed" in out.stderr
    assert crate_file_problems(results) == []
    graph = {e["@id"]: e for e in json.loads((results / "ro-crate-metadata.json").read_text())["@graph"]}
    assert graph["#run"]["actionStatus"]["@id"] == "http://schema.org/FailedActionStatus"
    assert "#job-workbook-dataset=synthetic" not in graph
    # Snakemake removes the failed job's output: the crate does not list a file that is gone
    assert "synthetic/results.xlsx" not in graph and not (results / "synthetic" / "results.xlsx").exists()
    assert graph["report/front.rst"]["description"].startswith(
        "not made by this run: outdated, its job had to run and did not finish ("
    )
    assert main([str(results)]) == 0
