"""A filmed pendulum: its period from tracked centres, and g from it and a length (docs/video.md, "A real clip").

The bob's position across the swing, ``x(t) = c + s t + A exp(-gamma t) cos(omega t + phi)``
(a damped sine with a slow drift), is fitted by least squares in pixels (:func:`fit_swing`);
omega's standard error comes from the residual scatter. Its path in the image is an arc of a
circle about the pivot (:func:`arc_radius`): its curvature gives the pendulum's length in pixels,
hence the amplitude in radians and the bob's radius as a fraction of the length.

g follows (:func:`pendulum_g`) from the undamped angular frequency ``omega0^2 = omega^2 +
gamma^2``, a sphere's equivalent length ``d + (2/5) r^2 / d`` (a rigid sphere of radius r whose
centre is d below the pivot) and the finite amplitude (the period grows as ``1 + theta0^2 / 16``):
``g = omega0^2 L_eq (1 + <theta0^2> / 8)``. The length's and the frame interval's errors are
systematic ones, carried beside the statistical one and combined with it in quadrature (g
scales as the length, and as the inverse square of the time).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import least_squares


@dataclass(frozen=True)
class SwingFit:
    """The fitted damped sine: omega (rad/s), its standard error, gamma (1/s), amplitude at t = 0 (px)."""

    omega: float
    se_omega: float
    gamma: float
    amplitude_px: float  # A at t = 0
    phase: float
    centre_px: float  # c: the swing's centre at t = 0
    drift_px_s: float  # s: the centre's drift
    rms_px: float  # the residuals' root mean square (px)
    n: int

    @property
    def period(self) -> float:
        """Return the period of the damped swing (s)."""
        return float(2 * np.pi / self.omega)

    @property
    def omega0(self) -> float:
        """Return the undamped angular frequency (rad/s): sqrt(omega^2 + gamma^2)."""
        return float(np.hypot(self.omega, self.gamma))

    def amplitude_at(self, t_s: ArrayLike) -> np.ndarray:
        """Return the swing's amplitude (px) at times ``t_s``."""
        return np.abs(self.amplitude_px) * np.exp(-self.gamma * np.asarray(t_s, float))

    def model(self, t_s: ArrayLike) -> np.ndarray:
        """Return the fitted position (px) at times ``t_s``."""
        t = np.asarray(t_s, float)
        return (
            self.centre_px
            + self.drift_px_s * t
            + self.amplitude_px * np.exp(-self.gamma * t) * np.cos(self.omega * t + self.phase)
        )


def _strongest_omega(t: np.ndarray, x: np.ndarray) -> float:
    """Return the angular frequency of the strongest peak of the positions' spectrum (resampled evenly)."""
    dt = float(np.median(np.diff(t)))
    grid = np.arange(t[0], t[-1], dt)
    xi = np.interp(grid, t, x - x.mean()) * np.hanning(grid.size)
    n = 1 << int(np.ceil(np.log2(grid.size * 16)))
    power = np.abs(np.fft.rfft(xi, n))
    power[:3] = 0.0  # not the drift
    return float(2 * np.pi * np.fft.rfftfreq(n, dt)[np.argmax(power)])


def fit_swing(t_s: ArrayLike, x_px: ArrayLike) -> SwingFit:
    """Fit x(t) = c + s t + A exp(-gamma t) cos(omega t + phi) to a swinging bob's positions (px) at ``t_s`` (s).

    The start is the spectrum's strongest peak; at least 3 periods and 20 points are needed
    (fewer, or times not increasing, is a ValueError saying which).
    """
    t, x = np.asarray(t_s, float).ravel(), np.asarray(x_px, float).ravel()
    if t.size != x.size or t.size < 20 or not np.all(np.isfinite(t)) or not np.all(np.isfinite(x)):
        raise ValueError(f"fit_swing: need at least 20 finite (t, x) pairs of equal length (got {t.size}, {x.size})")
    if np.any(np.diff(t) <= 0):
        raise ValueError("fit_swing: times must increase")
    w0 = _strongest_omega(t, x)
    if not w0 * (t[-1] - t[0]) >= 6 * np.pi:
        raise ValueError(f"fit_swing: {w0 * (t[-1] - t[0]) / (2 * np.pi):.1f} periods; at least 3 are needed")
    tc = float(t[0])
    tt = t - tc

    def resid(p):
        c, s, a, g, w, ph = p
        return c + s * tt + a * np.exp(-g * tt) * np.cos(w * tt + ph) - x

    amp = 0.5 * float(np.ptp(x))
    best = None
    for ph in np.linspace(0.0, 2 * np.pi, 8, endpoint=False):
        sol = least_squares(resid, [float(x.mean()), 0.0, amp, 0.0, w0, ph], x_scale="jac")
        if best is None or sol.cost < best.cost:
            best = sol
    c, s, a, g, w, ph = best.x
    res = best.fun
    dof = t.size - 6
    cov = np.linalg.pinv(best.jac.T @ best.jac) * float(res @ res) / dof
    # the fit's time origin is t[0]: move the amplitude, phase and centre to t = 0
    return SwingFit(
        omega=float(w),
        se_omega=float(np.sqrt(cov[4, 4])),
        gamma=float(g),
        amplitude_px=float(a * np.exp(g * tc)),
        phase=float(ph - w * tc),
        centre_px=float(c - s * tc),
        drift_px_s=float(s),
        rms_px=float(np.sqrt(np.mean(res**2))),
        n=int(t.size),
    )


