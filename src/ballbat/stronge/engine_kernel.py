"""Stronge's general phase machine (Omega_t > Omega_n) for e_x alone, compiled with numba (issue 39's speed).

An eta^2 fit starts from the lowest chi^2 of a scan of 48 values of eta^2 from 1 to 30; about
20 of them have Omega_t > Omega_n in the bat's frame, where an impact may stick, slip, stick
again: the general phase machine of :func:`ballbat.stronge.model._engine`. numpy runs it on the
whole batch, piece by piece, sampling every stick piece on a grid for the first crossing of
|S| = Lam N/N_max, locating maxima of that difference between grid points and refining roots by
safeguarded Newton, some sixty operations on (impact, grid) arrays a piece: about 6 ms of a
calibration replicate's 59. Here each impact runs the same machine as scalar loops
(:func:`final_u`): the same pieces, closed forms, grid rule, tests and Newton iterations, with
two differences of bookkeeping. Each stick piece's grid is fine enough for its own impact
(numpy took the finest any impact of the batch needed), and each Newton iteration stops at its
own converged step (numpy stepped every root until the largest step was below the tolerance);
both give the same roots to within the tolerance's square. ``tests/stronge/test_engine_kernel.py``
compares the final U with numpy's on impacts of every regime.

The numpy engine stays the reference, and is what :func:`ballbat.stronge.model.stronge_solve`
runs for the pieces' records. Compiled once per machine (``cache=True``: kept in
``__pycache__`` beside this file or in ``NUMBA_CACHE_DIR``); imported where e_x is computed.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .soft_kernel import HALF_PI, _sincos, bracketed_step

_jit = njit(cache=True, nogil=True, error_model="numpy")

#: :func:`final_u`'s status: the impact separated; or it did not within the pieces allowed.
SEPARATED, NO_SEPARATION = 0, 1


@_jit
def _sign(x: float) -> float:
    """numpy.sign of one value (0 for 0, NaN for NaN)."""
    if x > 0:
        return 1.0
    if x < 0:
        return -1.0
    return x * 0.0 if np.isnan(x) else 0.0


@_jit
def _normal(th: float, e: float, thf: float) -> tuple[float, float]:
    """Return N/N_max and its theta-derivative (``model._normal``)."""
    if th > HALF_PI:
        s, c = _sincos((thf - th) / e)
        return s, -c / e
    s, c = _sincos(th)
    return s, c


@_jit
def _stick_state(th0, u0, s0, rho, th) -> tuple[float, float]:
    """Return (U, S) at ``th`` in a stick piece from (th0, u0, s0) (``model._stick_state``)."""
    sr, cr = _sincos(rho * (th - th0))
    return u0 * cr - rho * s0 * sr, s0 * cr + (u0 / rho) * sr


@_jit
def _newton(th0, u0, s0, rho, Lam, e, thf, sgn, x, lo, hi, tol, maximum) -> float:
    """Safeguarded Newton from ``x`` in [lo, hi] (``model._newton_bracketed``) on g = sgn S - Lam N.

    ``maximum`` False: g's root (the crossing); True: the root of minus g' (where g has its
    maximum, ``model._crossings_at_maxima``).
    """
    for _ in range(100):
        U1, S1 = _stick_state(th0, u0, s0, rho, x)
        N1, dN1 = _normal(x, e, thf)
        if maximum:
            d2N = -N1 / e**2 if x > HALF_PI else -N1
            F = -(sgn * U1 - Lam * dN1)
            dF = -(-sgn * rho * rho * S1 - Lam * d2N)
        else:
            F, dF = sgn * S1 - Lam * N1, sgn * U1 - Lam * dN1
        new, lo, hi = bracketed_step(x, F, dF, lo, hi)
        step = abs(new - x)
        x = new
        if step < tol:
            break
    return x


@_jit
def _sampled_crossing(th0, u0, s0, rho, Lam, e, thf, end, grid, round_tol):
    """Sample g = |S| - Lam N on ``grid``; return the first upward crossing's bracket and sign, and g' and S there.

    Returns ``(first, gp, S)``: the index of the first grid point where g stands clear of
    rounding (``grid.size`` where none), and g' and S at every grid point.
    """
    K1 = grid.size
    gp, S = np.empty(K1), np.empty(K1)
    amp = math.hypot(s0, u0 / rho)  # amplitude of S in this stick piece
    first = K1
    for k in range(K1):
        U, Sk = _stick_state(th0, u0, s0, rho, grid[k])
        N, dN = _normal(grid[k], e, thf)
        abs_s, lam_n = abs(Sk), Lam * N
        g = abs_s - lam_n
        if k == 0:
            g = min(g, 0.0)  # the piece starts in (or on the edge of) stick
        gp[k], S[k] = _sign(Sk) * U - Lam * dN, Sk
        if first == K1 and g > round_tol * (abs_s + lam_n + amp):
            first = k
    return first, gp, S


@_jit
def _stick_event(th0, u0, s0, rho, Lam, e, thf, end, consts):
    """First theta in (th0, end] where |S| = Lam N/N_max is crossed upwards (NaN: none), and the sign of S there."""
    stick_grid, dphase, round_tol, tol = consts
    if th0 == 0.0 and u0 == 1.0 and s0 == 0.0 and end <= HALF_PI and rho >= 1.0 and Lam > 1.0:
        return np.nan, 0.0  # sticks through loading, provably (model._stuck_through_loading)
    K = max(int(stick_grid), int(math.ceil(max(rho * (end - th0), 0.0) / dphase)))  # noqa: RUF046 - numba's ceil
    grid = th0 + (end - th0) * (np.arange(0, K + 1) / K)
    first, gp, S = _sampled_crossing(th0, u0, s0, rho, Lam, e, thf, end, grid, round_tol)
    has = first <= K
    lo = grid[max(first - 1, 0)] if has else np.nan
    hi = grid[min(first, K)] if has else np.nan
    sg = _sign(S[min(first, K)]) if has else 0.0
    if np.isfinite(Lam):  # a maximum of g between two samples before the first sampled crossing
        for j in range(K):
            if not (gp[j] > 0 and gp[j + 1] < 0 and j + 1 < first):
                continue
            sgc = _sign(S[j] if abs(S[j]) > abs(S[j + 1]) else S[j + 1])
            xm = _newton(
                th0, u0, s0, rho, Lam, e, thf, sgc, 0.5 * (grid[j] + grid[j + 1]), grid[j], grid[j + 1], tol, True
            )
            S1 = _stick_state(th0, u0, s0, rho, xm)[1]
            N1 = _normal(xm, e, thf)[0]
            if sgc * S1 - Lam * N1 > 1e-12 * abs(S1) and xm > th0 + 1e-9:
                has, lo, hi, sg = True, grid[j], xm, sgc
                break
    if not has:
        return np.nan, 0.0
    return _newton(th0, u0, s0, rho, Lam, e, thf, sg, hi, lo, hi, tol, False), sg


@_jit
def _end_of_stick(th0, u0, s0, rho, Lam, e, thf, end, consts):
    """Advance a stick piece to where it slips or to ``end``: theta, U, S and mode there (``model._end_of_stick``)."""
    separation_tol = consts[4]
    tev, sg = _stick_event(th0, u0, s0, rho, Lam, e, thf, end, consts[:4])
    ev = np.isfinite(tev) and tev < thf - separation_tol
    tnew = tev if ev else end
    U1, S1 = _stick_state(th0, u0, s0, rho, tnew)
    N1 = 0.0 if tnew >= thf else _normal(tnew, e, thf)[0]
    if ev:
        return tnew, U1, sg * Lam * N1, int(sg)
    return tnew, U1, S1, 0


@_jit
def _slip_step(th0, u0, sig, rho, Lam, e, thf, round_tol, separation_tol):
    """Advance a slip piece to the end of its normal segment or to re-stick (``model._slip_step``, one impact)."""
    r2 = rho * rho
    unl = th0 >= HALF_PI
    z0 = (thf - th0) / e if unl else th0
    cz0 = _sincos(z0)[1]
    A = u0 + r2 * sig * Lam * e * cz0 if unl else u0 - r2 * sig * Lam * cz0
    B = sig * Lam * (1.0 / e - r2 * e) if unl else sig * Lam * (r2 - 1.0)
    w_end = A + B if unl else A
    dec = rho * e > 1.0 if unl else rho > 1.0  # sigma W decreasing in this segment
    h = (A + B) / (2.0 * B)
    if not np.isnan(h):
        h = min(max(h, 0.0), 1.0)
    ev = dec and sig * w_end < -round_tol * (abs(A) + abs(B)) and np.isfinite(h)
    z = 2.0 * math.asin(math.sqrt(h if np.isfinite(h) else 0.0))
    th_ev = thf - e * z if unl else z
    ev = ev and th_ev < thf - separation_tol
    th_new = th_ev if ev else (thf if unl else HALF_PI)
    z_new = z if ev else (0.0 if unl else HALF_PI)
    sz = 1.0 if z_new == HALF_PI else _sincos(z_new)[0]
    dcos = 2.0 * np.sin(0.5 * (z0 + z_new)) * np.sin(0.5 * (z0 - z_new))
    u_new = u0 - r2 * sig * Lam * e * dcos if unl else u0 + r2 * sig * Lam * dcos
    return th_new, u_new, sig * Lam * sz, ev


@_jit
def _one(rho, Lam, e, thf, max_pieces, consts) -> tuple[float, int]:
    """Return the final U of one impact and its status (:data:`SEPARATED` or :data:`NO_SEPARATION`)."""
    round_tol, separation_tol = consts[2], consts[4]
    th, u, s = 0.0, 1.0, 0.0
    mode = 0 if Lam > 1.0 else 1
    for _ in range(max_pieces):
        end = HALF_PI if th < HALF_PI else thf  # the end of the piece's normal segment
        if mode == 0:
            th, u, s, mode = _end_of_stick(th, u, s, rho, Lam, e, thf, end, consts)
        else:
            th, u, s, ev = _slip_step(th, u, float(mode), rho, Lam, e, thf, round_tol, separation_tol)
            if ev:
                mode = 0
        if th >= thf:
            return u, SEPARATED
    return np.nan, NO_SEPARATION


@_jit
def final_u(rho, Lam, e, thf, max_pieces, consts) -> tuple[np.ndarray, int, int]:
    """Return the final U = u_f/u_0 of impacts of any rho (1-D arrays), the first not separated (-1: none), their count.

    ``consts``: (STICK_GRID, STICK_DPHASE, ROUND_TOL, NEWTON_TOL, SEPARATION_TOL) of
    :mod:`ballbat.stronge.model`; ``max_pieces``: its MAX_PIECES.
    """
    out = np.empty(rho.size)
    bad, count = -1, 0
    for i in range(rho.size):
        out[i], status = _one(rho[i], Lam[i], e[i], thf[i], max_pieces, consts)
        if status != SEPARATED:
            count += 1
            if bad < 0:
                bad = i
    return out, bad, count
