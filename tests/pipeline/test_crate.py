"""The crate of a results folder (ballbat.pipeline.crate): a later run adds its actions to the earlier ones, a
result changed or gone or stale is said so, a run cut short keeps the earlier crate (issue 37, section 1).
"""

from __future__ import annotations

import json

import pytest
from helpers import crate_folder as _folder
from helpers import crate_graph as _graph
from helpers import crate_ids as _ids
from helpers import crate_netcdf as _nc

from ballbat.pipeline import crate as crate_mod
from ballbat.pipeline.cratefiles import EARLIER_NAME, crate_file_problems
from ballbat.pipeline.provenance import sha256_file

# -- the crate of a folder describes every run in it -------------------------------------------------


def _workdir(tmp_path):
    (tmp_path / "Snakefile").write_text("# the workflow\n")
    (tmp_path / "config").mkdir()
    (tmp_path / "config" / "a.csv").write_text("a\n1\n")
    (tmp_path / "config" / "b.csv").write_text("b\n2\n")
    return tmp_path / "results"


def _job(rule, name, inp):
    return crate_mod.JobRecord(
        rule=rule,
        wildcards={"dataset": name},
        inputs=[inp],
        outputs=[f"results/{name}/out.nc"],
        logs=[f"results/{name}/logs/{rule}.log"],
        start=1.0e9,
        end=1.0e9 + 5,
    )


def _run(results, tmp_path, jobs, record=None):
    for job in jobs:
        _nc(tmp_path / job.outputs[0], job.key)
        (tmp_path / job.logs[0]).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / job.logs[0]).write_text("log\n")
    crate_mod.set_aside_crate(results)
    return crate_mod.write_run_crate(
        results, jobs, config={}, configfiles=[], workdir=tmp_path, record=record or (lambda p: None)
    )


@pytest.mark.slow  # more than 2 s
def test_a_later_run_adds_its_actions_to_the_earlier_ones(tmp_path):
    """Run 1 makes dataset a (rule ra); run 2, another config, makes b (rule rb). Run 2's crate has both
    jobs: a's action carried with its times, config values, rule and input (its snapshot copy too), its
    results saying they are an earlier run's; the crate checks against the folder and roc-validator.
    """
    from validate_crate import main

    results = _workdir(tmp_path)
    _run(results, tmp_path, [_job("ra", "a", "config/a.csv")])
    first = _graph(results)
    _run(results, tmp_path, [_job("rb", "b", "config/b.csv")])
    graph = _graph(results)
    assert not (results / EARLIER_NAME).exists()
    assert crate_file_problems(results) == []
    a, b = graph["#job-ra-dataset=a"], graph["#job-rb-dataset=b"]
    assert _ids(a["result"]) == ["a/logs/ra.log", "a/out.nc"] and _ids(b["result"]) == ["b/logs/rb.log", "b/out.nc"]
    assert a["startTime"] == first["#job-ra-dataset=a"]["startTime"]
    assert "earlier run" in a["description"]
    assert a["instrument"]["@id"] == "#rule-ra" and "#step-ra" in graph and "#control-ra-dataset=a" in graph
    assert "workflow.snapshot/config/a.csv" in _ids(a["object"])
    assert (results / "workflow.snapshot" / "config" / "a.csv").is_file()  # the earlier input is still copied
    assert graph["#job-ra-dataset=a-config-note"]["value"] == "ra-dataset=a"
    assert graph["a/out.nc"]["description"].startswith("not made by this run: made by an earlier run's job")
    assert _ids(graph["#run"]["result"]) == ["b/out.nc"]
    assert {"#job-ra-dataset=a", "#job-rb-dataset=b"} <= set(_ids(graph["./"]["mentions"]))
    assert main([str(results)]) == 0


