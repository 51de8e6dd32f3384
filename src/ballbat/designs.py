"""Fit designs: abscissa, ordinate and their derivatives for each straight-line fit of Sec. IV.

Each design maps the measured (v_bat, v_ball, theta, omega) of the impacts to the x and y of
one fit and to their Jacobians (n, 4) with respect to those measurements (columns in the
order of :data:`MEASURED`), which :func:`ballbat.linefit.fit_line` turns into effective
variances. psi and its derivatives come from Eq. angmom (:func:`ballbat.kinematics.psi_partials`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from .kinematics import angmom_argument, psi_partials, tan_psi_minus_theta

if TYPE_CHECKING:
    import xarray as xr
    from numpy.typing import ArrayLike

#: What a design returns: x, y and their Jacobians (n, 4) with respect to :data:`MEASURED`.
Design = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


class Measured(NamedTuple):
    """The measured quantities of a set of impacts (SI), in the order of the Jacobian columns."""

    v_bat: np.ndarray
    v_ball: np.ndarray
    theta: np.ndarray
    omega: np.ndarray

    @classmethod
    def from_dataset(cls, ds: xr.Dataset, sel: ArrayLike, prefix: str = "") -> Measured:
        """Read the impacts ``sel`` of ``ds`` (``prefix="truth_"``: their true values) as float arrays."""
        return cls(*(np.asarray(ds[prefix + k].values[sel], dtype=float) for k in cls._fields))


#: The measured quantities, in the order of the Jacobian columns.
MEASURED = Measured._fields


def measured_sigma(ds: xr.Dataset, sel: ArrayLike) -> np.ndarray | None:
    """Return the standard uncertainties (n, 4) of the impacts ``sel`` (columns :data:`MEASURED`).

    None unless ``ds`` holds ``<name>_err`` of every measured quantity.
    """
    if all(f"{k}_err" in ds for k in MEASURED):
        return np.stack([ds[f"{k}_err"].values[sel] for k in MEASURED], axis=1).astype(float)
    return None


def spin_design(m: Measured, r: ArrayLike, r_x: ArrayLike, alpha: ArrayLike) -> Design:
    """Eq. omega: x = v_bat sin psi / (r (1 + r_x)(1 + alpha)), y = omega."""
    v_bat, v_ball, theta, omega = m
    psi, dpsi = psi_partials(v_ball, theta, omega, r, alpha)
    c = 1.0 / (r * (1.0 + r_x) * (1.0 + alpha))
    x = v_bat * np.sin(psi) * c
    jx = (v_bat * np.cos(psi) * c)[:, None] * dpsi
    jx[:, 0] += np.sin(psi) * c
    jy = np.zeros_like(jx)
    jy[:, 3] = 1.0
    return x, omega, jx, jy


def tan_ratio_design(m: Measured, r: ArrayLike, alpha: ArrayLike) -> Design:
    """Eq. ratio: x = tan psi, y = tan(psi - theta) = q / sqrt(1 - q^2), q = alpha r omega / v_ball."""
    _, v_ball, theta, omega = m
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


def vtf_design(m: Measured, r: ArrayLike, r_x: ArrayLike, alpha: ArrayLike) -> Design:
    """Eq. vtf: x = tan psi / (1 + r_x), y = (v_ball,t + r omega) / v_bat,n.

    With Eq. angmom, v_ball,t = alpha r omega, so y = (1 + alpha) r omega / (v_bat cos psi).
    """
    v_bat, v_ball, theta, omega = m
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
