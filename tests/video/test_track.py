"""Tracking clips (ballbat.video.track; docs/video.md): rendered clips, tracked, against their truth."""

from __future__ import annotations

import csv
import io
from collections import Counter
from dataclasses import replace

import numpy as np
import pytest
from video_clips import BUSY, M_PER_PX, PLAIN, RADIUS_PX, spin_truth, swing_truth
from video_toss import NOISE, TOSS_M_PER_PX, TOSS_R, G, H, W, toss_clip, wall

from ballbat.tracks.io import long_csv_text
from ballbat.tracks.validate import TRACK_COLUMNS
from ballbat.video.clip import ClipInfo, VideoError
from ballbat.video.fall import fit_fall
from ballbat.video.io import Clip, open_clip, write_clip
from ballbat.video.render import render_frames
from ballbat.video.track import (
    MARKER_MARGIN,
    QUALITY_COLUMNS,
    TrackOptions,
    found_columns,
    still_background,
    track_clip,
)

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


# A small tossed ball before a still stick (docs/video.md, "A real clip"): the options for a real lab clip, each
# checked on what it is for: the still background subtracted (the stick's marks are otherwise bright round spots,
# "balls"), the ball's centroid (a ball this small), a wider search about the prediction (a ball that moves
# further between frames than 4 of its radii).

SMALL = {"ball_radius_px": TOSS_R, "background": "median", "ball_fit": "centroid"}


def _ball_rows(found):
    r = found.rows
    keep = np.array([p == "ball" for p in r["point"]], bool)
    return np.array(r["frame"])[keep], np.array(r["x_px"])[keep], np.array(r["y_px"])[keep]


def test_small_ball_before_a_still_stick_is_tracked_and_gives_g(tmp_path):
    """Found in at least 22 of 24 frames, within 0.1 px RMS of the truth; every frame found or left out with a reason.

    g from the tracked centres within 2 of its combined errors (the fit's statistical error
    only: the scale and frame rate are exact here).
    """
    clip, x, y = toss_clip(tmp_path)
    found = track_clip(clip, TrackOptions(**SMALL))
    frames, fx, fy = _ball_rows(found)
    left = [k for p, k, _ in found.left_out if p == "ball"]
    assert sorted([*frames.tolist(), *left]) == list(range(24))
    assert frames.size >= 22, Counter(w for _, _, w in found.left_out)
    err = np.hypot(fx - x[frames], fy - y[frames])
    assert np.sqrt(np.mean(err**2)) < 0.1, err
    fit = fit_fall(frames / 60.0, fy, TOSS_M_PER_PX)
    assert abs(fit.z(G)) < 2, (fit.a, fit.se)
    assert np.median(found.ball_radii) == pytest.approx(TOSS_R, rel=0.15)


def test_without_the_background_the_sticks_marks_are_taken_for_balls(tmp_path):
    """Without the still background subtracted, the stick's marks are "balls": the ball is left out, with that reason.

    The marks are bright round spots of about the ball's size.
    """
    clip, _, _ = toss_clip(tmp_path)
    found = track_clip(clip, TrackOptions(**{**SMALL, "background": "none"}))
    reasons = Counter(w for p, _, w in found.left_out if p == "ball")
    assert sum(n for w, n in reasons.items() if w.endswith("balls found")) >= 12, reasons


def test_still_background_is_the_scene_without_the_ball(tmp_path):
    clip, _, _ = toss_clip(tmp_path)
    bg = still_background(clip)
    assert bg.dtype == np.float32 and bg.shape == (H, W)
    # the median of 24 noisy frames: within 5 of the noise's sigma of the wall everywhere (the ball in at most 1 frame)
    assert np.max(np.abs(bg - wall())) < 5 * NOISE


