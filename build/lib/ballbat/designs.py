"""Fit designs: abscissa, ordinate and their derivatives for each straight-line fit of Sec. IV.

Each design maps the measured (v_bat, v_ball, theta, omega) of the impacts to the x and y of
one fit and to their Jacobians (n, 4) with respect to those measurements (columns in the
order of :data:`MEASURED`), which :func:`ballbat.linefit.fit_line` turns into effective
variances. psi and its derivatives come from Eq. angmom (:func:`ballbat.kinematics.psi_partials`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .kinematics import angmom_argument, psi_partials, tan_psi_minus_theta

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

#: What a design returns: x, y and their Jacobians (n, 4) with respect to :data:`MEASURED`.
Design = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]

#: The measured quantities, in the order of the Jacobian columns.
MEASURED = ("v_bat", "v_ball", "theta", "omega")


def spin_design(
    v_bat: ArrayLike,
    v_ball: ArrayLike,
    theta: ArrayLike,
    omega: ArrayLike,
    r: ArrayLike,
    r_x: ArrayLike,
    alpha: ArrayLike,
) -> Design:
    """Eq. omega: x = v_bat sin psi / (r (1 + r_x)(1 + alpha)), y = omega."""
    psi, dpsi = psi_partials(v_ball, theta, omega, r, alpha)
    c = 1.0 / (r * (1.0 + r_x) * (1.0 + alpha))
    x = v_bat * np.sin(psi) * c
    jx = (v_bat * np.cos(psi) * c)[:, None] * dpsi
    jx[:, 0] += np.sin(psi) * c
    jy = np.zeros_like(jx)
    jy[:, 3] = 1.0
    return x, omega, jx, jy


def tan_ratio_design(
    v_bat: ArrayLike, v_ball: ArrayLike, theta: ArrayLike, omega: ArrayLike, r: ArrayLike, alpha: ArrayLike
) -> Design:
    """Eq. ratio: x = tan psi, y = tan(psi - theta) = q / sqrt(1 - q^2), q = alpha r omega / v_ball."""
    psi, dpsi = psi_partials(v_ball, theta, omega, r, alpha)
    q = angmom_argument(v_ball, omega, r, alpha)
    x = np.tan(psi)
    y = tan_psi_minus_theta(v_ball, omega, r, alpha)
    jx = (1.0 / np.cos(psi) ** 2)[:, None] * dpsi
    dydq = (1.0 - q**2) ** -1.5
    jy = np.zeros_like(jx)
    jy[:, 1] = -dydq * q / v_ball
    jy[:, 3] = dydq * alpha * r / v_ball
    return x, y, jx, jy


def vtf_design(
    v_bat: ArrayLike,
    v_ball: ArrayLike,
    theta: ArrayLike,
    omega: ArrayLike,
    r: ArrayLike,
    r_x: ArrayLike,
    alpha: ArrayLike,
) -> Design:
    """Eq. vtf: x = tan psi / (1 + r_x), y = (v_ball,t + r omega) / v_bat,n.

    With Eq. angmom, v_ball,t = alpha r omega, so y = (1 + alpha) r omega / (v_bat cos psi).
    """
    psi, dpsi = psi_partials(v_ball, theta, omega, r, alpha)
    x = np.tan(psi) / (1.0 + r_x)
    y = (1.0 + alpha) * r * omega / (v_bat * np.cos(psi))
    jx = (1.0 / (np.cos(psi) ** 2 * (1.0 + r_x)))[:, None] * dpsi
    jy = (y * np.tan(psi))[:, None] * dpsi
    jy[:, 0] += -y / v_bat
    jy[:, 3] += (1.0 + alpha) * r / (v_bat * np.cos(psi))
    return x, y, jx, jy


def normalized_theta_design(v_bat: ArrayLike, y: ArrayLike, theta: ArrayLike, which: str, v_ref: float) -> Design:
    """Figs. 3-4: x = theta, y = the normalised ``which`` (omega or v_ball) = value v_ref / v_bat.

    ``y`` is the normalised value as ``normalize`` computed it
    (:func:`ballbat.kinematics.normalize_to_bat_speed`); v_bat and v_ref give its derivatives.
    """
    n = np.size(theta)
    jx = np.zeros((n, 4))
    jx[:, 2] = 1.0
    jy = np.zeros((n, 4))
    jy[:, 0] = -y / v_bat
    jy[:, MEASURED.index(which)] = v_ref / v_bat
    return theta, y, jx, jy
