"""Tests of ballbat.collision: a pitched, spinning ball hit by a swinging bat (Sec. V.B)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ballbat.collision import pitched_ball_collision
from ballbat.properties import load_balls, load_bats, recoil_factors
from ballbat.units import DEGREE, INCH, MPH, RPM

CONFIG = Path(__file__).resolve().parents[1] / "config"
BALLS = load_balls(CONFIG / "balls.csv")
BATS = load_bats(CONFIG / "bats.csv")
BASEBALL = BALLS["baseball"]
WOOD = BATS["wood"]

# Sec. V.B inputs (paper): pitch 85 mph descending 6 deg with 2000 rpm backspin (topspin
# relative to the batted ball, hence the minus sign), bat 73 mph swinging up at 6 deg,
# e_x = 0.4; e_y = 0.50 and the wood bat are the defaults of docs/model.md.
PAPER = dict(
    v_pitch=85 * MPH,
    pitch_descent=6 * DEGREE,
    pitch_spin=-2000 * RPM,
    v_bat=73 * MPH,
    attack_angle=6 * DEGREE,
    e_x=0.4,
    e_y=0.50,
    ball=BASEBALL,
    bat=WOOD,
)


def sec3_ball_at_rest(D, v_bat, e_x, e_y, ball, bat):
    """Sec. III of Kensrud et al. 2017 written out directly: Eqs. (D), (vballn), (vxf),
    (omega) and theta = psi - atan(v_t / v_n) (docs/model.md, "The forward model").
    """
    r_x, r_y = recoil_factors(ball, bat)
    alpha, r = ball.alpha, ball.r
    psi = np.arcsin(D / (r + bat.R))  # Eq. (D)
    v_bat_n = v_bat * np.cos(psi)
    v_n = (1 + e_y) / (1 + r_y) * v_bat_n  # Eq. (vballn)
    omega = (1 + e_x) * v_bat * np.sin(psi) / (r * (1 + r_x) * (1 + alpha))  # Eq. (omega)
    v_t = (1 + e_x) * alpha * v_bat * np.sin(psi) / ((1 + r_x) * (1 + alpha))  # Eq. (vxf)
    theta = psi - np.arctan(v_t / v_n)
    return psi, v_n, v_t, omega, theta


@pytest.mark.parametrize(
    ("ball", "bat"),
    [("baseball", "wood"), ("baseball", "metal_rough"), ("softball", "softball_composite")],
)
@pytest.mark.parametrize("attack_deg", [0.0, 6.0, -8.0])
def test_reduces_exactly_to_sec3_for_ball_at_rest(ball, bat, attack_deg):
    ball, bat = BALLS[ball], BATS[bat]
    reach = ball.r + bat.R
    D = np.linspace(-0.97, 0.97, 41) * reach
    v_bat, e_x, e_y = 34.0, 0.405, 0.45
    res = pitched_ball_collision(D, 0.0, 0.0, 0.0, v_bat, attack_deg * DEGREE, e_x, e_y, ball, bat)
    psi, v_n, v_t, omega, theta = sec3_ball_at_rest(D, v_bat, e_x, e_y, ball, bat)
    tol = dict(rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(res.psi, psi, **tol)
    np.testing.assert_allclose(res.v_n, v_n, rtol=1e-12, atol=1e-12 * v_bat)
    np.testing.assert_allclose(res.v_t, v_t, rtol=1e-12, atol=1e-12 * v_bat)
    np.testing.assert_allclose(res.backspin, omega, rtol=1e-12, atol=1e-12 * v_bat / ball.r)
    np.testing.assert_allclose(res.theta, theta, **tol)
    np.testing.assert_allclose(res.exit_speed, np.hypot(v_n, v_t), rtol=1e-12, atol=0)
    # The bat moves at attack_deg above the horizontal, so the lab launch angle is theta + attack.
    np.testing.assert_allclose(res.launch_angle, theta + attack_deg * DEGREE, **tol)


def test_friction_ratio_matches_eq_ratio_for_ball_at_rest():
    """Eq. (ratio): tan(psi - theta) = [alpha/(1+alpha) (1+e_x)/(1+r_x) (1+r_y)/(1+e_y)] tan psi."""
    D = np.linspace(0.05, 2.3, 12) * INCH
    e_x, e_y = 0.4, 0.5
    res = pitched_ball_collision(D, 0.0, 0.0, 0.0, 34.0, 0.0, e_x, e_y, BASEBALL, WOOD)
    r_x, r_y = recoil_factors(BASEBALL, WOOD)
    a = BASEBALL.alpha
    expected = a / (1 + a) * (1 + e_x) / (1 + r_x) * (1 + r_y) / (1 + e_y) * np.tan(res.psi)
    np.testing.assert_allclose(res.friction_ratio, expected, rtol=1e-12)
    np.testing.assert_allclose(np.tan(res.psi - res.theta), expected, rtol=1e-12)


def _bat_contact_after(res, W, psi, ball, bat):
    """Bat's contact-point velocity components along n and t after the impact, in the frame
    where the pitch was at rest before it (effective masses m/r_y and m alpha/((1+alpha) r_x)).
    """
    r_x, r_y = recoil_factors(ball, bat)
    m, a = ball.m, ball.alpha
    V_n = W * np.cos(psi) - r_y * res.J_n / m
    V_t = W * np.sin(psi) - r_x * (1 + a) / a * res.J_t / m
    return V_n, V_t


def test_general_collision_obeys_its_defining_relations():
    """Momentum, angular momentum about the contact point, e_y and e_x, for a moving ball."""
    D = np.linspace(-2.4, 2.4, 49) * INCH
    res = pitched_ball_collision(D, **PAPER)
    m, r, a = BASEBALL.m, BASEBALL.r, BASEBALL.alpha
    # Pitch and relative velocity W = v_bat - v_pitch in lab (X to the field, Z up).
    vp = PAPER["v_pitch"] * np.array([-np.cos(6 * DEGREE), -np.sin(6 * DEGREE)])
    vb = PAPER["v_bat"] * np.array([np.cos(6 * DEGREE), np.sin(6 * DEGREE)])
    Wv = vb - vp
    W = np.hypot(*Wv)
    phi = np.arctan2(Wv[1], Wv[0])
    n = np.stack([np.cos(phi + res.psi), np.sin(phi + res.psi)])
    t = np.stack([n[1], -n[0]])
    # Ball velocities relative to the pitch's initial velocity, along n and t.
    out = res.exit_speed * np.stack([np.cos(res.launch_angle), np.sin(res.launch_angle)])
    rel = out - vp[:, None]
    u_n, u_t = (rel * n).sum(0), (rel * t).sum(0)
    # Linear momentum of the ball: the velocity change is the impulse.
    np.testing.assert_allclose(u_n, res.J_n / m, rtol=1e-12)
    np.testing.assert_allclose(u_t, res.J_t / m, rtol=1e-12, atol=1e-12 * W)
    # Angular momentum of the ball about the contact point: m r v_t - I omega is unchanged.
    I = a * m * r**2
    L_before = -I * PAPER["pitch_spin"]
    L_after = m * r * u_t - I * res.backspin
    np.testing.assert_allclose(L_after, L_before, rtol=1e-12)
    # e_y: the normal relative velocity reverses with ratio e_y.
    V_n, V_t = _bat_contact_after(res, W, res.psi, BASEBALL, WOOD)
    np.testing.assert_allclose(u_n - V_n, PAPER["e_y"] * W * np.cos(res.psi), rtol=1e-12)
    # e_x: the tangential velocity of the ball's contact point relative to the bat's reverses
    # with ratio e_x (u_f = -e_x u_i), including the pitch's spin.
    u_i = r * PAPER["pitch_spin"] - W * np.sin(res.psi)
    u_f = u_t + r * res.backspin - V_t
    np.testing.assert_allclose(u_f, -PAPER["e_x"] * u_i, rtol=1e-10, atol=1e-12 * W)


def test_paper_inputs_exit_speed_peaks_near_head_on():
    """Sec. V.B: the exit speed peaks at small launch angle, D ~ 0, and drops off with D."""
    D = np.linspace(-1.0, 2.4, 341) * INCH
    res = pitched_ball_collision(D, **PAPER)
    D_peak = D[np.argmax(res.exit_speed)]
    assert abs(D_peak) <= 0.1 * INCH
    up = D >= 0
    assert np.all(np.diff(res.exit_speed[up]) < 0)
    # Head-on: the paper's 158 mph relative speed, a hard line drive near the 6 deg swing plane.
    at0 = pitched_ball_collision(0.0, **PAPER)
    assert 95 * MPH < at0.exit_speed < 110 * MPH
    assert 0 < at0.launch_angle < 10 * DEGREE


def test_paper_inputs_topspin_at_head_on():
    """Sec. V.B: the spin is negative (topspin) at D = 0, the pitch's backspin."""
    at0 = pitched_ball_collision(0.0, **PAPER)
    assert at0.backspin < 0
    # What is left of the pitch's spin: omega_i r_x/(1 + r_x) for e_x = alpha (here 0.4).
    r_x, _ = recoil_factors(BASEBALL, WOOD)
    np.testing.assert_allclose(at0.backspin, PAPER["pitch_spin"] * r_x / (1 + r_x), rtol=1e-12)


