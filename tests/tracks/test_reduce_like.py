"""The calibration reruns reuse what a calibration does not move (reduce_tracks's ``like``, issue 39): the values
are those of the reduction from scratch, bit for bit, one block or several.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers import BALLS, BATS, one_long_track

from ballbat import systematics
from ballbat.tracks import data
from ballbat.tracks.io import load_tracks
from ballbat.tracks.reduce import reduce_tracks


def _tracks(tmp_path, monkeypatch, blocks: bool):
    s = one_long_track(tmp_path / "tracks.nc", factor=5)
    if blocks:
        monkeypatch.setattr(data, "BLOCK_BYTES", 100_000)
    tr = load_tracks(tmp_path / "tracks.nc", balls=BALLS, bats=BATS)
    assert isinstance(tr, data.TrackBlocks) == blocks
    return s, tr


@pytest.mark.parametrize("blocks", [False, True])
@pytest.mark.parametrize("source", list(systematics.SOURCES))
def test_rerun_like_the_nominal_gives_the_values_from_scratch(tmp_path, monkeypatch, blocks, source):
    """Each calibration source at +-1.5 %: every value of the rerun that reuses the nominal equals the rerun's from
    scratch to the bit, and its flags are the nominal's.
    """
    s, tr = _tracks(tmp_path, monkeypatch, blocks)
    cameras = {"swing": s.swing.camera, "spin": s.spin.camera}
    nominal = reduce_tracks(tr, cameras, s.rig)
    for factor in (1.015, 0.985):
        cams, rig = systematics.shifted_settings(cameras, s.rig, source, factor)
        fresh = reduce_tracks(tr, cams, rig, population_shifts=False)
        like = reduce_tracks(tr, cams, rig, population_shifts=False, like=nominal)
        moved = 0
        for k, v in fresh.values.items():
            np.testing.assert_array_equal(like.values[k], v, err_msg=f"{source} x {factor}: {k}")
            moved += int(np.any(v != nominal.values[k]))
        assert moved >= 1, f"{source}: no value moved: the test shifts nothing"
        np.testing.assert_array_equal(like.flag, nominal.flag)
        np.testing.assert_array_equal(like.reason, nominal.reason)
    assert (nominal.flag != 0).sum() >= 1  # the flags are there to keep


def test_reduce_shifts_reuse_the_nominal(tmp_path, monkeypatch):
    """reduce_shifts passes the nominal on: the spin camera is fitted again for its own sources only (its pixel scale
    at +-1 sigma: twice), not for the swing camera's (its pixel scale and frame rate).
    """
    from dataclasses import replace

    from ballbat.tracks import reduce as red_mod

    s, tr = _tracks(tmp_path, monkeypatch, False)
    cameras = {
        "swing": replace(s.swing.camera, m_per_px_err=0.01, fps_err=1e-4),
        "spin": replace(s.spin.camera, m_per_px_err=0.01, fps_err=0.0),
    }
    nominal = reduce_tracks(tr, cameras, s.rig)
    calls = []
    real = red_mod.fit_spin
    monkeypatch.setattr(red_mod, "fit_spin", lambda *a, **k: calls.append(1) or real(*a, **k))
    shifts = systematics.reduce_shifts(tr, cameras, s.rig, None, nominal)
    assert len(calls) == 2
    i = list(systematics.SOURCES).index("swing_fps")
    assert np.any(shifts.shift["v_bat"][i] != 0)  # the swing camera's frame rate was rerun (glitches found again)
