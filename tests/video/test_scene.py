"""A clip's scene (ballbat.video.scene): its truth is the tracks renderer's without its noise."""

from __future__ import annotations

import numpy as np
import pytest

from ballbat.pipeline.config import checked_block
from ballbat.tracks.render import render_tracks, settings_from_config
from ballbat.units import DEGREE, MPH, RPM
from ballbat.video.scene import clip_truths

CFG = {
    "cameras": {
        "swing": {"fps": 3000, "m_per_px": 0.00074, "tee_px": [540, 480], "pixel_noise_px": 2.0},
        "spin": {"fps": 1000, "m_per_px": 0.00125, "tee_px": [600, 480], "pre_impact_frames": 5},
    },
    "rig": {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0},
    "seed": 5,
}


def test_clip_truth_is_the_tracks_renderers_without_its_noise():
    s = settings_from_config(checked_block(CFG, "render"))
    truth = {
        "v_bat": np.array([75.0]) * MPH,
        "v_ball": np.array([85.0]) * MPH,
        "theta": np.array([10.0]) * DEGREE,
        "omega": np.array([2000.0]) * RPM,
        "psi": np.array([15.0]) * DEGREE,
    }
    args = (truth, np.array([0.0366]), np.array(["W1"]), np.array(["baseball"]), np.array(["wood"]))
    clips = clip_truths(s, *args)
    assert [(c.impact_id, c.camera) for c in clips] == [("W1", "swing"), ("W1", "spin")]
    noisy = render_tracks(*args[:2], s, *args[2:])
    sw = clips[0]
    # the same draws: the noisy tracks scatter about the clip's truth by the renderer's 2 px
    d = noisy.cameras["swing"].x["ball"][0, : sw.n_frames] - sw.x["ball"]
    assert np.nanstd(d) == pytest.approx(2.0, rel=0.35)
    assert sw.x["ball"][0] == 540.0 and sw.y["ball"][0] == 480.0  # at rest on the tee, exactly
    assert sw.ball_radius_px == pytest.approx(0.0366 / 0.00074)
    assert sw.bat_base_px is not None and clips[1].bat_base_px is None
    # the base is where the tip is at impact: the tip passes within a frame's travel of it
    gap = np.nanmin(np.hypot(sw.x["bat_tip"] - sw.bat_base_px[0], sw.y["bat_tip"] - sw.bat_base_px[1]))
    assert gap < 75 * MPH * 34 / 28 / 3000 / 0.00074
