"""Regimes (phase sequences) of Stronge's contact model and their boundaries in psi.

The closed-form solver :func:`ballbat.stronge.model.stronge_solve` labels each impact with
its phase sequence ("stick-slip", "gross-slip", ...). :class:`Regime` is the integer code of
such a label for results files (CF ``flag_values``/``flag_meanings``);
:func:`regime_boundaries` finds the incidence angles where the label changes and sets them
beside the boundaries stated in Sec. V.A of Kensrud et al. (2017).

References
----------
.. [1] J. R. Kensrud, A. M. Nathan and L. V. Smith, Am. J. Phys. 85, 503 (2017), Sec. V.A.
.. [2] W. J. Stronge, "Planar impact of rough compliant bodies", Int. J. Impact Eng. 15,
   435 (1994).
"""

from __future__ import annotations

import enum
import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .model import ContactParams, stronge_solve

__all__ = ["Regime", "RegimeBoundaries", "regime_boundaries"]


class Regime(enum.IntEnum):
    """Integer code of a phase sequence of :func:`ballbat.stronge.model.stronge_solve`.

    Phases alternate between stick and slip, so a sequence is fixed by its first phase and
    its length. The codes cover every sequence of up to four phases; a longer one (possible
    only when Omega_t > Omega_n) is ``LONGER_SEQUENCE``, and the file that stores the code
    also stores the number of phases.
    """

    STICK = 1
    STICK_SLIP = 2
    STICK_SLIP_STICK = 3
    STICK_SLIP_STICK_SLIP = 4
    GROSS_SLIP = 5
    SLIP_STICK = 6
    SLIP_STICK_SLIP = 7
    SLIP_STICK_SLIP_STICK = 8
    LONGER_SEQUENCE = 9

    @property
    def label(self) -> str:
        """The solver's label of the sequence ("stick-slip", "gross-slip", ...)."""
        return self.name.lower().replace("_", "-")

    @classmethod
    def from_label(cls, label: str) -> Regime:
        """Return the code of a solver label.

        Parameters
        ----------
        label : str
            A regime of :class:`ballbat.stronge.model.StrongeSolution`, e.g. ``"stick-slip"``.

        Returns
        -------
        Regime
            Its code; ``LONGER_SEQUENCE`` for a valid sequence of more than four phases.

        Raises
        ------
        ValueError
            ``label`` is not a "-"-joined alternating sequence of "stick" and "slip".
        """
        if label == "gross-slip":
            return cls.GROSS_SLIP
        phases = label.split("-")
        alternating = all(a != b for a, b in itertools.pairwise(phases))
        if not (phases and set(phases) <= {"stick", "slip"} and alternating) or phases == ["slip"]:
            raise ValueError(f"Regime: {label!r} is not a phase sequence of Stronge's model")
        if len(phases) > 4:
            return cls.LONGER_SEQUENCE
        return cls[label.upper().replace("-", "_")]


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


def regime_boundaries(contact: ContactParams, n_grid: int = 721, psi_max: float = np.deg2rad(89.9)) -> RegimeBoundaries:
    """Find where the regime (phase sequence) of :func:`stronge_solve` changes with psi.

    Parameters
    ----------
    contact : the model's parameters, scalars (:class:`ballbat.stronge.model.ContactParams`).
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
    c = contact.scalars()
    psi = np.linspace(0.0, psi_max, int(n_grid) + 1)[1:]
    reg = stronge_solve(psi, c).regime
    ch = np.flatnonzero(reg[1:] != reg[:-1])
    lo, hi = psi[ch], psi[ch + 1]
    left = reg[ch]
    for _ in range(60):
        if lo.size == 0:
            break
        mid = 0.5 * (lo + hi)
        same = stronge_solve(mid, c).regime == left
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
        if np.all(hi - lo < 1e-13):
            break
    rho, mu, eta2, e_y = c.omega_ratio(), c.mu, c.eta2, c.e_y
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
