"""The errors-in-variables line's passes and Paule and Mandel's root, compiled with numba (issue 39's speed).

:func:`ballbat.linefit.eiv_line` iterates its weights, the intrinsic scatter tau^2 and the
slope three to eight times, and each tau^2 is a root found from a dozen sums over the
points. On the 50-110 impacts of a fit of e_x these are some 40 numpy calls a pass on short
arrays, so numpy's per-call overhead set their cost (about 17 ms of a calibration
replicate's 74: 37 fits, 190 roots). Here each fit's passes are one call (:func:`passes`),
as plain loops over the points; the arithmetic is the same, in another order of summation,
so the numbers agree with the former numpy passes to round-off (the tests compare them with
an independent numpy transcription, ``tests/test_linefit_kernels.py``).

tau^2 (:func:`q_root`): the root of Q(t) = sum r_i^2 / (v_i + t g_i) = target is found by
Newton's method on H = 1/Q. H is the parallel sum of the lines (v_i + t g_i)/r_i^2, hence
concave and increasing, so Newton from t = 0 (where H < 1/target) climbs to the root from
below without overshooting, and is exact at once for a single point; it stops where a step
no longer moves t. The former bracketing solver (scipy's ``brentq``, relative tolerance
1e-10) found the same root to its tolerance.

Compiled once per machine (``cache=True``: the machine code is kept in ``__pycache__`` beside
this file, or in ``NUMBA_CACHE_DIR``), a few seconds the first time; a process that fits a
line imports numba and loads the code once (about 0.3 s of CPU). :mod:`ballbat.linefit`
imports this module only where a line is fitted, so that reading the Snakefile does not.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_jit = njit(cache=True, nogil=True, error_model="numpy")

#: Newton's iterations for tau^2 at most (it converges in 3-8; a step that no longer moves t ends it).
MAX_NEWTON = 200

#: passes()'s status: the passes ended with a fit, or a variance or corrected spread not positive (no fit).
FITTED, NOT_FITTED = 0, 1


@_jit
def q_root(r2: np.ndarray, v0: np.ndarray, g: np.ndarray, target: float) -> float:
    """Return tau^2 >= 0 where sum r2 / (v0 + tau^2 g) equals ``target`` (0: below it at 0; inf: no tau reaches it)."""
    n = r2.size
    q0 = 0.0
    fixed = 0.0  # the points with g = 0: their part of Q whatever tau
    any_g = False
    for i in range(n):
        a = r2[i] / v0[i]
        q0 += a
        if g[i] > 0:
            any_g = True
        else:
            fixed += a
    if q0 - target <= 0 or not any_g:
        return 0.0
    if fixed >= target:
        return np.inf
    goal = 1.0 / target
    t = 0.0
    for _ in range(MAX_NEWTON):
        q = 0.0
        dq = 0.0
        for i in range(n):
            d = v0[i] + t * g[i]
            a = r2[i] / d
            q += a
            dq += a * g[i] / d
        # H = 1/Q, H' = Q'/(-Q^2) = dq / q^2
        step = (goal - 1.0 / q) * q * q / dq
        if not step > 0.0:  # at the root to rounding (H is concave: the steps only climb)
            break
        t_new = t + step
        if t_new == t:
            break
        t = t_new
    return t


@_jit
def _scatter_residuals(r, x, y, var_x, cov_xy, v, idx, nstrata, dof, out):
    """Write into ``out`` the residuals tau^2 is estimated from; return their degrees of freedom.

    As :func:`ballbat.linefit._scatter_residuals`: without strata (``nstrata`` < 2) the line's
    residuals and ``dof``; with strata each point's residual about its stratum's own
    moment-corrected slope (weights 1/``v``), one degree of freedom per stratum so fitted.
    """
    n = r.size
    if nstrata < 2:
        for i in range(n):
            out[i] = r[i]
        return dof
    num = np.zeros(nstrata)
    den = np.zeros(nstrata)
    for i in range(n):
        w = 1.0 / v[i]
        num[idx[i]] += w * (x[i] * y[i] - cov_xy[i])
        den[idx[i]] += w * (x[i] * x[i] - var_x[i])
    own = 0
    for s in range(nstrata):
        if den[s] > 0:
            own += 1
    for i in range(n):
        s = idx[i]
        out[i] = y[i] - num[s] / den[s] * x[i] if den[s] > 0 else r[i]
    return n - own


@_jit
def _normal_equations(X, y, W, var_x, cov_xy, xwx, A, rhs):
    """Fill X'WX, A = X'WX - diag(sum W var x, 0) and rhs = X'Wy - (sum W cov, 0)."""
    n, p = X.shape
    for a in range(p):
        rhs[a] = 0.0
        for b in range(p):
            xwx[a, b] = 0.0
    swv = 0.0
    swc = 0.0
    for i in range(n):
        w = W[i]
        for a in range(p):
            wa = w * X[i, a]
            rhs[a] += wa * y[i]
            for b in range(p):
                xwx[a, b] += wa * X[i, b]
        swv += w * var_x[i]
        swc += w * cov_xy[i]
    for a in range(p):
        for b in range(p):
            A[a, b] = xwx[a, b]
    A[0, 0] -= swv
    rhs[0] -= swc


