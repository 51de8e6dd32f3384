"""Regime boundaries of Stronge's contact model: where the phase sequence changes with psi.

Found by bisection on the closed-form solver (:func:`ballbat.stronge.model.stronge_solve`),
beside the boundaries the paper states (Sec. V.A), which the model does not always share
(docs/stronge.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .model import omega_ratio, stronge_solve


@dataclass(frozen=True)
class RegimeBoundaries:
    """Incidence angles where the phase sequence of Stronge's model changes.

    Attributes
    ----------
    psi : angles (rad) where the solver's regime changes, increasing.
    below, above : the regime just below and just above each angle.
    psi_stick_paper : atan(mu eta2), the paper's (and the model's) end of initial stick.
    psi_gross_paper : atan(3.5 mu (1 + e_y)), the paper's onset of gross slip.
    psi_rigid_reversal : atan(rho^2 mu eta2 (1 + e_y)): where gross slip of the model gives
        u_f = 0 (e_x = 0); equals the paper's 3.5 mu (1 + e_y) in the rigid frame. It is the
        rigid-body (Coulomb, no tangential compliance) onset of gross slip.
    psi_gross_model : the model's onset of gross slip in closed form (docs/stronge.md):
        atan(mu eta2) when Omega_t <= Omega_n, otherwise
        atan(rho^2 mu eta2 max(1, 1 + e_y - 1/(rho^2 e_y))) (C's slip velocity at t_c, or at
        separation, reaching zero). It tends to the paper's 3.5 mu (1 + e_y) as eta2 -> 0.
    """

    psi: NDArray
    below: tuple
    above: tuple
    psi_stick_paper: float
    psi_gross_paper: float
    psi_rigid_reversal: float
    psi_gross_model: float


def regime_boundaries(
    eta2: float,
    e_y: float,
    mu: float,
    r_x: float = 0.0,
    r_y: float = 0.0,
    alpha: float = 0.4,
    n_grid: int = 721,
    psi_max: float = np.deg2rad(89.9),
) -> RegimeBoundaries:
    """Find where the regime (phase sequence) of :func:`stronge_solve` changes with psi.

    Parameters
    ----------
    eta2, e_y, mu, r_x, r_y, alpha : scalars, as in :func:`stronge_ex`.
    n_grid : number of psi values scanned in (0, psi_max].
    psi_max : largest psi scanned, rad.

    Returns
    -------
    RegimeBoundaries
        The solver's boundaries (scan, then bisection on the regime label to ~1e-13 rad)
        next to the boundaries stated in Sec. V.A of Kensrud et al. (2017).

    Notes
    -----
    The paper (after Stronge) states: stick-slip for tan psi < mu eta2, slip-stick-slip for
    mu eta2 <= tan psi < 3.5 mu (1 + e_y), gross slip above. psi = 0 itself is left out of
    the scan (there the tangential motion vanishes and the limit psi -> 0 is pure stick).
    Two changes closer together than the scan step may be missed.
    """
    args = [float(a) for a in (eta2, e_y, mu, r_x, r_y, alpha)]
    psi = np.linspace(0.0, psi_max, int(n_grid) + 1)[1:]
    reg = stronge_solve(psi, *args).regime
    ch = np.flatnonzero(reg[1:] != reg[:-1])
    lo, hi = psi[ch], psi[ch + 1]
    left = reg[ch]
    for _ in range(60):
        if lo.size == 0:
            break
        mid = 0.5 * (lo + hi)
        same = stronge_solve(mid, *args).regime == left
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
        if np.all(hi - lo < 1e-13):
            break
    rho = omega_ratio(args[0], args[3], args[4], args[5])
    return RegimeBoundaries(
        psi=0.5 * (lo + hi),
        below=tuple(str(r) for r in reg[ch]),
        above=tuple(str(r) for r in reg[ch + 1]),
        psi_stick_paper=float(np.arctan(mu * eta2)),
        psi_gross_paper=float(np.arctan(3.5 * mu * (1.0 + e_y))),
        psi_rigid_reversal=float(np.arctan(rho**2 * mu * eta2 * (1.0 + e_y))),
        psi_gross_model=float(
            np.arctan(mu * eta2 * (1.0 if rho <= 1 else rho**2 * max(1.0, 1.0 + e_y - 1.0 / (rho**2 * e_y))))
        ),
    )
