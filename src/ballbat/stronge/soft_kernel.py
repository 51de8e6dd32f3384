"""Stronge's model on its fast path (rho = Omega_t/Omega_n <= 1), compiled with numba (issue 39's speed).

An eta^2 fit evaluates e_x of its 50-110 impacts some fifteen times, and at the eta^2 of
baseballs and softballs (above 3.5 (1 + r_x)/(1 + r_y)) every impact takes the fast path
(:func:`ballbat.stronge.model._uf_soft`): gross slip, or one stick phase from the start and
slip to separation, whose stick-to-slip time is the root of a smooth monotone function. In
numpy that is some 30 calls of a few microseconds each on short arrays for every Newton
step, so the calls' overhead, not the arithmetic, set the cost (about 4 ms of a calibration
replicate's 63). Here each impact is one pass of plain loops (:func:`uf_soft`): the same
formulas, the same safeguarded Newton iterations with the same tolerance, except that each
impact stops where its own step is below the model's ``NEWTON_TOL`` (``tol``; numpy
stepped every impact until the largest step was): the roots agree to that tolerance's square,
e_x to round-off (``tests/stronge/test_soft_kernel.py`` compares the two).

The numpy path stays the reference (``model.COMPILED_SOFT = False``). Compiled once per
machine (``cache=True``: kept in ``__pycache__`` beside this file or in ``NUMBA_CACHE_DIR``);
imported only where e_x is computed, so reading the Snakefile does not import numba.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_jit = njit(cache=True, nogil=True, error_model="numpy")

HALF_PI = 0.5 * math.pi  # the model's (0.5 * np.pi: the same double)

#: Newton's iterations at most (as :func:`ballbat.stronge.model._root_loading`'s and ``_root_unloading``'s).
ITERATIONS = 60


@_jit
def _sincos(x: float) -> tuple[float, float]:
    """sin(x), cos(x) from one tangent of the half angle (the model's ``_sincos``)."""
    t = math.tan(0.5 * x)
    t2 = t * t
    inv = 1.0 / (1.0 + t2)
    return 2.0 * t * inv, (1.0 - t2) * inv


@_jit
def bracketed_step(x: float, f: float, df: float, lo: float, hi: float) -> tuple[float, float, float]:
    """Return one safeguarded Newton step on an increasing f (``model._newton_bracketed``): (new x, lo, hi).

    The bracket is narrowed at ``x``, then Newton's step taken, bisection where it leaves the bracket.
    """
    if f > 0:
        hi = x
    else:
        lo = x
    new = x - f / df
    if not (new >= lo and new <= hi):
        new = 0.5 * (lo + hi)
    return new, lo, hi


@_jit
def _root_loading(rho: float, Lam: float, tol: float) -> float:
    """Root theta in (0, pi/2) of sin(rho theta) / (rho sin theta) = Lam (``model._root_loading``, one impact)."""
    lo, hi = 0.0, HALF_PI
    g = math.sqrt(6.0 * (Lam - 1.0) / max(1.0 - rho * rho, 1e-300))
    th = min(max(g, 1e-3 * HALF_PI), 0.999 * HALF_PI)
    lr = math.log(rho * Lam)
    for _ in range(ITERATIONS):
        sr, cr = _sincos(rho * th)
        s, c = _sincos(th)
        P = math.log(sr / s) - lr
        dP = rho * cr / sr - c / s
        new, lo, hi = bracketed_step(th, P, dP, lo, hi)
        step = abs(new - th)
        th = new
        if step < tol:
            break
    return th


@_jit
def _root_unloading(rho: float, Lam: float, e: float, thf: float, x0: float, tol: float) -> float:
    """Root x in (0, pi/2] of sin(rho (thf - e x)) = rho Lam sin(x) (``model._root_unloading``, one impact)."""
    lo, hi = 0.0, HALF_PI
    x = min(max(math.asin(min(x0, 1.0)), 1e-300), HALF_PI)
    lr = math.log(rho * Lam)
    er = e * rho
    for _ in range(ITERATIONS):
        sr, cr = _sincos(rho * (thf - e * x))
        sx, cx = _sincos(x)
        Q = np.log(sr / sx) - lr
        dQdy = -x * (er * cr / sr + cx / sx)
        if Q > 0:
            lo = x
        else:
            hi = x
        new = x * np.exp(-Q / dQdy)
        if not (new >= lo and new <= hi):  # bisect (geometrically) where Newton left the bracket
            new = math.sqrt(lo * hi) if lo > 0 else 0.5 * hi
        step = abs(new - x) / new
        x = new
        if step < tol:
            break
    return x


@_jit
def _uf_one(rho: float, Lam: float, e: float, thf: float, tol: float) -> float:
    """Return the final U of one impact with rho <= 1 (``model._uf_soft``'s cases)."""
    r2 = rho * rho
    if not Lam > 1.0:  # gross slip
        return 1.0 - r2 * Lam * (1.0 + e)
    s_half = _sincos(rho * HALF_PI)[0]
    s_f, c_f = _sincos(rho * thf)
    if s_half / rho > Lam:  # stick ends while loading
        th = _root_loading(rho, Lam, tol)
        cr = _sincos(rho * th)[1]
        return cr - r2 * Lam * (e + np.cos(th))
    x0 = s_f / (rho * Lam)
    if not x0 > 1e-280:  # stick to separation (psi = 0, the superball)
        return c_f
    x = _root_unloading(rho, Lam, e, thf, x0, tol)
    cr = _sincos(rho * (thf - e * x))[1]
    sh = np.sin(0.5 * x)
    return cr - r2 * Lam * 2.0 * e * sh * sh


@_jit
def uf_soft(rho: np.ndarray, Lam: np.ndarray, e: np.ndarray, thf: np.ndarray, tol: float) -> np.ndarray:
    """Return the final U = u_f/u_0 of impacts with rho <= 1 (1-D arrays; ``model._uf_soft``; ``tol``: NEWTON_TOL)."""
    out = np.empty(rho.size)
    for i in range(rho.size):
        out[i] = _uf_one(rho[i], Lam[i], e[i], thf[i], tol)
    return out
