"""Tracking clips (ballbat.video.track; docs/video.md): rendered clips, tracked, against their truth."""

from __future__ import annotations

import csv
import io
from dataclasses import replace

import numpy as np
import pytest
from video_clips import BUSY, M_PER_PX, PLAIN, RADIUS_PX, spin_truth, swing_truth

from ballbat.tracks.io import long_csv_text
from ballbat.tracks.validate import TRACK_COLUMNS
from ballbat.video.clip import ClipInfo, VideoError
from ballbat.video.io import Clip, open_clip, write_clip
from ballbat.video.render import render_frames
from ballbat.video.track import QUALITY_COLUMNS, TrackOptions, found_columns, track_clip

SPIN = TrackOptions(RADIUS_PX, ("ball", "dot_a", "dot_b"), dot_radius_px=0.008 / M_PER_PX)
SWING = TrackOptions(RADIUS_PX, ("ball", "bat_tip"), marker_radius_px=0.006 / M_PER_PX)


def _track(tmp_path, truth, look, opt, name="c.tif"):
    frames = render_frames(truth, look, M_PER_PX)
    path = write_clip(tmp_path / name, frames, truth.fps, frame_numbers=truth.frames)
    return track_clip(open_clip(path), opt)


def _errors(found, truth, point, as_point=None):
    r = found.rows
    at = {int(f): i for i, f in enumerate(truth.frames)}
    q = as_point or point
    sel = [i for i, p in enumerate(r["point"]) if p == point]
    return np.array(
        [
            np.hypot(r["x_px"][i] - truth.x[q][at[r["frame"][i]]], r["y_px"][i] - truth.y[q][at[r["frame"][i]]])
            for i in sel
        ]
    )


def test_ball_and_dots_of_a_busy_spin_clip_to_a_fraction_of_a_pixel(tmp_path):
    truth = spin_truth(n=8)
    found = _track(tmp_path, truth, BUSY, SPIN)
    ball = _errors(found, truth, "ball")
    # a 14.6 px ball among clutter: 0.41 px RMS measured (docs/video.md: 0.1 px on 30-50 px balls)
    assert ball.size >= 7 and np.sqrt(np.mean(ball**2)) < 0.5
    # dot labels are the tracker's own (a and b kept frame to frame), matched to the truth's once per clip
    same = np.sqrt(np.mean(_errors(found, truth, "dot_a") ** 2))
    swap = np.sqrt(np.mean(_errors(found, truth, "dot_a", "dot_b") ** 2))
    other = "dot_b" if same < swap else "dot_a"
    for p, q in (("dot_a", "dot_a" if same < swap else "dot_b"), ("dot_b", other)):
        e = _errors(found, truth, p, q)
        assert e.size >= 7 and np.sqrt(np.mean(e**2)) < 0.3
    rows = found.rows
    assert all(np.isfinite(rows["contrast"])) and all(c > 0 for c in rows["contrast"])


def test_dot_names_hold_while_one_dot_is_hidden_and_after_it_returns(tmp_path):
    truth = spin_truth(n=10, hide_b_from=3, hide_b_to=6)
    found = _track(tmp_path, truth, replace(PLAIN, dot_radius_m=0.005), replace(SPIN, dot_radius_px=2.0))
    rows = found.rows
    # the names are the tracker's: match them to the truth's on the first frame, then hold them
    first = {p: (rows["x_px"][i], rows["y_px"][i]) for i, p in enumerate(rows["point"]) if rows["frame"][i] == 100}
    a_is_a = np.hypot(first["dot_a"][0] - truth.x["dot_a"][0], first["dot_a"][1] - truth.y["dot_a"][0]) < 1
    name = {"dot_a": "dot_a", "dot_b": "dot_b"} if a_is_a else {"dot_a": "dot_b", "dot_b": "dot_a"}
    for p, q in name.items():
        e = _errors(found, truth, p, q)
        assert e.size >= (9 if q == "dot_a" else 6) and e.max() < 0.5
    hidden = sorted(k for p, k, _ in found.left_out if p == next(n for n, q in name.items() if q == "dot_b"))
    assert hidden == [103, 104, 105]


def test_tip_marker_and_ball_at_rest_of_a_swing_clip(tmp_path):
    truth = swing_truth(n=6)
    found = _track(tmp_path, truth, BUSY, SWING)
    tip, ball = _errors(found, truth, "bat_tip"), _errors(found, truth, "ball")
    assert tip.size == 6 and tip.max() < 0.15
    assert ball.size == 6 and np.sqrt(np.mean(ball**2)) < 0.4
    assert found.left_out == []


