"""g from a real clip of a pendulum whose length is stated (docs/video.md, "A real clip": a pendulum).

    .venv/bin/python bench/real_clip_pendulum.py film2_vga.mp4 > real_clip_pendulum.out

The clip: ``film2_vga.mp4`` of ``bartekpacia/pendulum`` on GitHub (no licence stated; not
vendored: pass its path). The repository's README states "Lenght of the rope in videos in this
repo is 0.62 m", and its app.py (commit 5edbb18, which reads this file) asks "Enter length of the
rope (mine's 0.62)". A ball (a toy capsule about 3 cm across) hangs on a thread in front of a
plain wall; the pivot is out of the frame. The phone's clip is trimmed by an edit list: 1844
frames shown, stamped 1/60 s apart.

The ball is tracked by its silhouette against the still background; the swing across the image
(x) is fitted with a damped sine (:func:`ballbat.video.pendulum.fit_swing`); the arc's curvature
gives the length in pixels, so the bob's radius as a fraction of the length and the amplitude in
radians. The rope is taken to run from the pivot to the ball's top (the ball's centre is a
radius further down) and the ball's centre of mass to be its centre.
"""

from __future__ import annotations

import sys
from collections import Counter
from dataclasses import replace
from pathlib import Path

import numpy as np

from ballbat.video.io import open_clip
from ballbat.video.pendulum import arc_radius, fit_swing, pendulum_g
from ballbat.video.track import TrackOptions, track_clip

ROPE_M = (0.62, 0.005)  # stated to the centimetre: half a centimetre taken as its standard error
BALL_RADIUS_PX = 28.0  # in the 550 x 310 clip
G = (9.81, 0.01)  # the place is not stated (the author's tools speak Polish: 9.808-9.815 there)


SEGMENTS = 4  # the clip cut into this many stretches (about 5 periods each): their periods' spread is the scatter


def _segment_periods(t, x):
    """Return the periods (s) of the swing fitted in each of :data:`SEGMENTS` equal stretches."""
    parts = zip(np.array_split(t, SEGMENTS), np.array_split(x, SEGMENTS), strict=True)
    return np.array([fit_swing(ts, xs).period for ts, xs in parts])


def _fit_g(t, x, length_px, r_px, r_err_px, length_px_err, dt_rel_err):
    """Fit the swing and return (fit, g, d, its error); omega's error from the stretches' spread, not the residuals'."""
    fit = fit_swing(t, x)
    periods = _segment_periods(t, x)
    se_period = float(periods.std(ddof=1) / np.sqrt(periods.size))
    print(
        f"  {SEGMENTS} stretches' periods {', '.join(f'{p:.5f}' for p in periods)} s: standard error of their mean"
        f" {se_period:.5f} s, against the whole fit's {2 * np.pi * fit.se_omega / fit.omega**2:.5f} (white residuals)"
    )
    fit = replace(fit, se_omega=max(fit.se_omega, fit.omega * se_period / fit.period))
    frac, frac_err = r_px / length_px, np.hypot(r_err_px / length_px, r_px * length_px_err / length_px**2)
    d = ROPE_M[0] / (1 - frac)  # pivot to the ball's centre: the rope and a radius
    d_err = np.hypot(ROPE_M[1] / (1 - frac), ROPE_M[0] * frac_err / (1 - frac) ** 2)
    th2 = float(np.mean((fit.amplitude_at(t) / length_px) ** 2))
    res = pendulum_g(fit, d, centre_err_m=d_err, bob_radius_m=d * frac, theta0_sq=th2, dt_rel_err=dt_rel_err)
    return fit, res, d, d_err, th2


def main(path: Path) -> None:
    """Track the ball, fit the swing and the arc, give g and its error budget."""
    clip = open_clip(path)
    info = clip.info
    print(f"{path.name}: {info.n_frames} frames, {info.width} x {info.height}, header {info.fps:.4f} fps")
    times = np.array([np.nan if ts is None else ts for _, ts, _ in clip.frames()])
    dt = np.diff(times)
    print(f"  stamps: {times.size} frames, {dt.min():.6f}-{dt.max():.6f} s apart, {times[-1] - times[0]:.3f} s")
    dt_rel_err = abs(info.fps * float(np.median(dt)) - 1)  # the header's rate against the stamps'
    # the header's rate is the stored frames' average, those cut off by the edit list too: the stamps are the clock
    info.fps = 1 / float(np.median(dt))
    print(f"  the stamps' rate {info.fps:.4f} fps is used; the header's differs by {dt_rel_err:.1e} (the time's error)")
    found = track_clip(clip, TrackOptions(BALL_RADIUS_PX, background="median", ball_fit="silhouette"))
    r = found.rows
    f, x, y = np.array(r["frame"]), np.array(r["x_px"]), np.array(r["y_px"])
    radii = np.array(found.ball_radii)
    print(f"tracked: ball in {f.size} of {times.size} frames; radius (median) {np.median(radii):.2f} px")
    for why, n in Counter(w for _, _, w in found.left_out).most_common(4):
        print(f"  left out {n:3d}: {why}")
    t = times[f]
    length_px, length_px_err = arc_radius(x, y)
    r_px = float(np.median(radii))
    r_err = 0.5 * float(np.subtract(*np.percentile(radii, [75, 25])))  # half the interquartile range
    print(f"arc: radius {length_px:.0f} +- {length_px_err:.0f} px; ball radius {r_px:.2f} +- {r_err:.2f} px")
    fit, res, d, d_err, th2 = _fit_g(t, x, length_px, r_px, r_err, length_px_err, dt_rel_err)
    print(
        f"swing: period {fit.period:.5f} s, omega {fit.omega:.5f} +- {fit.se_omega:.5f} rad/s, gamma {fit.gamma:.5f}"
        f" /s, amplitude {fit.amplitude_at(t[0]):.1f} -> {fit.amplitude_at(t[-1]):.1f} px, RMS {fit.rms_px:.2f} px"
    )
    print(
        f"  pivot to the ball's centre d = {d:.4f} +- {d_err:.4f} m (ball radius {d * r_px / length_px * 100:.2f} cm);"
        f" equivalent length {res.length_eq_m:.4f} m; amplitude factor {res.amplitude_factor:.5f}"
        f" (rms amplitude {np.degrees(np.sqrt(th2)):.2f} deg)"
    )
    print(
        f"g = {res.g:.3f} m/s^2 +- {res.se_stat:.3f} (scatter) +- {res.se_length:.3f} (length)"
        f" +- {res.se_time:.4f} (time, {dt_rel_err:.1e}) = +- {res.se:.3f};"
        f" (g - {G[0]}) / error = {res.z(*G):+.2f}"
    )
    print(f"  the rope alone as the length (the README's way): g = {fit.omega0**2 * ROPE_M[0]:.3f} m/s^2")
    y_fit = fit_swing(t, y)  # the bob rises twice a swing: y's own period is half x's
    print(f"  y's period {y_fit.period:.5f} s (half x's: {fit.period / 2:.5f})")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__.split("\n\n")[1])
    main(Path(sys.argv[1]))
