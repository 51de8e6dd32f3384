"""Reduce raw camera tracks to the impacts the chain analyses (Sec. II).

Per impact, all impacts at once (dense arrays, masked sums; no Python loop over impacts):

1. **Impact** (each camera): the ball's rest position is the median of its first
   :data:`N_REST` tracked frames; the first frame from which the ball stays further than a
   threshold (``max(THRESHOLD_FLOOR_PX, THRESHOLD_SIGMA x`` the rest scatter)) is the
   impact frame; the last frame before it at rest is ``rest_frame``.
2. **Free flight** (each camera): from ``ceil(CONTACT_MAX fps)`` frames after impact,
   x = a + v_x u and y + g u^2/2 = b + v_y u, a linear least-squares fit with the
   residual scatter as noise. Earlier frames that agree with the flight (within
   :data:`SEPARATION_SIGMA` sigma) are added; the first one is the separation frame; u is
   the time from separation (half a frame before it). Swing camera: v_ball and the launch
   angle (to the horizontal, in the swing direction).
3. **Contact** (swing camera): the contact's middle from the free flight extrapolated back to
   the rest position, its duration a nuisance parameter fitted to the ball's departure from
   rest (:func:`fit_contact`); its start, with its uncertainty.
   **Bat** (swing camera, frames before the contact's start only: the bat slows in the
   collision): the tip dot's positions give the swing direction (principal axis: the
   swing-plane angle beta) and, along it, u(t) = a + L sin(Omega (t - tau)) (a circle about
   the pivot seen edge-on, L = pivot_to_tip), fitted by Gauss-Newton with a prior
   tau ~ contact start +- (its error and TAU_PRIOR_FRAMES in quadrature);
   v_bat = Omega pivot_to_impact. theta = launch - beta.
4. **Spin** (spin camera, frames after separation): each dot's angle about the fitted
   ball centre, unwrapped frame to frame, fitted by one straight line per dot with a
   common slope omega (counter-clockwise on the image for a +x swing is backspin, > 0).

Uncertainties are the fits' own: residual scatter times the square root of the
(co)variance of the fitted parameters. A relative pixel-scale uncertainty
(``Camera.m_per_px_err``) is a systematic shared by all impacts of the camera: it scales
v_bat and v_ball together and is reported apart (``*_err_scale``).

Exclusions (flag > 0, values kept where they could be computed): no impact found; too
few frames for a fit; a dot whose distance from the ball's centre is not constant (the
dots do not rotate about the centre: a tilted spin axis); a spin too fast for the frame
rate to unwrap. Exclude, never drop.

:func:`reduce_tracks` returns a :class:`Reduction` (arrays and fits); the stage
:mod:`ballbat.stages.reduce` declares ``reduce.nc`` and assembles it.
"""

from __future__ import annotations

import enum
import functools
from dataclasses import dataclass, fields, replace
from typing import TYPE_CHECKING

import numpy as np

from ..batched import full_rank, gram, nanmedian_rows, tdot
from ..units import G
from .checks import IMPACT_Z, START_MARKS, camera_agreement, glitch_mask, misplaced_starts
from .data import CONTACT_PRIOR, POINTS, Camera, CameraTracks, Rig, Tracks
from .render import contact_distance

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

#: Frames at rest whose median is the ball's rest position.
N_REST = 5
#: Motion threshold in pixels: at least this, and THRESHOLD_SIGMA times the rest scatter.
THRESHOLD_FLOOR_PX = 3.0
THRESHOLD_SIGMA = 8.0
#: Longest contact (s): "under a millisecond" (Sec. II).
CONTACT_MAX = 1.0e-3
#: Grid points of the contact-time posterior (10 us steps over CONTACT_PRIOR).
CONTACT_GRID = 181
#: Narrowest spread of the contact times' distribution among a ball type's impacts
#: (:func:`_contact_population`), in grid steps: a peak no narrower than the grid resolves.
CONTACT_MIN_SD_STEPS = 2.0
#: A frame within this many sigma of the flight fit is already in free flight.
SEPARATION_SIGMA = 4.0
#: Sd of the prior on the bat's alignment time tau, in frames, beside the contact start's own error (its centre).
TAU_PRIOR_FRAMES = 0.6
#: Gauss-Newton iterations of the tip fit.
GN_ITERATIONS = 6
#: Apparent spin per frame beyond which unwrapping is ambiguous (rad per frame).
UNWRAP_LIMIT = 0.75 * np.pi
#: Times the dots' angles are unwrapped again about the fitted spin (:func:`fit_spin`).
SPIN_REUNWRAP = 3
#: A dot rotates about the centre when the scatter of its distance from the centre is
#: what the tracking noise alone gives (F test, false-alarm probability
#: RADIUS_FALSE_ALARM per dot), or below RADIUS_TOLERANCE x its mean radius.
RADIUS_TOLERANCE = 0.05
RADIUS_FALSE_ALARM = 1e-3


class ReduceFlag(enum.IntEnum):
    """Why an impact is excluded by the reduction (0: usable)."""

    OK = 0
    NO_IMPACT = 1
    TOO_FEW_FRAMES = 2
    DOT_NOT_ROTATING_ABOUT_CENTRE = 3
    SPIN_TOO_FAST = 4
    CAMERAS_DISAGREE = 5
    IMPLAUSIBLE = 6
    MISPLACED_MARK = 7


#: Name of the flag the rest of the chain reads (the source stage's exclusions).
FLAG_VAR = "ingest_flag"
#: Stage named in every exclusion reason this module gives.
STAGE = "reduce"


@dataclass(frozen=True)
class ReduceOptions:
    """Fewest frames per fit (the fits need at least two more than their parameters).

    No field has a default: the defaults are the config schema's ``min_frames`` alone
    (:func:`ballbat.stages.reduce.reduce_options`; :meth:`schema_defaults`).
    """

    min_tip_frames: int
    min_flight_frames: int
    min_spin_frames: int

    @classmethod
    def schema_defaults(cls) -> ReduceOptions:
        """Return the options the config schema gives a block without ``min_frames``."""
        from ..pipeline.config import checked_block

        mf = checked_block({}, "min_frames")
        return cls(int(mf["tip"]), int(mf["flight"]), int(mf["spin"]))


# ---------------------------------------------------------------------------------------
# masked helpers (arrays are (impact, column); w is a 0/1 float mask)


def _msum(a, w):
    return np.sum(np.where(w > 0, a, 0.0), axis=1)


def _first(mask):
    """Index of the first True column, -1 if none."""
    any_ = mask.any(axis=1)
    return np.where(any_, np.argmax(mask, axis=1), -1)


def _last(mask):
    any_ = mask.any(axis=1)
    return np.where(any_, mask.shape[1] - 1 - np.argmax(mask[:, ::-1], axis=1), -1)


def _take(a, idx):
    return np.take_along_axis(a, np.clip(idx, 0, a.shape[1] - 1)[:, None], axis=1)[:, 0]


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
    x0 = nanmedian_rows(np.where(early, x, np.nan))  # numpy.nanmedian's numbers, without masked arrays
    y0 = nanmedian_rows(np.where(early, y, np.nan))
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
        onset = _first(moving & stays)
        before = cols < onset[:, None]
        rest_frames = np.where((onset > 0)[:, None], valid & ~moving & before, early)
    rest = _last(valid & ~moving & (cols < np.where(onset < 0, 0, onset)[:, None]))
    n_rest = np.sum(valid & ~moving & before, axis=1)
    n_moving_before = np.sum(moving & before, axis=1)
    # a real rest: at least two frames at rest and none away from rest before the impact
    found = (onset > 0) & (rest >= 0) & (n_rest >= 2) & (n_moving_before == 0)
    return Onset(np.where(found, onset, -1), np.where(found, rest, -1), x0, y0, found)


