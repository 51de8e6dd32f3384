"""Fixtures shared by the test modules of this folder."""

import dataclasses

import pytest
import yaml
from helpers import SMALL

from ballbat.stages import normalize, reconstruct, reduce, render, simulate
from ballbat.tracks.data import camera_block


@pytest.fixture(scope="module")
def default_settings(root):
    cfg = yaml.safe_load((root / "config" / "config.yaml").read_text())
    return cfg["datasets"]["synthetic"]["synthetic"]


@pytest.fixture(scope="module")
def chain(config, balls, bats):
    """A small synthetic dataset through simulate, render, reduce, normalize, reconstruct (the workflow's settings)."""
    synth = simulate.from_config(config, "synthetic")
    sim = simulate.run(dataclasses.replace(synth, impacts=SMALL), balls, bats)
    rset = render.from_config(config, "synthetic")
    tracks = render.render(rset, sim, balls)
    rs = reduce.ReduceSettings.from_config(
        camera_block(config["datasets"]["synthetic"]["render"]), "render", systematics=False
    )
    red = reduce.run(rs, tracks, balls, bats)
    norm = normalize.run(normalize.NormalizeSettings.from_config(config), sim)
    rec = reconstruct.run(reconstruct.ReconstructSettings.from_config(config), norm, balls, bats)
    red_rec = reconstruct.run(
        reconstruct.ReconstructSettings(), normalize.run(normalize.NormalizeSettings(77.0), red), balls, bats
    )
    return {"sim": sim, "tracks": tracks, "rset": rset, "red": red, "norm": norm, "rec": rec, "red_rec": red_rec}
