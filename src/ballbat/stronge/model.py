"""Stronge's lumped-parameter contact model (Sec. V.A of Kensrud et al. 2017).

A sphere meets a surface through a massless contact point C and two linear springs: a
normal spring (stiffness k_n while loading, k_n / e_y**2 while unloading, which gives the
normal coefficient of restitution e_y) and an elastic tangential spring k_t = k_n / eta2
between the ball and C. C either sticks to the surface or slips on it with Coulomb friction
of coefficient mu. The specification is docs/model.md, "Stronge's contact model"; the equations,
their closed-form solutions and the comparison with the paper's numbers are in
``docs/stronge.md``.

Dimensionless variables used throughout (``theta = Omega_n t``, so ``t_c`` is
``theta = pi/2`` and separation is ``theta_f = (pi/2)(1 + e_y)``):

* ``N/N_max`` is ``sin(theta)`` while loading and ``sin((theta_f - theta)/e_y)`` while
  unloading, with ``N_max = k_n v_n / Omega_n`` (v_n: initial normal approach speed);
* tangential quantities are scaled by the initial tangential speed ``u_0 = v_n tan(psi)``:
  ``U = u/u_0``, ``S = s Omega_n/u_0``; with ``rho = Omega_t/Omega_n`` and
  ``Lam = mu eta2 / tan(psi)`` the equations are ``S' = U, U' = -rho**2 S`` (stick, valid
  while ``|S| <= Lam N/N_max``) and ``S = sigma Lam N/N_max, U' = -rho**2 sigma Lam N/N_max``
  (slip in direction ``sigma = +-1``); C's velocity is ``W = U - S'``.

Every phase is linear with constant coefficients, so :func:`stronge_ex` and
:func:`stronge_solve` evaluate each phase in closed form and find the phase-change times
by vectorised root finding (no loop over impacts). The reference integrator
(:mod:`.reference`, for tests) and the regime boundaries in psi (:mod:`.regimes`) live
beside this module.

References
----------
.. [1] J. R. Kensrud, A. M. Nathan and L. V. Smith, "Oblique collisions of baseballs and
   softballs with a bat", Am. J. Phys. 85, 503 (2017), Sec. V.A.
.. [2] W. J. Stronge, "Planar impact of rough compliant bodies", Int. J. Impact Eng. 15,
   435 (1994).
.. [3] W. J. Stronge, *Impact Mechanics* (Cambridge University Press, 2000), Ch. 5.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "ContactParams",
    "ImpactGeometry",
    "StrongeSolution",
    "omega_ratio",
    "stronge_ex",
    "stronge_solve",
]

HALF_PI = 0.5 * np.pi
#: Impacts per block in the vectorised solvers (keeps the work arrays in cache).
CHUNK = 8192
#: Most phase pieces (stick/slip x loading/unloading) one impact may pass through.
MAX_PIECES = 64
#: A phase change closer than this to separation (in Omega_n t) is ignored: the phase that
#: was running is taken to last until separation. Only matters in the limits psi -> 0 and
#: the superball (where stick lasts exactly to separation), where rounding would otherwise
#: report a slip phase of zero length.
SEPARATION_TOL = 1e-12
#: Least number of grid points per piece on which the stick-to-slip condition is sampled
#: before refining, and the largest step of the tangential phase Omega_t dt between them.
STICK_GRID = 24
STICK_DPHASE = 0.1
#: Relative size below which a phase-change condition counts as rounding, not a crossing.
ROUND_TOL = 1e-12
#: Newton iterations stop once every step is below this (in Omega_n t, or relative for
#: the log-variable iteration); the error after such a step is O(step^2).
NEWTON_TOL = 1e-10
_STICK, _SLIP = 1, 2
_PHASE_NAMES = {_STICK: "stick", _SLIP: "slip"}


# --------------------------------------------------------------------------------------
# parameters
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ContactParams:
    """The parameters of Stronge's contact model for one impact or a batch of impacts.

    Attributes
    ----------
    eta2 : k_n / k_t, the ratio of the normal and tangential spring constants (the paper's
        eta^2), > 0.
    e_y : normal coefficient of restitution, 0 < e_y <= 1.
    mu : coefficient of friction (static = sliding), >= 0.
    r_x, r_y : tangential and normal recoil factors of the target (Eqs. rx and ry). 0
        (default) is Stronge's rigid massive surface; the bat's values give the frame of the
        experiment.
    alpha : I_ball / (m r^2) of the ball.

    Scalars or arrays; they broadcast against each other and against the incidence angles
    they are solved at. The solvers check the values (:func:`stronge_ex`).
    """

    eta2: ArrayLike
    e_y: ArrayLike
    mu: ArrayLike
    r_x: ArrayLike = 0.0
    r_y: ArrayLike = 0.0
    alpha: ArrayLike = 0.4

    def values(self) -> tuple[ArrayLike, ...]:
        """Return (eta2, e_y, mu, r_x, r_y, alpha) as given."""
        return (self.eta2, self.e_y, self.mu, self.r_x, self.r_y, self.alpha)

    def broadcast(self, psi: ArrayLike) -> list[NDArray[np.float64]]:
        """Return psi and (eta2, e_y, mu, r_x, r_y, alpha) as float arrays of their common broadcast shape."""
        return np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (psi, *self.values())))

    def scalars(self) -> ContactParams:
        """Return the same parameters as Python floats (a TypeError if one is an array of several values)."""
        return ContactParams(*(float(a) for a in self.values()))

    def omega_ratio(self) -> NDArray[np.float64] | float:
        """Return Omega_t / Omega_n of these parameters (:func:`omega_ratio`)."""
        return omega_ratio(self.eta2, self.r_x, self.r_y, self.alpha)


def omega_ratio(
    eta2: ArrayLike, r_x: ArrayLike = 0.0, r_y: ArrayLike = 0.0, alpha: ArrayLike = 0.4
) -> NDArray[np.float64] | float:
    """Ratio Omega_t / Omega_n of the tangential and normal vibration frequencies.

    Parameters
    ----------
    eta2, r_x, r_y, alpha : as in :class:`ContactParams`; r_x = r_y = 0 is the rigid
        massive surface of Stronge's geometry.

    Returns
    -------
    ndarray (or float)
        ``sqrt(k_t m_n / (k_n m_t)) = sqrt((1 + alpha)(1 + r_x) / (alpha (1 + r_y) eta2))``.

    Notes
    -----
    Sec. V.A of Kensrud et al. 2017 gives Omega_t = Omega_n sqrt(3.5/eta^2) for a rigid
    surface (m_n = m, m_t = alpha m/(1 + alpha), alpha = 0.4). In the bat's frame the
    effective masses are m_n = m/(1 + r_y) and m_t = alpha m/((1 + alpha)(1 + r_x))
    (docs/model.md, "Effective masses"), which multiplies the ratio by sqrt((1 + r_x)/(1 + r_y)).
    """
    eta2, r_x, r_y, alpha = (np.asarray(a, dtype=float) for a in (eta2, r_x, r_y, alpha))
    out = np.sqrt((1.0 + alpha) * (1.0 + r_x) / (alpha * (1.0 + r_y) * eta2))
    return out if out.ndim else float(out)


def _check(name, value, ok, rule):
    bad = ~ok
    if np.any(bad):
        idx = np.flatnonzero(bad.ravel())
        vals = np.broadcast_to(value, bad.shape).ravel()[idx[:5]]
        raise ValueError(
            f"stronge: {name} must satisfy {rule}; got {', '.join(f'{v:g}' for v in vals)}"
            f" ({idx.size} bad value(s), first at flat index {idx[0]})"
        )


@dataclass(frozen=True)
class _Params:
    """Broadcast, flattened, dimensionless parameters of a batch of impacts."""

    shape: tuple
    tan_psi: NDArray  # |tan psi| = u_0 / v_n
    rho: NDArray  # Omega_t / Omega_n
    lam: NDArray  # mu eta2 (friction limit on S in units of v_n / Omega_n)
    Lam: NDArray  # mu eta2 / tan psi  (inf at psi = 0)
    e: NDArray  # e_y
    thf: NDArray  # separation, Omega_n t_f = (pi/2)(1 + e_y)
    eta2: NDArray


class ImpactGeometry:
    """Impacts whose e_x is wanted at many parameters: psi, r_x, r_y and alpha checked and prepared once.

    A fit evaluates the model at the same impacts for one eta^2 after another; what does not
    depend on (eta2, e_y, mu) (the checks of psi, r_x, r_y and alpha, ``|tan psi|`` and the
    effective masses' factors of Omega_t/Omega_n) is computed here once. :func:`stronge_ex`
    is ``ImpactGeometry(psi, r_x, r_y, alpha).e_x(eta2, e_y, mu)``, the same numbers.

    Parameters
    ----------
    psi : incidence angles, rad, |psi| < pi/2.
    r_x, r_y, alpha : as in :class:`ContactParams`; they broadcast against psi.
    """

    def __init__(self, psi: ArrayLike, r_x: ArrayLike = 0.0, r_y: ArrayLike = 0.0, alpha: ArrayLike = 0.4) -> None:
        psi, r_x, r_y, alpha = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (psi, r_x, r_y, alpha)))
        with np.errstate(invalid="ignore"):
            _check("psi", psi, np.abs(psi) < HALF_PI, "|psi| < pi/2 (radians)")
            _check("r_x", r_x, (r_x > -1) & np.isfinite(r_x), "-1 < r_x < inf")
            _check("r_y", r_y, (r_y > -1) & np.isfinite(r_y), "-1 < r_y < inf")
            _check("alpha", alpha, (alpha > 0) & np.isfinite(alpha), "0 < alpha < inf")
        self.shape = psi.shape
        self.tan_psi = np.abs(np.tan(psi))
        # Omega_t/Omega_n = sqrt(mass_num / (mass_den eta2)), the operations of omega_ratio in its order
        self.mass_num = (1.0 + alpha) * (1.0 + r_x)
        self.mass_den = alpha * (1.0 + r_y)

    def e_x(self, eta2: ArrayLike, e_y: ArrayLike, mu: ArrayLike) -> NDArray[np.float64] | float:
        """e_x of these impacts at (eta2, e_y, mu), which broadcast against them (:func:`stronge_ex`)."""
        return _solve_ex(self.params(eta2, e_y, mu))

    def params(self, eta2: ArrayLike, e_y: ArrayLike, mu: ArrayLike) -> _Params:
        """Return the broadcast, flattened, dimensionless parameters of these impacts at (eta2, e_y, mu)."""
        eta2, e_y, mu = (np.asarray(a, dtype=float) for a in (eta2, e_y, mu))
        shape = np.broadcast_shapes(self.shape, eta2.shape, e_y.shape, mu.shape)
        with np.errstate(invalid="ignore"):
            _check("eta2", eta2, (eta2 > 0) & np.isfinite(eta2), "0 < eta2 < inf")
            _check("e_y", e_y, (e_y > 0) & (e_y <= 1), "0 < e_y <= 1")
            _check("mu", mu, (mu >= 0) & np.isfinite(mu), "0 <= mu < inf")
        size = math.prod(shape)
        flat = [_flat(a, shape, size) for a in (self.tan_psi, self.mass_num, self.mass_den, eta2, e_y, mu)]
        T, num, den, eta2, e_y, mu = flat
        rho = np.sqrt(num / (den * eta2))
        rho = np.where(np.abs(rho - 1.0) < 1e-14, 1.0, rho)  # e.g. the superball, eta2 = 3.5
        lam = mu * eta2
        with np.errstate(divide="ignore", invalid="ignore"):
            Lam = np.where(T > 0, lam / T, np.inf)
        Lam = np.where((T == 0) | (Lam > 1e300), np.inf, Lam)
        thf = HALF_PI * (1.0 + e_y)
        return _Params(shape, T, rho, lam, Lam, e_y.copy(), thf, eta2.copy())


def _flat(a: NDArray, shape: tuple, size: int) -> NDArray:
    """Return ``a`` broadcast to ``shape`` and flattened (a scalar filled in, an array of that shape as it is)."""
    if a.shape == shape:
        return a.ravel()
    if a.ndim == 0:
        return np.full(size, a)
    return np.broadcast_to(a, shape).ravel()


def _prepare(psi: ArrayLike, contact: ContactParams) -> _Params:
    """Return the dimensionless parameters of the impacts psi at ``contact`` (:class:`ImpactGeometry`)."""
    c = contact
    return ImpactGeometry(psi, c.r_x, c.r_y, c.alpha).params(c.eta2, c.e_y, c.mu)


def _sincos(x):
    """sin(x), cos(x) from one tangent of the half angle (numpy's float64 tan is SIMD)."""
    t = np.tan(0.5 * x)
    t2 = t * t
    inv = 1.0 / (1.0 + t2)
    return 2.0 * t * inv, (1.0 - t2) * inv


# --------------------------------------------------------------------------------------
# fast path: Omega_t <= Omega_n
# --------------------------------------------------------------------------------------
def _uf_soft(rho, Lam, e, thf):
    """Return the final U = u_f/u_0 for rho = Omega_t/Omega_n <= 1 (1-D arrays).

    For rho <= 1 the phase sequence is provably simple (docs/stronge.md, "Fast path"):
    either gross slip (Lam <= 1) or one stick phase from t = 0 followed by slip to
    separation; the stretch stays >= 0, slip never sticks again, and the stick-to-slip time
    is the unique root of S(theta) = Lam N(theta)/N_max, found by safeguarded Newton.
    """
    uf = np.empty_like(rho)
    gross = ~(Lam > 1.0)
    r2 = rho * rho
    uf[gross] = 1.0 - r2[gross] * Lam[gross] * (1.0 + e[gross])
    st = np.flatnonzero(~gross)
    if st.size == 0:
        return uf
    rho, Lam, e, thf, r2 = rho[st], Lam[st], e[st], thf[st], r2[st]
    s_half, _ = _sincos(rho * HALF_PI)
    s_f, c_f = _sincos(rho * thf)
    load = s_half / rho > Lam  # S(pi/2) > Lam: stick ends while loading
    with np.errstate(divide="ignore", over="ignore", under="ignore"):
        x0 = s_f / (rho * Lam)  # first guess of (theta_f - theta_1)/e_y
    through = ~load & ~(x0 > 1e-280)  # stick to separation (psi = 0, superball)
    out = np.empty_like(rho)
    out[through] = c_f[through]
    i = np.flatnonzero(load)
    if i.size:
        th = _root_loading(rho[i], Lam[i])
        _, cr = _sincos(rho[i] * th)
        out[i] = cr - r2[i] * Lam[i] * (e[i] + np.cos(th))
    j = np.flatnonzero(~load & ~through)
    if j.size:
        x = _root_unloading(rho[j], Lam[j], e[j], thf[j], x0[j])
        _sr, cr = _sincos(rho[j] * (thf[j] - e[j] * x))
        sh = np.sin(0.5 * x)
        out[j] = cr - r2[j] * Lam[j] * 2.0 * e[j] * sh * sh
    uf[st] = out
    return uf


def _root_loading(rho, Lam, iters=60):
    """Root theta in (0, pi/2) of sin(rho theta) / (rho sin theta) = Lam, for rho < 1.

    The ratio increases monotonically from 1 (theta -> 0); Newton on its logarithm, kept
    inside a shrinking bracket (bisection when a step leaves it).
    """
    lo = np.zeros_like(rho)
    hi = np.full_like(rho, HALF_PI)
    g = np.sqrt(6.0 * (Lam - 1.0) / np.maximum(1.0 - rho * rho, 1e-300))  # small-angle guess
    th = np.clip(g, 1e-3 * HALF_PI, 0.999 * HALF_PI)
    lr = np.log(rho * Lam)
    for _ in range(iters):
        sr, cr = _sincos(rho * th)
        s, c = _sincos(th)
        P = np.log(sr / s) - lr
        dP = rho * cr / sr - c / s
        pos = P > 0
        hi = np.where(pos, th, hi)
        lo = np.where(pos, lo, th)
        new = th - P / dP
        bad = ~((new >= lo) & (new <= hi))
        if bad.any():
            new = np.where(bad, 0.5 * (lo + hi), new)
        step = np.max(np.abs(new - th))
        th = new
        if step < NEWTON_TOL:  # Newton's error after a step h is O(h^2)
            break
    return th


def _root_unloading(rho, Lam, e, thf, x0, iters=60):
    """Root x in (0, pi/2] of sin(rho (thf - e x)) = rho Lam sin(x), x = (theta_f - theta)/e_y.

    For rho <= 1 the ratio sin(rho theta)/(rho Lam N) increases monotonically in theta
    (decreases in x) and -> inf at separation, so the root is unique. Newton in log(x) on
    the logarithm of the ratio (nearly linear even when the root is very close to
    separation, psi -> 0), bracketed in x.
    """
    lo = np.zeros_like(rho)
    hi = np.full_like(rho, HALF_PI)
    x = np.clip(np.arcsin(np.minimum(x0, 1.0)), 1e-300, HALF_PI)
    lr = np.log(rho * Lam)
    er = e * rho
    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(iters):
            sr, cr = _sincos(rho * (thf - e * x))
            sx, cx = _sincos(x)
            Q = np.log(sr / sx) - lr
            dQdy = -x * (er * cr / sr + cx / sx)
            pos = Q > 0
            lo = np.where(pos, x, lo)
            hi = np.where(pos, hi, x)
            new = x * np.exp(-Q / dQdy)
            bad = ~((new >= lo) & (new <= hi))
            if bad.any():  # bisect (geometrically) where Newton left the bracket
                new = np.where(bad, np.where(lo > 0, np.sqrt(lo * hi), 0.5 * hi), new)
            step = np.max(np.abs(new - x) / new)
            x = new
            if step < NEWTON_TOL:
                break
    return x


# --------------------------------------------------------------------------------------
# general engine: any rho, all phase sequences
# --------------------------------------------------------------------------------------
def _normal(th, e, thf):
    """N/N_max, its theta-derivative and its integral from 0 (1-D or broadcastable)."""
    unl = th > HALF_PI
    z = np.where(unl, (thf - th) / e, th)
    s, c = _sincos(z)
    N = s
    dN = np.where(unl, -c / e, c)
    I = np.where(unl, 1.0 + e * c, 1.0 - c)
    return N, dN, I


def _stick_state(th0, u0, s0, rho, th):
    sr, cr = _sincos(rho * (th - th0))
    return u0 * cr - rho * s0 * sr, s0 * cr + (u0 / rho) * sr


def _newton_bracketed(fun, x, lo, hi, iters=100, tol=None):
    """Vectorised safeguarded Newton: ``fun(x) -> (f, df)`` with f(lo) <= 0 < f(hi)."""
    for _ in range(iters):
        F, dF = fun(x)
        pos = F > 0
        hi = np.where(pos, x, hi)
        lo = np.where(pos, lo, x)
        with np.errstate(divide="ignore", invalid="ignore"):
            new = x - F / dF
        bad = ~((new >= lo) & (new <= hi))
        if bad.any():
            new = np.where(bad, 0.5 * (lo + hi), new)
        step = np.max(np.abs(new - x), initial=0.0)
        x = new
        if step < (NEWTON_TOL if tol is None else tol):
            break
    return x


def _stick_event(piece: _StickPiece, end):
    """First theta in (th0, end] where |S| = Lam N/N_max is crossed upwards in a stick piece (NaN: none).

    g = |S| - Lam N is sampled on a grid (at least STICK_GRID points, and fine enough that
    Omega_t changes phase by at most STICK_DPHASE between points). A sign change brackets
    the crossing; in addition every local maximum of g between two negative samples is
    located (Newton on g') and checked, so that a near-tangential excursion of g above zero
    between grid points is not missed. The bracketed root is refined by safeguarded Newton.
    The grid is sampled in blocks of GRID_BLOCK impacts (:func:`_sample_stick`); the maxima
    and the roots of all of them are found together.
    """
    th0, rho = piece.th0, piece.rho
    if _stuck_through_loading(piece, end):
        return np.full(th0.shape, np.nan), np.zeros(th0.shape)
    K = max(STICK_GRID, int(np.ceil(np.max(rho * (end - th0), initial=0.0) / STICK_DPHASE)))
    k = np.arange(0, K + 1) / K
    starts = range(0, max(th0.size, 1), GRID_BLOCK)
    blocks = [_sample_stick(piece.take(slice(a, a + GRID_BLOCK)), end[a : a + GRID_BLOCK], k) for a in starts]
    has, lo, hi, sg = (np.concatenate([b[q] for b in blocks]) for q in range(4))
    ci = np.concatenate([b[4][0] + a for a, b in zip(starts, blocks, strict=True)])
    cand = (ci, *(np.concatenate([b[4][q] for b in blocks]) for q in range(1, 5)))
    _crossings_at_maxima(piece, cand, has, lo, hi, sg)
    out = np.full(th0.shape, np.nan)
    sig = np.zeros(th0.shape)
    i = np.flatnonzero(has)
    if i.size == 0:
        return out, sig
    crossing, sign_s = piece.take(i), sg[i]

    def F(x):
        U1, S1 = crossing.state(x)
        N1, dN1, _ = crossing.normal(x)
        return sign_s * S1 - crossing.Lam * N1, sign_s * U1 - crossing.Lam * dN1

    out[i] = _newton_bracketed(F, hi[i].copy(), lo[i], hi[i])
    sig[i] = sign_s
    return out, sig


def _stuck_through_loading(piece: _StickPiece, end) -> bool:
    """Whether every impact of the batch starts sticking from rest and provably sticks through loading.

    From theta = 0 with U = 1, S = 0 the stick is S = sin(rho theta)/rho, and for rho >= 1
    ``|sin(rho theta)| <= rho sin(theta)`` on [0, pi/2] (sin x / x falls on (0, pi]; beyond pi,
    rho sin(theta) > 2 rho theta / pi > 2), so |S| <= N < Lam N when Lam > 1: g stays below zero
    and the grid would find no crossing up to t_c. Such a batch (every impact's first piece
    when Omega_t >= Omega_n, all of the general engine's in :func:`stronge_ex`) is not sampled;
    a batch with any other piece is, whole, as before.
    """
    first = (piece.th0 == 0.0) & (piece.u0 == 1.0) & (piece.s0 == 0.0) & (end <= HALF_PI)
    return bool(np.all(first & (piece.rho >= 1.0) & (piece.Lam > 1.0)))


#: Impacts per block whose stick grids :func:`_stick_event` samples at once: the work arrays
#: (GRID_BLOCK x the grid's points) stay in the cache, about twice as fast as a few thousand
#: impacts at once (the same numbers: each impact's grid is its own).
GRID_BLOCK = 256


def _sample_stick(piece: _StickPiece, end, k):
    """Sample g = |S| - Lam N of stick pieces on their grids ``th0 + (end - th0) k`` (:func:`_stick_event`).

    Returns, per impact, whether g crosses zero on the grid and the bracket (lo, hi) of the
    first crossing with the sign of S there (NaN, NaN, 0: none), and the grid intervals before
    it where g' goes from + to - (a local maximum between two samples): their rows, the
    interval's ends and S at them.
    """
    th0, u0, s0, rho, Lam, e, thf = piece
    K = k.size - 1
    grid = th0[:, None] + (end - th0)[:, None] * k
    r_, L_ = rho[:, None], Lam[:, None]
    U, S = _stick_state(th0[:, None], u0[:, None], s0[:, None], r_, grid)
    N, dN = _normal_on_grid(grid, e, thf, end)
    with np.errstate(invalid="ignore"):
        abs_s, lam_n = np.abs(S), L_ * N
        g = abs_s - lam_n
        gp = np.sign(S) * U - L_ * dN
    g[:, 0] = np.minimum(g[:, 0], 0.0)  # the piece starts in (or on the edge of) stick
    # a crossing must stand clear of rounding (g can sit at 0 +- 1e-16 for a whole short
    # piece that starts with a re-stick, e.g. just before t_c)
    with np.errstate(invalid="ignore"):
        amp = np.hypot(s0, u0 / rho)[:, None]  # amplitude of S in this stick piece
        cross = g > ROUND_TOL * (abs_s + lam_n + amp)
    has = cross.any(axis=1)
    first = np.where(has, np.argmax(cross, axis=1), K + 1)
    rows = np.arange(th0.size)
    lo = np.where(has, grid[rows, np.maximum(first - 1, 0)], np.nan)
    hi = np.where(has, grid[rows, np.minimum(first, K)], np.nan)
    sg = np.where(has, np.sign(S[rows, np.minimum(first, K)]), 0.0)
    # local maxima of g strictly before the first sampled crossing
    jj = np.arange(K)[None, :]
    ci, cj = np.nonzero((gp[:, :-1] > 0) & (gp[:, 1:] < 0) & (jj + 1 < first[:, None]) & np.isfinite(L_))
    return has, lo, hi, sg, (ci, grid[ci, cj], grid[ci, cj + 1], S[ci, cj], S[ci, cj + 1])


def _normal_on_grid(grid, e, thf, end):
    """N/N_max and its derivative on a stick piece's grid (n, K + 1), computed once per distinct row.

    Row i of the grid is ``th0_i + (end_i - th0_i) k``, so impacts with the same (th0, end,
    e_y, theta_f) share their N on it: in a fit (one e_y) the first piece of every impact
    runs from 0 to t_c, and impacts that stuck through loading all start unloading at t_c.
    When end, e_y and theta_f are common and at most half the starts distinct, N is computed
    on the distinct rows (one row, returned as (1, K + 1), broadcasts against the grid). The
    numbers are :func:`_normal`'s on the whole grid (elementwise, the same operations on the
    same values).
    """
    shared = end.size > 1 and bool(np.all((end == end[0]) & (e == e[0]) & (thf == thf[0])))
    if shared and bool(np.all(grid[:, 0] == grid[0, 0])):
        N, dN, _ = _normal(grid[:1], e[:1, None], thf[:1, None])
        return N, dN
    if shared:
        uniq, first, inv = np.unique(grid[:, 0], return_index=True, return_inverse=True)
        shared = 2 * uniq.size <= end.size
    if not shared:  # mostly distinct rows: the whole grid
        N, dN, _ = _normal(grid, e[:, None], thf[:, None])
        return N, dN
    N, dN, _ = _normal(grid[first], e[first, None], thf[first, None])
    inv = inv.reshape(-1)
    return N[inv], dN[inv]


class _StickPiece(NamedTuple):
    """One stick or slip piece per impact: where it starts (theta, U, S) and the impact's parameters."""

    th0: NDArray  # theta at the start of the piece
    u0: NDArray  # U at the start
    s0: NDArray  # S at the start
    rho: NDArray  # Omega_t/Omega_n
    Lam: NDArray  # the friction bound of S over N/N_max
    e: NDArray  # e_y
    thf: NDArray  # theta at separation

    def take(self, i) -> _StickPiece:
        """Return the pieces of the impacts ``i``."""
        return _StickPiece(*(a[i] for a in self))

    def state(self, th):
        """Return (U, S) at ``th`` in this stick piece."""
        return _stick_state(self.th0, self.u0, self.s0, self.rho, th)

    def normal(self, th):
        """Return N/N_max, its derivative and its integral at ``th`` (:func:`_normal`)."""
        return _normal(th, self.e, self.thf)


def _crossings_at_maxima(piece: _StickPiece, cand, has, lo, hi, sg) -> None:
    """Check the local maxima of g = |S| - Lam N between two grid points; mark the crossings.

    ``cand`` (rows, the intervals' ends ga and gb, S at them) are the grid intervals where g'
    changes from + to -. Each maximum is located by Newton on g'; one that stands clear of
    zero is a crossing, and the first per impact replaces that impact's bracket (``has``,
    ``lo``, ``hi``, ``sg``, in place).
    """
    ci, ga, gb, Sa, Sb = cand
    if ci.size == 0:
        return
    at_max = piece.take(ci)
    sgc = np.sign(np.where(np.abs(Sa) > np.abs(Sb), Sa, Sb))

    def dg(x):
        U1, S1 = at_max.state(x)
        N1, dN1, _ = at_max.normal(x)
        d2N = np.where(x > HALF_PI, -N1 / at_max.e**2, -N1)
        # minus g' so that the bracket convention f(lo) <= 0 < f(hi) holds
        return -(sgc * U1 - at_max.Lam * dN1), -(-sgc * at_max.rho * at_max.rho * S1 - at_max.Lam * d2N)

    xm = _newton_bracketed(dg, 0.5 * (ga + gb), ga, gb)
    _, S1 = at_max.state(xm)
    N1, _, _ = at_max.normal(xm)
    # a maximum that only touches zero (the edge of stick, e.g. at a re-stick) is not a
    # crossing: require it to stand clear of rounding
    up = (sgc * S1 - at_max.Lam * N1 > 1e-12 * np.abs(S1)) & (xm > at_max.th0 + 1e-9)
    if np.any(up):
        ui, first_idx = np.unique(ci[up], return_index=True)
        pick = np.flatnonzero(up)[first_idx]
        has[ui] = True
        lo[ui] = ga[pick]
        hi[ui] = xm[pick]
        sg[ui] = sgc[pick]


def _slip_step(th0, u0, sig, rho, Lam, e, thf):
    """Advance a slip piece to the end of its normal segment or to re-stick.

    Returns (theta_new, U_new, S_new, restuck). Closed form: within a segment C's velocity
    is W = A + B cos(z) with z the normal-force phase, and sigma W is monotone.
    """
    r2 = rho * rho
    unl = th0 >= HALF_PI
    z0 = np.where(unl, (thf - th0) / e, th0)
    _, cz0 = _sincos(z0)
    # loading: U = U0 - r2 sig Lam (cos z0 - cos th); W = A + B cos th
    # unloading (z = (thf - th)/e): U = U0 - r2 sig Lam e (cos z - cos z0); W = A + B cos z
    A = np.where(unl, u0 + r2 * sig * Lam * e * cz0, u0 - r2 * sig * Lam * cz0)
    B = np.where(unl, sig * Lam * (1.0 / e - r2 * e), sig * Lam * (r2 - 1.0))
    # W at the segment end: loading end z = pi/2 (cos 0); unloading end z = 0 (cos 1)
    w_end = np.where(unl, A + B, A)
    dec = np.where(unl, rho * e > 1.0, rho > 1.0)  # sigma W decreasing in this segment
    # root of A + B cos z = 0: z = arccos(-A/B), written as 2 asin(sqrt((A + B)/(2B))) so
    # that it stays accurate for small z (re-stick just before separation or near t = 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = np.clip((A + B) / (2.0 * B), 0.0, 1.0)
    ev = dec & (sig * w_end < -ROUND_TOL * (np.abs(A) + np.abs(B))) & np.isfinite(h)
    z = 2.0 * np.arcsin(np.sqrt(np.where(np.isfinite(h), h, 0.0)))
    th_ev = np.where(unl, thf - e * z, z)
    ev &= th_ev < thf - SEPARATION_TOL
    th_end = np.where(unl, thf, HALF_PI)
    th_new = np.where(ev, th_ev, th_end)
    z_new = np.where(ev, z, np.where(unl, 0.0, HALF_PI))
    sz, cz_new = _sincos(z_new)
    sz = np.where(z_new == HALF_PI, 1.0, sz)
    cz_new = np.where(z_new == HALF_PI, 0.0, cz_new)
    # cos z_new - cos z0 (unloading) and cos z0 - cos th_new (loading), free of cancellation
    dcos = 2.0 * np.sin(0.5 * (z0 + z_new)) * np.sin(0.5 * (z0 - z_new))
    u_new = np.where(unl, u0 - r2 * sig * Lam * e * dcos, u0 + r2 * sig * Lam * dcos)
    s_new = sig * Lam * sz
    return th_new, u_new, s_new, ev


@dataclass
class _Pieces:
    start: NDArray  # (n, P) theta at the start of each piece (inf: unused)
    mode: NDArray  # (n, P) 0 stick, +-1 slip direction
    u: NDArray  # (n, P) U at the start
    s: NDArray  # (n, P) S at the start
    n: NDArray  # (n,) number of pieces
    uf: NDArray  # (n,) final U


def _engine(p: _Params, idx, record: bool = True) -> _Pieces:
    """Run the phase machine for the impacts ``idx`` (flat indices into ``p``), in blocks (:func:`_engine_block`)."""
    blocks = [_engine_block(p, idx[a : a + CHUNK], record) for a in range(0, max(idx.size, 1), CHUNK)]
    if len(blocks) == 1:
        return blocks[0]
    P = max(b.start.shape[1] for b in blocks)

    def pad(a, fill):
        return np.pad(a, ((0, 0), (0, P - a.shape[1])), constant_values=fill)

    return _Pieces(
        np.concatenate([pad(b.start, np.inf) for b in blocks]),
        np.concatenate([pad(b.mode, 0) for b in blocks]),
        np.concatenate([pad(b.u, 0.0) for b in blocks]),
        np.concatenate([pad(b.s, 0.0) for b in blocks]),
        np.concatenate([b.n for b in blocks]),
        np.concatenate([b.uf for b in blocks]),
    )


def _end_of_stick(piece: _StickPiece, end):
    """Advance stick pieces to where they slip (:func:`_stick_event`) or to ``end``.

    Returns theta, U, S and the mode (+-1 slipping, 0 still sticking) there.
    """
    tev, sg = _stick_event(piece, end)
    ev = np.isfinite(tev) & (tev < piece.thf - SEPARATION_TOL)
    tnew = np.where(ev, tev, end)
    U1, S1 = piece.state(tnew)
    N1, _, _ = piece.normal(tnew)
    N1 = np.where(tnew >= piece.thf, 0.0, N1)
    with np.errstate(invalid="ignore"):
        s_new = np.where(ev, sg * piece.Lam * N1, S1)
    return tnew, U1, s_new, np.where(ev, sg, 0).astype(np.int8)


def _end_of_slip(piece: _StickPiece, slip_mode):
    """Advance slip pieces (direction ``slip_mode``) to re-stick or the end of their normal segment.

    Returns theta, U, S and the mode (0 stuck again, else ``slip_mode``) there (:func:`_slip_step`).
    """
    tnew, U1, S1, ev = _slip_step(
        piece.th0, piece.u0, slip_mode.astype(float), piece.rho, piece.Lam, piece.e, piece.thf
    )
    return tnew, U1, S1, np.where(ev, 0, slip_mode).astype(np.int8)


def _engine_block(p: _Params, idx, record: bool = True) -> _Pieces:
    """Run the phase machine for one block of impacts.

    ``record=False``: only the final U (:func:`stronge_ex`); the pieces' records are left empty
    (width 0), the same ``uf``.
    """
    rho, Lam, e, thf = p.rho[idx], p.Lam[idx], p.e[idx], p.thf[idx]
    n = idx.size
    P = MAX_PIECES
    width = P if record else 0
    start = np.full((n, width), np.inf)
    mode_rec = np.zeros((n, width), dtype=np.int8)
    u_rec = np.zeros((n, width))
    s_rec = np.zeros((n, width))
    npieces = np.zeros(n, dtype=int)
    th = np.zeros(n)
    u = np.ones(n)
    s = np.zeros(n)
    mode = np.where(Lam > 1.0, 0, 1).astype(np.int8)
    uf = np.full(n, np.nan)
    act = np.arange(n)
    for k in range(P):
        if act.size == 0:
            break
        if record:
            start[act, k] = th[act]
            mode_rec[act, k] = mode[act]
            u_rec[act, k] = u[act]
            s_rec[act, k] = s[act]
        npieces[act] = k + 1
        piece = _StickPiece(th[act], u[act], s[act], rho[act], Lam[act], e[act], thf[act])
        piece_mode = mode[act]
        # the end of the piece's normal segment: maximum compression, or separation
        end = np.where(piece.th0 < HALF_PI, HALF_PI, piece.thf)
        n_th, n_u, n_s, n_m = piece.th0.copy(), piece.u0.copy(), piece.s0.copy(), piece_mode.copy()
        sticking = piece_mode == 0
        i = np.flatnonzero(sticking)
        if i.size:
            n_th[i], n_u[i], n_s[i], n_m[i] = _end_of_stick(piece.take(i), end[i])
        j = np.flatnonzero(~sticking)
        if j.size:
            n_th[j], n_u[j], n_s[j], n_m[j] = _end_of_slip(piece.take(j), piece_mode[j])
        th[act], u[act], s[act], mode[act] = n_th, n_u, n_s, n_m
        fin = n_th >= piece.thf
        uf[act[fin]] = n_u[fin]
        act = act[~fin]
    if act.size:
        k = idx[act[0]]
        raise RuntimeError(
            f"stronge: no separation after {MAX_PIECES} stick/slip pieces for {act.size} impact(s),"
            f" e.g. tan(psi)={p.tan_psi[k]:g}, eta2={p.eta2[k]:g}, e_y={p.e[k]:g},"
            f" mu*eta2={p.lam[k]:g}, Omega_t/Omega_n={p.rho[k]:g}"
        )
    P = min(max(int(npieces.max(initial=1)), 1), width)
    return _Pieces(start[:, :P], mode_rec[:, :P], u_rec[:, :P], s_rec[:, :P], npieces, uf)


# --------------------------------------------------------------------------------------
# public solvers
# --------------------------------------------------------------------------------------
def stronge_ex(psi: ArrayLike, contact: ContactParams) -> NDArray[np.float64]:
    """Tangential coefficient of restitution e_x of Stronge's contact model.

    Parameters
    ----------
    psi : incidence angle between the relative velocity and the normal, rad, |psi| < pi/2.
        e_x is even in psi.
    contact : the model's parameters (eta2, e_y, mu, r_x, r_y, alpha); they broadcast
        against psi and each other.

    Returns
    -------
    ndarray
        ``e_x = -u_f / u_0`` with u the tangential velocity of the ball's contact point
        relative to the surface (Sec. III.B). At psi = 0 the limit psi -> 0 is returned.

    Notes
    -----
    Sec. V.A of Kensrud et al. (2017), after Stronge (1994, 2000); the model is
    specified in docs/model.md and derived in docs/stronge.md. For Omega_t <= Omega_n
    (eta2 >= 3.5 (1 + r_x)/(1 + r_y) when alpha = 0.4) the result is
    ``e_x = rho^2 mu eta2 (1 + e_y)/tan(psi) - 1`` when ``tan(psi) >= mu eta2`` (gross
    slip) and otherwise ``e_x = -cos(rho theta_1) + rho^2 (mu eta2/tan psi) (1 + e_y -
    I(theta_1))`` with theta_1 the end of the initial stick, found by Newton iteration;
    other cases run the general phase machine of :func:`stronge_solve`.
    """
    return _solve_ex(_prepare(psi, contact))


#: e_x's fast path (rho <= 1) compiled (:mod:`.soft_kernel`); False: the numpy reference (:func:`_uf_soft`).
COMPILED_SOFT = True


def _soft(rho, Lam, e, thf):
    """Return the final U on the fast path, compiled (:func:`.soft_kernel.uf_soft`) or not (:data:`COMPILED_SOFT`)."""
    if not COMPILED_SOFT:
        return _uf_soft(rho, Lam, e, thf)
    from .soft_kernel import uf_soft

    return uf_soft(*(np.ascontiguousarray(a, dtype=float) for a in (rho, Lam, e, thf)), NEWTON_TOL)


#: e_x's general phase machine (rho > 1) compiled (:mod:`.engine_kernel`); False: the numpy engine (:func:`_engine`).
COMPILED_ENGINE = True


def _general(p: _Params, idx: NDArray) -> NDArray:
    """Return the final U of the impacts ``idx`` through the general phase machine, compiled or not."""
    if not COMPILED_ENGINE:
        return _engine(p, idx, record=False).uf
    from .engine_kernel import final_u

    args = (np.ascontiguousarray(a[idx], dtype=float) for a in (p.rho, p.Lam, p.e, p.thf))
    consts = (float(STICK_GRID), STICK_DPHASE, ROUND_TOL, NEWTON_TOL, SEPARATION_TOL)
    uf, bad, count = final_u(*args, MAX_PIECES, consts)
    if bad >= 0:
        k = idx[bad]
        raise RuntimeError(
            f"stronge: no separation after {MAX_PIECES} stick/slip pieces for {count} impact(s),"
            f" e.g. tan(psi)={p.tan_psi[k]:g}, eta2={p.eta2[k]:g}, e_y={p.e[k]:g},"
            f" mu*eta2={p.lam[k]:g}, Omega_t/Omega_n={p.rho[k]:g}"
        )
    return uf


def _solve_ex(p: _Params) -> NDArray[np.float64] | float:
    """e_x of the prepared impacts ``p`` (:func:`stronge_ex`): the fast path where rho <= 1, else the engine."""
    uf = np.empty(p.rho.size)
    soft = p.rho <= 1.0
    for a in range(0, uf.size, CHUNK):
        b = min(a + CHUNK, uf.size)
        sl = slice(a, b)
        m = soft[sl]
        if m.all():
            uf[sl] = _soft(p.rho[sl], p.Lam[sl], p.e[sl], p.thf[sl])
        else:
            i = np.flatnonzero(m) + a
            if i.size:
                uf[i] = _soft(p.rho[i], p.Lam[i], p.e[i], p.thf[i])
            j = np.flatnonzero(~m) + a
            uf[j] = _general(p, j)
    ex = -uf
    return ex.reshape(p.shape) if p.shape else float(ex[0])


@dataclass(frozen=True)
class StrongeSolution:
    """Result of :func:`stronge_solve`; arrays have the broadcast shape of the inputs.

    Attributes
    ----------
    e_x : tangential coefficient of restitution, -u_f/u_0.
    regime : phase sequence per impact ("stick-slip", "gross-slip", "slip-stick-slip",
        "stick" if stick lasts to separation, or another "-"-joined sequence).
    t_stick_end : end of the initial stick, t/t_c (NaN if the impact starts in slip or
        sticks to separation).
    t_restick : first slip-to-stick transition, t/t_c (NaN if none).
    t_final_slip : onset of the slip that lasts to separation, t/t_c (0 for gross slip,
        NaN if the last phase is stick).
    t_separation : 1 + e_y.
    t_stretch_max, stretch_max : time (t/t_c) and value of the largest |s| during contact,
        s in units of the maximum normal compression v_n/Omega_n (the sign is that of s).
    omega_ratio : Omega_t/Omega_n.
    n_phases : number of stick/slip phases.
    t : common time grid t/t_c (histories=True only), shape (n_time,).
    normal_force : N/N_max on the grid, shape (..., n_time); NaN after separation.
    tangential_force : F/N_max, F = k_t s the tangential spring force (> 0 when it opposes
        the initial relative motion).
    stretch : s Omega_n/v_n, the tangential spring's stretch in units of v_n/Omega_n.
    c_velocity : velocity of the contact point C relative to the surface / v_n.
    u : tangential velocity of the ball's contact point relative to the surface / v_n
        (the "transverse velocity" of Fig. 10).
    energy : total mechanical energy (kinetic + both springs' potential) / initial kinetic
        energy.
    """

    e_x: NDArray
    regime: NDArray
    t_stick_end: NDArray
    t_restick: NDArray
    t_final_slip: NDArray
    t_separation: NDArray
    t_stretch_max: NDArray
    stretch_max: NDArray
    omega_ratio: NDArray
    n_phases: NDArray
    t: NDArray | None = None
    normal_force: NDArray | None = None
    tangential_force: NDArray | None = None
    stretch: NDArray | None = None
    c_velocity: NDArray | None = None
    u: NDArray | None = None
    energy: NDArray | None = None


def _eval_pieces(pc: _Pieces, rho, Lam, e, thf, th):
    """U, S, W (T-scaled) at theta ``th`` (n, m) from the piece records."""
    k = np.zeros(th.shape, dtype=int)
    for q in range(1, pc.start.shape[1]):
        k += th >= pc.start[:, q : q + 1]
    rows = np.arange(th.shape[0])[:, None]
    t0, m, u0, s0 = pc.start[rows, k], pc.mode[rows, k].astype(float), pc.u[rows, k], pc.s[rows, k]
    r, L, ee, ff = rho[:, None], Lam[:, None], e[:, None], thf[:, None]
    N, dN, I = _normal(th, ee, ff)
    _, _, I0 = _normal(t0, ee, ff)
    Us, Ss = _stick_state(t0, u0, s0, r, th)
    with np.errstate(invalid="ignore"):
        Ul = u0 - r * r * m * L * (I - I0)
        Sl = m * L * N
        Wl = Ul - m * L * dN
    slip = m != 0
    U = np.where(slip, Ul, Us)
    S = np.where(slip, Sl, Ss)
    W = np.where(slip, Wl, 0.0)
    return U, S, W, N


def _stretch_max(pc: _Pieces, rho, Lam, e, thf):
    """Time and value of max |S| over the contact, from the pieces (T-scaled S)."""
    n, _P = pc.start.shape
    end = np.concatenate([pc.start[:, 1:], np.full((n, 1), np.inf)], axis=1)
    end = np.minimum(end, thf[:, None])
    cands = [pc.start, end]
    # stick pieces: S = R cos(rho (th - th0) - phi); extrema at rho (th - th0) = phi + k pi
    phi = np.arctan2(pc.u / rho[:, None], pc.s)
    phi = np.mod(phi, np.pi)
    for kk in range(3):
        tc = pc.start + (phi + kk * np.pi) / rho[:, None]
        tc = np.where((pc.mode == 0) & (tc < end), tc, np.nan)
        cands.append(tc)
    # slip pieces: |S| = Lam N, largest at t_c when inside the piece
    tc = np.where((pc.mode != 0) & (pc.start <= HALF_PI) & (end >= HALF_PI), HALF_PI, np.nan)
    cands.append(tc)
    C = np.concatenate(cands, axis=1)
    C = np.where(np.isfinite(C) & (C <= thf[:, None]), C, np.nan)
    Cf = np.where(np.isnan(C), 0.0, C)
    _U, S, _W, _N = _eval_pieces(pc, rho, Lam, e, thf, Cf)
    A = np.where(np.isnan(C), -1.0, np.abs(S))
    k = np.argmax(A, axis=1)
    rows = np.arange(n)
    return Cf[rows, k], S[rows, k]


def _regimes(pc: _Pieces):
    n, P = pc.mode.shape
    valid = np.arange(P)[None, :] < pc.n[:, None]
    cat = np.where(valid, np.where(pc.mode == 0, _STICK, _SLIP), 0).astype(np.int8)
    prev = np.concatenate([np.zeros((n, 1), np.int8), cat[:, :-1]], axis=1)
    keep = (cat != prev) & valid
    order = np.argsort(~keep, axis=1, kind="stable")
    comp = np.take_along_axis(np.where(keep, cat, 0), order, axis=1)
    nph = keep.sum(axis=1)
    width = max(int(nph.max(initial=1)), 1)
    comp = comp[:, :width]
    uniq, inv = np.unique(comp, axis=0, return_inverse=True)
    names = []
    for row in uniq:
        seq = [_PHASE_NAMES[c] for c in row if c]
        if seq == ["slip"]:
            names.append("gross-slip")
        else:
            names.append("-".join(seq))
    width = max((len(s) for s in names), default=1)
    return np.array(names, dtype=f"<U{width}")[inv.ravel()], comp, nph


def _phase_times(pc, n: int, idx: np.ndarray, to_t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return the end of the first stick, the start of a re-stick and of the final slip (t/t_c; NaN: none)."""
    P = pc.start.shape[1]
    valid = np.arange(P)[None, :] < pc.n[:, None]
    cat = np.where(pc.mode == 0, _STICK, _SLIP)
    # transitions between consecutive pieces
    prevcat = np.concatenate([np.zeros((n, 1), int), cat[:, :-1]], axis=1)
    trans = valid & (np.arange(P)[None, :] > 0) & (cat != prevcat)
    first_stick = cat[:, 0] == _STICK
    k1 = np.where(trans.any(axis=1), np.argmax(trans, axis=1), -1)
    t_stick_end = np.where(first_stick & (k1 > 0), pc.start[idx, np.maximum(k1, 0)] * to_t, np.nan)
    rest = trans & (cat == _STICK)
    kr = np.argmax(rest, axis=1)
    t_restick = np.where(rest.any(axis=1), pc.start[idx, kr] * to_t, np.nan)
    last_cat = cat[idx, pc.n - 1]
    # last transition index
    kl = P - 1 - np.argmax(trans[:, ::-1], axis=1)
    t_final = np.where(trans.any(axis=1), pc.start[idx, kl] * to_t, 0.0)
    t_final = np.where(last_cat == _SLIP, t_final, np.nan)
    return t_stick_end, t_restick, t_final


def stronge_solve(
    psi: ArrayLike,
    contact: ContactParams,
    histories: bool = False,
    n_time: int = 601,
    t_max: float | None = None,
) -> StrongeSolution:
    """Solve Stronge's contact model: e_x, the phase sequence, event times and histories.

    Parameters
    ----------
    psi, contact
        As in :func:`stronge_ex`; they broadcast against each other.
    histories : bool
        Also return time histories on a common grid of ``n_time`` points of t/t_c from 0 to
        the largest 1 + e_y (values after an impact's separation are NaN).
    n_time : int
        Number of grid points of the histories.
    t_max : float, optional
        End of the time grid, t/t_c (default: the largest 1 + e_y, i.e. the last
        separation). Must not end before that separation, so that impacts solved apart (with
        different e_y) can share one grid.

    Returns
    -------
    StrongeSolution

    Notes
    -----
    Every phase (normal loading/unloading x tangential stick/slip) is solved in closed form
    (docs/stronge.md). Stick ends when k_t|s| reaches mu N (sampled on a grid of
    STICK_GRID points per piece, then refined by safeguarded Newton); slip ends when C's
    velocity w = u - ds/dt reaches zero, found in closed form because sigma w is monotone
    within a loading or unloading segment. The phase conditions are those of Sec. V.A of
    Kensrud et al. (2017) and Stronge (1994). Phase changes within SEPARATION_TOL of
    separation are ignored.
    """
    p = _prepare(psi, contact)
    n = p.rho.size
    idx = np.arange(n)
    pc = _engine(p, idx)
    regime, _comp, nph = _regimes(pc)
    to_t = 1.0 / HALF_PI
    t_stick_end, t_restick, t_final = _phase_times(pc, n, idx, to_t)
    tsm, smax = _stretch_max(pc, p.rho, p.Lam, p.e, p.thf)
    with np.errstate(invalid="ignore"):
        smax = smax * p.tan_psi
    sh = p.shape
    kw = dict(
        e_x=(-pc.uf).reshape(sh),
        regime=regime.reshape(sh),
        t_stick_end=t_stick_end.reshape(sh),
        t_restick=t_restick.reshape(sh),
        t_final_slip=t_final.reshape(sh),
        t_separation=(1.0 + p.e).reshape(sh),
        t_stretch_max=(tsm * to_t).reshape(sh),
        stretch_max=np.where(p.tan_psi > 0, smax, 0.0).reshape(sh),
        omega_ratio=p.rho.reshape(sh),
        n_phases=nph.reshape(sh),
    )
    if histories:
        t_sep = float(np.max(1.0 + p.e, initial=1.0))
        if t_max is not None and not t_max >= t_sep:
            raise ValueError(f"stronge_solve: t_max = {t_max:g} ends before separation at t/t_c = {t_sep:g}")
        t = np.linspace(0.0, t_sep if t_max is None else float(t_max), int(n_time))
        th = np.broadcast_to(t * HALF_PI, (n, t.size))
        after = th > p.thf[:, None]
        thc = np.minimum(th, p.thf[:, None])
        U, S, W, N = _eval_pieces(pc, p.rho, p.Lam, p.e, p.thf, thc)
        T = p.tan_psi[:, None]
        with np.errstate(invalid="ignore"):
            u, s, w = U * T, np.where(T > 0, S * T, 0.0), np.where(T > 0, W * T, 0.0)
        N = np.where(after, np.nan, np.maximum(N, 0.0))
        u, s, w = (np.where(after, np.nan, a) for a in (u, s, w))
        r2 = (p.rho**2)[:, None]
        eta2 = p.eta2[:, None]
        En = np.where(th < HALF_PI, 1.0, p.e[:, None] ** 2)
        E = (En + (u * u + r2 * s * s) / (eta2 * r2)) / (1.0 + T * T / (eta2 * r2))
        E = np.where(after, np.nan, E)
        shp = (*sh, t.size)
        kw.update(
            t=t,
            normal_force=N.reshape(shp),
            tangential_force=(s / eta2).reshape(shp),
            stretch=s.reshape(shp),
            c_velocity=w.reshape(shp),
            u=u.reshape(shp),
            energy=E.reshape(shp),
        )
    if not sh:
        kw = {k: (v[()] if isinstance(v, np.ndarray) and k != "t" and v.ndim == 0 else v) for k, v in kw.items()}
    return StrongeSolution(**kw)
