"""The free-flight fit: its velocity errors along and across the motion."""

import numpy as np
import pytest

from ballbat.tracks.fit_flight import Onset, fit_flight
from ballbat.units import G

FPS = 2000.0


def _blurred_flights(n, frames, along, across, seed):
    """Balls at rest for 3 frames, then in free flight at 30 m/s, 20 deg up, scattering ``along`` (m) along
    the motion and ``across`` it (a blurred ball's scatter); returns the fit and the true velocity.
    """
    rng = np.random.default_rng(seed)
    t = (np.arange(frames) - 3)[None, :] / FPS * np.ones((n, 1))
    u = np.clip(t, 0.0, None)
    v, ang = 30.0, np.radians(20.0)
    x, y = v * np.cos(ang) * u, v * np.sin(ang) * u - 0.5 * G * u**2
    ea, ec = along * rng.standard_normal(u.shape), across * rng.standard_normal(u.shape)
    x += ea * np.cos(ang) - ec * np.sin(ang)
    y += ea * np.sin(ang) + ec * np.cos(ang)
    zeros = np.zeros(n)
    onset = Onset(np.full(n, 3), np.full(n, 2), zeros, zeros, np.ones(n, bool))
    return fit_flight(x, y, t, onset, FPS), (v, ang)


def test_the_speed_and_direction_errors_follow_the_scatter_along_and_across_the_motion():
    """4000 impacts of 20 free-flight frames, scattering twice as much along the motion as across it: the
    stated variances of the speed and of the direction (times the speed) agree with the spread of the
    fitted values within 8 % (the spread's own precision is 2 %); the pooled variance, one scatter for
    both, is 0.62 times the speed's and 2.5 times the direction's, so the test can fail.
    """
    fl, (v, ang) = _blurred_flights(4000, 25, 2e-4, 1e-4, seed=3)
    # the velocity at the fit's reference time, less gravity's turn since the impact (t = 0)
    vy = fl.vy + G * fl.t_ref
    speed, direction = np.hypot(fl.vx, vy), np.arctan2(vy, fl.vx)
    assert np.all(fl.n == 20)
    assert np.var(speed) / np.mean(fl.var_along) == pytest.approx(1.0, rel=0.08)
    assert np.var(direction * v) / np.mean(fl.var_across) == pytest.approx(1.0, rel=0.08)
    pooled = (fl.var_along + fl.var_across) / 2  # one scatter for both: the pooled residuals' 2n - 4 dof
    assert np.var(speed) / np.mean(pooled) > 1.4
    assert np.var(direction * v) / np.mean(pooled) < 0.7
    assert abs(np.mean(speed) - v) < 3 * np.std(speed) / np.sqrt(speed.size)
    assert abs(np.mean(direction) - ang) < 3 * np.std(direction) / np.sqrt(speed.size)
