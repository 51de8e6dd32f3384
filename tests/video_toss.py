"""A drawn clip of a small tossed ball before a still scale (tests/video/test_track.py, tests/cli/test_track_video.py).

Shaped like Tracker's BallToss example (docs/video.md, "A real clip"): a ball 4.5 px in radius,
lit from above, tossed across a dark wall, a metre stick of bright marks standing in view,
sensor noise; written as a TIFF stack.
"""

from __future__ import annotations

import numpy as np

from ballbat.video.io import Clip, open_clip, write_clip

W, H = 320, 240
TOSS_R = 4.5  # the ball's radius, px
NOISE = 2.0
TOSS_M_PER_PX = 1 / 200.0  # the stick: 200 px per metre
G = 9.81


def wall() -> np.ndarray:
    """Return the still scene: a dark wall and the stick."""
    img = np.full((H, W), 18.0)
    img[10:230, 158:163] = 60.0  # the stick, with bright square marks every 20 px
    for y in range(14, 226, 20):
        img[y : y + 7, 157:164] = 210.0
    return img


def _ball_image(cx: float, cy: float) -> np.ndarray:
    """Return a shaded ball (brighter at the top) on black, its edge anti-aliased by 4 x 4 supersampling."""
    s = (np.arange(4) + 0.5) / 4 - 0.5
    yy, xx = np.mgrid[0:H, 0:W]
    out = np.zeros((H, W))
    for dy in s:
        for dx in s:
            u, v = xx + dx - cx, yy + dy - cy
            inside = u * u + v * v < TOSS_R * TOSS_R
            out += np.where(inside, 150.0 + 40.0 * np.clip(-v / TOSS_R, -1, 1), 0.0)
    return out / 16


def _toss(n: int, fps: float, vx: float):
    t = np.arange(n) / fps
    return 30.0 + vx * t, 200.0 - 400.0 * t + 0.5 * (G / TOSS_M_PER_PX) * t * t


def toss_clip(
    tmp_path, n: int = 24, fps: float = 60.0, vx: float = 650.0, name: str = "toss.tif"
) -> tuple[Clip, np.ndarray, np.ndarray]:
    """Write the clip (``n`` frames at ``fps``, the ball ``vx`` px/s across) and return it with the ball's true x, y."""
    rng = np.random.default_rng(5)
    still = wall()
    x, y = _toss(n, fps, vx)
    frames = []
    for cx, cy in zip(x, y, strict=True):
        img = still + _ball_image(cx, cy)
        frames.append(np.clip(np.round(img + rng.normal(0, NOISE, img.shape)), 0, 255).astype(np.uint8))
    write_clip(tmp_path / name, frames, fps)
    return open_clip(tmp_path / name), x, y
