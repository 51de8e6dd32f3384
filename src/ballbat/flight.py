"""Flight of a batted baseball: the drag and lift model of Nathan's trajectory calculator.

The model (docs/model.md, "Flight"; Nathan's TrajectoryCalculator spreadsheet [1]_):

    a = -k C_D |v| v + k C_L |v| (omega_hat x v) - g z_hat,     k = rho A / (2 m),

with ``v`` the velocity relative to the air, ``A = pi r^2`` the ball's cross-section,

    C_D = 0.3008 + 0.0292 (spin_rpm / 1000) f,     S = (r omega / |v|) f,
    C_L = 1.120 S / (0.583 + 2.333 S),             f = exp(-t / (tau v_100 / |v|)),

``v_100 = 100 mph`` and ``tau = 30 s``. The spin axis ``omega_hat`` is fixed in space; only
the spin's effect (through ``f``) decays.

Axes (the calculator's): x towards first base, y towards centre field, z up; home plate at
the origin. Two integrators share that right-hand side:

* ``method="accurate"`` -- a vectorised Dormand-Prince 5(4) integrator with a step size
  controlled separately for every trajectory, quintic Hermite interpolation between steps
  (positions, velocities and accelerations at both ends) and the landing time ``z = 0``
  found by bisection on that interpolant.
* ``method="calculator"`` -- the calculator's own fixed-step scheme: with the acceleration
  ``a_n`` evaluated at the start of the step, ``x_{n+1} = x_n + v_n dt + a_n dt^2 / 2`` and
  ``v_{n+1} = v_n + a_n dt`` (``dt = 0.01 s``), the landing found by linear interpolation
  between the last point above and the first point below ``z = 0``.

See ``docs/flight.md`` for the constants, their sources and the validation numbers.

References
----------
.. [1] A. M. Nathan, "Baseball Trajectory Calculator" (Excel spreadsheet
   TrajectoryCalculator-new-3D), http://baseball.physics.illinois.edu/trajectory-calculator-new.html
.. [2] J. R. Kensrud, A. M. Nathan and L. V. Smith, "Oblique collisions of baseballs and
   softballs with a bat", Am. J. Phys. 85, 503 (2017), Sec. V.B and Fig. 11.
.. [3] J. R. Dormand and P. J. Prince, "A family of embedded Runge-Kutta formulae",
   J. Comput. Appl. Math. 6, 19 (1980).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .units import FOOT, INCH, INHG_IN_MMHG, MPH, OUNCE, RPM, G, fahrenheit_to_celsius

__all__ = [
    "CD0",
    "CD_SPIN",
    "CL0",
    "CL1",
    "CL2",
    "DEFAULT_RHO",
    "FlightResult",
    "G",
    "air_density",
    "fly",
]

#: Drag coefficient without spin (Nathan's calculator, docs/model.md).
CD0 = 0.3008
#: Spin term of the drag coefficient, per 1000 rpm (Nathan's calculator, docs/model.md).
CD_SPIN = 0.0292
#: Lift coefficient C_L = CL2 S / (CL0 + CL1 S) (Nathan's calculator, docs/model.md).
CL2, CL0, CL1 = 1.120, 0.583, 2.333
#: Reference speed of the spin-decay law, 100 mph in m/s.
V100 = 100.0 * MPH
#: Pressure scale of the air-density formula, 1/m (docs/model.md, "Flight").
BETA = 0.0001217

#: The spreadsheet's own rounded unit factors, used by ``method="calculator"`` when
#: ``calculator_rounding`` is True (see :func:`fly`, Notes): mph -> ft/s, v_100 in ft/s,
#: g in ft/s^2, and its drag constant ``c0 = 0.07182 rho_lb`` with ``rho_lb = 0.06261 rho``
#: (the exact factor from kg/m^3 to lb/ft^3 is 0.062428).
SHEET_FPS_PER_MPH = 1.467
SHEET_V100_FPS = 146.7
SHEET_G_FPS2 = 32.174
SHEET_C0 = 0.07182
SHEET_LB_FT3 = 0.06261

#: Calculator defaults: 5.125 oz ball of 9.125 in circumference, start (0, 2 ft, 3 ft).
DEFAULT_BALL_MASS = 5.125 * OUNCE
DEFAULT_BALL_CIRCUMFERENCE = 9.125 * INCH
DEFAULT_START = (0.0, 2.0 * FOOT, 3.0 * FOOT)


#: Default conditions of Nathan's calculator: 70 deg F in deg C, 29.92 inHg in mmHg, 15 ft in m.
DEFAULT_TEMP_C = float(fahrenheit_to_celsius(70.0))


def air_density(
    temp_C: ArrayLike = DEFAULT_TEMP_C,
    pressure_mmHg: ArrayLike = 29.92 * INHG_IN_MMHG,
    elevation_m: ArrayLike = 15.0 * FOOT,
    rel_humidity_pct: ArrayLike = 50.0,
) -> NDArray[np.float64] | float:
    """Density of moist air, kg/m^3, as in Nathan's trajectory calculator.

    Parameters
    ----------
    temp_C : air temperature, deg C (default 70 deg F).
    pressure_mmHg : barometric pressure, mmHg (default 29.92 inHg).
    elevation_m : elevation of the field, m (default 15 ft).
    rel_humidity_pct : relative humidity, % (default 50).

    Returns
    -------
    float or ndarray
        ``rho``; about 1.1938 kg/m^3 for the defaults.

    Notes
    -----
    ``rho = 1.2929 (273/(T + 273)) (P exp(-beta h) - 0.3783 RH SVP/100) / 760`` with
    ``beta = 0.0001217 /m`` and the saturation vapour pressure (mmHg)
    ``SVP = 4.5841 exp((18.687 - T/234.5) T/(257.14 + T))`` (docs/model.md, "Flight"; Nathan's
    calculator).
    """
    T = np.asarray(temp_C, dtype=float)
    P = np.asarray(pressure_mmHg, dtype=float)
    h = np.asarray(elevation_m, dtype=float)
    RH = np.asarray(rel_humidity_pct, dtype=float)
    svp = 4.5841 * np.exp((18.687 - T / 234.5) * T / (257.14 + T))
    rho = 1.2929 * (273.0 / (T + 273.0)) * (P * np.exp(-BETA * h) - 0.3783 * RH * svp / 100.0) / 760.0
    return float(rho) if rho.ndim == 0 else rho


#: Air density at the calculator's default conditions (70 deg F, 15 ft, 50 %, 29.92 inHg).
DEFAULT_RHO = air_density()


@dataclass(frozen=True)
class FlightResult:
    """Outcome of :func:`fly`, SI units; leading dimensions are the broadcast input shape.

    Attributes
    ----------
    carry : horizontal distance of the landing point from home plate (the origin), m.
    hang_time : time of flight from the start to ``z = 0``, s.
    apex : greatest height above the ground, m.
    landing : landing point ``(x, y, 0)``, m, shape ``(..., 3)``.
    t : sample times, s, shape ``(..., n_points)``, or None (not requested).
    points : positions at those times, m, shape ``(..., n_points, 3)``, or None.
    """

    carry: NDArray[np.float64]
    hang_time: NDArray[np.float64]
    apex: NDArray[np.float64]
    landing: NDArray[np.float64]
    t: NDArray[np.float64] | None = None
    points: NDArray[np.float64] | None = None


# --------------------------------------------------------------------------------------------
# Right-hand side
# --------------------------------------------------------------------------------------------


class _Model:
    """Constants of one batch of trajectories (arrays of length N, or scalars)."""

    def __init__(self, k, r, spin, omega_hat, wind, tau, v100=V100, g=G):
        self.k = k  # (N,) 1/m
        self.r_spin = r * spin  # (N,) m/s, r * |omega|
        self.cd_spin = CD_SPIN * (spin / RPM) / 1000.0  # (N,)
        self.omega_hat = omega_hat  # (N, 3)
        self.wind = wind  # (N, 3)
        self.inv_tau = 1.0 / (tau * v100)  # scalar, 1/m
        self.g = g

    def take(self, idx):
        m = object.__new__(_Model)
        m.k, m.r_spin, m.cd_spin = self.k[idx], self.r_spin[idx], self.cd_spin[idx]
        m.omega_hat, m.wind, m.inv_tau, m.g = self.omega_hat[idx], self.wind[idx], self.inv_tau, self.g
        return m

    def accel(self, t, vel):
        """Acceleration (N, 3) at times t (N,) for ground velocities vel (N, 3)."""
        u = vel - self.wind
        speed = np.sqrt(np.einsum("ij,ij->i", u, u))
        f = np.exp(-t * speed * self.inv_tau)  # exp(-t / (tau v100 / |v|))
        cd = CD0 + self.cd_spin * f
        rwf = self.r_spin * f
        # C_L |v| = CL2 S |v| / (CL0 + CL1 S) with S = r omega f / |v|, written without 1/|v|.
        den = CL0 * speed + CL1 * rwf
        cl_speed = np.divide(CL2 * rwf * speed, den, out=np.zeros_like(den), where=den > 0)
        oh = self.omega_hat
        cross = np.empty_like(u)
        cross[:, 0] = oh[:, 1] * u[:, 2] - oh[:, 2] * u[:, 1]
        cross[:, 1] = oh[:, 2] * u[:, 0] - oh[:, 0] * u[:, 2]
        cross[:, 2] = oh[:, 0] * u[:, 1] - oh[:, 1] * u[:, 0]
        a = self.k[:, None] * (cl_speed[:, None] * cross - (cd * speed)[:, None] * u)
        a[:, 2] -= self.g
        return a


# --------------------------------------------------------------------------------------------
# Quintic Hermite interpolation on one step (value and time derivative)
# --------------------------------------------------------------------------------------------


def _hermite5(s, h, y0, v0, a0, y1, v1, a1):
    """Quintic Hermite interpolant at fraction ``s`` of a step of length ``h``.

    Matches value, first and second derivative at both ends; exact for polynomials of degree
    five. Returns (value, d value / dt). Arguments broadcast.
    """
    s2 = s * s
    s3 = s2 * s
    s4 = s3 * s
    s5 = s4 * s
    h0 = 1 - 10 * s3 + 15 * s4 - 6 * s5
    h1 = s - 6 * s3 + 8 * s4 - 3 * s5
    h2 = 0.5 * (s2 - 3 * s3 + 3 * s4 - s5)
    h3 = 10 * s3 - 15 * s4 + 6 * s5
    h4 = -4 * s3 + 7 * s4 - 3 * s5
    h5 = 0.5 * (s3 - 2 * s4 + s5)
    d0 = -30 * s2 + 60 * s3 - 30 * s4
    d1 = 1 - 18 * s2 + 32 * s3 - 15 * s4
    d2 = 0.5 * (2 * s - 9 * s2 + 12 * s3 - 5 * s4)
    d4 = -12 * s2 + 28 * s3 - 15 * s4
    d5 = 0.5 * (3 * s2 - 8 * s3 + 5 * s4)
    hh = h * h
    val = h0 * y0 + h * h1 * v0 + hh * h2 * a0 + h3 * y1 + h * h4 * v1 + hh * h5 * a1
    der = (d0 * (y0 - y1) + h * d1 * v0 + hh * d2 * a0 + h * d4 * v1 + hh * d5 * a1) / h
    return val, der


def _bisect(fun, n, iters=60):
    """Root in s of ``fun(s)`` on [0, 1] for n problems with fun(0) > 0 >= fun(1)."""
    lo = np.zeros(n)
    hi = np.ones(n)
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        pos = fun(mid) > 0
        lo = np.where(pos, mid, lo)
        hi = np.where(pos, hi, mid)
    return 0.5 * (lo + hi)


# --------------------------------------------------------------------------------------------
# Dormand-Prince 5(4)
# --------------------------------------------------------------------------------------------

_DP_C = (0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0)
_DP_A = (
    (),
    (1 / 5,),
    (3 / 40, 9 / 40),
    (44 / 45, -56 / 15, 32 / 9),
    (19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729),
    (9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656),
    (35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84),
)
# 5th-order weights are the last row of A (FSAL); error = 5th - 4th order.
_DP_E = (71 / 57600, 0.0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40)


def _dp_step(model, t, X, V, A0, h):
    """One Dormand-Prince step for x' = v, v' = a(t, v). Returns X1, V1, A1, error norm."""
    hc = h[:, None]
    kx = [V]
    kv = [A0]
    for i in range(1, 7):
        row = _DP_A[i]
        Vi = V + hc * sum(c * kv[j] for j, c in enumerate(row) if c != 0.0)
        kx.append(Vi)
        if i < 6:
            kv.append(model.accel(t + _DP_C[i] * h, Vi))
        else:
            X1 = X + hc * sum(c * kx[j] for j, c in enumerate(row) if c != 0.0)
            V1 = Vi
            A1 = model.accel(t + h, V1)
            kv.append(A1)
    ex = hc * sum(c * kx[j] for j, c in enumerate(_DP_E) if c != 0.0)
    ev = hc * sum(c * kv[j] for j, c in enumerate(_DP_E) if c != 0.0)
    return X1, V1, A1, ex, ev


def _dp_error(Xi, Vi, X1, V1, ex, ev, rtol: float, atol: float) -> np.ndarray:
    """Return each trajectory's Dormand-Prince error estimate in units of its tolerance (RMS over the 6 states)."""
    sx = atol + rtol * np.maximum(np.abs(Xi), np.abs(X1))
    sv = atol + rtol * np.maximum(np.abs(Vi), np.abs(V1))
    return np.sqrt((np.sum((ex / sx) ** 2, axis=1) + np.sum((ev / sv) ** 2, axis=1)) / 6.0)


