"""Collision of a pitched, spinning ball with a swinging bat (Sec. V.B of Kensrud et al. 2017).

The impulsive two-coefficient model of Sec. III (Eqs. vballn, vballt, angmom) generalised
from a ball at rest to a moving, spinning ball. Everything happens in the vertical plane
that holds the pitch and the swing. The step-by-step derivation, and its reduction to the
Sec. III equations for a ball at rest, is in ``docs/collision.md``.

Frame and sign conventions (docs/model.md, "Conventions"):

* Lab axes: X horizontal, pointing from home plate towards the field (the direction the
  batted ball goes), Z vertically up. The pitch moves towards -X.
* ``n`` points from the bat's centre to the ball's centre at impact; ``t`` is ``n`` rotated
  by -90 deg in the (X, Z) plane, so the bat's velocity relative to the ball is
  ``|W| (cos psi n + sin psi t)``, as in Fig. 2 of the paper.
* ``omega > 0`` is the spin of the paper's Fig. 2: the ball's contact point (on the bat's
  side) moves along +t, which is *backspin of the batted ball*. The spin of the pitch uses
  the same convention, so a fastball with 2000 rpm of backspin (backspin relative to its own
  motion towards the plate) has ``pitch_spin = -2000 rpm``: it is topspin relative to the
  batted ball.
* ``D`` is the perpendicular offset of the ball's centre from the line through the bat's
  centre along the bat's velocity *relative to the ball*, ``W = v_bat - v_pitch``;
  ``D > 0`` when the ball's centre lies above that line (the bat undercuts the ball,
  which gives backspin). Then ``sin psi = D / (r + R)``; for a ball at rest ``W`` is the bat
  velocity and this is the paper's Eq. (D).

References
----------
.. [1] J. R. Kensrud, A. M. Nathan and L. V. Smith, "Oblique collisions of baseballs and
   softballs with a bat", Am. J. Phys. 85, 503 (2017).
.. [2] R. Cross and A. M. Nathan, "Scattering of a baseball by a bat", Am. J. Phys. 74,
   896 (2006).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .properties import Ball, Bat, recoil_factors

__all__ = ["CollisionResult", "pitched_ball_collision"]


@dataclass(frozen=True)
class CollisionResult:
    """Outcome of :func:`pitched_ball_collision`, SI units, arrays of the broadcast shape.

    Attributes
    ----------
    exit_speed : speed of the batted ball in the lab frame, m/s.
    launch_angle : angle of the batted ball's velocity above the horizontal, rad.
    backspin : spin of the batted ball, rad/s; > 0 is backspin, < 0 topspin.
    psi : angle between the relative velocity ``W`` and the normal ``n``, rad.
    theta : angle of the batted ball's lab velocity from the direction of ``W``, counted
        towards ``n`` (``launch_angle`` minus the elevation of ``W``); the paper's theta for a
        ball at rest, rad.
    v_n, v_t : lab-frame components of the batted ball's velocity along ``n`` and ``t``, m/s
        (the paper's v_ball,n and v_ball,t for a ball at rest).
    J_n, J_t : normal and tangential impulses on the ball, N s.
    friction_ratio : ``|J_t / J_n|``, the smallest friction coefficient that can supply the
        tangential impulse the chosen ``e_x`` requires (Eq. muk).
    exceeds_mu : True where ``friction_ratio > mu``: the impact would be in gross slip, so
        the given ``e_x`` is not consistent with Coulomb friction of coefficient ``mu``.
        The kinematics are still those of the given ``e_x``; nothing is clipped. All False
        when ``mu`` is None.
    """

    exit_speed: NDArray[np.float64]
    launch_angle: NDArray[np.float64]
    backspin: NDArray[np.float64]
    psi: NDArray[np.float64]
    theta: NDArray[np.float64]
    v_n: NDArray[np.float64]
    v_t: NDArray[np.float64]
    J_n: NDArray[np.float64]
    J_t: NDArray[np.float64]
    friction_ratio: NDArray[np.float64]
    exceeds_mu: NDArray[np.bool_]


def pitched_ball_collision(
    D: ArrayLike,
    v_pitch: ArrayLike,
    pitch_descent: ArrayLike,
    pitch_spin: ArrayLike,
    v_bat: ArrayLike,
    attack_angle: ArrayLike,
    e_x: ArrayLike,
    e_y: ArrayLike,
    ball: Ball,
    bat: Bat,
    mu: ArrayLike | None = None,
) -> CollisionResult:
    """Batted-ball speed, launch angle and spin for a pitched, spinning ball hit by a bat.

    Parameters
    ----------
    D : offset of the ball's centre from the line through the bat's centre along the
        relative velocity ``W = v_bat - v_pitch``, m; > 0 when the ball is above that line
        (undercut, backspin). ``|D|`` must be below ``ball.r + bat.R``.
    v_pitch : pitch speed at the plate, m/s (>= 0; 0 for a ball at rest).
    pitch_descent : angle of the pitch's velocity below the horizontal, rad (> 0: falling).
    pitch_spin : spin of the pitch in the batted-ball convention, rad/s: ``omega > 0`` is
        backspin *of the batted ball*, so a fastball's backspin enters with a minus sign
        (2000 rpm of backspin -> ``pitch_spin = -2000 * RPM``).
    v_bat : speed of the bat at the impact point, m/s (> 0).
    attack_angle : angle of the bat's velocity above the horizontal, rad (> 0: upswing).
    e_x : tangential coefficient of restitution, ``-u_f / u_i`` with ``u`` the relative
        tangential velocity of the contact points (ball minus bat).
    e_y : normal coefficient of restitution (ratio of the normal relative velocities).
    ball, bat : properties (SI); the bat enters through its recoil factors r_x and r_y.
    mu : friction coefficient for the ``exceeds_mu`` flag (scalar or broadcastable to the
        result), or None (no check).

    Returns
    -------
    CollisionResult
        Arrays broadcast over all array arguments.

    Raises
    ------
    ValueError
        If ``|D| >= r + R`` (no contact), if the bat does not approach the ball
        (``W = 0``), or if an input is not finite.

    Notes
    -----
    With ``m`` the ball's mass, ``alpha = I_ball/(m r^2)`` (Eq. iball) and the bat's
    effective masses ``m/r_y`` (normal, Eq. ry) and ``m alpha/((1+alpha) r_x)`` (tangential,
    Eq. rx), the impulses on the ball are

    ``J_n = m (1 + e_y) W_n / (1 + r_y)``, with ``W_n = |W| cos psi``,

    ``J_t = -m alpha (1 + e_x) u_i / ((1 + alpha)(1 + r_x))``, with
    ``u_i = r omega_i - |W| sin psi`` the initial relative tangential velocity of the contact
    points. The ball then leaves with ``v = v_pitch + (J_n n + J_t t)/m`` and spin
    ``omega = omega_i + J_t/(alpha m r)``; the ball's angular momentum about the contact
    point, ``m r v_t - I omega``, is conserved. For ``v_pitch = 0`` and ``omega_i = 0`` this
    is exactly Eqs. (vballn), (omega) and (vxf) of Kensrud et al. 2017 with
    ``theta = psi - atan(v_t / v_n)``; the derivation is in ``docs/collision.md``
    (docs/model.md, "Collision of a pitched, spinning ball").
    """
    D, v_pitch, descent, spin_i, v_bat, attack, e_x, e_y = _checked_inputs(
        D, v_pitch, pitch_descent, pitch_spin, v_bat, attack_angle, e_x, e_y
    )
    m, r, alpha = ball.m, ball.r, ball.alpha
    r_x, r_y = recoil_factors(ball, bat)
    reach = r + bat.R
    if np.any(np.abs(D) >= reach):
        bad = D[np.abs(D) >= reach]
        raise ValueError(
            f"pitched_ball_collision: |D| must be below r + R = {reach:.6g} m for {ball.ball} on "
            f"{bat.bat}; got D = {bad.ravel()[:5]} m (no contact)"
        )

    # Lab velocities in the (X, Z) plane: pitch towards -X and falling, bat towards +X.
    pitch_x, pitch_z = -v_pitch * np.cos(descent), -v_pitch * np.sin(descent)
    W, phi_W = _relative_velocity(v_bat, attack, pitch_x, pitch_z)
    sin_psi = D / reach
    cos_psi = np.sqrt(1.0 - sin_psi**2)
    psi, (n_x, n_z), (t_x, t_z) = _contact_frame(sin_psi, phi_W)

    # Impulses from the definitions of e_y and e_x (per unit ball mass).
    W_n = W * cos_psi
    W_t = W * sin_psi
    jn = (1.0 + e_y) * W_n / (1.0 + r_y)
    u_i = r * spin_i - W_t
    jt = -(1.0 + e_x) * u_i * alpha / ((1.0 + alpha) * (1.0 + r_x))

    out_x = pitch_x + jn * n_x + jt * t_x
    out_z = pitch_z + jn * n_z + jt * t_z
    spin_f = spin_i + jt / (alpha * r)
    v_n = pitch_x * n_x + pitch_z * n_z + jn
    v_t = pitch_x * t_x + pitch_z * t_z + jt

    friction_ratio = np.abs(jt) / jn  # jn > 0: |psi| < 90 deg and W > 0
    if mu is None:
        exceeds = np.zeros(friction_ratio.shape, dtype=bool)
    else:
        exceeds = friction_ratio > np.asarray(mu, dtype=float)

    return CollisionResult(
        exit_speed=np.hypot(out_x, out_z),
        launch_angle=np.arctan2(out_z, out_x),
        backspin=spin_f,
        psi=psi,
        theta=psi - np.arctan2(v_t, v_n),
        v_n=v_n,
        v_t=v_t,
        J_n=m * jn,
        J_t=m * jt,
        friction_ratio=friction_ratio,
        exceeds_mu=np.broadcast_to(exceeds, friction_ratio.shape).copy(),
    )


def _checked_inputs(*args: ArrayLike) -> tuple[NDArray[np.float64], ...]:
    """Broadcast the array arguments of :func:`pitched_ball_collision` to float arrays; all finite."""
    names = ("D", "v_pitch", "pitch_descent", "pitch_spin", "v_bat", "attack_angle", "e_x", "e_y")
    arrays = tuple(np.asarray(a, dtype=float) for a in np.broadcast_arrays(*args))
    for name, arr in zip(names, arrays, strict=True):
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"pitched_ball_collision: {name} has non-finite values")
    return arrays


def _relative_velocity(v_bat, attack, pitch_x, pitch_z) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return the speed ``|W|`` of the bat relative to the ball and the elevation of ``W``, rad."""
    W_x = v_bat * np.cos(attack) - pitch_x
    W_z = v_bat * np.sin(attack) - pitch_z
    W = np.hypot(W_x, W_z)
    if np.any(W == 0.0):
        raise ValueError("pitched_ball_collision: the bat does not move relative to the ball (W = 0)")
    return W, np.arctan2(W_z, W_x)


def _contact_frame(sin_psi, phi_W):
    """Return psi and the lab components of ``n`` and ``t`` (Eq. D: ``sin psi = D / (r + R)``).

    ``n`` stands at ``phi_W + psi`` above +X; ``t`` is ``n`` rotated by -90 deg.
    """
    psi = np.arcsin(sin_psi)
    normal_angle = phi_W + psi
    n_x, n_z = np.cos(normal_angle), np.sin(normal_angle)
    return psi, (n_x, n_z), (n_z, -n_x)
