"""The bat's swing (swing camera, frames before the contact's start; step 3 of :mod:`ballbat.tracks.reduce`).

The tip dot's positions give the swing direction (principal axis: the swing-plane angle
beta) and, along it, u(t) = a + L sin(Omega (t - tau)) (a circle about the pivot seen
edge-on, L = pivot_to_tip), fitted by Gauss-Newton with a prior tau ~ contact start +- (its
error and :data:`TAU_PRIOR_FRAMES` in quadrature) (:func:`fit_swing`); v_bat = Omega
pivot_to_impact.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..batched import gram, tdot
from .fit_flight import Onset
from .masked import fitted_columns, msum

if TYPE_CHECKING:
    from numpy.typing import ArrayLike


#: Sd of the prior on the bat's alignment time tau, in frames, beside the contact start's own error (its centre).
TAU_PRIOR_FRAMES = 0.6


#: Gauss-Newton iterations of the tip fit.
GN_ITERATIONS = 6

#: The tip fit's iterations in compiled loops (:mod:`ballbat.tracks.swing_kernel`); False: numpy's (the reference).
SWING_COMPILED = True


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


def _swing_axis(X: np.ndarray, Y: np.ndarray, t: np.ndarray, w: np.ndarray, n: np.ndarray) -> tuple:
    """Return the tip's centroid and the principal axis of its marks, oriented along the motion.

    Returns ``cx, cy, ux, uy, tm, along, perp``: the centroid, the axis' unit vector (later
    frames further along), the mean time, and each mark's distance along and across the axis.
    """
    cx, cy = msum(X, w) / n, msum(Y, w) / n
    dx, dy = X - cx[:, None], Y - cy[:, None]
    sxx, syy, sxy = msum(dx * dx, w), msum(dy * dy, w), msum(dx * dy, w)
    phi = 0.5 * np.arctan2(2 * sxy, sxx - syy)  # principal axis
    ux, uy = np.cos(phi), np.sin(phi)
    # orient along the motion: later frames further along
    tm = msum(t, w) / n
    forward = msum((t - tm[:, None]) * (dx * ux[:, None] + dy * uy[:, None]), w) >= 0
    ux, uy = np.where(forward, ux, -ux), np.where(forward, uy, -uy)
    along = dx * ux[:, None] + dy * uy[:, None]
    perp = -dx * uy[:, None] + dy * ux[:, None]
    return cx, cy, ux, uy, tm, along, perp


def _swing_jacobian(J: np.ndarray, mask: np.ndarray, d_omega: np.ndarray, d_tau: np.ndarray) -> np.ndarray:
    """Write the columns of :func:`fit_swing`'s Jacobian that change (by omega and tau) into ``J``, 0 off ``mask``."""
    J[..., 1] = np.where(mask, d_omega, 0.0)
    J[..., 2] = np.where(mask, d_tau, 0.0)
    return J