def _refuse_late(active: np.ndarray, t: np.ndarray, X: np.ndarray, t_max: float) -> None:
    """Raise a RuntimeError naming the trajectories still airborne after ``t_max``."""
    late = active & (t > t_max)
    if late.any():
        raise RuntimeError(
            f"fly: {late.sum()} trajectories still airborne after t_max = {t_max} s "
            f"(first: index {np.flatnonzero(late)[0]}, z = {X[late][0, 2]:.3g} m)"
        )


def _fly_accurate(model, X0, V0, rtol, atol, t_max, keep_history):
    """Adaptive Dormand-Prince 5(4), one step size per trajectory, on the active ones only.

    The steps that contain the apex (vz: + -> -) and the landing (z: > 0 -> <= 0) are kept;
    the apex and landing are then located on their quintic Hermite interpolants in one
    vectorised root search each.
    """
    N = X0.shape[0]
    t = np.zeros(N)
    X, V = X0.copy(), V0.copy()
    A = model.accel(t, V)
    h = np.full(N, 0.05)
    apex = X0[:, 2].copy()
    # Step data (t0, h, X0, V0, A0, X1, V1, A1) of the apex and landing steps.
    top_t0, top_h, top_z = np.zeros(N), np.zeros(N), np.zeros((N, 6))
    has_top = np.zeros(N, dtype=bool)
    land_t0, land_h, land_x = np.zeros(N), np.zeros(N), np.zeros((N, 3, 6))
    active = np.ones(N, dtype=bool)
    history = [(t.copy(), X.copy(), V.copy(), A.copy())] if keep_history else None
    n_iter = 0
    while active.any():
        n_iter += 1
        if n_iter > 100000:
            raise RuntimeError("fly: Dormand-Prince integration did not finish in 100000 steps")
        idx = np.flatnonzero(active)
        mdl = model.take(idx)
        ti, Xi, Vi, Ai, hi = t[idx], X[idx], V[idx], A[idx], h[idx]
        X1, V1, A1, ex, ev = _dp_step(mdl, ti, Xi, Vi, Ai, hi)
        err = _dp_error(Xi, Vi, X1, V1, ex, ev, rtol, atol)
        ok = err <= 1.0
        fac = np.clip(0.9 * np.maximum(err, 1e-10) ** -0.2, 0.2, 5.0)
        h[idx] = hi * np.where(ok, fac, np.minimum(fac, 1.0))
        if ok.any():
            acc = idx[ok]
            ti, Xi, Vi, Ai, hi = ti[ok], Xi[ok], Vi[ok], Ai[ok], hi[ok]
            X1, V1, A1 = X1[ok], V1[ok], A1[ok]
            top = (Vi[:, 2] > 0) & (V1[:, 2] <= 0)
            if top.any():
                g = acc[top]
                has_top[g] = True
                top_t0[g], top_h[g] = ti[top], hi[top]
                top_z[g] = np.stack([Xi[top, 2], Vi[top, 2], Ai[top, 2], X1[top, 2], V1[top, 2], A1[top, 2]], axis=1)
            down = (Xi[:, 2] > 0) & (X1[:, 2] <= 0)
            if down.any():
                g = acc[down]
                land_t0[g], land_h[g] = ti[down], hi[down]
                land_x[g] = np.stack([Xi[down], Vi[down], Ai[down], X1[down], V1[down], A1[down]], axis=2)
                active[g] = False
            apex[acc] = np.maximum(apex[acc], X1[:, 2])
            t[acc] = ti + hi
            X[acc], V[acc], A[acc] = X1, V1, A1
        _refuse_late(active, t, X, t_max)
        if keep_history:
            history.append((t.copy(), X.copy(), V.copy(), A.copy()))

    # Apex: root of dz/dt on the apex step's interpolant.
    if has_top.any():
        w = np.flatnonzero(has_top)
        args = (top_h[w], *top_z[w].T)
        s = _bisect(lambda s_: _hermite5(s_, *args)[1], w.size)
        apex[w] = np.maximum(apex[w], _hermite5(s, *args)[0])
    # Landing: root of z on the landing step's interpolant.
    args = (land_h, *land_x[:, 2].T)
    s = _bisect(lambda s_: _hermite5(s_, *args)[0], N)
    hang = land_t0 + s * land_h
    landing = np.zeros((N, 3))
    for c in (0, 1):
        landing[:, c] = _hermite5(s, land_h, *land_x[:, c].T)[0]
    return hang, apex, landing, history