def test_a_ball_moving_far_between_frames_needs_a_wider_search(tmp_path):
    """A ball 43 px a frame apart (30 fps, 1300 px/s) is lost by the default search and found by a 60-px one.

    43 px is beyond 4 radii (18 px) of a prediction made from one position; the 60-px search finds
    the ball in every frame in view but at most one.
    """
    clip, x, _ = toss_clip(tmp_path, n=8, fps=30.0, vx=1300.0, name="fast.tif")
    narrow = track_clip(clip, TrackOptions(**SMALL))
    wide = track_clip(clip, TrackOptions(**SMALL, search_px=60.0))
    n_narrow, n_wide = _ball_rows(narrow)[0].size, _ball_rows(wide)[0].size
    in_view = int(np.sum(x < W - 2 * TOSS_R - 3))
    assert n_wide >= in_view - 1 and n_narrow <= n_wide - 2, (n_narrow, n_wide, in_view)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"background": "mean"}, "background 'mean' is not 'none' or 'median'"),
        ({"ball_fit": "template"}, "ball_fit 'template' is not 'edge', 'centroid' or 'silhouette'"),
        ({"search_px": 0.0}, "search_px 0.0 must be positive"),
    ],
)
def test_unknown_options_are_refused(kwargs, message):
    with pytest.raises(ValueError, match=message):
        TrackOptions(5.0, **kwargs)


# A dark steel ball with a bright highlight dropped before a grey wall (docs/video.md, "A real clip": the Phantom
# clip's ball): no bright disc, so the bright-disc search finds none; its silhouette against the still background does.

DROP_R, DROP_FPS, DROP_M_PER_PX = 12.0, 1000.0, 1 / 4000.0  # 4000 px per metre


def _drop_clip(tmp_path, n=40):
    rng = np.random.default_rng(7)
    h, w = 300, 100
    wall_img = np.full((h, w), 40.0)
    wall_img[:, 80:92] = 200.0  # a still bright strip (a tape)
    t = np.arange(n) / DROP_FPS
    x, y = 45.0 + 0.0 * t, 30.0 + 3000.0 * t + 0.5 * (9.81 / DROP_M_PER_PX) * t * t
    s = (np.arange(4) + 0.5) / 4 - 0.5
    yy, xx = np.mgrid[0:h, 0:w]
    frames = []
    for cx, cy in zip(x, y, strict=True):
        img = np.zeros((h, w))
        for dy in s:
            for dx in s:
                u, v = xx + dx - cx, yy + dy - cy
                d2 = u * u + v * v
                ball = 15.0 + 200.0 * np.exp(-((u + 3) ** 2 + (v + 4) ** 2) / 8.0)  # dark, a highlight up-left
                img += np.where(d2 < DROP_R**2, ball, wall_img)
        img /= 16
        frames.append(np.clip(np.round(img + rng.normal(0, 1.5, img.shape)), 0, 255).astype(np.uint8))
    write_clip(tmp_path / "drop.tif", frames, DROP_FPS)
    return open_clip(tmp_path / "drop.tif"), x, y


def test_a_dark_ball_with_a_highlight_is_found_by_its_silhouette_and_gives_g(tmp_path):
    """The silhouette finds the ball in every frame, within 0.5 px RMS; g within 2 standard errors; its radius to 1 px.

    The edge model and the centroid look for a bright disc: they find the ball in at most a
    quarter of the frames (its highlight, or nothing).
    """
    clip, x, y = _drop_clip(tmp_path)
    found = track_clip(clip, TrackOptions(DROP_R, background="median", ball_fit="silhouette"))
    frames, fx, fy = _ball_rows(found)
    assert frames.size == 40, Counter(w for _, _, w in found.left_out)
    err = np.hypot(fx - x[frames], fy - y[frames])
    assert np.sqrt(np.mean(err**2)) < 0.5, err  # 0.36 px measured: the boundary's whole pixels
    fit = fit_fall(frames / DROP_FPS, fy, DROP_M_PER_PX)
    assert abs(fit.z(9.81)) < 2, (fit.a, fit.se)
    assert abs(np.median(found.ball_radii) - DROP_R) < 1.0, np.median(found.ball_radii)
    for fit_name in ("edge", "centroid"):
        other = track_clip(clip, TrackOptions(DROP_R, background="median", ball_fit=fit_name))
        assert _ball_rows(other)[0].size <= 10, (fit_name, Counter(w for _, _, w in other.left_out))


def test_the_silhouette_needs_the_still_background():
    with pytest.raises(ValueError, match="ball_fit 'silhouette' needs background 'median'"):
        TrackOptions(5.0, ball_fit="silhouette")


