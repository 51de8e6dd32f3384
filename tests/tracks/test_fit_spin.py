"""The spin camera's spin fit (issue 22): the joint fit of the dots and the ball's centre, and its tilt test."""

from __future__ import annotations

import numpy as np
import pytest

from ballbat.tracks import fit_spin as module
from ballbat.tracks.fit_flight import Flight, _line_fit
from ballbat.tracks.fit_spin import OFFSET_FALSE_ALARM, fit_spin
from ballbat.units import G

FPS = 1000.0


def _spinning_ball(n, frames, noise, radii, seed, tilt=0.0, ball_radius=0.0366):
    """Return n impacts of a ball flying at 30 m/s, its two dots turning at 50-300 rad/s, tracked with ``noise`` (m).

    ``tilt`` (rad) tilts the spin axis from the line of sight towards +x: each dot's circle is then
    squeezed along x by cos(tilt) and moved along x by its height above the circle times sin(tilt).
    Returns the spin fit's inputs and the true spin.
    """
    rng = np.random.default_rng(seed)
    omega = rng.uniform(50, 300, n)
    phase = rng.uniform(0, 2 * np.pi, n)
    t = np.arange(frames)[None, :] / FPS * np.ones((n, 1))
    xc, yc = 30 * t, 5 * t - 0.5 * G * t**2
    x = xc + noise * rng.standard_normal((n, frames))
    y = yc + noise * rng.standard_normal((n, frames))
    mask = np.ones((n, frames), bool)
    t_ref = np.full(n, -0.5 / FPS)
    ax, bx, ay, by, sigma, (along, across), k, _, um, sxx = _line_fit(t - t_ref[:, None], x, y, mask.astype(float))
    flight = Flight(bx, by, along, across, ax, ay, t_ref, sigma, k.astype(int), np.zeros(n, int), mask, um, sxx)
    dx, dy = {}, {}
    for j, p in enumerate(("dot_a", "dot_b")):
        rho = rng.uniform(*radii, n)[:, None]
        height = np.sqrt(ball_radius**2 - rho**2)
        turn = phase[:, None] + j * np.pi + omega[:, None] * t
        dx[p] = xc + height * np.sin(tilt) + rho * np.cos(turn) * np.cos(tilt) + noise * rng.standard_normal(t.shape)
        dy[p] = yc + rho * np.sin(turn) + noise * rng.standard_normal(t.shape)
    return (dx, dy, t, flight, None, (x, y)), omega


@pytest.mark.slow  # 20 000 impacts: about 4 s
def test_the_spin_fitted_with_the_centre_is_unbiased_at_large_noise():
    """5 px of a 1000-fps spin camera (6.25 mm), 22 frames, dots 22-30 mm from the axis: the slope of the
    dots' angles about the flight's fitted centre is low (the angle is not linear in the centre's error),
    by 0.03 of its error on every impact, which a ball's 200 impacts add up (eta^2 of softballs: +0.13 SE).
    The joint fit on the positions is not; its errors stay honest (spread of z 1 within 3 %).
    """
    (dx, dy, t, flight, cam, ball), omega = _spinning_ball(20000, 22, 0.00625, (0.022, 0.030), seed=7)
    joint = fit_spin(dx, dy, t, flight, cam, ball)
    angles = fit_spin(dx, dy, t, flight, cam)  # without the ball's track: the angles' slope alone
    z_joint = (joint.omega - omega) / joint.omega_err
    z_angles = (angles.omega - omega) / angles.omega_err
    se = 1 / np.sqrt(omega.size)
    assert abs(z_joint.mean()) < 3 * se, z_joint.mean()
    assert z_angles.mean() < -3 * se, z_angles.mean()  # what the joint fit removes (-0.029 here)
    assert 0.97 < z_joint.std() < 1.03, z_joint.std()