def _resample_accurate(history, hang, n_points):
    """Positions at ``n_points`` times from 0 to ``hang`` by quintic Hermite on the steps."""
    N = hang.shape[0]
    tH = np.stack([h[0] for h in history], axis=1)  # (N, S), non-decreasing along S
    XH, VH, AH = (np.stack([h[i] for h in history], axis=1) for i in (1, 2, 3))  # (N, S, 3)
    S = tH.shape[1]
    T = np.linspace(0.0, 1.0, n_points)[None, :] * hang[:, None]
    # One searchsorted for all trajectories: shift each row into its own time window.
    shift = (np.arange(N) * (tH.max() + 1.0))[:, None]
    j = np.searchsorted((tH + shift).ravel(), (T + shift).ravel(), side="right").reshape(N, n_points)
    j = np.clip(j - 1 - np.arange(N)[:, None] * S, 0, S - 2)  # last step start with t_j <= T
    rows = np.arange(N)[:, None]
    t0, t1 = tH[rows, j], tH[rows, j + 1]
    h = np.maximum(t1 - t0, np.finfo(float).tiny)[..., None]
    s = np.clip((T - t0)[..., None] / h, 0.0, 1.0)
    P = _hermite5(s, h, XH[rows, j], VH[rows, j], AH[rows, j], XH[rows, j + 1], VH[rows, j + 1], AH[rows, j + 1])[0]
    P[:, -1, 2] = 0.0
    return T, P


