"""The impact and the free flight of the ball (each camera; steps 1-2 of :mod:`ballbat.tracks.reduce`).

1. **Impact**: the ball's rest position is the median of its first :data:`N_REST` tracked
   frames; the first frame from which the ball stays further than a threshold
   (``max(THRESHOLD_FLOOR_PX, THRESHOLD_SIGMA x`` the rest scatter)) is the impact frame; the
   last frame before it at rest is ``rest_frame`` (:func:`find_onset`).
2. **Free flight**: from ``ceil(CONTACT_MAX fps)`` frames after impact, x = a + v_x u and
   y + g u^2/2 = b + v_y u, a linear least-squares fit with the residual scatter as noise,
   stated along and across the motion apart (a blurred ball scatters more along its motion;
   the fit itself is the same: both coordinates share one design, so weighting by a 2 x 2
   scatter leaves it unchanged).
   Earlier frames that agree with the flight (within :data:`SEPARATION_SIGMA` sigma) are
   added; the first one is the separation frame; u is the time from separation (half a frame
   before it) (:func:`fit_flight`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..batched import nanmedian_rows
from ..units import G
from .masked import first_true, last_true, msum, take_at

if TYPE_CHECKING:
    from numpy.typing import ArrayLike


#: Frames at rest whose median is the ball's rest position.
N_REST = 5


#: Motion threshold in pixels: at least this, and THRESHOLD_SIGMA times the rest scatter.
THRESHOLD_FLOOR_PX = 3.0


THRESHOLD_SIGMA = 8.0


#: Longest contact (s): "under a millisecond" (Sec. II).
CONTACT_MAX = 1.0e-3


#: A frame within this many sigma of the flight fit is already in free flight.
SEPARATION_SIGMA = 4.0


@dataclass
class Onset:
    """Impact found in one camera's ball track (columns; -1 where not found)."""

    onset: np.ndarray
    rest: np.ndarray
    rest_x: np.ndarray
    rest_y: np.ndarray
    found: np.ndarray


def _rest_scatter(x: np.ndarray, y: np.ndarray, rest: np.ndarray) -> np.ndarray:
    """Tracking scatter per coordinate (px) from successive differences of the frames at rest.

    Differences of neighbouring rest frames do not depend on the rest position, so a few
    frames give an unbiased estimate (the deviations from a median of five frames include
    exact zeros and underestimate it). Their mean is removed, so a track that is already
    moving steadily (no rest filmed) shows a small scatter and no rest.
    """
    pair = rest[:, 1:] & rest[:, :-1]
    n = pair.sum(axis=1)
    with np.errstate(all="ignore"):
        dx = np.where(pair, np.diff(x, axis=1), 0.0)
        dy = np.where(pair, np.diff(y, axis=1), 0.0)
        mx = dx.sum(axis=1) / np.maximum(n, 1)
        my = dy.sum(axis=1) / np.maximum(n, 1)
        ss = np.sum(np.where(pair, (dx - mx[:, None]) ** 2 + (dy - my[:, None]) ** 2, 0.0), axis=1)
        return np.where(n > 1, np.sqrt(ss / (4 * np.maximum(n - 1, 1))), np.nan)


def find_onset(x: np.ndarray, y: np.ndarray) -> Onset:
    """First column from which the ball stays away from its rest position (pixels).

    Parameters
    ----------
    x, y : ndarray
        Ball centre, (impact, column) pixels, NaN where not tracked.

    Returns
    -------
    Onset
    """
    valid = np.isfinite(x) & np.isfinite(y)
    rank = np.cumsum(valid, axis=1)
    early = valid & (rank <= N_REST)
    cols = np.arange(x.shape[1])[None, :]
    # numpy.nanmedian's numbers, without masked arrays, over the columns up to the last early frame
    # (the same values: the columns after it hold none)
    end = int(last_true(early.any(axis=0)[None, :])[0]) + 1
    x0 = nanmedian_rows(np.where(early, x, np.nan)[:, :end])
    y0 = nanmedian_rows(np.where(early, y, np.nan)[:, :end])
    # Two passes: the tracking scatter from the first frames, then from every frame at rest
    # before the impact that pass found (more frames, a steadier threshold).
    rest_frames = early
    for _ in range(2):
        sig = _rest_scatter(x, y, rest_frames)
        thr = np.maximum(THRESHOLD_FLOOR_PX, THRESHOLD_SIGMA * np.nan_to_num(sig))
        d = np.hypot(x - x0[:, None], y - y0[:, None])
        moving = valid & (d > thr[:, None])
        ok_after = moving | ~valid
        stays = np.flip(np.cumprod(np.flip(ok_after, axis=1), axis=1), axis=1).astype(bool)
        onset = first_true(moving & stays)
        before = cols < onset[:, None]
        rest_frames = np.where((onset > 0)[:, None], valid & ~moving & before, early)
    rest = last_true(valid & ~moving & (cols < np.where(onset < 0, 0, onset)[:, None]))
    n_rest = np.sum(valid & ~moving & before, axis=1)
    n_moving_before = np.sum(moving & before, axis=1)
    # a real rest: at least two frames at rest and none away from rest before the impact
    found = (onset > 0) & (rest >= 0) & (n_rest >= 2) & (n_moving_before == 0)
    return Onset(np.where(found, onset, -1), np.where(found, rest, -1), x0, y0, found)


