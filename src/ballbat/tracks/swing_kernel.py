"""The tip fit's Gauss-Newton iterations, compiled with numba (issue 39's speed).

:func:`ballbat.tracks.fit_swing.fit_swing` fits each impact's tip marks before the contact
with three parameters (the offset along the swing a, the angular speed omega, the alignment
time tau, held near the contact's start by a prior): six Gauss-Newton steps and the final
covariance. In numpy every step is some twenty operations on (impact, frame) arrays and a
batched 3 x 3 solve, about 1 ms for a replicate's 108 impacts, three times a replicate (the
nominal reduction and the contact population's two shifts). Here each impact's iterations run
as plain loops over its fitted frames (:func:`gauss_newton`): the same formulas and steps, the
normal equations summed frame by frame rather than by BLAS, so the fit agrees with numpy's to
round-off (``tests/tracks/test_fit_swing.py`` compares them). The numpy code stays the
reference (``fit_swing.SWING_COMPILED = False``).

Compiled once per machine (``cache=True``: kept in ``__pycache__`` beside this file or in
``NUMBA_CACHE_DIR``); imported where a swing is fitted, never when the Snakefile is read.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_jit = njit(cache=True, nogil=True, error_model="numpy")


@_jit
def _normal(i, along, t, mask, L, a, om, tau, A, b):
    """Fill impact ``i``'s J'J (3 x 3) and J'r at (a, om, tau); return its residuals' sum of squares."""
    A[:, :] = 0.0
    b[:] = 0.0
    ss = 0.0
    for f in range(t.shape[1]):
        if not mask[i, f]:
            continue
        dt = t[i, f] - tau
        arg = om * dt
        c = math.cos(arg)
        r = along[i, f] - (a + L * math.sin(arg))
        j0, j1, j2 = 1.0, L * dt * c, -L * om * c
        A[0, 0] += j0 * j0
        A[0, 1] += j0 * j1
        A[0, 2] += j0 * j2
        A[1, 1] += j1 * j1
        A[1, 2] += j1 * j2
        A[2, 2] += j2 * j2
        b[0] += j0 * r
        b[1] += j1 * r
        b[2] += j2 * r
        ss += r * r
    A[1, 0], A[2, 0], A[2, 1] = A[0, 1], A[0, 2], A[1, 2]
    return ss


@_jit
def gauss_newton(along, t, mask, L, a0, om0, tau0, sigma_tau, n, iterations):
    """Return a, omega, tau, omega's error and the rms residual of every impact's tip fit (``fit_swing``'s steps).

    ``a0``, ``om0``: the start; ``tau0``: the contact's start (the prior's centre and tau's
    start); ``sigma_tau``: the prior's sd; ``n``: each impact's fitted frames. The prior is held
    at 1e12 for the first two steps, then set from the residuals (s^2 / sigma_tau^2).
    """
    m = a0.size
    a, om, tau = a0.copy(), om0.copy(), tau0.copy()
    om_err, rms = np.empty(m), np.empty(m)
    A, b = np.empty((3, 3)), np.empty(3)
    for i in range(m):
        prior = 1e12
        ok = n[i] >= 4
        for it in range(iterations):
            _normal(i, along, t, mask, L, a[i], om[i], tau[i], A, b)
            A[2, 2] += prior
            b[2] += prior * (tau0[i] - tau[i])
            if not ok:
                A[:, :] = np.eye(3)
                b[:] = 0.0
            step = np.linalg.solve(A, b)
            a[i], om[i], tau[i] = a[i] + step[0], om[i] + step[1], tau[i] + step[2]
            if it == 1:
                ss = _normal(i, along, t, mask, L, a[i], om[i], tau[i], A, b)
                prior = ss / (n[i] - 2) / sigma_tau[i] ** 2
        ss = _normal(i, along, t, mask, L, a[i], om[i], tau[i], A, b)
        s2 = ss / (n[i] - 3)
        A[2, 2] += s2 / sigma_tau[i] ** 2
        if not ok:
            A[:, :] = np.eye(3)
        cov11 = np.linalg.inv(A)[1, 1] * s2
        om_err[i] = math.sqrt(cov11 * (n[i] - 3) / max(n[i] - 5, 1.0))
        rms[i] = math.sqrt(ss / n[i])
    return a, om, tau, om_err, rms