def _fly_calculator(model, X0, V0, dt, t_max, keep_history):
    N = X0.shape[0]
    X, V = X0.copy(), V0.copy()
    t = 0.0
    apex = X0[:, 2].copy()
    hang = np.full(N, np.nan)
    landing = np.full((N, 3), np.nan)
    active = np.ones(N, dtype=bool)
    last = np.zeros(N, dtype=int)  # index of the last point above the ground
    history = [X.copy()] if keep_history else None
    n = 0
    while active.any():
        A = model.accel(np.full(N, t), V)
        X1 = X + V * dt + 0.5 * A * dt * dt
        V1 = V + A * dt
        n += 1
        t = n * dt
        down = active & (X[:, 2] > 0) & (X1[:, 2] <= 0)
        if down.any():
            frac = X[down, 2] / (X[down, 2] - X1[down, 2])
            hang[down] = t - dt + frac * dt
            landing[down] = X[down] + frac[:, None] * (X1[down] - X[down])
            landing[down, 2] = 0.0
            last[down] = n - 1
            active &= ~down
        X = np.where(active[:, None], X1, X)
        V = np.where(active[:, None], V1, V)
        apex = np.maximum(apex, X[:, 2])
        if keep_history:
            history.append(X.copy())
        if active.any() and t > t_max:
            raise RuntimeError(f"fly: {active.sum()} trajectories still airborne after t_max = {t_max} s")
    return hang, apex, landing, (history, last)


