"""One chain (ballbat.chain): a replicate is a replace of the seeds; check uses the workflow's defaults; the
stages' settings are frozen and come from the validated config (issue 33).
"""

from __future__ import annotations

import copy
import dataclasses

import pytest

from ballbat import chain
from ballbat.stages import fit_ex, implications, ingest, normalize, reconstruct, reduce, render, simulate, stronge
from ballbat.synthetic import SyntheticSettings
from ballbat.tracks.data import camera_block
from ballbat.tracks.render import settings_from_config


def test_a_replicate_is_a_replace_of_the_seeds(config):
    """A study's replicate changes the settings by their seeds alone (the render settings drawn anew)."""
    settings = chain.DatasetSettings.from_config(config, "synthetic")
    rep = settings.with_seeds(5, 6)
    assert rep.synthetic.seed == 5 and rep.render.seed == 6
    assert rep.reduce == settings.reduce and rep.fit_ex == settings.fit_ex
    assert settings.synthetic.seed == config["datasets"]["synthetic"]["synthetic"]["seed"]  # frozen, not changed
    with pytest.raises(ValueError, match="measured"):
        chain.DatasetSettings.from_block(
            {"impacts": "x.csv"}, "m", settings.normalize, settings.fit_ex, systematics=True
        ).with_seeds(1, 2)


def test_check_uses_the_workflows_defaults(config):
    """``ballbat check``'s settings are the schema's: those of the default config, which restates none."""
    check = chain.schema_settings({"impacts": "x.csv"}, "check")
    workflow = chain.DatasetSettings.from_config(config, "synthetic")
    assert check.normalize == workflow.normalize and check.fit_ex == workflow.fit_ex
    assert copy.deepcopy(check.block) == {"impacts": "x.csv"}


# ---------------------------------------------------------------------------------------
# settings


NEW_SETTINGS = (
    fit_ex.FitExSettings,
    normalize.NormalizeSettings,
    reconstruct.ReconstructSettings,
    stronge.StrongeSettings,
    reduce.ReduceSettings,
    ingest.IngestSettings,
    implications.ImplicationsSettings,
)


@pytest.mark.parametrize("cls", NEW_SETTINGS, ids=lambda c: c.__name__)
def test_stage_settings_are_frozen_and_have_no_code_defaults(cls):
    """Values come from the validated config alone (defaults live in the schema)."""
    assert cls.__dataclass_params__.frozen
    for f in dataclasses.fields(cls):
        assert f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING, f.name


def test_settings_from_the_validated_config(config):
    assert fit_ex.FitExSettings.from_config(config) == fit_ex.FitExSettings(
        config["analysis"]["mu_k_example"], systematic=True, check_physical=True, mu_k_bound=True
    )
    assert normalize.NormalizeSettings.from_config(config).v_ref_mph == config["normalize"]["v_ref_mph"]
    assert dataclasses.asdict(stronge.StrongeSettings.from_config(config)) == config["stronge"]
    block = config["datasets"]["synthetic"]["render"]
    rs = reduce.ReduceSettings.from_config(camera_block(block), "render", systematics=False)
    assert rs.cameras["swing"].fps == block["cameras"]["swing"]["fps"]
    assert rs.rig.pivot_to_impact == pytest.approx(block["rig"]["pivot_to_impact_in"] * 0.0254)
    assert simulate.from_config(config, "synthetic") == SyntheticSettings(
        **config["datasets"]["synthetic"]["synthetic"]
    )
    assert render.from_config(config, "synthetic") == settings_from_config(block)
    with pytest.raises(dataclasses.FrozenInstanceError):
        normalize.NormalizeSettings(77.0).v_ref_mph = 80.0  # type: ignore[misc]
