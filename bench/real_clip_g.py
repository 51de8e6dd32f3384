"""g from a real clip of a tossed ball; the tracker against the same clip's hand marks (docs/video.md, "A real clip").

    .venv/bin/python bench/real_clip_g.py BALLTOSS_TRZ BALLTOSS_30FPS_MP4 > real_clip_g.out

The clip is Tracker's own example of a tossed ball (Douglas Brown; the Open Source Physics
``tracker`` repository, GPL-3.0, ``examples/``): ``BallToss.trz`` holds a 13-frame H.264 clip
(640 x 480, every other frame of the camera's 30 fps, stamped 66 ms apart) and Tracker's
project, with the ball marked by hand in frames 2-12 and the scale set on the metre stick in
view (398.7 px per m); ``BallTossOut.mp4`` is the 30 fps clip (32 frames). Neither is
vendored (docs/video.md says why): pass their paths.

The ball (about 4.4 px in radius) is tracked with the options a small ball on a still scene
needs: the still background subtracted (``background="median"``: the stick's bright marks
are otherwise taken for balls), a search of 100 px about the prediction (the ball moves up to
50 px a frame), and its centroid (``ball_fit="centroid"``: the edge model needs a larger ball).
"""

from __future__ import annotations

import sys
import tempfile
import zipfile
from collections import Counter
from pathlib import Path

import numpy as np

from ballbat.tracks.formats.tracker import read_trk
from ballbat.video.fall import fit_fall, mark_agreement
from ballbat.video.io import open_clip
from ballbat.video.track import TrackOptions, track_clip

OPT = TrackOptions(ball_radius_px=5.0, background="median", search_px=100.0, ball_fit="centroid")
SCALE_ERR = 1.4 / 398.7  # the calibration's two ends placed to about 1 px each: 0.35 % of the stick's 398.7 px
G = (9.81, 0.01)  # the local g is not stated (Cabrillo College, Aptos, California: about 9.80)


def _track(path: Path):
    clip = open_clip(path)
    found = track_clip(clip, OPT)
    r = found.rows
    ball = np.array([p == "ball" for p in r["point"]])
    frames = np.array(r["frame"])[ball]
    x, y = np.array(r["x_px"])[ball], np.array(r["y_px"])[ball]
    print(f"{path.name}: {clip.info.n_frames} frames, {clip.info.fps:.4f} fps ({clip.info.source['fps']})")
    print(f"  ball found in {frames.size} frames: {frames.tolist()}")
    print(f"  radius (median) {np.median(found.ball_radii):.2f} px")
    for why, n in Counter(w for _, _, w in found.left_out).most_common():
        print(f"  left out {n:2d}: {why}")
    return clip, frames, x, y


def _g(label: str, t, y, m_per_px, dt_rel_err=0.0):
    fit = fit_fall(t, y, m_per_px, m_per_px_err=SCALE_ERR * m_per_px, dt_rel_err=dt_rel_err)
    print(
        f"  {label}: a = {fit.a:.3f} m/s^2 +- {fit.se_stat:.3f} (scatter, {fit.n} points, RMS {fit.rms_px:.2f} px)"
        f" +- {fit.se_scale:.3f} (scale) +- {fit.se_time:.3f} (time) = +- {fit.se:.3f};"
        f" (a - {G[0]}) / error = {fit.z(*G):+.1f}"
    )
    return fit


def main(trz: Path, mp4_30: Path) -> None:
    """Track both clips, fit g from the tracked centres and the hand marks, and compare them."""
    with tempfile.TemporaryDirectory() as tmp, zipfile.ZipFile(trz) as z:
        trk = next(n for n in z.namelist() if n.endswith(".trk"))
        video = next(n for n in z.namelist() if n.endswith(".mp4"))
        z.extract(trk, tmp)
        z.extract(video, tmp)
        marks = read_trk(Path(tmp) / trk)
        _, frames, x, y = _track(Path(tmp) / video)
    fm, xm, ym = marks.tracks["ball"]
    print(f"hand marks: {fm.size} frames {fm.tolist()}, {marks.fps:.4f} fps ({marks.source['fps']}),")
    print(f"  m_per_px {marks.m_per_px:.6g} ({marks.source['m_per_px']})")
    m = marks.m_per_px
    print("\n## g, y(t) = y0 + v0 t + a t^2/2 (image y, down)")
    for label, dt in (("the file's 66 ms", 1 / marks.fps), ("2/30 s (the 30 fps camera's)", 2 / 30)):
        print(f"frame interval {label}:")
        _g("hand marks", fm * dt, ym, m)
        _g("tracked   ", frames * dt, y, m)
        hand = fit_fall(fm * dt, xm, m)
        print(f"  x (horizontal): hand marks a_x = {hand.a:+.3f} +- {hand.se_stat:.3f} m/s^2")
    _, f30, x30, y30 = _track(mp4_30)
    _g("tracked, 30 fps clip", f30 / 30, y30, m, dt_rel_err=0.001)  # 30 fps stamped; 29.97 (NTSC) is 0.1 % off
    print(f"  x (horizontal): a_x = {fit_fall(f30 / 30, x30, m).a:+.3f} m/s^2")
    print("\n## tracked against the hand marks (tracked + 0.5 px: Tracker's pixel centres)")
    ag = mark_agreement((frames, x, y), (fm, xm, ym), pixel_shift=0.5)
    print(f"  {ag.frames.size} frames in common {ag.frames.tolist()}")
    print(f"  dx {np.round(ag.dx, 2).tolist()}")
    print(f"  dy {np.round(ag.dy, 2).tolist()}")
    (ox, oy), (sx, sy) = ag.offset, ag.rms
    print(f"  mean offset ({ox:+.2f}, {oy:+.2f}) px; RMS about it ({sx:.2f}, {sy:.2f}) px")
    for axis, v in (("x", xm), ("y", ym)):
        s = fit_fall(fm / marks.fps, v, m).rms_px
        print(f"  the hand marks' own scatter about their parabola, {axis}: RMS {s:.2f} px")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__.split("\n\n")[1])
    main(Path(sys.argv[1]), Path(sys.argv[2]))
