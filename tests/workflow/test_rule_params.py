"""The rule scripts take their values from their rule's params only, and those params are what the stages read.

A script that read ``snakemake.config`` would use a value Snakemake does not record: changing it
would leave the product stale ("Nothing to be done"). Here every script is read for
``snakemake.config``, and on a finished default run one value of every stage's settings is
changed in turn: Snakemake must find the product of that stage's rule with changed params (a dry
run's reasons), and not that of a stage that reads none of them.

The stage layer (src/ballbat/stages/): each stage's run on small in-memory inputs.

Each stage writes exactly its declared table, the source stages share the one impacts table,
a stage gives the numbers of the compute functions it calls, its settings come from the
validated config, the rule scripts are one call of a stage, and a replicate of the studies is
those same calls.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from ballbat.stages import fit_ex, implications, normalize, render, simulate, stronge
from workflow_helpers import ROOT


def test_no_rule_script_reads_the_config():
    readers = [
        p.name for p in sorted((ROOT / "workflow" / "scripts").glob("*.py")) if "snakemake.config" in p.read_text()
    ]
    assert readers == []


def test_the_params_rebuild_the_settings_the_config_gives(config):
    """Each stage's settings from the rule's params (as the rules pass them) equal those from the config."""
    assert fit_ex.FitExSettings.from_params({"mu_k_example": 0.5}) == fit_ex.FitExSettings.from_config(config)
    assert normalize.NormalizeSettings.from_params({"v_ref_mph": 77.0}) == normalize.NormalizeSettings.from_config(
        config
    )
    assert stronge.StrongeSettings.from_params(config["stronge"]) == stronge.StrongeSettings.from_config(config)
    block = config["datasets"]["synthetic"]
    assert simulate.from_params(block["synthetic"]) == simulate.from_config(config, "synthetic")
    assert render.from_params(block["render"]) == render.from_config(config, "synthetic")
    params = {"scenario": config["implications"]["scenarios"]["paper"], "air": config["implications"]["air"]}
    assert implications.ImplicationsSettings.from_params(params) == implications.ImplicationsSettings.from_config(
        config, "paper"
    )


#: One value of each stage's settings -> the product of the rule that must see it changed. (The
#: reduction's settings are the render block, whose change reruns it through the new tracks, so
#: that the dry run names no params: the reduce rule passes them as ``settings``, as before.)
CHANGES = {
    ("normalize", "v_ref_mph"): (80.0, "results/synthetic/normalize.nc"),
    ("analysis", "mu_k_example"): (0.4, "results/synthetic/fit_ex.nc"),
    ("stronge", "n_time"): (201, "results/synthetic/stronge.nc"),
    ("datasets", "synthetic", "synthetic", "seed"): (1, "results/synthetic/simulate.nc"),
    ("datasets", "synthetic", "render", "tilted_fraction"): (0.05, "results/synthetic/tracks.nc"),
    ("implications", "air", "temperature_F"): (80.0, "results/implications/paper.nc"),
}


def _params_changed(wd: Path, keys: tuple, value) -> set[str]:
    """The products whose rule's params differ once config value ``keys`` is ``value`` (a dry run's reasons)."""
    from workflow_helpers import snakemake, write_config

    def edit(cfg):
        node = cfg
        for k in keys[:-1]:
            node = node[k]
        assert node[keys[-1]] != value, keys
        node[keys[-1]] = value

    original = (wd / "config" / "config.yaml").read_text()
    write_config(wd, edit)
    try:  # (--list-params-changes lists every product here, changed or not)
        out = snakemake(wd, "-n", "--rerun-triggers", "params").stdout
    finally:
        (wd / "config" / "config.yaml").write_text(original)
    return {
        name.strip()
        for outputs, reason in re.findall(r"^\s+output: (.*)\n(?:.*\n)*?\s+reason: (.*)$", out, flags=re.M)
        if "Params have changed" in reason
        for name in outputs.split(",")
    }


@pytest.mark.slow
@pytest.mark.parametrize("keys", list(CHANGES), ids=[".".join(k) for k in CHANGES])
def test_every_stage_value_is_in_its_rules_params(default_run, tmp_path, keys):
    from workflow_helpers import copy_run

    value, product = CHANGES[keys]
    changed = _params_changed(copy_run(default_run, tmp_path / "wd"), keys, value)
    assert product in changed, sorted(changed)
    # a stage that reads none of these values is not rerun (the figures, tables and workbook
    # record the whole config in their params, for their provenance, and are)
    assert "results/synthetic/reconstruct.nc" not in changed


# ---------------------------------------------------------------------------------------
# the rule scripts and the studies call the stages


SCRIPTS = {
    "simulate": "simulate",
    "ingest": "ingest",
    "render_tracks": "render",
    "track_clips": "clip_tracks",
    "reduce": "reduce",
    "normalize": "normalize",
    "reconstruct": "reconstruct",
    "fit_ex": "fit_ex",
    "fit_stronge": "stronge",
    "implications": "implications",
    "study_batch": "batch",  # beside the studies (ballbat.studies.batch), not a stage of the chain
}


def _script_calls(source: str) -> tuple[set[tuple[str, str]], list[str]]:
    """A rule script's ``from PACKAGE import NAME`` imports and the calls it makes (``stage.run``, ``build_dataset``).

    Read from the syntax tree, so that a comment or a string naming a call is not one.
    """
    imports, calls = set(), []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and node.module:
            imports |= {(node.module, a.asname or a.name) for a in node.names}
        elif isinstance(node, ast.Call):
            calls.append(ast.unparse(node.func))
    return imports, calls


def test_the_script_scan_reads_calls_not_text():
    """A call named in a comment or a string is no call; one written through the module is."""
    imports, calls = _script_calls(
        "from ballbat.stages import fit_ex\n# fit_ex.run(settings, ds)\nx = 'fit_ex.run('\nds = fit_ex.run(s, d)\n"
    )
    assert imports == {("ballbat.stages", "fit_ex")}
    assert calls == ["fit_ex.run"]


@pytest.mark.parametrize(("script", "stage"), SCRIPTS.items())
def test_rule_script_is_one_call_of_its_stage(script, stage):
    imports, calls = _script_calls((ROOT / "workflow" / "scripts" / f"{script}.py").read_text())
    package = "ballbat.studies" if script == "study_batch" else "ballbat.stages"
    assert (package, stage) in imports
    stages = {name for module, name in imports if module in ("ballbat.stages", "ballbat.studies")}
    runs = [c for c in calls if c.endswith(".run") and c.split(".")[0] in stages]
    assert runs == [f"{stage}.run"], runs  # one stage, run once: the script chains nothing
    assert not {"build_dataset", "xr.Dataset", "xarray.Dataset"} & set(calls)
