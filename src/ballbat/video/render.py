"""Frames of a synthetic high-speed clip, drawn from its truth (:class:`~ballbat.video.scene.ClipTruth`).

Each frame is the average of sub-exposures spread over the exposure time (motion blur), the
points where the clip's motion puts them at each (:class:`~ballbat.video.scene.ClipMotion`;
linear between the frames' true positions for a clip made by hand). Drawn in the region the
moving objects cover, over a fixed background:

* background: a dark wall with clutter (grey boxes and bars, slightly soft), times the lighting;
* lighting: a linear gradient and a vignette across the view (``lighting``: their strength);
* the ball: a white Lambert-shaded sphere lit from the upper left, anti-aliased edge (the
  coverage of each pixel by the disc, to first order in the distance to the edge); its two
  dots dark ellipses, foreshortened towards the limb (a small disc on the sphere, seen in
  projection), centred on their true positions;
* the bat (cameras that track ``bat_tip``): the barrel seen nearly along its axis, a dark
  capsule from the point of the axis at the impact's depth to the end cap, with a white tip
  marker on the end cap; it is in front of the ball and hides it where they overlap;
* sensor: shot and read noise, then quantised to ``bit_depth`` bits (8 to 16), saturating.

Frames are yielded one at a time (:func:`render_frames`): a clip is never held whole.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from .scene import ClipTruth

_LIGHT = np.array([-0.3, -0.35, 0.89]) / np.linalg.norm([-0.3, -0.35, 0.89])


@dataclass(frozen=True)
class Look:
    """How a camera images the scene (defaults: a well-lit high-speed setup).

    exposure_s : exposure time (s); the blur is the distance moved in it.
    bit_depth : bits per pixel, 8 to 16.
    read_noise, shot_noise : standard deviations as fractions of full scale (shot noise at
        full scale; it scales as the square root of the signal).
    lighting : strength of the gradient and vignette (0: even).
    clutter : number of boxes and bars in the background.
    dot_radius_m, marker_radius_m, barrel_radius_m : sizes on the object (m); ``m_per_px``
        turns them into pixels.
    seed : seed of the background and the noise.
    """

    exposure_s: float = 50e-6
    bit_depth: int = 8
    read_noise: float = 0.008
    shot_noise: float = 0.01
    lighting: float = 0.3
    clutter: int = 15
    dot_radius_m: float = 0.004
    marker_radius_m: float = 0.006
    barrel_radius_m: float = 0.033
    seed: int = 0

    def __post_init__(self):
        """Refuse a bit depth outside 8 to 16."""
        if not 8 <= int(self.bit_depth) <= 16:
            raise ValueError(f"bit_depth {self.bit_depth}: 8 to 16 bits")


def lighting_field(width: int, height: int, strength: float) -> np.ndarray:
    """Relative illumination of the view (height x width, float32): gradient and vignette, mean near 1."""
    yy, xx = np.mgrid[0:height, 0:width].astype(np.float32)
    u, v = xx / width - 0.5, yy / height - 0.5
    return (1.0 + strength * (0.35 * u - 0.25 * v - 0.8 * (u * u + v * v) + 0.1)).astype(np.float32)


def background(width: int, height: int, look: Look, light: np.ndarray) -> np.ndarray:
    """Return the static background (float32, fraction of full scale): a dark wall with clutter, lit."""
    rng = np.random.default_rng([look.seed, 0xB6])
    img = np.full((height, width), 0.18, np.float32)
    for _ in range(look.clutter):
        x0, y0 = rng.uniform(0, width), rng.uniform(0, height)
        w, h = (rng.uniform(5, 60), rng.uniform(40, 300)) if rng.uniform() < 0.5 else rng.uniform(20, 120, 2)
        sl = np.s_[int(y0) : int(y0 + h), int(x0) : int(x0 + w)]
        img[sl] = rng.uniform(0.05, 0.45)
    return ndimage.gaussian_filter(img, 1.2) * light


def _coverage(dist: np.ndarray) -> np.ndarray:
    """Fraction of a pixel inside a shape, from the signed distance of its centre to the edge (px)."""
    return np.clip(0.5 - dist, 0.0, 1.0)


def _sample_positions(truth: ClipTruth, k: int, offsets: np.ndarray) -> dict[str, np.ndarray]:
    """Each point's (x, y) at frame ``k`` + each offset (frames): the clip's motion, else linear between frames.

    With the clip's motion (:class:`~ballbat.video.scene.ClipMotion`) every sub-exposure is
    where the point truly is then (NaN for a dot behind the ball), for the points in view at
    frame ``k`` (one out of view there is not drawn). Without it (a clip made by hand), linear
    between frames, and where a neighbouring frame has no position (the point appears or
    disappears) the nearest frame's position is used (NaN if it has none).
    """
    if truth.motion is not None:
        at = truth.motion(k + offsets)
        return {p: v if np.isfinite(truth.x[p][k]) else np.full_like(v, np.nan) for p, v in at.items()}
    n = truth.n_frames
    t = k + offsets
    lo = np.clip(np.floor(t).astype(int), 0, max(n - 2, 0))
    hi = np.minimum(lo + 1, n - 1)
    f = t - lo
    near = np.clip(np.rint(t).astype(int), 0, n - 1)
    out = {}
    for p in truth.x:
        cols = []
        for v in (truth.x[p], truth.y[p]):
            w = v[lo] + f * (v[hi] - v[lo])
            cols.append(np.where(np.isfinite(w), w, v[near]))
        out[p] = np.stack(cols, axis=1)
    return out


def _ball_layer(gx, gy, c, r, dots, dot_r):
    """Coverage and radiance of the ball (with its dots) on a grid of pixel centres."""
    dx, dy = gx - c[0], gy - c[1]
    rho = np.hypot(dx, dy)
    cov = _coverage(rho - r)
    q = np.clip(rho / r, 0, 1)
    nz = np.sqrt(1 - q * q)
    shade = 0.35 + 0.65 * np.clip((dx * _LIGHT[0] + dy * _LIGHT[1]) / r + nz * _LIGHT[2], 0, None)
    albedo = np.full(gx.shape, 0.78)
    for d in dots:
        if not np.isfinite(d).all():
            continue
        ox, oy = d[0] - c[0], d[1] - c[1]
        dd = np.hypot(ox, oy)
        ux, uy = (ox / dd, oy / dd) if dd > 1e-9 else (1.0, 0.0)
        fore = np.sqrt(max(1 - (dd / r) ** 2, 1e-4))
        a = ((gx - d[0]) * ux + (gy - d[1]) * uy) / fore
        b = -(gx - d[0]) * uy + (gy - d[1]) * ux
        albedo *= 1 - 0.85 * _coverage(np.hypot(a, b) - dot_r)
    return cov, albedo * shade


def _bat_layer(gx, gy, tip, base, depth, r_barrel, r_marker):
    """Coverage and radiance of the barrel (capsule from the impact's depth to the end cap) and its marker."""
    ax, ay = base[0] + depth * (tip[0] - base[0]), base[1] + depth * (tip[1] - base[1])
    sx, sy = tip[0] - ax, tip[1] - ay
    ll = sx * sx + sy * sy
    t = np.clip(((gx - ax) * sx + (gy - ay) * sy) / ll, 0, 1) if ll > 1e-12 else 0.0
    cov = _coverage(np.hypot(gx - ax - t * sx, gy - ay - t * sy) - r_barrel)
    marker = _coverage(np.hypot(gx - tip[0], gy - tip[1]) - r_marker)
    return cov, 0.10 + 0.80 * marker


@dataclass
class _Sizes:
    ball: float
    dot: float
    marker: float
    barrel: float


def _draw(img: np.ndarray, light: np.ndarray, truth: ClipTruth, pos: dict, sizes: _Sizes) -> None:
    """Composite the sub-exposures at ``pos`` (point -> (n, 2)) onto ``img`` in place (their average)."""
    pts = [v for v in pos.values() if np.isfinite(v).any()]
    if not pts:
        return
    allp = np.concatenate(pts)
    allp = allp[np.isfinite(allp).all(axis=1)]
    pad = max(sizes.ball, sizes.barrel) + 3
    x0, y0 = (max(int(np.floor(v)), 0) for v in allp.min(axis=0) - pad)
    x1 = min(int(np.ceil(allp[:, 0].max() + pad)), truth.width)
    y1 = min(int(np.ceil(allp[:, 1].max() + pad)), truth.height)
    if x1 <= x0 or y1 <= y0:
        return
    gy, gx = np.mgrid[y0:y1, x0:x1].astype(np.float64)
    bg = img[y0:y1, x0:x1].astype(np.float64)
    lit = light[y0:y1, x0:x1]
    acc = np.zeros_like(bg)
    n = next(iter(pos.values())).shape[0]
    for j in range(n):
        val = bg.copy()
        c = pos["ball"][j]
        if np.isfinite(c).all():
            dots = [pos[p][j] for p in ("dot_a", "dot_b") if p in pos]
            cov, rad = _ball_layer(gx, gy, c, sizes.ball, dots, sizes.dot)
            val += cov * (rad * lit - val)
        if "bat_tip" in pos and truth.bat_base_px is not None and np.isfinite(pos["bat_tip"][j]).all():
            cov, rad = _bat_layer(
                gx, gy, pos["bat_tip"][j], truth.bat_base_px, truth.impact_depth, sizes.barrel, sizes.marker
            )
            val += cov * (rad * lit - val)
        acc += val
    img[y0:y1, x0:x1] = acc / n


def _sub_offsets(truth: ClipTruth, k: int, exposure_frames: float) -> np.ndarray:
    """Offsets (frames) of the sub-exposures of frame ``k``: enough that each moves at most 0.5 px."""
    step = 0.0
    for p in truth.x:
        lo, hi = max(k - 1, 0), min(k + 1, truth.n_frames - 1)
        d = np.hypot(truth.x[p][hi] - truth.x[p][lo], truth.y[p][hi] - truth.y[p][lo]) / max(hi - lo, 1)
        if np.isfinite(d):
            step = max(step, d)
    n = int(np.clip(np.ceil(step * exposure_frames / 0.5), 1, 64))
    return (np.arange(n) + 0.5) / n * exposure_frames - exposure_frames / 2 if n > 1 else np.zeros(1)


def render_frames(truth: ClipTruth, look: Look, m_per_px: float) -> Iterator[np.ndarray]:
    """Yield the clip's frames one by one (uint8 for 8 bits, else uint16 holding ``bit_depth`` bits)."""
    light = lighting_field(truth.width, truth.height, look.lighting)
    back = background(truth.width, truth.height, look, light)
    sizes = _Sizes(
        truth.ball_radius_px,
        look.dot_radius_m / m_per_px,
        look.marker_radius_m / m_per_px,
        look.barrel_radius_m / m_per_px,
    )
    full = (1 << look.bit_depth) - 1
    dtype = np.uint8 if look.bit_depth == 8 else np.uint16
    rng = np.random.default_rng([look.seed, 0x5E45])
    exposure_frames = look.exposure_s * truth.fps
    for k in range(truth.n_frames):
        img = back.copy()
        _draw(img, light, truth, _sample_positions(truth, k, _sub_offsets(truth, k, exposure_frames)), sizes)
        sd = np.sqrt(look.read_noise**2 + look.shot_noise**2 * np.clip(img, 0, None))
        img += sd * rng.standard_normal(img.shape, dtype=np.float32)
        yield np.clip(np.rint(img * full), 0, full).astype(dtype)