def test_a_ball_behind_the_bat_is_left_out_with_the_reason(tmp_path):
    truth = swing_truth(n=3)
    truth.x["bat_tip"][:] = truth.x["ball"][0] + np.array([-40.0, -8.0, -40.0])
    truth.y["bat_tip"][:] = truth.y["ball"][0]
    found = _track(tmp_path, truth, PLAIN, SWING)
    reasons = {k: why for p, k, why in found.left_out if p == "ball"}
    assert list(reasons) == [1] and any(w in reasons[1] for w in ("rays", "no ball found", "not round"))
    assert sorted(k for p, k in zip(found.rows["point"], found.rows["frame"], strict=True) if p == "ball") == [0, 2]


def test_no_ball_two_balls_and_the_border_are_reasons(tmp_path):
    empty = spin_truth(n=2)
    empty.x["ball"][:] = np.nan
    found = _track(tmp_path, empty, PLAIN, TrackOptions(RADIUS_PX), "empty.tif")
    assert [why for _, _, why in found.left_out] == ["no ball found"] * 2 and not found.rows["frame"]

    two = spin_truth(n=2)
    frames = [np.maximum(f, np.roll(f, 80, axis=1)) for f in render_frames(two, PLAIN, M_PER_PX)]
    found = track_clip(open_clip(write_clip(tmp_path / "two.tif", iter(frames), 1000.0)), TrackOptions(RADIUS_PX))
    assert [why for _, _, why in found.left_out] == ["2 balls found"] * 2

    edge = spin_truth(n=1)
    edge.x["ball"][0] = 5.0
    found = _track(tmp_path, edge, PLAIN, TrackOptions(RADIUS_PX), "edge.tif")
    assert found.left_out and all("border" in why or "no ball" in why for _, _, why in found.left_out)


def test_tracks_and_quality_tables_are_written_as_the_reduction_reads_them(tmp_path):
    truth = swing_truth(n=3)
    truth.x["bat_tip"][1] = np.nan  # the tip out of view in frame 1
    found = _track(tmp_path, truth, PLAIN, SWING)
    tracks, quality = found_columns(found, "W07", "swing")
    rows = list(csv.reader(io.StringIO(long_csv_text(tracks))))
    assert tuple(rows[0]) == TRACK_COLUMNS and len(rows) == 1 + 5
    assert {r[0] for r in rows[1:]} == {"W07"} and all(r[4] and r[5] for r in rows[1:])
    qrows = list(csv.DictReader(io.StringIO(long_csv_text(quality, QUALITY_COLUMNS))))
    assert len(qrows) == 6
    out = [r for r in qrows if r["left_out"]]
    assert [(r["point"], r["frame"], r["x_px"], r["left_out"]) for r in out] == [
        ("bat_tip", "1", "", "no tip marker found")
    ]
    assert all(float(r["residual_px"]) < 0.5 for r in qrows if r["point"] == "ball")


class _Timed(Clip):
    """A clip whose file gives timestamps: 1 ms apart, then one frame missing."""

    def frames(self):
        img = next(render_frames(spin_truth(n=1), PLAIN, M_PER_PX))
        for k, t in enumerate((0.0, 0.001, 0.002, 0.004)):
            yield k, t, img


def test_a_dropped_frame_is_named():
    clip = _Timed(ClipInfo("lab/W01_spin.mp4", "h264", 240, 160, 4, 8, fps=1000.0))
    with pytest.raises(VideoError, match=r"W01_spin\.mp4: frame 3: timestamp 0\.004 s is \+1\.00 frames off 1000 fps"):
        track_clip(clip, TrackOptions(RADIUS_PX))


def test_options_are_the_trackers_expectations():
    assert replace(SPIN, ball_radius_px=10.0).points == ("ball", "dot_a", "dot_b")


def test_a_faint_spot_is_not_taken_for_the_marker(tmp_path):
    """The marker leaves the view; a faint bright spot near where it was is left out, not tracked."""
    truth = swing_truth(n=6)
    truth.x["bat_tip"][4:] = np.nan
    frames = list(render_frames(truth, PLAIN, M_PER_PX))
    for f in frames[4:]:  # a grey spot (a quarter of the marker's contrast) where the marker would be
        yy, xx = np.mgrid[0:160, 0:240]
        f[np.hypot(xx - 95.0, yy - 102.0) < 2.4] = 90
    found = track_clip(open_clip(write_clip(tmp_path / "c.tif", iter(frames), 3000.0)), SWING)
    tips = [k for p, k in zip(found.rows["point"], found.rows["frame"], strict=True) if p == "bat_tip"]
    assert tips == [0, 1, 2, 3]
    why = [w for p, k, w in found.left_out if p == "bat_tip"]
    assert len(why) == 2 and any("too faint for the marker (44 vs 1" in w for w in why), why