def _resample_calculator(history, hang, landing, dt, n_points):
    """Linear interpolation between the scheme's points (as the spreadsheet's own plot)."""
    history, last = history
    H = np.stack(history, axis=1)  # (N, steps, 3); frozen after landing
    N, steps = H.shape[:2]
    T = np.linspace(0.0, 1.0, n_points)[None, :] * hang[:, None]
    pos = T / dt
    i0 = np.clip(np.floor(pos).astype(int), 0, steps - 1)
    i1 = np.clip(i0 + 1, 0, steps - 1)
    frac = (pos - i0)[..., None]
    rows = np.arange(N)[:, None]
    P = H[rows, i0] + frac * (H[rows, i1] - H[rows, i0])
    # Between the last point above ground and the landing point, interpolate towards landing.
    tail = i0 >= last[:, None]
    if tail.any():
        seg = np.clip((T - last[:, None] * dt) / (hang - last * dt)[:, None], 0.0, 1.0)[..., None]
        Hl = H[np.arange(N), last][:, None, :]
        P = np.where(tail[..., None], Hl + seg * (landing[:, None, :] - Hl), P)
    return T, P


# --------------------------------------------------------------------------------------------
# Public entry point
# --------------------------------------------------------------------------------------------


def fly(
    v0: ArrayLike,
    launch_angle: ArrayLike,
    spray_angle: ArrayLike = 0.0,
    backspin: ArrayLike = 0.0,
    sidespin: ArrayLike = 0.0,
    *,
    ball_mass: float = DEFAULT_BALL_MASS,
    ball_circumference: float | None = DEFAULT_BALL_CIRCUMFERENCE,
    ball_radius: float | None = None,
    rho: float = DEFAULT_RHO,
    start: ArrayLike = DEFAULT_START,
    wind: ArrayLike | None = None,
    tau: float = 30.0,
    method: str = "accurate",
    dt: float = 0.01,
    rtol: float = 1e-9,
    atol: float = 1e-9,
    t_max: float = 60.0,
    n_points: int | None = None,
    calculator_rounding: bool = True,
) -> FlightResult:
    """Fly batted balls with the drag and lift model of Nathan's trajectory calculator.

    Parameters
    ----------
    v0 : launch speed, m/s.
    launch_angle : angle of the launch velocity above the horizontal, rad.
    spray_angle : horizontal direction of the launch velocity, rad, measured from the y axis
        (straight-away centre field) towards +x (first base / right field).
    backspin : backspin, rad/s (< 0 is topspin). The backspin axis is horizontal and
        perpendicular to the launch direction, pointing to the batted ball's right.
    sidespin : sidespin, rad/s, about the axis perpendicular to the launch velocity in the
        vertical plane that contains it (the calculator's convention). Positive sidespin
        tilts the spin axis towards +z (counter-clockwise seen from above) and curves the
        ball towards -x (to the left as seen from home plate); negative to the right.
    ball_mass : kg (default 5.125 oz).
    ball_circumference, ball_radius : give one; radius wins when both are given
        (default circumference 9.125 in).
    rho : air density, kg/m^3 (default :data:`DEFAULT_RHO`, see :func:`air_density`);
        ``rho = 0`` gives a projectile in vacuum.
    start : starting point (x, y, z), m (default (0, 2 ft, 3 ft)); broadcasts as (..., 3).
    wind : horizontal wind velocity (w_x, w_y), m/s, or None; the air forces use the
        velocity relative to the air.
    tau : spin-decay time constant, s (``np.inf``: no decay).
    method : ``"accurate"`` (Dormand-Prince 5(4), adaptive) or ``"calculator"`` (the
        spreadsheet's fixed-step scheme with step ``dt``).
    dt : step of the calculator scheme, s.
    rtol, atol : tolerances of the accurate integrator (relative; absolute in m and m/s).
    t_max : give up (RuntimeError) if a ball is still airborne after this time, s.
    n_points : if given, also return each trajectory resampled at ``n_points`` times evenly
        spaced from launch to landing.
    calculator_rounding : with ``method="calculator"`` only: use the spreadsheet's rounded
        unit factors (1.467 ft/s per mph, v_100 = 146.7 ft/s, g = 32.174 ft/s^2 and its drag
        constant 0.07182 x 0.06261 rho) so that its published numbers come out; False uses
        exact SI factors. Ignored by the accurate method, which is always exact.

    Returns
    -------
    FlightResult
        carry (horizontal distance of the landing point from home plate, the origin), hang
        time, apex height, landing point, and optionally the sampled trajectory.

    Notes
    -----
    Acceleration, coefficients and spin decay exactly as docs/model.md ("Flight"):
    ``a = -k C_D |v| v + k C_L |v| (omega_hat x v) - g z``, ``k = rho A/(2 m)``,
    ``C_D = 0.3008 + 0.0292 (spin_rpm/1000) f``, ``S = (r omega/|v|) f``,
    ``C_L = 1.120 S/(0.583 + 2.333 S)``, ``f = exp(-t/(tau v_100/|v|))``. The spin vector is
    built as in Nathan's calculator [1]_, with ``theta`` the launch and ``phi`` the spray
    angle: ``omega = backspin (cos phi, -sin phi, 0) + sidespin (-sin theta sin phi,
    -sin theta cos phi, cos theta)`` (no gyro spin), fixed in direction during the flight.
    ``spin_rpm`` is the magnitude of that vector (the spreadsheet puts only its backspin
    component in C_D; the two agree when the sidespin is zero). Where the spreadsheet uses the
    ground speed in ``f`` for the lift and the air speed for the drag, this function uses
    the air speed for both (identical without wind).

    The calculator scheme is ``x_{n+1} = x_n + v_n dt + a_n dt^2/2``,
    ``v_{n+1} = v_n + a_n dt`` with the landing by linear interpolation in z between the
    last two points, as in the spreadsheet; its published case (103 mph, 27.5 deg,
    2500 rpm) lands at 421.5 ft after 5.52 s with apex 92.0 ft (docs/model.md). Those numbers
    need the spreadsheet's rounded unit factors too (``calculator_rounding``): its drag
    constant is 0.29 % above the exact ``rho A/(2 m)`` and its launch speed 0.023 % above
    the exact mph conversion; with exact factors the same scheme gives 421.8 ft, 5.52 s and
    92.0 ft (docs/flight.md).
    """
    ball_radius = _check_settings(method, ball_mass, ball_circumference, ball_radius, rho, tau, dt, n_points)
    shape, launch = _launch_arrays(v0, launch_angle, spray_angle, backspin, sidespin, start, wind)
    V0, spin, omega_hat = _launch_velocity_and_spin(launch)
    N = launch.speed.size
    k = np.full(N, rho * np.pi * ball_radius**2 / (2.0 * ball_mass))
    if method == "calculator" and calculator_rounding:
        # The spreadsheet's c0 (1/ft) = 0.07182 rho_lb (5.125 oz / m)(C / 9.125 in)^2.
        circ = 2.0 * np.pi * ball_radius
        k_ft = SHEET_C0 * SHEET_LB_FT3 * rho * (5.125 * OUNCE / ball_mass) * (circ / (9.125 * INCH)) ** 2
        k = np.full(N, k_ft / FOOT)
        V0 = V0 * (SHEET_FPS_PER_MPH * FOOT / MPH)
        model = _Model(k, ball_radius, spin, omega_hat, launch.wind, tau, SHEET_V100_FPS * FOOT, SHEET_G_FPS2 * FOOT)
    else:
        model = _Model(k, ball_radius, spin, omega_hat, launch.wind, tau)
    X0 = launch.start

    keep = n_points is not None
    if method == "accurate":
        hang, apex, landing, hist = _fly_accurate(model, X0, V0, rtol, atol, t_max, keep)
        T, P = _resample_accurate(hist, hang, n_points) if keep else (None, None)
    else:
        hang, apex, landing, hist = _fly_calculator(model, X0, V0, dt, t_max, keep)
        T, P = _resample_calculator(hist, hang, landing, dt, n_points) if keep else (None, None)

    carry = np.hypot(landing[:, 0], landing[:, 1])
    return FlightResult(
        carry=carry.reshape(shape),
        hang_time=hang.reshape(shape),
        apex=apex.reshape(shape),
        landing=landing.reshape(*shape, 3),
        t=None if T is None else T.reshape(*shape, n_points),
        points=None if P is None else P.reshape(*shape, n_points, 3),
    )


