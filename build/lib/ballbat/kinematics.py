"""Kinematics of a bat hitting a ball at rest (Sec. III of Kensrud et al. 2017).

Forward model (used to make synthetic experiments) and its inverse (the reconstruction of
the impact geometry psi from measured exit speed, angle and spin). All inputs and outputs
are SI: m, m s-1, rad, rad s-1. Functions broadcast over numpy arrays of impacts.

Conventions (PHYSICS.md): n-hat points from the bat's centre to the ball's centre; the bat
velocity is v_bat (cos psi n-hat + sin psi t-hat); omega > 0 is the spin of the paper's
Fig. 2 (backspin when the bat undercuts the ball); theta is the ball's angle from the bat's
direction of travel.

References
----------
.. [1] J. R. Kensrud, A. M. Nathan and L. V. Smith, Am. J. Phys. 85, 503 (2017).
.. [2] R. Cross and A. M. Nathan, "Scattering of a baseball by a bat",
   Am. J. Phys. 74, 896 (2006).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike


def offset_from_psi(psi: ArrayLike, r: ArrayLike, R: ArrayLike) -> np.ndarray:
    """Ball-bat offset D from the impact angle psi (Eq. D): D = (r + R) sin psi."""
    return (r + R) * np.sin(psi)


def spin_bracket(v_bat: ArrayLike, psi: ArrayLike, r: ArrayLike, r_x: ArrayLike, alpha: ArrayLike = 0.4) -> np.ndarray:
    """Return the bracket of Eq. omega: v_bat sin psi / (r (1 + r_x)(1 + alpha)), rad s-1.

    The measured spin is (1 + e_x) times this term; Fig. 5 plots omega against it.
    """
    return v_bat * np.sin(psi) / (r * (1.0 + r_x) * (1.0 + alpha))


def vtf_bracket(psi: ArrayLike, r_x: ArrayLike) -> np.ndarray:
    """Return the bracket of Eq. vtf: tan psi / (1 + r_x) (dimensionless, Fig. 9 abscissa)."""
    return np.tan(psi) / (1.0 + r_x)


def vtf_ordinate(
    v_ball: ArrayLike, theta: ArrayLike, omega: ArrayLike, v_bat: ArrayLike, psi: ArrayLike, r: ArrayLike
) -> np.ndarray:
    """Return the left side of Eq. vtf: (v_ball,t + r omega) / v_bat,n (Fig. 9 ordinate).

    v_ball,t = v_ball sin(psi - theta) and v_bat,n = v_bat cos psi.
    """
    return (v_ball * np.sin(psi - theta) + r * omega) / (v_bat * np.cos(psi))


@dataclass(frozen=True)
class Outgoing:
    """Outgoing ball of a ball-at-rest collision (SI)."""

    v_n: np.ndarray  # m s-1, normal component
    v_t: np.ndarray  # m s-1, tangential component
    omega: np.ndarray  # rad s-1
    v_ball: np.ndarray  # m s-1, speed
    theta: np.ndarray  # rad, angle from the bat's direction of travel


def ball_at_rest_collision(
    v_bat: ArrayLike,
    psi: ArrayLike,
    e_x: ArrayLike,
    e_y: ArrayLike,
    r: ArrayLike,
    r_x: ArrayLike,
    r_y: ArrayLike,
    alpha: ArrayLike = 0.4,
) -> Outgoing:
    """Outgoing ball after a bat at speed ``v_bat`` and angle ``psi`` hits a ball at rest.

    Parameters
    ----------
    v_bat : bat speed at the impact point, m s-1.
    psi : angle of the bat velocity to the normal n-hat, rad.
    e_x, e_y : tangential and normal coefficients of restitution.
    r : ball radius, m.   r_x, r_y : recoil factors (Eqs. rx, ry).
    alpha : I_ball / (m r^2) (Eq. iball).

    Notes
    -----
    v_n = (1 + e_y)/(1 + r_y) v_bat cos psi                    (Eq. vballn)
    v_t = (1 + e_x) alpha v_bat sin psi / ((1 + r_x)(1 + alpha)) (Eq. vxf)
    omega = (1 + e_x) v_bat sin psi / (r (1 + r_x)(1 + alpha))  (Eq. omega)
    theta = psi - atan(v_t / v_n)                               (Fig. 2 geometry)
    """
    v_n = (1.0 + e_y) / (1.0 + r_y) * v_bat * np.cos(psi)
    v_t = (1.0 + e_x) * alpha * v_bat * np.sin(psi) / ((1.0 + r_x) * (1.0 + alpha))
    omega = (1.0 + e_x) * spin_bracket(v_bat, psi, r, r_x, alpha)
    return Outgoing(
        v_n=v_n,
        v_t=v_t,
        omega=omega,
        v_ball=np.hypot(v_n, v_t),
        theta=psi - np.arctan2(v_t, v_n),
    )


class ImpactFlag(enum.IntEnum):
    """Why an impact cannot be used (the ``flag`` of reconstruct.nc, ``ingest_flag`` of ingest.nc).

    One code list for every stage: Eq. angmom's failures (1-3), set wherever psi is
    reconstructed, the exclusions made when a measured file is read (4, in reconstruct.nc),
    and measurements no collision can produce (5, ``ingest_flag``: implied e_x outside
    [-1, 1], an exit speed beyond the collision's bounds, an outlier of its bat x ball group).
    """

    OK = 0
    PSI_UNDEFINED = 1
    BAD_SPEED = 2
    BAT_BEHIND_BALL = 3
    EXCLUDED_AT_INGEST = 4
    IMPLAUSIBLE = 5


#: A sentence per :class:`ImpactFlag`, for the readable ``*_reason`` variables.
FLAG_TEXT = {
    ImpactFlag.OK: "ok",
    ImpactFlag.PSI_UNDEFINED: "alpha r omega / v_ball outside [-1, 1]: psi undefined (Eq. angmom)",
    ImpactFlag.BAD_SPEED: "non-finite or non-positive measured speed",
    ImpactFlag.BAT_BEHIND_BALL: "reconstructed |psi| >= 90 deg: the bat cannot reach the ball there",
    ImpactFlag.EXCLUDED_AT_INGEST: "excluded when the measured file was read (see ingest_flag_reason)",
    ImpactFlag.IMPLAUSIBLE: "a measurement no ball-bat collision can produce (a unit mistake?)",
}


def angmom_argument(v_ball: ArrayLike, omega: ArrayLike, r: ArrayLike, alpha: ArrayLike) -> np.ndarray:
    """Return the argument of Eq. angmom's arcsine: sin(psi - theta) = alpha r omega / v_ball."""
    return alpha * r * np.asarray(omega, dtype=float) / np.asarray(v_ball, dtype=float)


def reconstruct_psi(
    v_ball: ArrayLike, theta: ArrayLike, omega: ArrayLike, r: ArrayLike, alpha: ArrayLike
) -> tuple[np.ndarray, np.ndarray]:
    """Impact angle psi from measured exit speed, angle and spin (Eq. angmom).

    Returns ``(psi, flag)``. Angular momentum of the ball about the contact point
    vanishes (Eq. angmom): alpha m r^2 omega = m v_ball r sin(psi - theta), so
    psi = theta + asin(alpha r omega / v_ball). Where the argument lies outside [-1, 1]
    psi is NaN and ``flag`` is :attr:`ImpactFlag.PSI_UNDEFINED`: never clipped. A small
    negative psi (bat over the ball's centre, or noise near head-on impacts) is valid.
    This is the one implementation of Eq. angmom; :func:`psi_partials` adds its derivatives.
    """
    v_ball = np.asarray(v_ball, dtype=float)
    bad_speed = ~np.isfinite(v_ball) | (v_ball <= 0)
    arg = angmom_argument(np.where(bad_speed, np.nan, v_ball), omega, r, alpha)
    out_of_range = ~bad_speed & (np.abs(arg) > 1.0)
    with np.errstate(invalid="ignore"):
        psi = np.where(bad_speed | out_of_range, np.nan, theta + np.arcsin(np.clip(arg, -1, 1)))
    flag = np.zeros(np.shape(psi), dtype=np.int8)
    flag[out_of_range] = ImpactFlag.PSI_UNDEFINED
    flag[bad_speed] = ImpactFlag.BAD_SPEED
    with np.errstate(invalid="ignore"):
        flag[(flag == 0) & ~(np.abs(psi) < np.pi / 2)] = ImpactFlag.BAT_BEHIND_BALL
    return psi, flag


def tan_psi_minus_theta(v_ball: ArrayLike, omega: ArrayLike, r: ArrayLike, alpha: ArrayLike) -> np.ndarray:
    """Return tan(psi - theta) = v_ball,t / v_ball,n, the right side of Eq. muk.

    The ratio of tangential to normal impulse bounds the kinetic friction from below
    (mu_k >= tan(psi - theta), Eq. muk). With Eq. angmom, sin(psi - theta) = q =
    alpha r omega / v_ball, so tan(psi - theta) = q / sqrt(1 - q^2) (NaN where |q| > 1).
    """
    q = angmom_argument(v_ball, omega, r, alpha)
    with np.errstate(invalid="ignore"):
        return q / np.sqrt(1.0 - q**2)


def psi_partials(
    v_ball: ArrayLike, theta: ArrayLike, omega: ArrayLike, r: ArrayLike, alpha: ArrayLike
) -> tuple[np.ndarray, np.ndarray]:
    """Psi of Eq. angmom and its derivatives with respect to (v_bat, v_ball, theta, omega).

    For usable impacts (|alpha r omega / v_ball| < 1). Returns ``(psi, dpsi)`` with ``dpsi``
    of shape (n, 4), the columns in the order of :data:`ballbat.designs.MEASURED`.
    """
    q = angmom_argument(v_ball, omega, r, alpha)
    root = np.sqrt(1.0 - q**2)
    psi = theta + np.arcsin(q)
    d = np.stack([np.zeros_like(q), -q / (v_ball * root), np.ones_like(q), alpha * r / (v_ball * root)], axis=1)
    return psi, d


def normalize_to_bat_speed(value: ArrayLike, v_bat: ArrayLike, v_ref: float) -> np.ndarray:
    """Scale a measured spin or exit speed to the reference bat speed (Sec. II).

    Both scale linearly with bat speed (Eqs. vballn, vxf, omega), so the normalised value
    is value * v_ref / v_bat. The paper's text prints the ratio upside down; only
    v_ref / v_bat normalises (PHYSICS.md).
    """
    return np.asarray(value, dtype=float) * (v_ref / np.asarray(v_bat, dtype=float))


def tan_ratio_slope_model(
    e_x: ArrayLike, e_y: ArrayLike, r_x: ArrayLike, r_y: ArrayLike, alpha: ArrayLike = 0.4
) -> np.ndarray:
    """Slope of tan(psi - theta) against tan psi predicted by Eq. ratio."""
    return alpha / (1.0 + alpha) * (1.0 + e_x) / (1.0 + r_x) * (1.0 + r_y) / (1.0 + e_y)


def e_y_from_tan_ratio_slope(
    slope: ArrayLike, e_x: ArrayLike, r_x: ArrayLike, r_y: ArrayLike, alpha: ArrayLike = 0.4
) -> np.ndarray:
    """Invert Eq. ratio for the normal COR e_y that a measured slope implies."""
    return alpha / (1.0 + alpha) * (1.0 + e_x) / (1.0 + r_x) * (1.0 + r_y) / slope - 1.0


def gross_slip_onset(
    mu_k: ArrayLike,
    tan_slope: ArrayLike,
    v_bat: ArrayLike,
    e_x: ArrayLike,
    r: ArrayLike,
    r_x: ArrayLike,
    alpha: ArrayLike = 0.4,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Largest psi before gross slip for friction ``mu_k`` (Sec. IV example).

    Gross slip sets in where tan(psi - theta) reaches mu_k (Eq. muk); with the measured
    slope of Eq. ratio, tan psi = mu_k / slope. Returns ``(psi, theta, omega)`` at that
    point, omega from Eq. omega at bat speed ``v_bat``.
    """
    psi = np.arctan(mu_k / tan_slope)
    theta = psi - np.arctan(mu_k)
    omega = (1.0 + e_x) * spin_bracket(v_bat, psi, r, r_x, alpha)
    return psi, theta, omega
