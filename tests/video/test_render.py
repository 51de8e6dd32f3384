"""Synthetic clips (ballbat.video.render; docs/video.md)."""

from __future__ import annotations

import types
from dataclasses import replace

import numpy as np
import pytest
from video_clips import M_PER_PX, PLAIN, RADIUS_PX, spin_truth, swing_truth, two_impact_truths

from ballbat.video.render import Look, _sample_positions, _sub_offsets, render_frames


def _level(frame, x, y):
    return float(frame[round(y), round(x)])


def test_frames_are_streamed_with_the_bit_depth_asked():
    gen = render_frames(spin_truth(n=3), replace(PLAIN, bit_depth=12), M_PER_PX)
    assert isinstance(gen, types.GeneratorType)
    frames = list(gen)
    assert len(frames) == 3
    assert all(f.dtype == np.uint16 and f.shape == (160, 240) and f.max() <= 4095 for f in frames)
    assert next(render_frames(spin_truth(n=1), PLAIN, M_PER_PX)).dtype == np.uint8
    with pytest.raises(ValueError, match="bit_depth"):
        Look(bit_depth=20)


def test_ball_drawn_where_the_truth_says_with_its_dots_and_size():
    truth = spin_truth(n=2)
    frame = next(render_frames(truth, PLAIN, M_PER_PX)).astype(float)
    cx, cy = truth.x["ball"][0], truth.y["ball"][0]
    back = _level(frame, cx, cy + RADIUS_PX + 4)
    assert _level(frame, cx + 3, cy - 3) > back + 60  # the ball is bright on the dark wall
    for p in ("dot_a", "dot_b"):  # each dot darker than the ball beside it
        dx, dy = truth.x[p][0], truth.y[p][0]
        assert _level(frame, dx, dy) < _level(frame, dx + 0.45 * (cx - dx), dy + 0.45 * (cy - dy)) - 40
    # the disc's area (pixels above the wall's level and noise) is pi r^2 to a few per cent
    assert (frame > back + 12).sum() == pytest.approx(np.pi * RADIUS_PX**2, rel=0.06)


def test_a_hidden_dot_is_not_drawn():
    shown = next(render_frames(spin_truth(n=1), PLAIN, M_PER_PX)).astype(float)
    hidden = next(render_frames(spin_truth(n=1, hide_b_from=0), PLAIN, M_PER_PX)).astype(float)
    t = spin_truth(n=1)
    x, y = t.x["dot_b"][0], t.y["dot_b"][0]
    assert _level(hidden, x, y) > _level(shown, x, y) + 40


def test_the_bat_is_in_front_of_the_ball():
    t = swing_truth(n=1)
    t.x["bat_tip"][0], t.y["bat_tip"][0] = t.x["ball"][0] - 5, t.y["ball"][0]
    frame = next(render_frames(t, PLAIN, M_PER_PX)).astype(float)
    ball_only = next(render_frames(swing_truth(n=1), PLAIN, M_PER_PX)).astype(float)
    # the barrel's dark body (13 px radius) covers the ball beside its marker (2.4 px radius)
    x, y = t.x["bat_tip"][0] + 4, t.y["bat_tip"][0] + 4
    assert _level(frame, x, y) < _level(ball_only, x, y) - 60
    assert _level(frame, t.x["bat_tip"][0], t.y["bat_tip"][0]) > 150  # the white marker on the end cap


def test_motion_blur_stretches_the_ball_along_its_motion():
    t = spin_truth(n=3, v_px=10.0)
    quiet = replace(PLAIN, read_noise=0.0)
    sharp = list(render_frames(t, quiet, M_PER_PX))[1].astype(float)
    blurred = list(render_frames(t, replace(quiet, exposure_s=0.6e-3), M_PER_PX))[1].astype(float)

    def spread(img, axis):  # variance of the ball's light along an axis (the wall at about 46 taken off)
        w = np.clip(img - 46.0, 0, None).sum(axis=axis)
        u = np.arange(w.size)
        m = (w * u).sum() / w.sum()
        return (w * (u - m) ** 2).sum() / w.sum()

    # a 6 px smear (0.6 frame at 10 px a frame) adds 6^2 / 12 = 3 px^2 along x, nothing along y
    assert spread(blurred, 0) - spread(sharp, 0) == pytest.approx(3.0, abs=0.6)
    assert spread(blurred, 1) - spread(sharp, 1) == pytest.approx(0.0, abs=0.3)


def test_noise_lighting_and_clutter_vary_the_background():
    plain = next(render_frames(spin_truth(n=1), PLAIN, M_PER_PX)).astype(float)
    busy = next(render_frames(spin_truth(n=1), Look(seed=4), M_PER_PX)).astype(float)
    corner = np.s_[:40, 180:]
    assert plain[corner].std() < 2.0
    assert busy[corner].std() > 3 * plain[corner].std()


def test_the_blur_of_the_frame_before_the_contact_is_the_motion_before_it():
    """The exposure of the last frame before the contact is drawn from the motion then, not towards the next frame.

    Linear between frames, the slower tip after the contact leaked into that frame and moved its
    marker's centroid back along the swing (0.01-0.06 px at 50 us and 3000 fps): a bat speed
    2e-4 low in every filmed impact.
    """
    sw = two_impact_truths()[0]
    ball = sw.x["ball"]
    k = int(np.flatnonzero(ball != ball[0])[0]) - 1
    offsets = _sub_offsets(sw, k, 50e-6 * sw.fps)
    assert offsets.size > 1
    now = _sample_positions(sw, k, offsets)
    linear = _sample_positions(replace(sw, motion=None), k, offsets)
    truth = np.array([sw.x["bat_tip"][k], sw.y["bat_tip"][k]])
    assert np.hypot(*(now["bat_tip"].mean(axis=0) - truth)) < 2e-3
    assert np.hypot(*(linear["bat_tip"].mean(axis=0) - truth)) > 1e-2  # what the linear blur did
    assert np.all(np.abs(now["ball"] - [ball[k], sw.y["ball"][k]]) < 1e-3)  # the ball rests through the exposure