def test_an_earlier_result_changed_or_gone_is_not_listed_as_it(tmp_path):
    """An earlier job's output deleted since is not listed at all; one rewritten by hand is no job's result
    (listed as a file not written by the workflow); an action with no result left is dropped; its input,
    changed since, is named with the sha256 it had.
    """
    results = _workdir(tmp_path)
    _run(results, tmp_path, [_job("ra", "a", "config/a.csv"), _job("rc", "c", "config/a.csv")])
    (results / "a" / "out.nc").unlink()
    (results / "a" / "logs" / "ra.log").unlink()
    (results / "c" / "out.nc").write_bytes(b"a user's own file")
    old_digest = sha256_file(tmp_path / "config" / "a.csv")
    (tmp_path / "config" / "a.csv").write_text("a\n3\n")
    _run(results, tmp_path, [_job("rb", "b", "config/b.csv")])
    graph = _graph(results)
    assert crate_file_problems(results) == []
    assert "a/out.nc" not in graph and "#job-ra-dataset=a" not in graph
    c = graph["#job-rc-dataset=c"]
    assert _ids(c["result"]) == ["c/logs/rc.log"]
    assert graph["c/out.nc"]["description"].startswith("not written by this workflow")
    earlier = [graph[i] for i in _ids(c["object"]) if i.startswith("#earlier-input-")]
    assert len(earlier) == 1 and earlier[0]["sha256"] == old_digest


def test_a_stale_earlier_output_says_so(tmp_path):
    """An earlier output whose input has changed since is listed as that job's result, and stale."""
    results = _workdir(tmp_path)
    _run(results, tmp_path, [_job("ra", "a", "config/a.csv")])
    records = {"results/a/out.nc": {"rule": "ra", "input": ["config/a.csv"], "input_checksums": {"config/a.csv": "0"}}}
    _run(results, tmp_path, [_job("rb", "b", "config/b.csv")], record=records.get)
    graph = _graph(results)
    assert "a/out.nc" in _ids(graph["#job-ra-dataset=a"]["result"])
    assert "stale: its input config/a.csv has changed since (sha256)" in graph["a/out.nc"]["description"]


def test_a_run_cut_short_keeps_the_earlier_crate_aside(tmp_path):
    """A run that starts sets the crate aside (no crate in the folder while it runs); a second start (the
    first cut short) keeps it, and the next crate still carries the first run's actions.
    """
    results = _workdir(tmp_path)
    _run(results, tmp_path, [_job("ra", "a", "config/a.csv")])
    crate_mod.set_aside_crate(results)
    assert not (results / "ro-crate-metadata.json").exists() and (results / EARLIER_NAME).is_file()
    crate_mod.set_aside_crate(results)
    assert (results / EARLIER_NAME).is_file()
    _run(results, tmp_path, [_job("rb", "b", "config/b.csv")])
    assert "#job-ra-dataset=a" in _graph(results)


def test_failed_crate_leaves_none(tmp_path, monkeypatch):
    """A crate that fails half-way leaves no metadata file (the old one goes first) and no temporary file."""
    results = tmp_path / "results"
    results.mkdir()
    (results / "ro-crate-metadata.json").write_text("{}")
    (results / "a.nc").write_bytes(b"x")
    (results / ".workflow.snapshot.old123").mkdir()  # what an earlier crate cut short left

    def boom(*args, **kwargs):
        raise RuntimeError("disk full")

    monkeypatch.setattr(crate_mod, "build_crate", boom)
    job = crate_mod.JobRecord(rule="r", wildcards={}, inputs=[], outputs=["results/a.nc"])
    with pytest.raises(RuntimeError, match="disk full"):
        crate_mod.write_run_crate(results, [job], config={}, configfiles=[], workdir=tmp_path)
    assert sorted(p.name for p in results.iterdir()) == ["a.nc", "workflow.snapshot"]


# ---------------------------------------------------------------------------------------
# Issue 34: the crate is the folder's truth (target-only and failed runs, limits)


