"""Sec. III kinematics: forward model, psi reconstruction, normalisation (Kensrud et al. 2017).

Tables I-II, unit conversions and the recoil factors (Sec. III, Eqs. rx and ry).
"""

from __future__ import annotations

import numpy as np
import pytest

from ballbat.kinematics import (
    ball_at_rest_collision,
    e_y_from_tan_ratio_slope,
    gross_slip_onset,
    normalize_to_bat_speed,
    offset_from_psi,
    reconstruct_psi,
    spin_bracket,
    tan_ratio_slope_model,
    vtf_bracket,
    vtf_ordinate,
)
from ballbat.properties import recoil_factors
from ballbat.units import DEGREE, INCH, MPH, RPM


@pytest.fixture
def wood_baseball(balls, bats):
    ball = balls["baseball"]
    r_x, r_y = recoil_factors(ball, bats["wood"])
    return ball, r_x, r_y


def test_forward_model_satisfies_eqs(wood_baseball):
    ball, r_x, r_y = wood_baseball
    v_bat = np.linspace(63, 88, 7) * MPH
    psi = np.linspace(0, 30, 7) * DEGREE
    out = ball_at_rest_collision(v_bat, psi, 0.464, 0.45, ball.r, r_x, r_y)
    # Eq. angmom: alpha m r^2 omega = m v_ball r sin(psi - theta)
    np.testing.assert_allclose(0.4 * ball.r * out.omega, out.v_ball * np.sin(psi - out.theta), rtol=1e-12, atol=1e-15)
    # Eq. vballt: v_t + r omega = (1 + e_x)/(1 + r_x) v_bat sin psi
    np.testing.assert_allclose(out.v_t + ball.r * out.omega, 1.464 / (1 + r_x) * v_bat * np.sin(psi), rtol=1e-12)
    # Eq. vtf
    np.testing.assert_allclose(
        vtf_ordinate(out.v_ball, out.theta, out.omega, v_bat, psi, ball.r), 1.464 * vtf_bracket(psi, r_x), rtol=1e-12
    )
    # Eq. ratio
    with np.errstate(invalid="ignore", divide="ignore"):
        slope = np.tan(psi - out.theta)[1:] / np.tan(psi)[1:]
    np.testing.assert_allclose(slope, tan_ratio_slope_model(0.464, 0.45, r_x, r_y), rtol=1e-12)


def test_reconstruct_inverts_forward(wood_baseball):
    ball, r_x, r_y = wood_baseball
    psi = np.linspace(-5, 60, 40) * DEGREE
    out = ball_at_rest_collision(34.0, psi, 0.4, 0.5, ball.r, r_x, r_y)
    got, flag = reconstruct_psi(out.v_ball, out.theta, out.omega, ball.r, ball.alpha)
    np.testing.assert_allclose(got, psi, atol=1e-12)
    assert (flag == 0).all()


def test_reconstruct_flags_instead_of_clipping(balls):
    r = balls["baseball"].r
    # alpha r omega / v_ball = 0.4 * 0.036 * 4000 / 20 > 1: impossible measurement
    psi, flag = reconstruct_psi(np.array([20.0, 30.0, 0.0, np.nan]), 0.1, np.array([4000.0, 100.0, 100.0, 1.0]), r, 0.4)
    assert np.isnan(psi[0]) and flag[0] == 1
    assert flag[1] == 0 and np.isfinite(psi[1])
    assert flag[2] == 2 and flag[3] == 2 and np.isnan(psi[2:]).all()


def test_normalisation_uses_77_over_v_bat():
    # Sec. II: scale to 77 mph. Only 77/v_bat makes a value measured at 88 mph smaller.
    assert normalize_to_bat_speed(100.0, 88 * MPH, 77 * MPH) == pytest.approx(100.0 * 77 / 88, rel=1e-14)
    assert normalize_to_bat_speed(100.0, 77 * MPH, 77 * MPH) == pytest.approx(100.0, rel=1e-14)


def test_spin_bracket_slope_is_one_plus_ex(wood_baseball):
    ball, r_x, r_y = wood_baseball
    psi = 20 * DEGREE
    out = ball_at_rest_collision(77 * MPH, psi, 0.405, 0.45, ball.r, r_x, r_y)
    assert out.omega / spin_bracket(77 * MPH, psi, ball.r, r_x) == pytest.approx(1.405, rel=1e-13)


def test_sec4_gross_slip_example(balls, bats):
    """Sec. IV: with mu_k = 0.50, gross slip near psi = 60 deg, omega = 6400 rpm, theta = 34 deg.

    Inputs are the paper's: Fig. 6 slope 0.281 and pooled e_x = 0.405 (Eq. ex), baseball at
    77 mph, r_x averaged over the three baseball bats (the paper pools them). The paper rounds
    to ~1 deg and ~100 rpm; tolerances say so.
    """
    ball = balls["baseball"]
    r_x = np.mean([recoil_factors(ball, bats[b])[0] for b in ("wood", "metal_rough", "metal_smooth")])
    psi, theta, omega = gross_slip_onset(0.5, 0.281, 77 * MPH, 0.405, ball.r, r_x)
    assert psi / DEGREE == pytest.approx(60, abs=1.0)
    assert theta / DEGREE == pytest.approx(34, abs=0.5)
    assert omega / RPM == pytest.approx(6400, rel=0.02)


def test_e_y_inversion_round_trip():
    s = tan_ratio_slope_model(0.4, 0.45, 0.25, 0.23)
    assert e_y_from_tan_ratio_slope(s, 0.4, 0.25, 0.23) == pytest.approx(0.45, rel=1e-13)


@pytest.mark.parametrize(
    ("ball", "bat", "D_max_in"),
    [
        # Table I: psi_max 30 deg -> D_max 1.35 in (baseball); 41 deg -> 2.00 in (softball).
        # The paper does not say which bat's R; the metal bats (R = 1.28-1.29 in) reproduce the
        # baseball value and the softball composite bat (R = 1.13 in) the softball value.
        ("baseball", "metal_rough", 1.35),
        ("softball", "softball_composite", 2.00),
    ],
)
def test_table1_D_max_from_psi_max(balls, bats, ball, bat, D_max_in):
    D = offset_from_psi(balls[ball].psi_max, balls[ball].r, bats[bat].R)
    assert D / INCH == pytest.approx(D_max_in, abs=0.015)  # Table I rounds to 0.01 in
    assert balls[ball].psi_max == pytest.approx({"baseball": 30, "softball": 41}[ball] * DEGREE)
