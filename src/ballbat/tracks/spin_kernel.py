"""The joint spin fit's normal equations, compiled with numba (issue 39's speed).

Each Gauss-Newton step of :func:`ballbat.tracks.fit_spin._spin_block` needs, per impact, the
normal matrix J'J (9 x 9) and J'r of its 9 parameters (the ball's centre x0, vx, y0, vy, the
spin, each dot's radius and phase) over its ball rows (x and y of every frame of free flight)
and dot rows (x and y of each dot in every frame it is tracked). numpy built the whole
Jacobian (impacts x 6 x frames x 9, two thirds of it zeros: a ball row moves 2 parameters, a
dot row 5 of the 9) and multiplied it out: at 70 000 impacts (a study's truth job) about 4 s of
its 24. Here each impact's rows are summed into J'J and J'r as they are made, without the
Jacobian and without its zeros (:func:`normal_equations`); the products are the same, summed
in another order, so the steps agree with the numpy ones to round-off
(``tests/tracks/test_spin_kernel.py``). On the last step the kernel also returns what the test
of a common offset of the dots' circles needs (J'J_o, J_o'J_o, J_o'r, with J_o the offset's two
columns: minus each dot row's weight on its coordinate).

Compiled once per machine (``cache=True``, kept in ``__pycache__`` beside this file or in
``NUMBA_CACHE_DIR``); imported where a spin is fitted, never when the Snakefile is read.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_jit = njit(cache=True, nogil=True, error_model="numpy")

#: Parameters of an impact's joint fit: x0, vx, y0, vy, the spin, each dot's radius and phase.
NPAR = 9


@_jit
def _add_row(A, b, i, idx, vals, nnz, r):
    """Add one row of the Jacobian (its ``nnz`` non-zero ``vals`` in the columns ``idx``) and its residual ``r``.

    Into impact ``i``'s J'J and J'r; the row's other columns are zero and add nothing.
    """
    for a in range(nnz):
        ia, va = idx[a], vals[a]
        b[i, ia] += va * r
        for c in range(nnz):
            A[i, ia, idx[c]] += va * vals[c]


@_jit
def _ball_rows(i, X, Y, ub, wb, p, g, A, b):
    """Add impact ``i``'s ball rows (x and y of each frame with weight); return their sum of squared residuals."""
    ix, iy, vals = np.array([0, 1]), np.array([2, 3]), np.zeros(2)
    ss = 0.0
    for f in range(X.shape[1]):
        w = wb[i, f]
        if not w > 0:
            continue
        u = ub[i, f]
        rx = (X[i, f] - (p[0] + p[1] * u)) * w
        ry = (Y[i, f] - (p[2] + p[3] * u - 0.5 * g * u * u)) * w
        vals[0], vals[1] = -w, -u * w
        _add_row(A, b, i, ix, vals, 2, rx)
        _add_row(A, b, i, iy, vals, 2, ry)
        ss += rx * rx + ry * ry
    return ss


@_jit
def _dot_rows(i, j, cx, cy, m, wd, ud, p, g, A, b, last, Bo, go, Go):
    """Add impact ``i``'s rows of dot ``j`` (0 or 1); with ``last`` the offset's terms too; return the residuals' ss."""
    k = 5 + 2 * j  # the dot's radius and phase
    rho, phase, om = p[k], p[k + 1], p[4]
    ix, iy, vals = np.array([0, 1, 4, k, k + 1]), np.array([2, 3, 4, k, k + 1]), np.zeros(5)
    ss = 0.0
    for f in range(cx.shape[1]):
        if not m[i, f]:
            continue
        w, u = wd[i, f], ud[i, f]
        ang = phase + om * u
        c, s = np.cos(ang), np.sin(ang)
        rc, rs = rho * c, rho * s
        rx = (cx[i, f] - (p[0] + p[1] * u) - rc) * w
        ry = (cy[i, f] - (p[2] + p[3] * u - 0.5 * g * u * u) - rs) * w
        vals[0], vals[1], vals[2], vals[3], vals[4] = -w, -u * w, rs * u * w, -c * w, rs * w
        _add_row(A, b, i, ix, vals, 5, rx)
        if last:
            for a in range(5):
                Bo[i, ix[a], 0] -= vals[a] * w
            go[i, 0] -= w * rx
        vals[0], vals[1], vals[2], vals[3], vals[4] = -w, -u * w, -rc * u * w, -s * w, -rc * w
        _add_row(A, b, i, iy, vals, 5, ry)
        if last:
            for a in range(5):
                Bo[i, iy[a], 1] -= vals[a] * w
            go[i, 1] -= w * ry
            Go[i] += w * w
        ss += rx * rx + ry * ry
    return ss


@_jit
def normal_equations(p, X, Y, ub, wb, DX, DY, DM, DW, DU, g, last):
    """Return every impact's J'J (n, 9, 9), J'r (n, 9) and sum of squared residuals (n,) at the parameters ``p``.

    ``X``, ``Y``, ``ub``, ``wb``: the ball's centre, times and weights (impact, frame); ``DX``,
    ``DY``, ``DM``, ``DW``, ``DU``: the dots' positions, masks, weights and times (dot, impact,
    frame). With ``last`` also the offset test's J'J_o (n, 9, 2), J_o'r (n, 2) and J_o'J_o's
    diagonal (n,) (its two entries are equal); otherwise these are zeros.
    """
    n = p.shape[0]
    A = np.zeros((n, NPAR, NPAR))
    b = np.zeros((n, NPAR))
    ss = np.zeros(n)
    Bo = np.zeros((n, NPAR, 2))
    go = np.zeros((n, 2))
    Go = np.zeros(n)
    for i in range(n):
        s = _ball_rows(i, X, Y, ub, wb, p[i], g, A, b)
        for j in range(2):
            s += _dot_rows(i, j, DX[j], DY[j], DM[j], DW[j], DU[j], p[i], g, A, b, last, Bo, go, Go)
        ss[i] = s
    return A, b, ss, Bo, go, Go