@_jit
def _solve(A, rhs, beta):
    """Solve A beta = rhs for p = 1 or 2 (2 x 2: elimination with the larger pivot); False where A is not positive."""
    if A[0, 0] <= 0:
        return False
    if A.shape[0] == 1:
        beta[0] = rhs[0] / A[0, 0]
        return True
    if A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0] <= 0:
        return False
    if abs(A[1, 0]) > abs(A[0, 0]):  # pivot on the second row
        l_ = A[0, 0] / A[1, 0]
        u = A[0, 1] - l_ * A[1, 1]
        z = rhs[0] - l_ * rhs[1]
        beta[1] = z / u
        beta[0] = (rhs[1] - A[1, 1] * beta[1]) / A[1, 0]
    else:
        l_ = A[1, 0] / A[0, 0]
        u = A[1, 1] - l_ * A[0, 1]
        z = rhs[1] - l_ * rhs[0]
        beta[1] = z / u
        beta[0] = (rhs[0] - A[0, 1] * beta[1]) / A[0, 0]
    return True


@_jit
def passes(X, y, jx, jy, sig2, var_x, cov_xy, g, beta0, iterations, extra_passes, scatter, idx, nstrata, stop):
    """:func:`ballbat.linefit.eiv_line`'s passes of the weights, tau^2 and the slope, from the start ``beta0``.

    ``extra_passes``: the passes with tau^2 after the ``iterations`` (where ``scatter``);
    ``idx``/``nstrata``: each point's stratum (``nstrata`` < 2: none); ``stop``: end at the
    fixed point (a pass whose slope and tau^2 are those it started from, to the bit, after
    the first, or after the first with tau^2). Returns ``(status, beta, tau2, scatter, W,
    xwx, A, var0, passes made)``; ``status`` :data:`NOT_FITTED` where an effective variance
    or the corrected spread of x is not positive.
    """
    n, p = X.shape
    k = jx.shape[1]
    beta = beta0.copy()
    tau2 = 0.0
    settled = iterations if scatter else 1
    var0 = np.empty(n)
    W = np.empty(n)
    r = np.empty(n)
    r_s = np.empty(n)
    r2 = np.empty(n)
    v = np.empty(n)
    x = X[:, 0].copy()
    xwx = np.empty((p, p))
    A = np.empty((p, p))
    rhs = np.empty(p)
    new = np.empty(p)
    total = iterations + (extra_passes if scatter else 0)
    made = 0
    for it in range(total):
        made = it + 1
        for i in range(n):
            s = 0.0
            for j in range(k):
                d = jy[i, j] - beta[0] * jx[i, j]
                s += d * d * sig2[i, j]
            if s <= 0:
                return NOT_FITTED, beta, tau2, scatter, W, xwx, A, var0, made
            var0[i] = s
        tau2_before, scatter_before = tau2, scatter
        if scatter and it >= iterations - 1:
            for i in range(n):
                fit = 0.0
                for a in range(p):
                    fit += X[i, a] * beta[a]
                r[i] = y[i] - fit
                v[i] = var0[i] + tau2 * g[i]
            dof = _scatter_residuals(r, x, y, var_x, cov_xy, v, idx, nstrata, n - p, r_s)
            if dof >= 1:
                for i in range(n):
                    r2[i] = r_s[i] * r_s[i]
                tau2 = q_root(r2, var0, g, float(dof))
            else:
                tau2 = np.inf
            if not np.isfinite(tau2):  # the points at x ~ 0 alone exceed the dof, or none is left
                scatter = False
                tau2 = 0.0
        for i in range(n):
            W[i] = 1.0 / (var0[i] + tau2 * g[i])
        _normal_equations(X, y, W, var_x, cov_xy, xwx, A, rhs)
        if not _solve(A, rhs, new):
            return NOT_FITTED, beta, tau2, scatter, W, xwx, A, var0, made
        same = tau2 == tau2_before and scatter == scatter_before
        for a in range(p):
            same = same and new[a] == beta[a]
            beta[a] = new[a]
        if stop and it >= settled and same:
            break
    return FITTED, beta, tau2, scatter, W, xwx, A, var0, made