@dataclass
class Flight:
    """Free-flight fit of one camera's ball track (physical frame, m and s)."""

    vx: np.ndarray
    vy: np.ndarray
    vx_var: np.ndarray
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
    """X = a + b u and Y + g u^2/2 = c + d u on the same frames; pooled residual scatter."""
    n = _msum(np.ones_like(u), w)
    with np.errstate(all="ignore"):
        um = _msum(u, w) / n
        du = u - um[:, None]
        sxx = _msum(du**2, w)
        Yc = Y + 0.5 * G * u**2
        bx = _msum(du * X, w) / sxx
        by = _msum(du * Yc, w) / sxx
        ax = _msum(X, w) / n - bx * um
        ay = _msum(Yc, w) / n - by * um
        rx = X - ax[:, None] - bx[:, None] * u
        ry = Yc - ay[:, None] - by[:, None] * u
        ss = _msum(rx**2 + ry**2, w)
        sigma = np.sqrt(ss / (2 * n - 4))
        return ax, bx, ay, by, sigma, sigma**2 / sxx, n, np.hypot(rx, ry), um, sxx


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
    t_ref = _take(t, _first(first))
    u = t - t_ref[:, None]
    ax, bx, ay, by, sigma, var, n, res, um, sxx = _line_fit(u, X, Y, first.astype(float))
    # separation: the first frame from which every frame agrees with the flight (earlier
    # frames of the contact window lag behind it); the fit itself keeps to the safe frames
    cand = valid & onset.found[:, None] & (cols >= on) & (cols < on + n_c)
    agree = cand & (res < SEPARATION_SIGMA * sigma[:, None])
    last_bad = _last(cand & ~agree)
    sep_col = np.where(last_bad >= 0, last_bad + 1, onset.onset)
    sep_col = np.where(onset.found, np.minimum(sep_col, _first(first)), -1)
    mask = first
    t_ref = _take(t, sep_col) - 0.5 / fps
    u = t - t_ref[:, None]
    ax, bx, ay, by, sigma, var, n, res, um, sxx = _line_fit(u, X, Y, mask.astype(float))
    return Flight(bx, by, var, ax, ay, t_ref, sigma, n.astype(int), sep_col, mask, um, sxx)


@dataclass
class Swing:
    """Tip-dot fit: angular speed of the bat before impact and the swing direction."""

    omega: np.ndarray
    omega_err: np.ndarray
    beta: np.ndarray
    beta_err: np.ndarray
    tau: np.ndarray
    a: np.ndarray
    ux: np.ndarray
    uy: np.ndarray
    cx: np.ndarray
    cy: np.ndarray
    rms: np.ndarray
    n: np.ndarray
    mask: np.ndarray


def radius_scatter_limit(noise: ArrayLike, noise_dof: ArrayLike, n: ArrayLike) -> np.ndarray:
    """Largest rms of a dot's distance from the ball's centre that tracking noise explains.

    The distance's scatter over ``n`` frames is the tracking noise (per coordinate, estimated
    from the free-flight fit with ``noise_dof`` degrees of freedom) plus the fitted centre's
    own error (about noise x sqrt(2 / n)). The ratio of its sample variance (``n - 1``
    degrees of freedom) to the estimated noise variance follows an F distribution; it
    exceeds the returned limit squared with probability :data:`RADIUS_FALSE_ALARM`.

    Parameters
    ----------
    noise : ndarray
        Tracking noise (m) per impact.
    noise_dof : ndarray
        Degrees of freedom of that estimate.
    n : ndarray
        Frames of the dot.

    Returns
    -------
    ndarray
        NaN where ``n`` < 2 or the noise has no degree of freedom.
    """
    from scipy import stats

    n = np.asarray(n, dtype=float)
    dof2 = np.asarray(noise_dof, dtype=float)
    ok = (n >= 2) & (dof2 >= 1)
    q = stats.f.isf(RADIUS_FALSE_ALARM, np.maximum(n - 1, 1), np.maximum(dof2, 1))
    with np.errstate(all="ignore"):
        lim = np.asarray(noise, dtype=float) * np.sqrt((1 + 2 / np.maximum(n, 1)) * q)
    return np.where(ok, lim, np.nan)


@dataclass
class Contact:
    """Each impact's contact, fitted from the ball's departure from rest (swing camera; s)."""

    t_mid: np.ndarray
    t_start: np.ndarray
    t_start_err: np.ndarray
    duration: np.ndarray
    duration_err: np.ndarray
    n: np.ndarray


def _beta_weights(grid: np.ndarray, p: ArrayLike) -> np.ndarray:
    """Weights on the grid of a beta distribution over its range with mean logistic(p[0]) and concentration exp(p[1]).

    Cell centres of the grid, so both ends stay finite; the concentration is held so that
    the standard deviation is at least :data:`CONTACT_MIN_SD_STEPS` grid steps.
    """
    m = 1.0 / (1.0 + np.exp(-p[0]))
    kappa = min(np.exp(p[1]), m * (1 - m) * (grid.size / CONTACT_MIN_SD_STEPS) ** 2)
    log_x, log_1mx = _beta_logs(grid.size)
    logw = (m * kappa - 1) * log_x + ((1 - m) * kappa - 1) * log_1mx
    w = np.exp(logw - logw.max())
    return w / w.sum()


@functools.lru_cache(maxsize=8)
def _beta_logs(n: int) -> tuple[np.ndarray, np.ndarray]:
    """log(x) and log(1 - x) at the cell centres x of a grid of ``n`` (read-only; computed once per n).

    :func:`_beta_weights` runs inside the Nelder-Mead search of :func:`_contact_population`, a
    hundred times a replicate, on the same grid.
    """
    x = (np.arange(n) + 0.5) / n
    logs = np.log(x), np.log1p(-x)
    for a in logs:
        a.flags.writeable = False
    return logs


