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


def test_reduce_nc_from_blocks_is_that_of_one_block(tmp_path, monkeypatch):
    """reduce.nc of tracks held in blocks (30 impacts, one track 5x longer, budget lowered) is that of one block.

    The cross-checks' lines and warnings, flags, reasons and integers alike; floats to 1e-12 of the values
    (the calibration-shifted values, through a second reduction each, to 1e-9: 1.2e-10 seen), and the
    uncertainties and scatters to 1e-10 (a covariance's inverse amplifies the sums' round-off: v_bat_err
    1.03e-12 on an AMD EPYC, within 1e-12 on the machines before).
    """
    from dataclasses import replace

    from helpers import BALLS, BATS, one_long_track

    from ballbat.tracks import data
    from ballbat.tracks.io import load_tracks
    from ballbat.tracks.reduce import ReduceOptions

    s = one_long_track(tmp_path / "tracks.nc", factor=5)
    cams = {"swing": replace(s.swing.camera, m_per_px_err=0.01), "spin": s.spin.camera}
    settings = reduce.ReduceSettings(cams, s.rig, ReduceOptions.schema_defaults(), "tracks", True, True, True)
    a = reduce.run(settings, load_tracks(tmp_path / "tracks.nc", balls=BALLS, bats=BATS), BALLS, BATS)
    monkeypatch.setattr(data, "BLOCK_BYTES", 100_000)
    blocks = load_tracks(tmp_path / "tracks.nc", balls=BALLS, bats=BATS)
    assert len(blocks.blocks) == 3
    b = reduce.run(settings, blocks, BALLS, BATS)
    assert a.attrs == b.attrs and a.attrs["reduce_checks"].count("\n") >= 3
    assert set(a.variables) == set(b.variables) and "v_bat_shift" in a and "contact_shift_v_bat" in a
    for k in a.variables:
        x, y = a[k].values, b[k].values
        if k.endswith("_shift") or k.startswith("contact_shift_"):
            q = a[k.removeprefix("contact_shift_").removesuffix("_shift")].values
            np.testing.assert_allclose(q + y, q + x, rtol=1e-9, atol=0, err_msg=k)
        elif x.dtype.kind == "f":
            spread = k.endswith(("_err", "_rms", "_sd"))
            np.testing.assert_allclose(y, x, rtol=1e-10 if spread else 1e-12, atol=0, err_msg=k)
        else:
            np.testing.assert_array_equal(y, x, err_msg=k)
