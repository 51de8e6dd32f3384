"""A clip's scene (ballbat.video.scene): its truth is the tracks renderer's without its noise."""

from __future__ import annotations

import numpy as np
import pytest
from video_clips import SCENE_RENDER, two_impact_truths

from ballbat.pipeline.config import checked_block
from ballbat.tracks.render import render_tracks, settings_from_config
from ballbat.units import DEGREE, MPH, RPM
from ballbat.video.scene import clip_truths

CFG = SCENE_RENDER


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


def test_the_clips_motion_is_its_truth_at_every_frame():
    """Between frames the clip keeps its impact's motion, which passes through every frame's truth."""
    for c in two_impact_truths():
        at = c.motion(np.arange(c.n_frames, dtype=float))
        for p, xy in at.items():
            seen = np.isfinite(c.x[p])
            assert seen.sum() > 3
            np.testing.assert_allclose(xy[seen, 0], c.x[p][seen], rtol=0, atol=1e-9)
            np.testing.assert_allclose(xy[seen, 1], c.y[p][seen], rtol=0, atol=1e-9)
        if c.camera == "spin":  # a dot behind the ball is NaN in both (in the view: the motion goes on past it)
            for p in ("dot_a", "dot_b"):
                x = at[p][:, 0]
                inside = ~(x >= c.width) & (np.arange(c.n_frames) < np.flatnonzero(np.isfinite(c.x["ball"]))[-1])
                assert np.array_equal(np.isnan(x)[inside], np.isnan(c.x[p])[inside])


def test_the_motion_between_frames_bends_at_the_contact():
    """Across the contact's start the motion is not linear between frames: the tip slows at once, the ball rests.

    Linear between the frames' truths (what the renderer drew before), the frame before the
    contact carried part of the slower motion after it: its tip 0.01-0.06 px behind.
    """
    sw = two_impact_truths()[0]
    ball = sw.x["ball"]
    k = int(np.flatnonzero(ball != ball[0])[0]) - 1  # the last frame with the ball at rest: the contact follows
    half = np.linspace(0.0, 0.5, 11)[1:]
    after = sw.motion(k + half)
    # the ball has not moved in the half frame after the last frame at rest, up to the contact's start (~t^4)
    assert np.all(np.abs(after["ball"][:, 0] - ball[k]) < 0.05)
    # the tip: before the contact at the speed of the frames before; linear to the next frame is slower
    tip = sw.motion(np.array([k - 1.0, k, k + 1.0]))["bat_tip"]
    before = tip[1] - tip[0]
    lin_speed = np.hypot(*(tip[2] - tip[1]))
    assert lin_speed < 0.97 * np.hypot(*before)  # the slowdown shows between the frames
    t_contact = sw.motion.clock.pre_impact_frames - sw.motion.clock.phase[0]  # frame position of t = 0
    assert k < t_contact < k + 1
    early = sw.motion(np.array([k + 0.5 * (t_contact - k)]))["bat_tip"][0]
    np.testing.assert_allclose(early, tip[1] + 0.5 * (t_contact - k) * before, atol=2e-3)
