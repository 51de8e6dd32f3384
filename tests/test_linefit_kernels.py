"""The compiled passes of the errors-in-variables line and Paule-Mandel's root against numpy transcriptions."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from ballbat import linefit, linefit_kernels
from ballbat.linefit import _scatter_residuals, scatter_gain


def _q_root_brent(r2, v0, g, target):
    """The root as scipy's bracketing solver finds it (the code before the kernel)."""

    def q(t):
        return float((r2 / (v0 + t * g)).sum()) - target

    if q(0.0) <= 0 or not np.any(g > 0):
        return 0.0
    if float(np.sum(r2[g <= 0] / v0[g <= 0])) >= target:
        return np.inf
    hi = float(np.sum(r2) / np.sum(g))
    while q(hi) > 0:
        hi *= 4.0
    return float(brentq(q, 0.0, hi, xtol=1e-14, rtol=1e-10))


def _passes_numpy(X, y, noise, beta, iterations, scatter, strata):
    """eiv_line's passes as numpy computed them (every pass made: no fixed-point stop)."""
    jx, jy, sig2, var_x, cov_xy, g = noise
    x, (n, p), tau2 = X[:, 0], X.shape, 0.0
    for it in range(iterations + (linefit.SCATTER_PASSES if scatter else 0)):
        var0 = ((jy - beta[0] * jx) ** 2 * sig2).sum(axis=1)
        if (var0 <= 0).any():
            return None
        if scatter and it >= iterations - 1:
            r_s, dof = _scatter_residuals(y - X @ beta, x, y, var_x, cov_xy, var0 + tau2 * g, strata, n - p)
            tau2 = _q_root_brent(r_s * r_s, var0, g, float(dof)) if dof >= 1 else np.inf
            if not np.isfinite(tau2):
                scatter, tau2 = False, 0.0
        W = 1.0 / (var0 + tau2 * g)
        A = X.T @ (W[:, None] * X)
        A[0, 0] -= (W * var_x).sum()
        rhs = X.T @ (W * y)
        rhs[0] -= (W * cov_xy).sum()
        if A[0, 0] <= 0 or (p == 2 and np.linalg.det(A) <= 0):
            return None
        beta = np.linalg.solve(A, rhs)
    return beta, tau2, scatter


def _case(rng, k):
    n = int(rng.integers(4, 120))
    x = rng.uniform(0.0 if k % 7 == 0 else 0.05, 2.0, n)
    jx = np.stack([np.ones(n), rng.uniform(0, 0.5, n)], 1)
    jy = np.stack([np.full(n, 1.3), np.ones(n)], 1)
    sig2 = np.full((n, 2), [0.03, 0.01, 0.1][k % 3]) ** 2
    y = (1.3 + [0.0, 0.05, 0.2][k % 3] * rng.standard_normal(n)) * x + 0.04 * rng.standard_normal(n)
    strata = rng.integers(0, 3, n).astype(str) if k % 4 == 1 else None
    var_x, cov_xy = np.sum(jx**2 * sig2, axis=1), np.sum(jx * jy * sig2, axis=1)
    X = x[:, None] if k % 5 else np.stack([x, np.ones_like(x)], axis=1)
    return X, y, (jx, jy, sig2, var_x, cov_xy, scatter_gain(x, var_x)), strata


def test_the_compiled_passes_agree_with_numpy(monkeypatch):
    """Slope and tau^2 of 300 fits (with and without scatter, strata, intercept) agree to 1e-9 relative."""
    monkeypatch.setattr(linefit, "STOP_AT_FIXED_POINT", False)
    rng = np.random.default_rng(5)
    worst, with_tau = 0.0, 0
    for k in range(300):
        X, y, noise, strata = _case(rng, k)
        start = np.linalg.lstsq(X, y, rcond=None)[0]
        want = _passes_numpy(X, y, noise, start, 3, k % 2 == 0, strata)
        got = linefit._eiv_passes(X, y, noise, start, 3, k % 2 == 0, strata)
        assert (want is None) == (got is None), k
        if want is None:
            continue
        assert got[2] == want[2], k  # the scatter term kept or dropped alike
        np.testing.assert_allclose(got[0], want[0], rtol=1e-9, atol=1e-12)
        assert got[1] == pytest.approx(want[1], rel=1e-8, abs=1e-15)
        worst = max(worst, float(np.max(np.abs(got[0] - want[0]) / np.abs(want[0]))))
        with_tau += want[1] > 0
    assert with_tau >= 40  # the cases do exercise tau^2 > 0
    assert worst < 1e-10, worst


def test_the_newton_root_is_the_brent_root_to_its_tolerance():
    """Paule-Mandel's root (Newton on 1/Q) is brentq's within its 1e-10, and solves Q = target to round-off."""
    rng = np.random.default_rng(8)
    for _ in range(500):
        n = int(rng.integers(2, 80))
        r2 = rng.chisquare(1, n) * rng.uniform(0.5, 20.0)
        v0, g = rng.uniform(0.1, 2.0, n), rng.uniform(0.0, 3.0, n) * (rng.random(n) > 0.1)
        target = float(rng.integers(1, n + 1))
        want, got = _q_root_brent(r2, v0, g, target), linefit._q_root(r2, v0, g, target)
        if not np.isfinite(want) or want == 0.0:
            assert got == want
            continue
        assert got == pytest.approx(want, rel=2e-10, abs=1e-14)
        assert float(np.sum(r2 / (v0 + got * g))) == pytest.approx(target, rel=1e-12)


def test_a_single_point_s_root_is_exact_at_once():
    """One point: 1/Q is linear in tau^2, so Newton lands on r^2/target - v0 over g (to rounding)."""
    r2, v0, g = np.array([9.0]), np.array([1.0]), np.array([2.0])
    assert linefit_kernels.q_root(r2, v0, g, 1.0) == pytest.approx(4.0, rel=1e-15)
