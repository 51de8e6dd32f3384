"""g from a real high-speed clip of a dropped steel ball beside a tape measure (docs/video.md, "A real clip").

    .venv/bin/python bench/real_clip_drop.py CaidaLibreTrim.mp4 > real_clip_drop.out

The clip: ``CaidaLibreTrim.mp4`` of ``SantiagoGiraldoM17/LaboratorioCaidaLibre`` on GitHub (no
licence stated; not vendored: pass its path). Its report states 1000 fps on a Phantom camera,
exported to mp4 (stamped 30 fps) and trimmed to start as the ball moves; a tape measure (cm
and inch) hangs beside the ball. The ball (a dark steel sphere with a bright highlight, 37 px
in radius) is tracked by its silhouette against the still background (``ball_fit="silhouette"``).

The scale is measured here from the tape's millimetre ticks: the period of the still
background's brightness down the tick columns (a zero-padded Fourier transform's peak), and,
as a check, of the inch side's sixteenths.
"""

from __future__ import annotations

import sys
from collections import Counter
from pathlib import Path

import numpy as np

from ballbat.video.fall import fit_fall
from ballbat.video.io import open_clip
from ballbat.video.track import TrackOptions, still_background, track_clip

FPS = 1000.0  # the report's Phantom rate; the file's 30 fps is the export's
G = (9.78, 0.01)  # the place is not stated (Colombia, by the authors' names: about 9.77-9.78)


def _period(bg: np.ndarray, cols: slice, lo: float, hi: float) -> float:
    """Return the strongest period (px) in [lo, hi] of the mean column profile, from a zero-padded FFT's peak."""
    p = bg[:, cols].mean(axis=1)
    p = (p - p.mean()) * np.hanning(p.size)
    n = 1 << 18
    f = np.fft.rfftfreq(n)
    a = np.abs(np.fft.rfft(p, n))
    s = (f > 1 / hi) & (f < 1 / lo)
    return float(1 / f[s][np.argmax(a[s])])


def main(path: Path, mm_cols: slice, inch_cols: slice) -> None:
    """Measure the scale, track the ball, fit g."""
    clip = open_clip(path)
    print(f"{path.name}: {clip.info.n_frames} frames, {clip.info.width} x {clip.info.height}, file {clip.info.fps} fps")
    bg = still_background(clip)
    mm = _period(bg, mm_cols, 3.0, 4.5)
    sixteenth = _period(bg, inch_cols, 5.0, 6.5)
    print(f"scale: mm ticks {mm:.4f} px (columns {mm_cols.start}-{mm_cols.stop - 1}),")
    print(
        f"  1/16 in ticks {sixteenth:.4f} px = {sixteenth / 1.5875:.4f} px per mm ({sixteenth / 1.5875 / mm - 1:+.2%})"
    )
    m_per_px = 1e-3 / mm
    scale_err = abs(sixteenth / 1.5875 / mm - 1)  # the two scales' disagreement, taken as the scale's error
    for tol in (0.3, 0.05):
        opt = TrackOptions(37.0, background="median", ball_fit="silhouette", radius_tolerance=tol)
        found = track_clip(clip, opt)
        r = found.rows
        f, x, y = np.array(r["frame"]), np.array(r["x_px"]), np.array(r["y_px"])
        print(
            f"\nradius_tolerance {tol}: ball in {f.size} frames, radius (median) {np.median(found.ball_radii):.2f} px"
        )
        for why, n in Counter(w for _, _, w in found.left_out).most_common(4):
            print(f"  left out {n:3d}: {why}")
        fit = fit_fall(f / FPS, y, m_per_px, m_per_px_err=scale_err * m_per_px)
        fx = fit_fall(f / FPS, x, m_per_px)
        print(
            f"  a = {fit.a:.3f} m/s^2 +- {fit.se_stat:.3f} (scatter, RMS {fit.rms_px:.2f} px) +- {fit.se_scale:.3f}"
            f" (scale) = +- {fit.se:.3f}; (a - {G[0]}) / error = {fit.z(*G):+.1f}; a_x = {fx.a:+.3f} m/s^2"
        )
        res = fit.residuals_px(f / FPS, y)
        good = np.abs(res) < 3 * 1.4826 * np.median(np.abs(res))
        fit2 = fit_fall(f[good] / FPS, y[good], m_per_px, m_per_px_err=scale_err * m_per_px)
        print(
            f"  without the {np.count_nonzero(~good)} points over 3 robust SD off:"
            f" a = {fit2.a:.3f} +- {fit2.se_stat:.3f} (RMS {fit2.rms_px:.2f} px)"
            f" = +- {fit2.se:.3f}; (a - {G[0]}) / error = {fit2.z(*G):+.1f}"
        )
        print(
            f"  needed for g: a scale {G[0] / fit2.a - 1:+.2%} larger, or a rate {np.sqrt(fit2.a / G[0]) - 1:+.2%} off"
        )


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__.split("\n\n")[1])
    main(Path(sys.argv[1]), slice(220, 229), slice(272, 275))