def test_a_still_spot_like_the_marker_is_not_taken_for_it(tmp_path):
    """A copy of the marker (with its end cap) still in the background, nearer the frame's centre than the
    swinging marker: the whole-frame search takes it first, but a marker that does not move is the
    background's. Its two marks are taken back and left out with the reason, and the marker is tracked from
    the next frame on, to its truth (before: the still copy, in all 8 frames).
    """
    truth = swing_truth(n=8)
    frames = list(render_frames(truth, PLAIN, M_PER_PX))
    x0, y0 = round(truth.x["bat_tip"][0]), round(truth.y["bat_tip"][0])
    patch = frames[0][y0 - 9 : y0 + 10, x0 - 9 : x0 + 10].copy()
    for f in frames:
        f[21:40, 111:130] = patch  # centred on (120, 30), up to 0.4 px off the marker's own sub-pixel place
    found = track_clip(open_clip(write_clip(tmp_path / "c.tif", iter(frames), 3000.0)), SWING)
    rows = [
        (k, x)
        for p, k, x in zip(found.rows["point"], found.rows["frame"], found.rows["x_px"], strict=True)
        if p == "bat_tip"
    ]
    assert [k for k, _ in rows] == [2, 3, 4, 5, 6, 7]
    assert max(abs(x - truth.x["bat_tip"][k]) for k, x in rows) < 0.15
    why = {k: w for p, k, w in found.left_out if p == "bat_tip"}
    assert sorted(why) == [0, 1] and all("does not move" in w for w in why.values()), why


def test_a_still_spots_earlier_mark_a_pixel_or_two_off_is_taken_back_with_it(tmp_path):
    """The still copy of the marker first seen 2 px from where it then stays (a clutter spot the bat passed): its
    first mark is not part of the still run, but lies within two marker radii of the spot, so it is the spot's and
    is taken back with the run (before: kept, 2 px off the spot and 102 px off the swinging marker).
    """
    truth = swing_truth(n=8)
    frames = list(render_frames(truth, PLAIN, M_PER_PX))
    x0, y0 = round(truth.x["bat_tip"][0]), round(truth.y["bat_tip"][0])
    patch = frames[0][y0 - 9 : y0 + 10, x0 - 9 : x0 + 10].copy()
    frames[0][21:40, 113:132] = patch  # centred on (122, 30) in the first frame
    for f in frames[1:]:
        f[21:40, 111:130] = patch  # then on (120, 30)
    found = track_clip(open_clip(write_clip(tmp_path / "c.tif", iter(frames), 3000.0)), SWING)
    marks = [k for p, k in zip(found.rows["point"], found.rows["frame"], strict=True) if p == "bat_tip"]
    assert marks == [3, 4, 5, 6, 7]
    why = {k: w for p, k, w in found.left_out if p == "bat_tip"}
    assert sorted(why) == [0, 1, 2] and all("does not move" in w for w in why.values()), why


def test_a_marker_cut_by_the_frames_border_is_left_out(tmp_path):
    """The marker swings out of the view: where its surround reaches the border it is left out with the reason.

    Kept (before), the last mark, 1.0 px from the border (the marker 2.4 px in radius), was 0.37 px inside its
    truth: part of the marker is outside the frame.
    """
    truth = swing_truth(n=8, width=240, tip_start=174.6)
    found = _track(tmp_path, truth, PLAIN, SWING)
    marks = {
        k: x
        for p, k, x in zip(found.rows["point"], found.rows["frame"], found.rows["x_px"], strict=True)
        if p == "bat_tip"
    }
    mr = SWING.marker_radius_px
    edge = {k: 239 - truth.x["bat_tip"][k] for k in range(8)}
    assert sorted(marks) == [k for k in range(8) if edge[k] >= MARKER_MARGIN * mr + 0.5]
    assert max(abs(x - truth.x["bat_tip"][k]) for k, x in marks.items()) < 0.05
    why = {k: w for p, k, w in found.left_out if p == "bat_tip"}
    assert why and all("from the frame's border: cut" in w for w in why.values()), why
    assert sorted(why) == [k for k in range(8) if edge[k] < MARKER_MARGIN * mr - 0.5] == [7]