@dataclass
class Flight:
    """Free-flight fit of one camera's ball track (physical frame, m and s).

    ``var_along`` and ``var_across``: the variance of the velocity's component along the motion
    (the speed) and across it (the speed times the direction), each from the residuals' scatter
    in that direction.
    """

    vx: np.ndarray
    vy: np.ndarray
    var_along: np.ndarray
    var_across: np.ndarray
    x0: np.ndarray
    y0: np.ndarray
    t_ref: np.ndarray
    sigma: np.ndarray
    n: np.ndarray
    separation: np.ndarray
    mask: np.ndarray
    u_mean: np.ndarray
    sxx: np.ndarray

    def centre(self, t: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Fitted centre at times ``t`` (impact, column)."""
        u = t - self.t_ref[:, None]
        return self.x0[:, None] + self.vx[:, None] * u, self.y0[:, None] + self.vy[:, None] * u - 0.5 * G * u**2


def _line_fit(u, X, Y, w):
    """X = a + b u and Y + g u^2/2 = c + d u on the same frames; the pooled scatter, and the slopes' variances.

    The variances are those of the velocity along the motion and across it, each from the residuals'
    scatter in that direction (n - 2 degrees of freedom).
    """
    n = msum(np.ones_like(u), w)
    with np.errstate(all="ignore"):
        um = msum(u, w) / n
        du = u - um[:, None]
        sxx = msum(du**2, w)
        Yc = Y + 0.5 * G * u**2
        bx = msum(du * X, w) / sxx
        by = msum(du * Yc, w) / sxx
        ax = msum(X, w) / n - bx * um
        ay = msum(Yc, w) / n - by * um
        rx = X - ax[:, None] - bx[:, None] * u
        ry = Yc - ay[:, None] - by[:, None] * u
        ss = msum(rx**2 + ry**2, w)
        sigma = np.sqrt(ss / (2 * n - 4))
        cos, sin = (bx / np.hypot(bx, by))[:, None], (by / np.hypot(bx, by))[:, None]
        ss_along = msum((rx * cos + ry * sin) ** 2, w)
        var = (ss_along / (n - 2) / sxx, (ss - ss_along) / (n - 2) / sxx)
        return ax, bx, ay, by, sigma, var, n, np.hypot(rx, ry), um, sxx


def fit_flight(X: ArrayLike, Y: ArrayLike, t: ArrayLike, onset: Onset, fps: float) -> Flight:
    """Fit free flight after the contact; find the separation frame from the data.

    Parameters
    ----------
    X, Y : ndarray
        Ball centre (m) in the physical frame (X along the swing, Y up), NaN untracked.
    t : ndarray
        Time of each column (s).
    onset : Onset
        The impact found in this camera.
    fps : float
        Frame rate.

    Returns
    -------
    Flight
    """
    valid = np.isfinite(X) & np.isfinite(Y)
    cols = np.arange(X.shape[1])[None, :]
    n_c = int(np.ceil(CONTACT_MAX * fps - 1e-9))
    on = onset.onset[:, None]
    first = valid & onset.found[:, None] & (cols >= on + n_c)
    t_ref = take_at(t, first_true(first))
    u = t - t_ref[:, None]
    ax, bx, ay, by, sigma, _, n, res, um, sxx = _line_fit(u, X, Y, first.astype(float))
    # separation: the first frame from which every frame agrees with the flight (earlier
    # frames of the contact window lag behind it); the fit itself keeps to the safe frames
    cand = valid & onset.found[:, None] & (cols >= on) & (cols < on + n_c)
    agree = cand & (res < SEPARATION_SIGMA * sigma[:, None])
    last_bad = last_true(cand & ~agree)
    sep_col = np.where(last_bad >= 0, last_bad + 1, onset.onset)
    sep_col = np.where(onset.found, np.minimum(sep_col, first_true(first)), -1)
    mask = first
    t_ref = take_at(t, sep_col) - 0.5 / fps
    u = t - t_ref[:, None]
    ax, bx, ay, by, sigma, (var_along, var_across), n, res, um, sxx = _line_fit(u, X, Y, mask.astype(float))
    return Flight(bx, by, var_along, var_across, ax, ay, t_ref, sigma, n.astype(int), sep_col, mask, um, sxx)