def arc_radius(x_px: ArrayLike, y_px: ArrayLike) -> tuple[float, float]:
    """Return the radius (px) of the bob's arc and its standard error, from y = a + b x + c x^2 (y down).

    A pendulum's bob, filmed across its swing, is lowest (largest image y) at the middle:
    y = y_low - (x - x0)^2 / (2 L) near the bottom, so L = -1 / (2 c). An arc bending the other
    way, or too flat to tell (c within 2 standard errors of 0), is a ValueError.
    """
    x, y = np.asarray(x_px, float).ravel(), np.asarray(y_px, float).ravel()
    if x.size != y.size or x.size < 4:
        raise ValueError(f"arc_radius: need at least 4 (x, y) pairs of equal length (got {x.size}, {y.size})")
    xc = x.mean()
    design = np.column_stack([np.ones_like(x), x - xc, (x - xc) ** 2])
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    res = y - design @ coef
    cov = np.linalg.inv(design.T @ design) * float(res @ res) / (x.size - 3)
    c, se_c = float(coef[2]), float(np.sqrt(cov[2, 2]))
    if not c < -2 * se_c:
        raise ValueError(f"arc_radius: curvature {c:.3g} +- {se_c:.2g} /px: no arc bending up about a pivot above")
    return -1 / (2 * c), se_c / (2 * c * c)


@dataclass(frozen=True)
class PendulumG:
    """g from a period and a length (m/s^2) with its errors, and what went into it."""

    g: float
    se_stat: float  # from omega's standard error
    se_length: float  # from the length's error
    se_time: float  # from the frame interval's error
    length_eq_m: float  # the equivalent simple pendulum's length
    amplitude_factor: float  # 1 + <theta0^2> / 8

    @property
    def se(self) -> float:
        """Return the combined standard error: the statistical and the systematic ones in quadrature."""
        return float(np.sqrt(self.se_stat**2 + self.se_length**2 + self.se_time**2))

    def z(self, g: float, g_err: float = 0.0) -> float:
        """Return (g_measured - g) over the combined error of both (``g_err``: the reference's own)."""
        return float((self.g - g) / np.hypot(self.se, g_err))


def pendulum_g(
    fit: SwingFit,
    centre_m: float,
    *,
    centre_err_m: float = 0.0,
    bob_radius_m: float = 0.0,
    theta0_sq: float = 0.0,
    dt_rel_err: float = 0.0,
) -> PendulumG:
    """Return g from a fitted swing and the bob centre's distance below the pivot (m).

    ``bob_radius_m``: a solid sphere's radius (its moment about its centre, 2/5 m r^2, lengthens
    the equivalent length by 2/5 r^2 / d); ``theta0_sq``: the mean square amplitude (rad^2) over
    the fitted stretch; ``centre_err_m`` and ``dt_rel_err``: the length's standard error and the
    frame interval's relative one (systematic: ``se_length = g centre_err_m / d`` to first order,
    ``se_time = 2 g dt_rel_err``).
    """
    if not (centre_m > 0 and centre_err_m >= 0 and bob_radius_m >= 0 and theta0_sq >= 0 and dt_rel_err >= 0):
        raise ValueError(
            f"pendulum_g: length must be positive, its error, the bob's radius, the amplitude and dt_rel_err "
            f"not negative (got {centre_m}, {centre_err_m}, {bob_radius_m}, {theta0_sq}, {dt_rel_err})"
        )
    d = centre_m
    length_eq = d + 0.4 * bob_radius_m**2 / d
    factor = 1 + theta0_sq / 8
    g = fit.omega0**2 * length_eq * factor
    dleq_dd = 1 - 0.4 * bob_radius_m**2 / d**2
    return PendulumG(
        g=float(g),
        se_stat=float(2 * g * fit.se_omega * fit.omega / fit.omega0**2),
        se_length=float(g * dleq_dd * centre_err_m / length_eq),
        se_time=float(2 * g * dt_rel_err),
        length_eq_m=float(length_eq),
        amplitude_factor=float(factor),
    )
