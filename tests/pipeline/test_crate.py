"""The crate of a results folder (ballbat.pipeline.crate): a later run adds its actions to the earlier ones, a
result changed or gone or stale is said so, a run cut short keeps the earlier crate (issue 37, section 1).
"""

from __future__ import annotations

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
