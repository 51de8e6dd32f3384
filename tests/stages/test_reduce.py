"""The reduce stage (ballbat.stages.reduce): the reduction and its cross-checks, a wrong block named."""

from __future__ import annotations

import numpy as np
import pytest

from ballbat.stages import reduce
from ballbat.tracks.data import camera_block


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