def test_paper_inputs_backspin_linear_in_D():
    """Sec. V.B: backspin is roughly linear in D over 0-2.5 in (in this model: exactly)."""
    D = np.linspace(0.0, 2.5, 26) * INCH
    res = pitched_ball_collision(D, **PAPER)
    slope, icpt = np.polyfit(D, res.backspin, 1)
    resid = res.backspin - (slope * D + icpt)
    assert np.max(np.abs(resid)) < 1e-9 * np.ptp(res.backspin)
    assert slope > 0
    # Launch angle rises monotonically with D over the same range.
    assert np.all(np.diff(res.launch_angle) > 0)


def test_exceeds_mu_flags_without_hiding():
    D = np.linspace(0.0, 2.5, 11) * INCH
    res = pitched_ball_collision(D, **PAPER, mu=0.5)
    assert np.all(np.isfinite(res.friction_ratio))
    np.testing.assert_array_equal(res.exceeds_mu, res.friction_ratio > 0.5)
    assert res.exceeds_mu[-1] and not res.exceeds_mu[0]
    # The kinematics are not altered by the flag.
    plain = pitched_ball_collision(D, **PAPER)
    np.testing.assert_array_equal(plain.exit_speed, res.exit_speed)
    assert not plain.exceeds_mu.any()