def _check_settings(method, ball_mass, ball_circumference, ball_radius, rho, tau, dt, n_points) -> float:
    """Check the scalar settings of :func:`fly`; return the ball's radius, m."""
    if method not in ("accurate", "calculator"):
        raise ValueError(f"fly: method must be 'accurate' or 'calculator', got {method!r}")
    if ball_radius is None:
        if ball_circumference is None:
            raise ValueError("fly: give ball_radius or ball_circumference")
        ball_radius = ball_circumference / (2.0 * np.pi)
    if not (ball_mass > 0 and ball_radius > 0):
        raise ValueError(f"fly: ball_mass and ball radius must be positive, got {ball_mass}, {ball_radius}")
    if not (np.isfinite(rho) and rho >= 0):
        raise ValueError(f"fly: rho must be finite and >= 0, got {rho}")
    if not tau > 0:
        raise ValueError(f"fly: tau must be positive, got {tau}")
    if method == "calculator" and not dt > 0:
        raise ValueError(f"fly: dt must be positive, got {dt}")
    if n_points is not None and n_points < 2:
        raise ValueError(f"fly: n_points must be at least 2, got {n_points}")
    return ball_radius


@dataclass(frozen=True)
class _Launch:
    """Launch conditions of N balls, flattened from the broadcast shape (SI)."""

    speed: NDArray  # (N,) launch speed
    launch_angle: NDArray  # (N,) above the horizontal
    spray_angle: NDArray  # (N,) from the y axis towards +x
    backspin: NDArray  # (N,)
    sidespin: NDArray  # (N,)
    start: NDArray  # (N, 3) starting point
    wind: NDArray  # (N, 3) wind velocity (w_x, w_y, 0)