def test_the_spin_fit_tells_a_tilted_axis_from_noise(monkeypatch):
    """At 5 px a dot's radius scatter cannot tell a spin axis tilted 30 degrees, but its circle sits
    about 10 mm off the ball's centre: the joint fit's score test flags most such impacts, and
    about OFFSET_FALSE_ALARM of the untilted ones (fewer: offsets within OFFSET_TOLERANCE are not flagged).
    """
    limit = -2 * np.log(OFFSET_FALSE_ALARM)
    (dx, dy, t, flight, cam, ball), _ = _spinning_ball(3000, 22, 0.00625, (0.022, 0.030), seed=3)
    straight = fit_spin(dx, dy, t, flight, cam, ball)
    assert np.mean(straight.offset_chi2 > limit) < 4 * OFFSET_FALSE_ALARM
    with monkeypatch.context() as m:  # no tolerance: the score statistic itself, chi^2 with 2 degrees of freedom
        m.setattr(module, "OFFSET_TOLERANCE", 0.0)
        plain = fit_spin(dx, dy, t, flight, cam, ball)
    assert 1.8 < np.mean(plain.offset_chi2) < 2.4
    np.testing.assert_array_equal(plain.offset, straight.offset)
    # within the tolerance an offset is not flagged, however significant; beyond it the test is the plain one
    within = np.hypot(*straight.offset.T) <= module.OFFSET_TOLERANCE
    assert within.sum() > 50 and np.all(straight.offset_chi2[within] == 0)
    np.testing.assert_array_equal(straight.offset_chi2[~within], plain.offset_chi2[~within])
    (dx, dy, t, flight, cam, ball), _ = _spinning_ball(300, 22, 0.00625, (0.022, 0.030), seed=4, tilt=np.radians(30))
    tilted = fit_spin(dx, dy, t, flight, cam, ball)
    assert np.mean(tilted.offset_chi2 > limit) > 0.8  # 87 % (seed 4)
    off = np.hypot(*tilted.offset.T)
    assert 0.006 < np.median(off) < 0.014, np.median(off)  # height 19-27 mm x sin 30 deg


def test_the_radius_limit_is_scipy_stats_f_isf_to_the_bit():
    """radius_scatter_limit's F quantile (scipy.special.fdtri at 1 - q) is scipy.stats.f.isf's number, bit for bit."""
    from scipy import stats

    from ballbat.tracks.fit_spin import RADIUS_FALSE_ALARM, radius_scatter_limit

    rng = np.random.default_rng(5)
    n = rng.integers(0, 80, 500).astype(float)
    dof = rng.integers(0, 300, 500).astype(float)
    noise = rng.uniform(1e-4, 3e-3, 500)
    got = radius_scatter_limit(noise, dof, n)
    ok = (n >= 2) & (dof >= 1)
    q = stats.f.isf(RADIUS_FALSE_ALARM, np.maximum(n - 1, 1), np.maximum(dof, 1))
    want = np.where(ok, noise * np.sqrt((1 + 2 / np.maximum(n, 1)) * q), np.nan)
    np.testing.assert_array_equal(got, want)
    assert np.isfinite(got).sum() > 400


# The compiled normal equations of the joint fit (ballbat.tracks.spin_kernel) against numpy's products.
def _both(monkeypatch, args):
    with monkeypatch.context() as m:
        m.setattr(module, "SPIN_COMPILED", False)
        want = fit_spin(*args)
    return want, fit_spin(*args)


def test_the_compiled_fit_is_numpy_s_to_round_off(monkeypatch):
    """600 impacts at 5 px, some with frames or a whole dot untracked: spin, error, phases and offset agree."""
    (dx, dy, t, flight, cam, ball), _ = _spinning_ball(600, 22, 0.00625, (0.022, 0.030), seed=5)
    rng = np.random.default_rng(1)
    for d in ("dot_a", "dot_b"):
        gone = rng.random(dx[d].shape) < 0.15  # frames where a dot is hidden
        dx[d][gone], dy[d][gone] = np.nan, np.nan
    dx["dot_b"][:20] = np.nan  # impacts whose second dot is never tracked
    want, got = _both(monkeypatch, (dx, dy, t, flight, cam, ball))
    for name in ("omega", "omega_err", "offset"):
        w, g = getattr(want, name), getattr(got, name)
        assert np.array_equal(np.isnan(w), np.isnan(g)), name
        np.testing.assert_allclose(g, w, rtol=1e-12, atol=1e-15, err_msg=name)
    np.testing.assert_allclose(got.offset_chi2, want.offset_chi2, rtol=1e-8, atol=1e-12)  # a score of small differences
    for d in ("dot_a", "dot_b"):
        np.testing.assert_allclose(got.intercept[d], want.intercept[d], rtol=1e-12, atol=1e-12)
    assert np.isfinite(got.omega).sum() > 550


def test_an_impact_whose_fit_cannot_be_made_keeps_the_angle_fit(monkeypatch):
    """Non-finite positions in an impact's tracked frames: compiled and numpy alike keep the angles' spin and error."""
    (dx, dy, t, flight, cam, ball), _ = _spinning_ball(50, 22, 0.001, (0.022, 0.030), seed=6)
    x, y = ball
    x = x.copy()
    x[3, 5] = np.inf  # a tracked frame of the ball at infinity
    angles = fit_spin(dx, dy, t, flight, cam)
    want, got = _both(monkeypatch, (dx, dy, t, flight, cam, (x, y)))
    assert got.omega[3] == want.omega[3] == angles.omega[3]
    assert got.omega_err[3] == want.omega_err[3] == angles.omega_err[3]
    np.testing.assert_allclose(got.omega, want.omega, rtol=1e-12)