def fit_swing(
    X: ArrayLike,
    Y: ArrayLike,
    t: ArrayLike,
    onset: Onset,
    fps: float,
    L: float,
    t_contact: ArrayLike,
    t_contact_err: ArrayLike | float = 0.0,
    exposure: float = 0.0,
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
        Start of the contact (:func:`~ballbat.tracks.fit_contact.fit_contact`): only earlier frames are fitted (the
        bat slows in the collision), and the tip is aligned with the impact then (the prior
        of the alignment time tau).
    t_contact_err : ndarray or float
        Its uncertainty (s): the prior's sd is this and :data:`TAU_PRIOR_FRAMES` in quadrature.
    exposure : float
        A frame's exposure time (s; 0: not known, a frame an instant). A frame is fitted only
        if a whole exposure after its time still ends before the contact's start: a frame's
        image is its exposure's average, and one exposed into the contact shows the bat
        already slowing (a lag of slowdown x speed x overlap^2 / (2 exposure): up to 0.06 px
        at 3000 fps and 50 us), which moved the alignment time and so the bat speed (docs/video.md).
        A whole exposure, not half: a camera's time stamp may mark its exposure's start or middle.

    Returns
    -------
    Swing
    """
    valid = np.isfinite(X) & np.isfinite(Y)
    t_contact = np.asarray(t_contact, dtype=float)
    found = onset.found & np.isfinite(t_contact)
    full_mask = valid & found[:, None] & (t + exposure < np.where(found, t_contact, -np.inf)[:, None])
    X, Y, t, mask = fitted_columns(full_mask, np.asarray(X, dtype=float), np.asarray(Y, dtype=float), t)
    w = mask.astype(float)
    n = msum(np.ones_like(X), w)
    with np.errstate(all="ignore"):
        cx, cy, ux, uy, tm, along, perp = _swing_axis(X, Y, t, w, n)
        beta = np.arctan2(uy, ux)
        s_perp = np.sqrt(msum(perp**2, w) / (n - 2))
        # Student-t: with few frames the scatter estimate is itself uncertain (sd of t with n - 2 dof)
        beta_err = s_perp / np.sqrt(msum(along**2, w)) * np.sqrt((n - 2) / np.maximum(n - 4, 1))

        tau0 = np.where(found, t_contact, 0.0)
        st = tm - tau0
        slope = msum((t - tm[:, None]) * along, w) / msum((t - tm[:, None]) ** 2, w)
        om = slope / L
        a = -L * np.sin(om * st)  # start: u = a + L sin(om (t - tau0)) through the centroid
        sigma_tau = np.hypot(TAU_PRIOR_FRAMES / fps, np.nan_to_num(np.asarray(t_contact_err, dtype=float)))
        iterations = _compiled_iterations if SWING_COMPILED else _numpy_iterations
        a, om, tau, omega_err, rms = iterations(along, t, mask, L, a, om, tau0, sigma_tau, n)
    return Swing(om, omega_err, beta, beta_err, tau, a, ux, uy, cx, cy, rms, n.astype(int), full_mask)


def _compiled_iterations(along, t, mask, L, a, om, tau0, sigma_tau, n) -> tuple:
    """Return :func:`fit_swing`'s a, omega, tau, omega's error and rms from its steps in compiled loops."""
    from .swing_kernel import gauss_newton

    vec = (np.ascontiguousarray(np.broadcast_to(v, om.shape), dtype=float) for v in (a, om, tau0, sigma_tau, n))
    return gauss_newton(
        np.ascontiguousarray(along, dtype=float),
        np.ascontiguousarray(np.broadcast_to(t, mask.shape), dtype=float),
        np.ascontiguousarray(mask),
        float(L),
        *vec,
        GN_ITERATIONS,
    )


def _numpy_iterations(along, t, mask, L, a, om, tau0, sigma_tau, n) -> tuple:
    """:func:`_compiled_iterations` with numpy's batched products and solves (the reference)."""
    with np.errstate(all="ignore"):
        tau = tau0.copy()
        prior = np.full_like(om, 1e12)  # first iterations: tau held at its prior
        J = np.empty((*mask.shape, 3))
        J[..., 0] = np.where(mask, 1.0, 0.0)
        for it in range(GN_ITERATIONS):
            arg = om[:, None] * (t - tau[:, None])
            c = np.cos(arg)
            r = along - (a[:, None] + L * np.sin(arg))
            J = _swing_jacobian(J, mask, L * (t - tau[:, None]) * c, -L * om[:, None] * c)
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
        J = _swing_jacobian(J, mask, L * (t - tau[:, None]) * c, -L * om[:, None] * c)
        A = gram(J)
        A[:, 2, 2] += s2 / sigma_tau**2
        A[~(n >= 4)] = np.eye(3)
        cov = np.linalg.inv(A) * s2[:, None, None]
        omega_err = np.sqrt(cov[:, 1, 1] * (n - 3) / np.maximum(n - 5, 1))  # Student-t, as for beta
        rms = np.sqrt(np.sum(rr**2, axis=1) / n)
    return a, om, tau, omega_err, rms