def _launch_arrays(v0, launch_angle, spray_angle, backspin, sidespin, start, wind) -> tuple[tuple[int, ...], _Launch]:
    """Broadcast and flatten the launch conditions of :func:`fly`, checked whole.

    Returns the broadcast shape and the conditions as (N,) and (N, 3) arrays.
    """
    start = np.asarray(start, dtype=float)
    if start.shape[-1:] != (3,):
        raise ValueError(f"fly: start must have a last dimension of 3, got shape {start.shape}")
    wind_arr = np.zeros(2) if wind is None else np.asarray(wind, dtype=float)
    if wind_arr.shape[-1:] != (2,):
        raise ValueError(f"fly: wind must be (w_x, w_y), got shape {wind_arr.shape}")
    shape = np.broadcast_shapes(
        np.shape(v0),
        np.shape(launch_angle),
        np.shape(spray_angle),
        np.shape(backspin),
        np.shape(sidespin),
        start.shape[:-1],
        wind_arr.shape[:-1],
    )
    N = int(np.prod(shape))

    def flat(a):
        return np.broadcast_to(np.asarray(a, dtype=float), shape).reshape(N)

    X0 = np.broadcast_to(start, (*shape, 3)).reshape(N, 3).astype(float)
    W = np.zeros((N, 3))
    W[:, :2] = np.broadcast_to(wind_arr, (*shape, 2)).reshape(N, 2)
    launch = _Launch(*(flat(a) for a in (v0, launch_angle, spray_angle, backspin, sidespin)), X0, W)
    names = ("v0", "launch_angle", "spray_angle", "backspin", "sidespin", "start", "wind")
    for name, field in zip(names, fields(launch), strict=True):
        arr = getattr(launch, field.name)
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"fly: {name} has non-finite values")
    bad = (X0[:, 2] < 0) | ((X0[:, 2] == 0) & (np.sin(launch.launch_angle) <= 0))
    if bad.any():
        raise ValueError("fly: every ball must start above the ground (or at z = 0 moving up)")
    return shape, launch