def _contact_population(lik: np.ndarray, groups: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """Per impact, the distribution of contact times among its group's impacts (grid weights).

    A beta distribution over the grid's range whose mean and concentration maximise the group's
    marginal likelihood, prod_i sum_j lik_ij w_j (Nelder-Mead from the uniform
    distribution, beta(1, 1)). Smooth on purpose: the nonparametric maximum-likelihood
    distribution is a few spikes, and posteriors under it understate their spread (by 1.2-1.7x
    in tests). A beta family holds the uniform distribution and ones piled at either end of
    the range, so likelihoods that say little leave it near uniform and many weak ones
    together still find where the contacts lie (an EM on a normal cut to the range shrank it
    towards the middle when the likelihoods were flat, and was therefore not run on them: at
    5 px and 0.5 ms contacts every duration came out 0.2-0.5 ms long). A group with no finite
    likelihood gets the uniform distribution.
    """
    from scipy.optimize import minimize

    prior = np.full(lik.shape, 1.0 / lik.shape[1])
    for g in np.unique(groups):
        rows = (groups == g) & np.all(np.isfinite(lik), axis=1)
        if not rows.any():
            continue
        L = np.ascontiguousarray(lik[rows] / lik[rows].max(axis=1, keepdims=True))

        def nll(p, L=L):
            # elementwise and summed along rows, not a BLAS product: the same bits wherever L lies in memory
            return -float(np.sum(np.log(np.sum(L * _beta_weights(grid, p)[None, :], axis=1) + 1e-300)))

        uniform = np.array([0.0, np.log(2.0)])  # beta(1, 1)
        simplex = uniform + np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
        best = minimize(
            nll, uniform, method="Nelder-Mead", options={"initial_simplex": simplex, "xatol": 1e-3, "fatol": 1e-6}
        )
        p = best.x if best.fun < nll(uniform) - 1e-9 * len(L) else uniform  # flat: no gain, uniform kept
        prior[groups == g] = _beta_weights(grid, p)
    return prior


def fit_contact(
    X: ArrayLike, Y: ArrayLike, t: ArrayLike, onset: Onset, flight: Flight, groups: ArrayLike | None = None
) -> Contact:
    """Each impact's contact interval from the ball's track, with its uncertainty.

    The free flight extrapolated back passes the rest position at the impulse-weighted mean
    time of the contact ``t_mid`` (its midpoint for a symmetric force pulse). The contact
    lasts ``t_c``: the ball leaves rest at ``t_mid - t_c / 2`` and, under a force that follows
    sin^2 (the shape of a ball-bat force pulse: :func:`.render.contact_distance`), is
    ``v contact_distance(t - t_mid + t_c / 2, t_c)`` along its flight direction until
    ``t_mid + t_c / 2``, then on its free flight. ``t_c`` is a nuisance parameter: its
    likelihood on a grid over :data:`CONTACT_PRIOR` from the ball's frames within the widest
    contact about ``t_mid`` (Gaussian, the flight fit's noise per coordinate). The prior is
    the distribution of contact times among the impacts of the same group (ball type),
    estimated from all their likelihoods (:func:`_contact_population`), so that the
    posterior means are unbiased on average over the group even where the frames say
    little (a uniform prior would pull every one towards the middle of its range).
    The posterior's mean and standard deviation give the contact's duration and start;
    the start's error adds the extrapolated ``t_mid``'s. With no frame inside the contact
    the posterior is the group's distribution.

    Parameters
    ----------
    X, Y : ndarray
        Ball centre (m), physical frame, NaN untracked.
    t : ndarray
        Time of each column (s).
    onset : Onset
        The impact found in this camera.
    flight : Flight
        Its free-flight fit.
    groups : ndarray, optional
        Group of each impact (its ball type); one group if None.

    Returns
    -------
    Contact
        NaN where no impact was found.
    """
    X = np.asarray(X, dtype=float)
    Y = np.asarray(Y, dtype=float)
    t = np.asarray(t, dtype=float)
    valid = np.isfinite(X) & np.isfinite(Y)
    cols = np.arange(X.shape[1])[None, :]
    at_rest = valid & (cols <= onset.rest[:, None]) & onset.found[:, None]
    w = at_rest.astype(float)
    lo, hi = CONTACT_PRIOR
    with np.errstate(all="ignore"):
        v2 = flight.vx**2 + flight.vy**2
        v = np.sqrt(v2)
        for _ in range(2):  # the rest position from frames before the longest contact can have begun
            n_rest = w.sum(axis=1)
            xr, yr = _msum(X, w) / n_rest, _msum(Y, w) / n_rest
            u = ((xr - flight.x0) * flight.vx + (yr - flight.y0) * flight.vy) / v2
            t_mid = flight.t_ref + u
            early = at_rest & (t < t_mid[:, None] - 0.5 * hi)
            w = np.where(early.sum(axis=1)[:, None] >= 2, early, at_rest).astype(float)
        # error of t_mid: the extrapolated line's position error at u, over the speed
        var_pos = flight.sigma**2 * (1 / flight.n + (u - flight.u_mean) ** 2 / flight.sxx)
        t_mid_err = np.sqrt(var_pos + flight.sigma**2 / n_rest) / v
        s = ((X - xr[:, None]) * flight.vx[:, None] + (Y - yr[:, None]) * flight.vy[:, None]) / v[:, None]
        dt = t - t_mid[:, None]
        win = valid & onset.found[:, None] & (np.abs(dt) < 0.5 * hi)
        win &= np.isfinite(dt)
        # the window's columns only (a few frames per impact)
        first = np.where(win.any(axis=1), np.argmax(win, axis=1), 0)
        width = int(max(1, np.max(np.where(win.any(axis=1), _last(win) - first + 1, 1))))
        idx = np.minimum(first[:, None] + np.arange(width)[None, :], X.shape[1] - 1)
        dtw, sw = np.take_along_axis(dt, idx, axis=1), np.take_along_axis(s, idx, axis=1)
        ww = np.take_along_axis(win, idx, axis=1) & (first[:, None] + np.arange(width)[None, :] < X.shape[1])
        grid = np.linspace(lo, hi, CONTACT_GRID)
        logl = np.empty((X.shape[0], grid.size))
        for j, tc in enumerate(grid):
            x = np.clip(dtw + 0.5 * tc, 0.0, tc)  # time since the start, within the contact
            model = v[:, None] * (contact_distance(x, tc) + np.maximum(dtw - 0.5 * tc, 0.0))
            logl[:, j] = -0.5 * _msum((sw - model) ** 2, ww.astype(float)) / flight.sigma**2
        logl -= np.max(logl, axis=1, keepdims=True)
        lik = np.exp(logl)
        grp = np.zeros(X.shape[0], dtype=int) if groups is None else np.unique(groups, return_inverse=True)[1]
        post = lik * _contact_population(lik, np.where(onset.found, grp, -1), grid)
        post /= post.sum(axis=1, keepdims=True)
        tc_mean = post @ grid
        tc_err = np.sqrt(np.maximum(post @ grid**2 - tc_mean**2, 0.0))
    ok = onset.found & (n_rest > 0) & np.isfinite(t_mid) & np.isfinite(tc_mean)
    nan = np.full(X.shape[0], np.nan)
    return Contact(
        t_mid=np.where(ok, t_mid, nan),
        t_start=np.where(ok, t_mid - 0.5 * tc_mean, nan),
        t_start_err=np.where(ok, np.hypot(t_mid_err, 0.5 * tc_err), nan),
        duration=np.where(ok, tc_mean, nan),
        duration_err=np.where(ok, tc_err, nan),
        n=np.where(ok, win.sum(axis=1), 0).astype(int),
    )


def _swing_axis(X: np.ndarray, Y: np.ndarray, t: np.ndarray, w: np.ndarray, n: np.ndarray) -> tuple:
    """Return the tip's centroid and the principal axis of its marks, oriented along the motion.

    Returns ``cx, cy, ux, uy, tm, along, perp``: the centroid, the axis' unit vector (later
    frames further along), the mean time, and each mark's distance along and across the axis.
    """
    cx, cy = _msum(X, w) / n, _msum(Y, w) / n
    dx, dy = X - cx[:, None], Y - cy[:, None]
    sxx, syy, sxy = _msum(dx * dx, w), _msum(dy * dy, w), _msum(dx * dy, w)
    phi = 0.5 * np.arctan2(2 * sxy, sxx - syy)  # principal axis
    ux, uy = np.cos(phi), np.sin(phi)
    # orient along the motion: later frames further along
    tm = _msum(t, w) / n
    forward = _msum((t - tm[:, None]) * (dx * ux[:, None] + dy * uy[:, None]), w) >= 0
    ux, uy = np.where(forward, ux, -ux), np.where(forward, uy, -uy)
    along = dx * ux[:, None] + dy * uy[:, None]
    perp = -dx * uy[:, None] + dy * ux[:, None]
    return cx, cy, ux, uy, tm, along, perp


def fit_swing(
    X: ArrayLike,
    Y: ArrayLike,
    t: ArrayLike,
    onset: Onset,
    fps: float,
    L: float,
    t_contact: ArrayLike,
    t_contact_err: ArrayLike | float = 0.0,
) -> Swing:
    """Fit the tip dot's pre-impact motion (a circle of radius L about the pivot, seen edge-on).

    Parameters
    ----------
    X, Y : ndarray
        Tip dot (m) in the physical frame, NaN untracked.
    t : ndarray
        Time of each column (s).
    onset : Onset
        The impact found in the swing camera (its ball track).
    fps : float
        Frame rate.
    L : float
        Pivot-to-tip distance (m).
    t_contact : ndarray
        Start of the contact (:func:`fit_contact`): only earlier frames are fitted (the
        bat slows in the collision), and the tip is aligned with the impact then (the prior
        of the alignment time tau).
    t_contact_err : ndarray or float
        Its uncertainty (s): the prior's sd is this and :data:`TAU_PRIOR_FRAMES` in quadrature.

    Returns
    -------
    Swing
    """
    valid = np.isfinite(X) & np.isfinite(Y)
    t_contact = np.asarray(t_contact, dtype=float)
    found = onset.found & np.isfinite(t_contact)
    mask = valid & found[:, None] & (t < np.where(found, t_contact, -np.inf)[:, None])
    w = mask.astype(float)
    n = _msum(np.ones_like(X), w)
    with np.errstate(all="ignore"):
        cx, cy, ux, uy, tm, along, perp = _swing_axis(X, Y, t, w, n)
        beta = np.arctan2(uy, ux)
        s_perp = np.sqrt(_msum(perp**2, w) / (n - 2))
        # Student-t: with few frames the scatter estimate is itself uncertain (sd of t with n - 2 dof)
        beta_err = s_perp / np.sqrt(_msum(along**2, w)) * np.sqrt((n - 2) / np.maximum(n - 4, 1))

        tau0 = np.where(found, t_contact, 0.0)
        st = tm - tau0
        slope = _msum((t - tm[:, None]) * along, w) / _msum((t - tm[:, None]) ** 2, w)
        om = slope / L
        a = -L * np.sin(om * st)  # start: u = a + L sin(om (t - tau0)) through the centroid
        tau = tau0.copy()
        prior = np.full_like(om, 1e12)  # first iterations: tau held at its prior
        sigma_tau = np.hypot(TAU_PRIOR_FRAMES / fps, np.nan_to_num(np.asarray(t_contact_err, dtype=float)))
        for it in range(GN_ITERATIONS):
            arg = om[:, None] * (t - tau[:, None])
            c = np.cos(arg)
            r = along - (a[:, None] + L * np.sin(arg))
            J = np.stack([np.ones_like(t), L * (t - tau[:, None]) * c, -L * om[:, None] * c], axis=-1)
            J = np.where(mask[..., None], J, 0.0)
            r = np.where(mask, r, 0.0)
            A = gram(J)
            b = tdot(J, r)
            A[:, 2, 2] += prior
            b[:, 2] += prior * (tau0 - tau)
            ok = n >= 4
            A[~ok] = np.eye(3)
            b[~ok] = 0.0
            step = np.linalg.solve(A, b[..., None])[..., 0]
            a, om, tau = a + step[:, 0], om + step[:, 1], tau + step[:, 2]
            if it == 1:
                rr = np.where(mask, along - (a[:, None] + L * np.sin(om[:, None] * (t - tau[:, None]))), 0.0)
                s2 = np.sum(rr**2, axis=1) / (n - 2)
                prior = s2 / sigma_tau**2
        rr = np.where(mask, along - (a[:, None] + L * np.sin(om[:, None] * (t - tau[:, None]))), 0.0)
        s2 = np.sum(rr**2, axis=1) / (n - 3)
        arg = om[:, None] * (t - tau[:, None])
        c = np.cos(arg)
        J = np.stack([np.ones_like(t), L * (t - tau[:, None]) * c, -L * om[:, None] * c], axis=-1)
        J = np.where(mask[..., None], J, 0.0)
        A = gram(J)
        A[:, 2, 2] += s2 / sigma_tau**2
        A[~(n >= 4)] = np.eye(3)
        cov = np.linalg.inv(A) * s2[:, None, None]
        omega_err = np.sqrt(cov[:, 1, 1] * (n - 3) / np.maximum(n - 5, 1))  # Student-t, as for beta
        rms = np.sqrt(np.sum(rr**2, axis=1) / n)
    return Swing(om, omega_err, beta, beta_err, tau, a, ux, uy, cx, cy, rms, n.astype(int), mask)


@dataclass
class Spin:
    """Dot-angle fit: spin, and each dot's radius about the ball's centre."""

    omega: np.ndarray
    omega_err: np.ndarray
    rms: np.ndarray
    n: np.ndarray
    radius: dict
    radius_sd: dict
    angle: dict
    intercept: dict
    mask: dict
    max_step: np.ndarray
    #: score test that the dots turn about a point off the ball's centre (a tilted axis), chi^2 with 2
    #: degrees of freedom, and that point's offset from the centre (m, x and y): :func:`_spin_joint_fit`
    offset_chi2: np.ndarray | None = None
    offset: np.ndarray | None = None


def _unwrap(phi, mask):
    """Unwrap angles along columns over the masked (tracked) frames only; gaps keep the last angle."""
    cols = np.arange(phi.shape[1])[None, :]
    idx = np.where(mask, cols, -1)
    prev = np.maximum.accumulate(idx, axis=1)
    prev_before = np.concatenate([np.full((phi.shape[0], 1), -1), prev[:, :-1]], axis=1)
    has_prev = mask & (prev_before >= 0)
    p_prev = np.take_along_axis(phi, np.clip(prev_before, 0, None), axis=1)
    gap = np.where(has_prev, cols - prev_before, 1)
    d = np.where(has_prev, np.angle(np.exp(1j * (phi - p_prev))), 0.0)
    first = _first(mask)
    start = _take(phi, first)
    out = start[:, None] + np.cumsum(d, axis=1)
    per_frame = np.where(has_prev, np.abs(d) / gap, 0.0)
    return np.where(mask, out, np.nan), per_frame.max(axis=1)


def _reunwrap(omega, sxy, raw, t, sums, angle, masks):
    """Unwrap the dots' angles again, each to the turn nearest the fitted line; return the spin.

    The frame-to-frame unwrap fails where a dot's angle noise (tracking noise / radius) is
    large, and since the dots turn one way its failures are one-sided (a dot of 12 mm at 6 mm
    of noise: spin 4 % low). ``sums`` and ``angle`` (per dot) are updated in place.
    """
    for _ in range(SPIN_REUNWRAP):
        sxt = 0.0
        for p in ("dot_a", "dot_b"):
            n, tm, pm, W = sums[p]
            w = masks[p].astype(float)
            line = (pm - omega * tm)[:, None] + omega[:, None] * t
            phi = np.where(masks[p], line + np.angle(np.exp(1j * (raw[p] - line))), np.nan)
            pm = _msum(phi, w) / n
            sums[p] = (n, tm, pm, W)
            sxt = sxt + W * _msum((t - tm[:, None]) * (phi - pm[:, None]), w)
            angle[p] = phi
        omega = sxt / sxy
    return omega


def _centre_variance(ct_x, ct_y, cx, cy, t, flight: Flight, sums, masks, sxy):
    """Return the angle fit's spin variance from the fitted centre's errors.

    They are common to all frames and both dots: the centre's covariance (intercept and
    velocity of each coordinate) propagated through the dot angles.
    """
    u = t - flight.t_ref[:, None]
    gx0 = gvx = gy0 = gvy = 0.0
    for p in ("dot_a", "dot_b"):
        _, tm, _, W = sums[p]
        w = masks[p].astype(float)
        dx, dy = ct_x[p] - cx, ct_y[p] - cy
        rho2 = dx**2 + dy**2
        wk = W[:, None] * (t - tm[:, None]) / sxy[:, None]
        gx0 = gx0 + _msum(wk * dy / rho2, w)
        gvx = gvx + _msum(wk * u * dy / rho2, w)
        gy0 = gy0 - _msum(wk * dx / rho2, w)
        gvy = gvy - _msum(wk * u * dx / rho2, w)
    c2, um, sx = flight.sigma**2, flight.u_mean, flight.sxx
    return c2 * (
        (gx0**2 + gy0**2) * (1 / flight.n + um**2 / sx) + (gvx**2 + gvy**2) / sx - 2 * (gx0 * gvx + gy0 * gvy) * um / sx
    )


def _dot_about_centre(dx: np.ndarray, dy: np.ndarray, t: np.ndarray, after: np.ndarray) -> tuple:
    """Return one dot's marks after separation about the ball's centre (errors ignored by the caller).

    ``mask, weights, count, mean distance, its sd, unwrapped angle, largest step`` per impact.
    """
    m = after & np.isfinite(dx) & np.isfinite(dy)
    w = m.astype(float)
    n = _msum(np.ones_like(t), w)
    rho = np.hypot(dx, dy)
    radius = _msum(rho, w) / n
    radius_sd = np.sqrt(_msum((rho - radius[:, None]) ** 2, w) / (n - 1))
    phi, step = _unwrap(np.arctan2(dy, dx), m)
    return m, w, n, radius, radius_sd, phi, step


def fit_spin(
    ct_x: ArrayLike, ct_y: ArrayLike, t: ArrayLike, flight: Flight, cam: Camera, ball: tuple | None = None
) -> Spin:
    """Fit the dots' angles about the fitted ball centre after separation.

    With the ball's track (``ball``), the spin is then fitted jointly with the centre's flight
    (:func:`_spin_joint_fit`): the angle about a fitted centre is not linear in the centre's
    error, and at large tracking noise it lowers the spin.

    Parameters
    ----------
    ct_x, ct_y : dict
        Dot positions in the physical frame (m), ``dot_a`` and ``dot_b``.
    t : ndarray
        Time of each column (s).
    flight : Flight
        Free-flight fit of the spin camera's ball track.
    cam : Camera
        The spin camera.
    ball : tuple of ndarray, optional
        The spin camera's ball centre (X, Y), m, as ``flight`` was fitted to.

    Returns
    -------
    Spin
    """
    cx, cy = flight.centre(t)
    cols = np.arange(t.shape[1])[None, :]
    after = (cols >= flight.separation[:, None]) & (flight.separation[:, None] >= 0)
    sxt = sxy = 0.0
    n_tot = 0
    res_parts = []
    radius, radius_sd, angle, intercept, masks = {}, {}, {}, {}, {}
    max_step = np.zeros(t.shape[0])
    sums = {}
    with np.errstate(all="ignore"):
        for p in ("dot_a", "dot_b"):
            m, w, n, radius[p], radius_sd[p], phi, step = _dot_about_centre(ct_x[p] - cx, ct_y[p] - cy, t, after)
            max_step = np.maximum(max_step, step)
            tm = _msum(t, w) / n
            pm = _msum(phi, w) / n
            W = radius[p] ** 2  # angle noise ~ tracking noise / radius: weight ~ radius^2
            sums[p] = (n, tm, pm, W)
            sxt = sxt + W * _msum((t - tm[:, None]) * (phi - pm[:, None]), w)
            sxy = sxy + W * _msum((t - tm[:, None]) ** 2, w)
            n_tot = n_tot + n
            angle[p], masks[p] = phi, m
        omega = _reunwrap(
            sxt / sxy, sxy, {p: np.arctan2(ct_y[p] - cy, ct_x[p] - cx) for p in masks}, t, sums, angle, masks
        )
        ss = 0.0
        for p in ("dot_a", "dot_b"):
            n, tm, pm, W = sums[p]
            intercept[p] = pm - omega * tm
            r = angle[p] - intercept[p][:, None] - omega[:, None] * t
            ss = ss + W * _msum(r**2, masks[p].astype(float))
            res_parts.append(r)
        s2 = ss / (n_tot - 3)
        omega_err = np.sqrt(s2 / sxy + _centre_variance(ct_x, ct_y, cx, cy, t, flight, sums, masks, sxy))
        offset_chi2 = offset = None
        if ball is not None:
            omega, omega_err, intercept, offset_chi2, offset = _spin_joint_fit(
                ball, ct_x, ct_y, t, flight, omega, omega_err, intercept, radius, masks, np.sqrt(s2)
            )
        rms = np.sqrt(
            sum(
                _msum((angle[p] - intercept[p][:, None] - omega[:, None] * t) ** 2, masks[p].astype(float))
                for p in masks
            )
            / n_tot
        )
    return Spin(
        omega,
        omega_err,
        rms,
        np.asarray(n_tot).astype(int),
        radius,
        radius_sd,
        angle,
        intercept,
        masks,
        max_step,
        offset_chi2,
        offset,
    )


#: Gauss-Newton iterations of the joint fit of spin and centre (:func:`_spin_joint_fit`).
SPIN_GN_ITERATIONS = 4
#: False-alarm probability of the test that the dots turn about a point off the ball's centre.
OFFSET_FALSE_ALARM = 1e-3


#: Impacts per block of the joint spin fit (its design matrix is impacts x 6 columns x 9 parameters).
SPIN_FIT_BLOCK = 2000


def _spin_joint_fit(ball, ct_x, ct_y, t, flight: Flight, omega, omega_err, intercept, radius, masks, s_dot):
    """:func:`_spin_block` on blocks of :data:`SPIN_FIT_BLOCK` impacts (a bounded memory), joined."""
    n = t.shape[0]
    if n <= SPIN_FIT_BLOCK:
        return _spin_block(ball, ct_x, ct_y, t, flight, omega, omega_err, intercept, radius, masks, s_dot)
    parts = []
    for lo in range(0, n, SPIN_FIT_BLOCK):
        sl = slice(lo, lo + SPIN_FIT_BLOCK)

        def cut(x, sl=sl):
            return {k: v[sl] for k, v in x.items()} if isinstance(x, dict) else x[sl]

        fl = replace(flight, **{f.name: getattr(flight, f.name)[sl] for f in fields(flight)})
        parts.append(
            _spin_block(
                tuple(cut(b) for b in ball),
                cut(ct_x),
                cut(ct_y),
                cut(t),
                fl,
                cut(omega),
                cut(omega_err),
                cut(intercept),
                cut(radius),
                cut(masks),
                cut(s_dot),
            )
        )
    joined = []
    for k, first in enumerate(parts[0]):
        if isinstance(first, dict):
            joined.append({d: np.concatenate([p[k][d] for p in parts]) for d in first})
        else:
            joined.append(np.concatenate([p[k] for p in parts]))
    return tuple(joined)


def _spin_dot_rows(p, j, ct_x, ct_y, m, wd, ud, zero_one):
    """Residual rows (x, y) and their Jacobian blocks (impact, frame, 9) of dot ``j`` at the parameters ``p``.

    For :func:`_spin_block`: the dot at the ball's centre plus its radius turned by the
    spin; ``m`` its tracked frames, ``wd`` their weights, ``ud`` their times (0 untracked),
    ``zero_one`` arrays of 0 and 1 of their shape.
    """
    zero, one = zero_one
    rho, phase = p[:, [5 + 2 * j]], p[:, [6 + 2 * j]]
    ang = phase + p[:, [4]] * ud
    c, sn = np.cos(ang), np.sin(ang)
    dcx, dcy = p[:, [0]] + p[:, [1]] * ud, p[:, [2]] + p[:, [3]] * ud - 0.5 * G * ud**2
    rows = [np.where(m, (ct_x - dcx - rho * c) * wd, 0.0), np.where(m, (ct_y - dcy - rho * sn) * wd, 0.0)]
    jx = [-one, -ud, zero, zero, rho * sn * ud] + ([-c, rho * sn, zero, zero] if j == 0 else [zero, zero, -c, rho * sn])
    jy = [zero, zero, -one, -ud, -rho * c * ud] + (
        [-sn, -rho * c, zero, zero] if j == 0 else [zero, zero, -sn, -rho * c]
    )
    return rows, [np.stack(jx, axis=-1) * wd[..., None], np.stack(jy, axis=-1) * wd[..., None]]


def _spin_block(ball, ct_x, ct_y, t, flight: Flight, omega, omega_err, intercept, radius, masks, s_dot):
    """Fit the spin, the dots' radii and phases and the ball's flight together, on positions.

    The angle of a dot about the flight's fitted centre is not linear in the centre's error
    (nor in the dot's own when the noise is a good part of the radius), so the slope of
    those angles is low by a part in 10^3 at 5 px of noise, 0.03 of its error on every
    impact, which a ball's 200 impacts add up to 0.13 of eta^2's error (softballs, 60 per
    bat; docs/tracks.md). On the
    positions, where the noise is Gaussian, one least-squares fit of the ball's centre
    (:meth:`Flight.centre`'s model) and the dots turning about it at one spin has no such
    bias. Each coordinate of the ball is weighted by the flight fit's scatter, each of a
    dot's by the angle fit's (``s_dot``). Starts at the angle fit; an impact whose fit
    does not converge to finite values keeps the angle fit's spin and error.

    The fit also tests whether the dots turn about the ball's centre at all: a spin axis tilted
    from the line of sight moves the circle the dots trace off the centre, by the dot's
    height above its circle times the sine of the tilt (5-15 mm for tilts of 15-40 degrees).
    The score test of a common offset of both dots' circles (chi^2, 2 degrees of freedom)
    tells such an axis where the scatter of the dots' radii cannot (large noise).

    Returns
    -------
    omega, omega_err, intercept, offset_chi2, offset
        The spin (rad/s), its standard error, each dot's phase at t = 0, the offset's score
        statistic and the offset itself (m, (impact, 2); one Gauss-Newton step).
    """
    X, Y = ball
    u = t - flight.t_ref[:, None]
    ub = np.where(flight.mask, u, 0.0)
    p = np.stack(
        [flight.x0, flight.vx, flight.y0, flight.vy, omega]
        + [v for d in ("dot_a", "dot_b") for v in (radius[d], intercept[d] + omega * flight.t_ref)],
        axis=1,
    )
    wb = np.where(flight.mask, 1.0 / flight.sigma[:, None], 0.0)
    dots = ("dot_a", "dot_b")
    with np.errstate(all="ignore"):
        # what does not change between iterations: the dots' weights and times, the ball's Jacobian
        wd = {d: np.where(masks[d], 1.0 / s_dot[:, None], 0.0) for d in dots}
        ud = {d: np.where(masks[d], u, 0.0) for d in dots}
        zero, one = np.zeros_like(u), np.ones_like(u)
        ball_jac = [
            np.stack([-one, -ub, zero, zero] + [zero] * 5, axis=-1) * wb[..., None],
            np.stack([zero, zero, -one, -ub] + [zero] * 5, axis=-1) * wb[..., None],
        ]
        for _ in range(SPIN_GN_ITERATIONS):
            cx, cy = p[:, [0]] + p[:, [1]] * ub, p[:, [2]] + p[:, [3]] * ub - 0.5 * G * ub**2
            rows = [np.where(wb > 0, (X - cx) * wb, 0.0), np.where(wb > 0, (Y - cy) * wb, 0.0)]
            jac = list(ball_jac)
            for j, d in enumerate(dots):
                r_d, j_d = _spin_dot_rows(p, j, ct_x[d], ct_y[d], masks[d], wd[d], ud[d], (zero, one))
                rows += r_d
                jac += j_d
            r = np.concatenate(rows, axis=1)
            J = np.concatenate(jac, axis=1)
            A = gram(J)
            b = tdot(J, r)
            ok = np.all(np.isfinite(A), axis=(1, 2)) & np.all(np.isfinite(b), axis=1)
            ok &= full_rank(np.where(ok[:, None, None], A, np.eye(9)))
            A[~ok] = np.eye(9)
            b[~ok] = 0.0
            p = p - np.linalg.solve(A, b[..., None])[..., 0]
        cov = np.linalg.inv(A)
        # the weights' scale from the residuals (the ball's and the dots' scatter are estimates)
        n_rows = 2 * (flight.mask.sum(axis=1) + masks["dot_a"].sum(axis=1) + masks["dot_b"].sum(axis=1))
        chi2 = np.sum(r**2, axis=1) / np.maximum(n_rows - 9, 1)
        err = np.sqrt(cov[:, 4, 4] * chi2)
        # score test of a common offset of the dots' circles (the last iteration's residuals and design)
        Jo = np.zeros((*r.shape, 2))
        nb = 2 * u.shape[1]  # the ball's x and y rows come first, then x and y of each dot
        for j, d in enumerate(dots):
            k = nb + 2 * j * u.shape[1]
            Jo[:, k : k + u.shape[1], 0] = -wd[d]
            Jo[:, k + u.shape[1] : k + 2 * u.shape[1], 1] = -wd[d]
        B = gram(J, Jo)
        V = gram(Jo) - gram(B, cov @ B)
        g = tdot(Jo, r)
        V[~ok] = np.eye(2)
        step = -np.linalg.solve(V, g[..., None])[..., 0]
        offset_chi2 = np.sum(g * -step, axis=1) / chi2
    good = ok & np.isfinite(p[:, 4]) & np.isfinite(err)
    new_omega = np.where(good, p[:, 4], omega)
    new_err = np.where(good, err, omega_err)
    new_intercept = {
        d: np.where(good, p[:, 6 + 2 * j] - p[:, 4] * flight.t_ref, intercept[d])
        for j, d in enumerate(("dot_a", "dot_b"))
    }
    offset_chi2 = np.where(good, offset_chi2, np.nan)
    return new_omega, new_err, new_intercept, offset_chi2, np.where(good[:, None], step, np.nan)


@dataclass
class Reduction:
    """Everything the reduction found, per impact (for the results file and the QA figure)."""

    tracks: Tracks
    cameras: dict
    rig: Rig
    onset: dict
    flight: dict
    swing: Swing
    spin: Spin
    times: dict
    phys: dict
    values: dict
    flag: np.ndarray
    reason: np.ndarray
    n_outliers: dict
    agreement: object = None
    contact: Contact | None = None
    shifts: object = None  # calibration systematics (ballbat.systematics.reduce_shifts), when asked for


def remove_glitches(tracks: Tracks, cameras: dict[str, Camera]) -> tuple[Tracks, dict[str, np.ndarray]]:
    """Return the tracks without their single-frame glitches (:func:`.checks.glitch_mask`), and the count per impact.

    The ball's and the dots' frames from the last at rest to the end of the longest contact
    (:data:`CONTACT_MAX`) after the impact frame (:func:`find_onset` on the raw track) are
    not tested. The input is not changed. Counts are per camera (all its points), shape (impact,).
    """
    cams, counts = {}, {}
    for name, ct in tracks.cameras.items():
        xs, ys = {}, {}
        count = np.zeros(tracks.n, dtype=np.int64)
        on = find_onset(ct.x["ball"], ct.y["ball"])
        n_c = int(np.ceil(CONTACT_MAX * cameras[name].fps - 1e-9))
        cols = np.arange(ct.n_columns)[None, :]
        kink = on.found[:, None] & (cols >= on.rest[:, None] - 1) & (cols <= on.onset[:, None] + n_c + 1)
        for p in POINTS[name]:
            bad = glitch_mask(ct.x[p], ct.y[p], None if p == "bat_tip" else kink)
            xs[p], ys[p] = np.where(bad, np.nan, ct.x[p]), np.where(bad, np.nan, ct.y[p])
            count += bad.sum(axis=1)
        cams[name] = CameraTracks(ct.frame0, xs, ys)
        counts[name] = count
    return replace(tracks, cameras=cams), counts


def physical(ct: CameraTracks, cam: Camera, point: str) -> tuple[np.ndarray, np.ndarray]:
    """Pixel track -> physical frame (m): X along the swing direction's horizontal, Y up."""
    return cam.sign * ct.x[point] * cam.m_per_px, -ct.y[point] * cam.m_per_px


def reduce_tracks(
    tracks: Tracks, cameras: dict[str, Camera], rig: Rig, options: ReduceOptions | None = None
) -> Reduction:
    """Reduce every impact's tracks to v_bat, v_ball, theta, omega with fitted uncertainties.

    Parameters
    ----------
    tracks : Tracks
        Dense tracks of both cameras.
    cameras : dict
        ``swing`` and ``spin`` :class:`Camera` settings.
    rig : Rig
        Pivot-to-tip and pivot-to-impact distances.
    options : ReduceOptions, optional
        Fewest frames per fit (default: the config schema's, :meth:`ReduceOptions.schema_defaults`).

    Returns
    -------
    Reduction
        The fits, the values (SI) and the flag and reason of every impact.
    """
    opt = options or ReduceOptions.schema_defaults()
    tracks, n_outliers = remove_glitches(tracks, cameras)
    onset, flight, times, phys, contact, swing, spin = _fit_motions(tracks, cameras, rig)
    values = _measured_values(flight["swing"], swing, spin, contact, cameras, rig)
    flag, reason, agree = _exclusions(tracks, onset, flight, swing, spin, cameras, opt)
    return Reduction(
        tracks,
        cameras,
        rig,
        onset,
        flight,
        swing,
        spin,
        times,
        phys,
        values,
        flag,
        reason.astype(str),
        n_outliers,
        agree,
        contact,
    )


def _fit_motions(tracks: Tracks, cameras: dict[str, Camera], rig: Rig) -> tuple:
    """Fit every impact: the ball's onset and free flight in each camera, the contact, the swing, the spin.

    Returns ``onset, flight, times, phys, contact, swing, spin`` (:class:`Reduction`'s fields).
    """
    n = tracks.n
    onset, flight, times, phys = {}, {}, {}, {}
    for name in ("swing", "spin"):
        ct, cam = tracks.cameras[name], cameras[name]
        t = np.broadcast_to(np.arange(ct.n_columns)[None, :] / cam.fps, (n, ct.n_columns))
        times[name] = t
        onset[name] = find_onset(ct.x["ball"], ct.y["ball"])
        X, Y = physical(ct, cam, "ball")
        phys[(name, "ball")] = (X, Y)
        flight[name] = fit_flight(X, Y, t, onset[name], cam.fps)
    Xt, Yt = physical(tracks.cameras["swing"], cameras["swing"], "bat_tip")
    phys[("swing", "bat_tip")] = (Xt, Yt)
    contact = fit_contact(*phys[("swing", "ball")], times["swing"], onset["swing"], flight["swing"], tracks.ball)
    swing = fit_swing(
        Xt,
        Yt,
        times["swing"],
        onset["swing"],
        cameras["swing"].fps,
        rig.pivot_to_tip,
        contact.t_start,
        contact.t_start_err,
    )
    dots = {p: physical(tracks.cameras["spin"], cameras["spin"], p) for p in ("dot_a", "dot_b")}
    for p, v in dots.items():
        phys[("spin", p)] = v
    spin = fit_spin(
        {p: v[0] for p, v in dots.items()},
        {p: v[1] for p, v in dots.items()},
        times["spin"],
        flight["spin"],
        cameras["spin"],
        phys[("spin", "ball")],
    )
    return onset, flight, times, phys, contact, swing, spin


def _measured_values(
    fs: Flight, swing: Swing, spin: Spin, contact: Contact, cameras: dict[str, Camera], rig: Rig
) -> dict[str, np.ndarray]:
    """v_bat, v_ball, theta, omega and the other measured values of every impact (SI), from the fits.

    The ball's velocity is the flight fit's at the contact's end, where the ball leaves the bat
    (the fit's own velocity is at its reference time, the separation frame's, which is on
    average 0.17 ms before the contact's end at 1 px and 0.63 ms after it at 5 px, while gravity
    turns the flight down by g / v ~ 0.3 rad/s: +5e-5 to -2e-4 rad on every launch angle;
    without a fitted contact, the fit's own).
    """
    with np.errstate(all="ignore"):
        t_end = contact.t_mid + 0.5 * contact.duration - fs.t_ref
        known = np.isfinite(t_end)
        vy = np.where(known, fs.vy - G * t_end, fs.vy)
        v_ball = np.hypot(fs.vx, vy)
        v_ball_err = np.sqrt(fs.vx_var)  # same design for both components: isotropic
        launch = np.arctan2(vy, fs.vx)
        # the contact end's error turns the velocity by g cos(launch) / v per second
        end_err = np.where(known, contact.t_start_err, 0.0)  # t_mid + t_c / 2: the start's error
        launch_err = np.hypot(np.sqrt(fs.vx_var) / v_ball, G * np.cos(launch) * end_err / v_ball)
        theta = launch - swing.beta
        theta = np.angle(np.exp(1j * theta))
        theta_err = np.hypot(launch_err, swing.beta_err)
        v_bat = swing.omega * rig.pivot_to_impact
        v_bat_err = swing.omega_err * rig.pivot_to_impact
    rel = cameras["swing"].m_per_px_err
    values = {
        "v_bat": v_bat,
        "v_bat_err": v_bat_err,
        "v_ball": v_ball,
        "v_ball_err": v_ball_err,
        "theta": theta,
        "theta_err": theta_err,
        "omega": spin.omega,
        "omega_err": spin.omega_err,
        "v_bat_err_scale": np.abs(v_bat) * rel,
        "v_ball_err_scale": np.abs(v_ball) * rel,
        "swing_plane_angle": swing.beta,
        "swing_plane_angle_err": swing.beta_err,
        "launch_angle": launch,
        "launch_angle_err": launch_err,
        "contact_time": contact.duration,
        "contact_time_err": contact.duration_err,
    }
    return values


class _Marks:
    """The flag and reason of every impact: each impact keeps the first reason that applies."""

    def __init__(self, n: int):
        self.flag = np.zeros(n, dtype=np.int8)
        self.reason = np.full(n, "ok", dtype=object)

    def __call__(self, cond: np.ndarray, code: ReduceFlag, texts) -> None:
        new = cond & (self.flag == 0)
        self.flag[new] = code
        for i in np.flatnonzero(new):
            self.reason[i] = f"{STAGE}: {texts(i)}"


def _exclusions(
    tracks: Tracks, onset: dict, flight: dict, swing: Swing, spin: Spin, cameras: dict[str, Camera], opt: ReduceOptions
) -> tuple[np.ndarray, np.ndarray, object]:
    """Return the flag and reason of every impact (the first reason that applies), and the cameras' agreement."""
    mark = _Marks(tracks.n)
    _start_exclusions(mark, tracks)
    agree = _motion_exclusions(mark, onset, flight, swing, cameras, opt)
    _spin_exclusions(mark, flight, spin, cameras["spin"].fps, opt)
    return mark.flag, mark.reason, agree


def _start_exclusions(mark: _Marks, tracks: Tracks) -> None:
    """Mark impacts with a track whose first marks lie far off its run (:func:`.checks.misplaced_starts`)."""
    for cam, ct in tracks.cameras.items():
        for p in POINTS[cam]:
            ms = misplaced_starts(ct.x[p], ct.y[p])
            mark(
                ms.found,
                ReduceFlag.MISPLACED_MARK,
                lambda i, cam=cam, p=p, ms=ms, ct=ct: (
                    f"{p}'s mark at frame {int(ct.frame0[i] + ms.column[i])} in the {cam} camera (one of the track's "
                    f"first {START_MARKS}) lies {ms.distance[i]:.0f} px off the line of its next marks (noise "
                    f"{ms.noise[i]:.2f} px): a misplaced click? Fix or delete that mark in the tracking tool"
                ),
            )


def _motion_exclusions(
    mark: _Marks, onset: dict, flight: dict, swing: Swing, cameras: dict[str, Camera], opt: ReduceOptions
) -> object:
    """Mark impacts without an impact, with too few frames or whose cameras disagree; return the agreement."""
    for name in ("swing", "spin"):
        mark(
            ~onset[name].found,
            ReduceFlag.NO_IMPACT,
            lambda i, name=name: (
                f"no impact found in the {name} camera: its ball track never leaves a rest position "
                "(needs >= 2 frames at rest, then motion to the end of the track)"
            ),
        )
    for name in ("swing", "spin"):
        mark(
            flight[name].n < opt.min_flight_frames,
            ReduceFlag.TOO_FEW_FRAMES,
            lambda i, name=name: (
                f"{flight[name].n[i]} free-flight frame(s) of the ball in the {name} camera, "
                f"fewer than {opt.min_flight_frames}"
            ),
        )
    agree = camera_agreement(flight, cameras)
    mark(
        np.abs(agree.z_speed) > IMPACT_Z,
        ReduceFlag.CAMERAS_DISAGREE,
        lambda i: (
            f"the ball's speed differs between the cameras: {agree.v['swing'][i]:.2f} +- "
            f"{agree.v_err['swing'][i]:.2f} m/s in swing, {agree.v['spin'][i]:.2f} +- {agree.v_err['spin'][i]:.2f} in "
            f"spin (z = {agree.z_speed[i]:.1f}): rows filed under the wrong camera or impact?"
        ),
    )
    mark(
        np.abs(agree.z_angle) > IMPACT_Z,
        ReduceFlag.CAMERAS_DISAGREE,
        lambda i: (
            f"the ball's launch angle differs between the cameras: {np.degrees(agree.launch['swing'][i]):.1f} "
            f"+- {np.degrees(agree.launch_err['swing'][i]):.1f} deg in swing, "
            f"{np.degrees(agree.launch['spin'][i]):.1f} +- {np.degrees(agree.launch_err['spin'][i]):.1f} in spin "
            f"(z = {agree.z_angle[i]:.1f}): rows filed under the "
            "wrong camera or impact, or a mirror or y setting?"
        ),
    )
    mark(
        swing.n < opt.min_tip_frames,
        ReduceFlag.TOO_FEW_FRAMES,
        lambda i: f"{swing.n[i]} pre-impact frame(s) of bat_tip in the swing camera, fewer than {opt.min_tip_frames}",
    )
    return agree


def _spin_exclusions(mark: _Marks, flight: dict, spin: Spin, fps_spin: float, opt: ReduceOptions) -> None:
    """Mark impacts whose spin dots are too few, do not rotate about the ball's centre, or turn too fast."""
    for p in ("dot_a", "dot_b"):
        n_p = spin.mask[p].sum(axis=1)
        mark(
            n_p < opt.min_spin_frames,
            ReduceFlag.TOO_FEW_FRAMES,
            lambda i, p=p, n_p=n_p: (
                f"{n_p[i]} frame(s) of {p} after separation in the spin camera, fewer than {opt.min_spin_frames}"
            ),
        )
    noise = flight["spin"].sigma
    noise_dof = 2 * flight["spin"].n - 4  # two coordinates, four fitted parameters
    for p in ("dot_a", "dot_b"):
        allowed = np.maximum(
            RADIUS_TOLERANCE * spin.radius[p], radius_scatter_limit(noise, noise_dof, spin.mask[p].sum(axis=1))
        )
        mark(
            spin.radius_sd[p] > allowed,
            ReduceFlag.DOT_NOT_ROTATING_ABOUT_CENTRE,
            lambda i, p=p, allowed=allowed: (
                f"{p}'s distance from the ball's centre varies by "
                f"{1e3 * spin.radius_sd[p][i]:.1f} mm rms (mean {1e3 * spin.radius[p][i]:.1f} mm, allowed "
                f"{1e3 * allowed[i]:.1f} mm): the dots do not rotate about the centre (tilted spin axis?)"
            ),
        )
    if spin.offset_chi2 is not None:
        limit = -2.0 * np.log(OFFSET_FALSE_ALARM)  # chi^2 with 2 degrees of freedom
        mark(
            spin.offset_chi2 > limit,
            ReduceFlag.DOT_NOT_ROTATING_ABOUT_CENTRE,
            lambda i: (
                f"the dots turn about a point {1e3 * np.hypot(*spin.offset[i]):.1f} mm off the ball's centre "
                f"(score test chi^2 {spin.offset_chi2[i]:.1f}, limit {limit:.1f}): a spin axis tilted from "
                "the line of sight"
            ),
        )
    mark(
        spin.max_step > UNWRAP_LIMIT,
        ReduceFlag.SPIN_TOO_FAST,
        lambda i: (
            f"a dot turns up to {spin.max_step[i]:.2f} rad between frames (limit {UNWRAP_LIMIT:.2f}): "
            f"spin too fast for {fps_spin:g} fps to unwrap"
        ),
    )