def test_other_files_are_listed_with_their_staleness(tmp_path):
    """A target-only run's crate lists every file of the folder: the other products (an earlier run's) each
    say so, with their staleness against the inputs Snakemake recorded for them (sha256 first, else time).
    """
    from ballbat.pipeline.cratefiles import crate_file_problems

    results, job = _folder(tmp_path)
    _nc(results / "old.nc", "old")
    _nc(results / "same.nc", "same")
    _nc(results / "derived.nc", "made from old.nc")
    (results / "logs" / "old.log").write_text("log of old.nc's job\n")
    (results / "unknown.tsv").write_text("s\n1\n")
    digest = sha256_file(tmp_path / "config" / "in.csv")
    old = {"config/in.csv": "sha256:00"}
    records = {
        "results/old.nc": {
            "rule": "q",
            "input": ["config/in.csv"],
            "input_checksums": old,
            "log": ["results/logs/old.log"],
        },
        "results/same.nc": {"rule": "q", "input": ["config/in.csv"], "input_checksums": {"config/in.csv": digest}},
        "results/derived.nc": {"rule": "d", "input": ["results/old.nc"], "input_checksums": {}},
    }
    crate_mod.write_run_crate(
        results, [job], config={}, configfiles=[], workdir=tmp_path, record=lambda p: records.get(p)
    )
    graph = _graph(results)
    assert crate_file_problems(results) == []
    assert "stale: its input config/in.csv has changed since (sha256)" in graph["old.nc"]["description"]
    assert "made by rule q; up to date with the 1 inputs it recorded" in graph["same.nc"]["description"]
    assert "its staleness is not known" in graph["unknown.tsv"]["description"]
    assert "stale: its input results/old.nc is stale" in graph["derived.nc"]["description"]
    assert (
        "stale: the log of the job that made results/old.nc (stale: its input" in graph["logs/old.log"]["description"]
    )
    assert "5 file(s) of the folder are not results of this run" in graph["./"]["description"]
    assert "old.nc" not in _ids(graph["#run"]["result"]) and "a.nc" in _ids(graph["#run"]["result"])


def test_failed_run_lists_no_unfinished_job(tmp_path):
    """After a failed run the crate marks the run failed; the job that did not finish has no action, and
    its old output is listed as not made by this run (never as its result).
    """
    results, job = _folder(tmp_path)
    _nc(results / "b.nc", "an earlier run's")
    unfinished = crate_mod.JobRecord(rule="s", wildcards={}, inputs=[], outputs=["results/b.nc"], completed=False)
    crate_mod.write_run_crate(results, [job, unfinished], config={}, configfiles=[], workdir=tmp_path)
    graph = _graph(results)
    assert graph["#run"]["actionStatus"]["@id"] == "http://schema.org/FailedActionStatus"
    assert "1 job(s) did not finish (s)" in graph["#run"]["error"]
    assert "#job-s" not in graph and "#job-r" in graph
    assert "not made by this run" in graph["b.nc"]["description"]


def test_a_users_file_at_an_output_path_is_not_the_jobs_result(tmp_path):
    """A user's own workbook and Markdown file at a job's output paths are listed as not the workflow's."""
    import openpyxl

    results, job = _folder(tmp_path)
    openpyxl.Workbook().save(results / "results.xlsx")
    (results / "table.md").write_text("| my | table |\n")
    job.outputs += ["results/results.xlsx", "results/table.md"]
    crate_mod.write_run_crate(results, [job], config={}, configfiles=[], workdir=tmp_path)
    graph = _graph(results)
    assert _ids(graph["#job-r"]["result"]) == ["a.nc", "logs/a.log"]
    for name in ("results.xlsx", "table.md"):
        assert graph[name]["description"].startswith("not written by this workflow"), name


def test_snapshot_copies_are_limited(tmp_path, monkeypatch):
    """An input data file above the snapshot's limit is not copied: the crate records its path, size and sha256."""
    results, job = _folder(tmp_path)
    (tmp_path / "config" / "big.csv").write_text("x\n" * 100)
    job.inputs.append("config/big.csv")
    monkeypatch.setattr(crate_mod, "SNAPSHOT_FILE_LIMIT", 50)
    crate_mod.write_run_crate(results, [job], config={}, configfiles=[], workdir=tmp_path)
    graph = _graph(results)
    assert (results / "workflow.snapshot" / "config" / "in.csv").is_file()
    assert not (results / "workflow.snapshot" / "config" / "big.csv").exists()
    big = [graph[i] for i in _ids(graph["#job-r"]["object"]) if i.startswith("#uncopied-")]
    assert len(big) == 1 and big[0]["name"] == "config/big.csv" and big[0]["contentSize"] == "200"
    assert big[0]["sha256"] == sha256_file(tmp_path / "config" / "big.csv")
    assert "200 bytes, above the limit of 50 per file" in big[0]["description"]
    monkeypatch.setattr(crate_mod, "SNAPSHOT_FILE_LIMIT", 10**6)
    monkeypatch.setattr(crate_mod, "SNAPSHOT_DATA_LIMIT", 50)
    crate_mod.write_run_crate(results, [job], config={}, configfiles=[], workdir=tmp_path)
    assert "past the limit of 50 for all data copies" in json.dumps(_graph(results))
