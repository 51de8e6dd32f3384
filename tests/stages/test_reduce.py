"""The stage layer (src/ballbat/stages/): each stage's run on small in-memory inputs.

Each stage writes exactly its declared table, the source stages share the one impacts table,
a stage gives the numbers of the compute functions it calls, its settings come from the
validated config, the rule scripts are one call of a stage, and a replicate of the studies is
those same calls.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from helpers import SMALL

from ballbat.stages import normalize, reconstruct, reduce, render, simulate
from ballbat.tracks.data import camera_block


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


def test_reduce_stage_is_the_reduction_and_its_cross_checks(chain, config):
    """reduce.run: the reduced values of reduce_tracks, the cross-checks' figures as attributes, exclusions listed."""
    from ballbat.tracks.reduce import reduce_tracks

    rs = reduce.ReduceSettings.from_config(
        camera_block(config["datasets"]["synthetic"]["render"]), "render", systematics=False
    )
    red = reduce_tracks(chain["tracks"], rs.cameras, rs.rig, rs.options)
    ds = chain["red"]
    for k in ("v_bat", "v_ball", "theta", "omega", "omega_err"):
        np.testing.assert_array_equal(ds[k].values, red.values[k])
    np.testing.assert_array_equal(ds["ingest_flag"].values, red.flag)
    assert ds.attrs["reduce_checks"].count("\n") >= 1 and "source_file" not in ds.attrs
    assert len(reduce.excluded_listing(ds)) == int((red.flag != 0).sum())


def test_reduce_settings_name_a_wrong_block():
    from ballbat.properties import InputError

    with pytest.raises(InputError, match=r"config datasets\.x\.tracks"):
        reduce.ReduceSettings.from_config({"cameras": {}, "rig": {}}, "config datasets.x.tracks", systematics=False)
