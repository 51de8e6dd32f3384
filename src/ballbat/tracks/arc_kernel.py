"""The tip-arc cross-check's Gauss-Newton fit, compiled with numba (issue 39's speed).

:func:`ballbat.tracks.checks.tip_arc` fits each impact's tip marks before the contact with
the series of a circle's arc (``a + V s - V^3 w s^3 / 6 + ...``, five terms, four parameters:
a, V, the alignment time tau under the reduction's prior, and w = 1 / L^2), ten Gauss-Newton
steps and the covariance. In numpy each step is some forty operations on (impact, frame)
arrays and a batched 4 x 4 solve: about 2.5 ms of a calibration replicate's cross-checks. Here
each impact's steps are plain loops over its frames (:func:`fit`): the same series, steps and
prior, the normal equations summed frame by frame and solved by elimination with partial
pivoting (a system with a zero pivot is singular, as LAPACK's), so kappa and its error agree
with numpy's to round-off (``tests/tracks/test_checks.py``). The numpy code stays the
reference (``checks.ARC_COMPILED = False``).

Compiled once per machine (``cache=True``: kept in ``__pycache__`` beside this file or in
``NUMBA_CACHE_DIR``); imported where the tracks are cross-checked.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_jit = njit(cache=True, nogil=True, error_model="numpy")

#: The arc's series: five terms, x^(2k+1) / (2k+1)! for k = 0..4.
FACTORIALS = np.array([math.factorial(2 * k + 1) for k in range(5)], dtype=np.float64)


@_jit
def _solve4(A, b, x) -> bool:
    """Solve the 4 x 4 system A x = b by elimination with partial pivoting (copies); False where a pivot is 0."""
    M = A.copy()
    v = b.copy()
    n = 4
    for c in range(n):
        p = c
        for r in range(c + 1, n):
            if abs(M[r, c]) > abs(M[p, c]):
                p = r
        if M[p, c] == 0.0:
            return False
        if p != c:
            for k in range(n):
                M[c, k], M[p, k] = M[p, k], M[c, k]
            v[c], v[p] = v[p], v[c]
        for r in range(c + 1, n):
            f = M[r, c] / M[c, c]
            for k in range(c, n):
                M[r, k] -= f * M[c, k]
            v[r] -= f * v[c]
    for c in range(n - 1, -1, -1):
        s = v[c]
        for k in range(c + 1, n):
            s -= M[c, k] * x[k]
        x[c] = s / M[c, c]
    return True


@_jit
def _normal(i, along, t, mask, a, V, tau, w, A, b, fact) -> float:
    """Fill impact ``i``'s J'J and J'r of the arc's series at (a, V, tau, w); return the residuals' sum of squares."""
    A[:, :] = 0.0
    b[:] = 0.0
    ss = 0.0
    row = np.empty(4)
    for f in range(t.shape[1]):
        if not mask[i, f]:
            continue
        s = t[i, f] - tau
        x = V * s
        x2 = x * x
        x2k = 1.0
        fx = dx = dw = 0.0
        for k in range(5):
            term = (-w) ** k / fact[k] * x2k
            fx += term * x
            dx += (2 * k + 1) * term
            if k:
                dw += (k * (-1) ** k * w ** (k - 1) / fact[k] * x2k) * x
            x2k *= x2
        r = along[i, f] - (a + fx)
        row[0], row[1], row[2], row[3] = 1.0, s * dx, -V * dx, dw
        for p in range(4):
            b[p] += row[p] * r
            for q in range(4):
                A[p, q] += row[p] * row[q]
        ss += r * r
    return ss


@_jit
def fit(along, t, mask, n, a, V, tau, tau0, ok, sigma_tau, iterations):
    """Return each impact's w, its variance and whether its fit was made (``checks.tip_arc``'s steps and covariance).

    ``a``, ``V``, ``tau``: the start (straight line, tau at its prior ``tau0``), where ``ok``;
    ``sigma_tau``: the prior's sd per impact. A singular system leaves its impact's fit not made.
    """
    m = a.size
    w_out, var_w, good = np.zeros(m), np.full(m, np.nan), ok.copy()
    A, b, step = np.empty((4, 4)), np.empty(4), np.empty(4)
    for i in range(m):
        ai, Vi, ti, wi = a[i], V[i], tau[i], 0.0
        dof = max(n[i] - 4, 1)
        for _ in range(iterations):
            s2 = _normal(i, along, t, mask, ai, Vi, ti, wi, A, b, FACTORIALS) / dof
            prior = s2 / sigma_tau[i] ** 2
            A[2, 2] += prior
            b[2] += prior * (tau0[i] - ti)
            if not good[i]:
                A[:, :] = np.eye(4)
                b[:] = 0.0
            if not (_solve4(A, b, step) and np.all(np.isfinite(step))):
                good[i] = False  # a singular system: that impact's check is not made
                continue
            if good[i]:
                ai, Vi, ti, wi = ai + step[0], Vi + step[1], ti + step[2], wi + step[3]
        s2 = _normal(i, along, t, mask, ai, Vi, ti, wi, A, b, FACTORIALS) / dof
        A[2, 2] += s2 / sigma_tau[i] ** 2
        if not good[i]:
            A[:, :] = np.eye(4)
        e3 = np.zeros(4)
        e3[3] = 1.0
        if _solve4(A, e3, step):
            var_w[i] = step[3] * s2
        w_out[i] = wi
    return w_out, var_w, good
