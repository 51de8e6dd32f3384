"""The ball's spin (spin camera, frames after separation; step 4 of :mod:`ballbat.tracks.reduce`).

Each dot's angle about the fitted ball centre, unwrapped frame to frame, fitted by one
straight line per dot with a common slope omega (counter-clockwise on the image for a +x
swing is backspin, > 0), then jointly with the centre (:func:`fit_spin`). A dot rotates
about the centre when the scatter of its distance from the centre is what the tracking
noise alone gives (:func:`radius_scatter_limit`).
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import TYPE_CHECKING

import numpy as np

from ..batched import full_rank, gram, tdot
from ..units import G
from .data import Camera
from .fit_flight import Flight
from .masked import first_true, msum, take_at

if TYPE_CHECKING:
    from numpy.typing import ArrayLike


#: Apparent spin per frame beyond which unwrapping is ambiguous (rad per frame).
UNWRAP_LIMIT = 0.75 * np.pi


#: Times the dots' angles are unwrapped again about the fitted spin (:func:`fit_spin`).
SPIN_REUNWRAP = 3


#: A dot rotates about the centre when the scatter of its distance from the centre is
#: what the tracking noise alone gives (F test, false-alarm probability
#: RADIUS_FALSE_ALARM per dot), or below RADIUS_TOLERANCE x its mean radius.
RADIUS_TOLERANCE = 0.05


RADIUS_FALSE_ALARM = 1e-3


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
    from scipy.special import fdtri  # scipy.stats.f.isf's own number (its ppf at 1 - q), without its checks

    n = np.asarray(n, dtype=float)
    dof2 = np.asarray(noise_dof, dtype=float)
    ok = (n >= 2) & (dof2 >= 1)
    q = fdtri(np.maximum(n - 1, 1), np.maximum(dof2, 1), 1.0 - RADIUS_FALSE_ALARM)
    with np.errstate(all="ignore"):
        lim = np.asarray(noise, dtype=float) * np.sqrt((1 + 2 / np.maximum(n, 1)) * q)
    return np.where(ok, lim, np.nan)


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
    first = first_true(mask)
    start = take_at(phi, first)
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
            pm = msum(phi, w) / n
            sums[p] = (n, tm, pm, W)
            sxt = sxt + W * msum((t - tm[:, None]) * (phi - pm[:, None]), w)
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
        gx0 = gx0 + msum(wk * dy / rho2, w)
        gvx = gvx + msum(wk * u * dy / rho2, w)
        gy0 = gy0 - msum(wk * dx / rho2, w)
        gvy = gvy - msum(wk * u * dx / rho2, w)
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
    n = msum(np.ones_like(t), w)
    rho = np.hypot(dx, dy)
    radius = msum(rho, w) / n
    radius_sd = np.sqrt(msum((rho - radius[:, None]) ** 2, w) / (n - 1))
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
            tm = msum(t, w) / n
            pm = msum(phi, w) / n
            W = radius[p] ** 2  # angle noise ~ tracking noise / radius: weight ~ radius^2
            sums[p] = (n, tm, pm, W)
            sxt = sxt + W * msum((t - tm[:, None]) * (phi - pm[:, None]), w)
            sxy = sxy + W * msum((t - tm[:, None]) ** 2, w)
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
            ss = ss + W * msum(r**2, masks[p].astype(float))
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
                msum((angle[p] - intercept[p][:, None] - omega[:, None] * t) ** 2, masks[p].astype(float))
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

#: Offset of the dots' circle from the ball's centre (m) that the test tolerates: a tilt of the spin
#: axis of about 1.3 degrees (the dots 22 mm above their circle), whose effect on the spin is below
#: 1e-4 of it, and several times the centre's and the dots' systematic errors in precise tracks
#: (0.03-0.1 px: 0.04-0.13 mm in the paper's spin camera), which a test of no offset at all read as
#: tilts once the dots were located to 0.03 px (docs/tracks.md).
OFFSET_TOLERANCE = 0.5e-3


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


def _spin_design(wd, ud, ub, wb) -> tuple[np.ndarray, np.ndarray]:
    """Return :func:`_spin_block`'s Jacobian (impact, 6, frame, 9) with what no iteration changes, and its residuals.

    Row blocks: the ball's x and y, then x and y of each dot (:func:`_spin_dot_rows` fills
    the columns that move with the parameters). Each entry is the same product (value x
    weight) the blocks were once stacked from, so the normal equations do not change by a bit.
    """
    n, nf = ub.shape
    J = np.empty((n, 6, nf, 9))
    r = np.empty((n, 6, nf))
    zero, one = np.zeros_like(ub), np.ones_like(ub)
    ball = ([-one, -ub, zero, zero] + [zero] * 5, [zero, zero, -one, -ub] + [zero] * 5)
    for k, cols in enumerate(ball):
        for c, v in enumerate(cols):
            J[:, k, :, c] = v * wb
    for j, d in enumerate(("dot_a", "dot_b")):
        w, u = wd[d], ud[d]
        own, other = (5, 6), (7, 8)
        if j == 1:
            own, other = other, own
        xcols = {0: -one, 1: -u, 2: zero, 3: zero, other[0]: zero, other[1]: zero}
        ycols = {0: zero, 1: zero, 2: -one, 3: -u, other[0]: zero, other[1]: zero}
        for c in xcols:
            J[:, 2 + 2 * j, :, c] = xcols[c] * w
            J[:, 3 + 2 * j, :, c] = ycols[c] * w
    return J, r


def _spin_dot_rows(p, j, ct_x, ct_y, m, wd, ud, J, r) -> None:
    """Write dot ``j``'s residual rows (x, y) and the moving columns of its Jacobian at the parameters ``p``.

    For :func:`_spin_block` (:func:`_spin_design`'s ``J`` and ``r``): the dot at the ball's
    centre plus its radius turned by the spin; ``m`` its tracked frames, ``wd`` their weights,
    ``ud`` their times (0 untracked).
    """
    rho, phase = p[:, [5 + 2 * j]], p[:, [6 + 2 * j]]
    ang = phase + p[:, [4]] * ud
    c, sn = np.cos(ang), np.sin(ang)
    dcx, dcy = p[:, [0]] + p[:, [1]] * ud, p[:, [2]] + p[:, [3]] * ud - 0.5 * G * ud**2
    bx, by = 2 + 2 * j, 3 + 2 * j
    rc, rs = rho * c, rho * sn  # (-rho) c is -(rho c) to the bit: IEEE rounding is symmetric
    r[:, bx] = np.where(m, (ct_x - dcx - rc) * wd, 0.0)
    r[:, by] = np.where(m, (ct_y - dcy - rs) * wd, 0.0)
    k = 5 + 2 * j  # the dot's radius and phase
    np.multiply(rs * ud, wd, out=J[:, bx, :, 4])
    np.multiply(-c, wd, out=J[:, bx, :, k])
    np.multiply(rs, wd, out=J[:, bx, :, k + 1])
    np.negative(rc, out=rc)
    np.multiply(rc * ud, wd, out=J[:, by, :, 4])
    np.multiply(-sn, wd, out=J[:, by, :, k])
    np.multiply(rc, wd, out=J[:, by, :, k + 1])


def _offset_terms(J, r, wd) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return J'J_o, J_o'J_o and J_o'r of the offset's columns J_o (:func:`_numpy_steps`' last Jacobian and residuals).

    J_o: minus each dot row's weight on its coordinate (x rows in column 0, y rows in column 1).
    """
    nf = wd["dot_a"].shape[1]
    Jo = np.zeros((*r.shape, 2))
    nb = 2 * nf  # the ball's x and y rows come first, then x and y of each dot
    for j, d in enumerate(("dot_a", "dot_b")):
        k = nb + 2 * j * nf
        Jo[:, k : k + nf, 0] = -wd[d]
        Jo[:, k + nf : k + 2 * nf, 1] = -wd[d]
    return gram(J, Jo), gram(Jo), tdot(Jo, r)


def _offset_score(B, Vo, g, cov, ok, chi2) -> tuple[np.ndarray, np.ndarray]:
    """Score test of a common offset of the dots' circles (:func:`_spin_block`'s last step).

    ``B``, ``Vo``, ``g``: J'J_o, J_o'J_o and J_o'r of the offset's columns J_o at the last step.
    Returns the statistic (chi^2, 2 degrees of freedom; 0 where the offset is within
    :data:`OFFSET_TOLERANCE`: an impact is flagged where its offset is both significant and
    larger than that) and the offset (one Gauss-Newton step).
    """
    V = Vo - gram(B, cov @ B)
    V[~ok] = np.eye(2)
    step = -np.linalg.solve(V, g[..., None])[..., 0]
    score = np.sum(g * -step, axis=1) / chi2
    return np.where(np.hypot(step[:, 0], step[:, 1]) > OFFSET_TOLERANCE, score, 0.0), step


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

    Each step's normal equations are summed impact by impact in compiled code
    (:func:`ballbat.tracks.spin_kernel.normal_equations`, :data:`SPIN_COMPILED`), or as numpy's
    products of the whole Jacobian (:func:`_numpy_steps`, the reference).

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
        # what does not change between iterations: the dots' weights and times
        wd = {d: np.where(masks[d], 1.0 / s_dot[:, None], 0.0) for d in dots}
        ud = {d: np.where(masks[d], u, 0.0) for d in dots}
        steps = _compiled_steps if SPIN_COMPILED else _numpy_steps
        p, A, ss, ok, offset_terms = steps(p, (X, Y, ub, wb), ct_x, ct_y, masks, wd, ud)
        cov = np.linalg.inv(A)
        # the weights' scale from the residuals (the ball's and the dots' scatter are estimates)
        n_rows = 2 * (flight.mask.sum(axis=1) + masks["dot_a"].sum(axis=1) + masks["dot_b"].sum(axis=1))
        chi2 = ss / np.maximum(n_rows - 9, 1)
        err = np.sqrt(cov[:, 4, 4] * chi2)
        offset_chi2, step = _offset_score(*offset_terms, cov, ok, chi2)
    good = ok & np.isfinite(p[:, 4]) & np.isfinite(err)
    new_omega = np.where(good, p[:, 4], omega)
    new_err = np.where(good, err, omega_err)
    new_intercept = {
        d: np.where(good, p[:, 6 + 2 * j] - p[:, 4] * flight.t_ref, intercept[d])
        for j, d in enumerate(("dot_a", "dot_b"))
    }
    offset_chi2 = np.where(good, offset_chi2, np.nan)
    return new_omega, new_err, new_intercept, offset_chi2, np.where(good[:, None], step, np.nan)


#: The joint spin fit's normal equations compiled (:mod:`ballbat.tracks.spin_kernel`); False: numpy's (the reference).
SPIN_COMPILED = True


def _step(p, A, b):
    """Return the Gauss-Newton step's new parameters, and which impacts' normal equations were usable.

    Usable: finite and of full rank; an impact whose are not keeps its parameters (the identity, a zero right side).
    """
    ok = np.all(np.isfinite(A), axis=(1, 2)) & np.all(np.isfinite(b), axis=1)
    ok &= full_rank(np.where(ok[:, None, None], A, np.eye(9)))
    A[~ok] = np.eye(9)
    b[~ok] = 0.0
    return p - np.linalg.solve(A, b[..., None])[..., 0], ok


def _compiled_steps(p, ball, ct_x, ct_y, masks, wd, ud):
    """:data:`SPIN_GN_ITERATIONS` steps, each impact's normal equations summed in compiled code.

    Returns the parameters, the last step's normal matrix, sum of squared residuals and usable
    impacts, and the offset test's terms (J'J_o, J_o'J_o, J_o'r) at the last step.
    """
    from .spin_kernel import normal_equations

    dots = ("dot_a", "dot_b")
    stacked = [np.ascontiguousarray(np.stack([a[d] for d in dots]), dtype=float) for a in (ct_x, ct_y)]
    DM = np.ascontiguousarray(np.stack([masks[d] for d in dots]), dtype=np.bool_)
    DW, DU = (np.ascontiguousarray(np.stack([a[d] for d in dots]), dtype=float) for a in (wd, ud))
    ball = [np.ascontiguousarray(a, dtype=float) for a in ball]
    for k in range(SPIN_GN_ITERATIONS):
        last = k == SPIN_GN_ITERATIONS - 1
        A, b, ss, Bo, go, Go = normal_equations(np.ascontiguousarray(p), *ball, *stacked, DM, DW, DU, G, last)
        p, ok = _step(p, A, b)
    Vo = Go[:, None, None] * np.eye(2)
    return p, A, ss, ok, (Bo, Vo, go)


def _numpy_steps(p, ball, ct_x, ct_y, masks, wd, ud):
    """:func:`_compiled_steps` with numpy's products of the whole Jacobian (the reference)."""
    X, Y, ub, wb = ball
    J6, r6 = _spin_design(wd, ud, ub, wb)
    J, r = J6.reshape(ub.shape[0], -1, 9), r6.reshape(ub.shape[0], -1)  # views: rows (ball x, y, dots' x, y)
    for _ in range(SPIN_GN_ITERATIONS):
        cx, cy = p[:, [0]] + p[:, [1]] * ub, p[:, [2]] + p[:, [3]] * ub - 0.5 * G * ub**2
        r6[:, 0] = np.where(wb > 0, (X - cx) * wb, 0.0)
        r6[:, 1] = np.where(wb > 0, (Y - cy) * wb, 0.0)
        for j, d in enumerate(("dot_a", "dot_b")):
            _spin_dot_rows(p, j, ct_x[d], ct_y[d], masks[d], wd[d], ud[d], J6, r6)
        A = gram(J)
        p, ok = _step(p, A, tdot(J, r))
    return p, A, np.sum(r**2, axis=1), ok, _offset_terms(J, r, wd)