def _launch_velocity_and_spin(launch: _Launch) -> tuple[NDArray, NDArray, NDArray]:
    """Return the launch velocity (N, 3), the spin's magnitude (N,) and its unit axis (N, 3).

    The spin vector as in Nathan's calculator (:func:`fly`, Notes): ``backspin (cos phi,
    -sin phi, 0) + sidespin (-sin theta sin phi, -sin theta cos phi, cos theta)``, with
    ``theta`` the launch and ``phi`` the spray angle; the axis is zero where there is no spin.
    """
    N = launch.speed.size
    cos_launch, sin_launch = np.cos(launch.launch_angle), np.sin(launch.launch_angle)
    cos_spray, sin_spray = np.cos(launch.spray_angle), np.sin(launch.spray_angle)
    V0 = launch.speed[:, None] * np.stack([cos_launch * sin_spray, cos_launch * cos_spray, sin_launch], axis=1)
    backspin_axis = np.stack([cos_spray, -sin_spray, np.zeros(N)], axis=1)
    sidespin_axis = np.stack([-sin_launch * sin_spray, -sin_launch * cos_spray, cos_launch], axis=1)
    omega = launch.backspin[:, None] * backspin_axis + launch.sidespin[:, None] * sidespin_axis
    spin = np.sqrt(np.einsum("ij,ij->i", omega, omega))
    omega_hat = np.divide(omega, spin[:, None], out=np.zeros_like(omega), where=spin[:, None] > 0)
    return V0, spin, omega_hat