def test_broadcasting():
    D = np.linspace(0.0, 2.0, 5) * INCH
    e_x = np.array([[0.0], [0.2], [0.4]])
    kw = {**PAPER, "e_x": e_x}
    res = pitched_ball_collision(D, **kw)
    assert res.exit_speed.shape == (3, 5) and res.exceeds_mu.shape == (3, 5)
    one = pitched_ball_collision(D[2], **{**PAPER, "e_x": 0.2})
    np.testing.assert_allclose(res.backspin[1, 2], one.backspin, rtol=1e-14)


def test_mirror_symmetry_without_spin():
    """With no incoming spin, D -> -D mirrors the collision about the relative velocity."""
    D = np.linspace(0.1, 2.0, 8) * INCH
    kw = {**PAPER, "pitch_spin": 0.0}
    up, down = pitched_ball_collision(D, **kw), pitched_ball_collision(-D, **kw)
    np.testing.assert_allclose(up.backspin, -down.backspin, rtol=1e-12)
    np.testing.assert_allclose(up.exit_speed, down.exit_speed, rtol=1e-12)
    np.testing.assert_allclose(up.theta, -down.theta, rtol=1e-12)


@pytest.mark.parametrize("D_in", [2.58, -2.7, 3.0])
def test_no_contact_raises(D_in):
    with pytest.raises(ValueError, match="no contact"):
        pitched_ball_collision(D_in * INCH, **PAPER)


def test_non_finite_input_raises():
    with pytest.raises(ValueError, match="e_y"):
        pitched_ball_collision(0.0, **{**PAPER, "e_y": np.nan})
