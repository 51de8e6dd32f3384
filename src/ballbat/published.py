"""Published numbers of Kensrud, Nathan & Smith (2017), each with its place in the paper.

These are the values the workflow compares against (``paper_comparison.csv``); they are
never used as inputs of a fit. Units are the paper's (the comparison table's units).
``uncertainty`` is the paper's standard error where it gives one, else None.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Sequence


@dataclass(frozen=True)
class Published:
    """A number the paper publishes: quantity, ball, bat, value, uncertainty, unit and where it stands."""

    quantity: str
    ball: str
    bat: str
    value: float
    uncertainty: float | None
    unit: str
    source: str


_BASE = "baseball"
_SOFT = "softball"

PUBLISHED: tuple[Published, ...] = (
    # Table II: e_x per bat and ball, standard errors in parentheses.
    Published("e_x", _BASE, "wood", 0.464, 0.014, "1", "Table II"),
    Published("e_x", _BASE, "metal_rough", 0.356, 0.015, "1", "Table II"),
    Published("e_x", _BASE, "metal_smooth", 0.374, 0.015, "1", "Table II"),
    Published("e_x", _SOFT, "wood", 0.234, 0.017, "1", "Table II"),
    Published("e_x", _SOFT, "metal_rough", 0.130, 0.038, "1", "Table II"),
    Published("e_x", _SOFT, "metal_smooth", 0.128, 0.013, "1", "Table II"),
    Published("e_x", _SOFT, "softball_composite", 0.128, 0.012, "1", "Table II"),
    # Eq. (ex), Sec. IV; Fig. 5 slopes 1.405 and 1.146.
    Published("e_x_pooled", _BASE, "", 0.405, 0.010, "1", "Eq. ex (Sec. IV), Fig. 5"),
    Published("e_x_pooled", _SOFT, "", 0.146, 0.009, "1", "Eq. ex (Sec. IV), Fig. 5"),
    # Figs. 3 and 4 captions.
    Published("spin_theta_slope", _BASE, "", 179.0, None, "rpm/deg", "Fig. 3"),
    Published("spin_theta_slope", _SOFT, "", 98.0, None, "rpm/deg", "Fig. 3"),
    Published("speed_theta_slope", _BASE, "", -0.65, None, "mph/deg", "Fig. 4"),
    Published("speed_theta_slope", _SOFT, "", -0.72, None, "mph/deg", "Fig. 4"),
    # Fig. 6 caption and Eq. ratio.
    Published("tan_ratio_slope", _BASE, "", 0.281, None, "1", "Fig. 6"),
    Published("tan_ratio_slope", _SOFT, "", 0.252, None, "1", "Fig. 6"),
    # Sec. IV, after Eq. ratio.
    Published("mu_k_lower_bound", _BASE, "", 0.15, None, "1", "Sec. IV (Eq. muk, Fig. 6)"),
    Published("mu_k_lower_bound", _SOFT, "", 0.20, None, "1", "Sec. IV (Eq. muk, Fig. 6)"),
    # Sec. IV example: with mu_k = 0.50 gross slip sets in near psi = 60 deg (baseball).
    Published("gross_slip_psi", _BASE, "", 60.0, None, "deg", "Sec. IV, mu_k = 0.5 example"),
    Published("gross_slip_theta", _BASE, "", 34.0, None, "deg", "Sec. IV, mu_k = 0.5 example"),
    Published("gross_slip_omega", _BASE, "", 6400.0, None, "rpm", "Sec. IV, mu_k = 0.5 example"),
    # Table I: largest psi and D of the experiment.
    Published("psi_max", _BASE, "", 30.0, None, "deg", "Table I"),
    Published("psi_max", _SOFT, "", 41.0, None, "deg", "Table I"),
    Published("D_max", _BASE, "", 1.35, None, "in", "Table I"),
    Published("D_max", _SOFT, "", 2.00, None, "in", "Table I"),
    # Sec. V.A: Stronge's model fitted with e_y = mu = 0.5.
    Published("eta2", _BASE, "", 4.75, None, "1", "Sec. V.A"),
    Published("eta2", _SOFT, "", 6.30, None, "1", "Sec. V.A"),
    Published("omega_t_over_omega_n", _BASE, "", 0.86, None, "1", "Sec. V.A"),
    Published("omega_t_over_omega_n", _SOFT, "", 0.75, None, "1", "Sec. V.A"),
    # Sec. V.A and Fig. 10, psi = 30 deg: stick until ~1.4 t_c, separation 1.5 t_c, stretch
    # largest at 1.16 t_c (baseball) and 1.33 t_c (softball).
    Published("stretch_max_time_psi30", _BASE, "", 1.16, None, "t_c", "Sec. V.A, Fig. 10"),
    Published("stretch_max_time_psi30", _SOFT, "", 1.33, None, "t_c", "Sec. V.A, Fig. 10"),
    Published("stick_end_time_psi30", _BASE, "", 1.4, None, "t_c", "Sec. V.A, Fig. 10 ('about')"),
    Published("stick_end_time_psi30", _SOFT, "", 1.4, None, "t_c", "Sec. V.A, Fig. 10 ('about')"),
    Published("separation_time_psi30", _BASE, "", 1.5, None, "t_c", "Sec. V.A, Fig. 10"),
    Published("separation_time_psi30", _SOFT, "", 1.5, None, "t_c", "Sec. V.A, Fig. 10"),
    # Table I: number of impacts.
    Published("n_impacts", _BASE, "", 58, None, "1", "Table I"),
    Published("n_impacts", _SOFT, "", 50, None, "1", "Table I"),
)

#: Sec. V.B statements, for the implications' ``paper`` scenario (wood bat, baseball). The
#: paper gives no uncertainties; "about 400 ft" and "peaks near D = 0" are its words.
PUBLISHED_IMPLICATIONS: tuple[Published, ...] = (
    Published("carry_max", _BASE, "wood", 400.0, None, "ft", "Sec. V.B: '400-ft home run at intermediate D', Fig. 11b"),
    Published("D_at_exit_speed_max", _BASE, "wood", 0.0, None, "in", "Sec. V.B: exit speed peaks at D ~ 0, Fig. 11a"),
)

#: Sec. V.B's case, the one PUBLISHED_IMPLICATIONS describe: an 85 mph fastball descending at 6 deg with
#: 2000 rpm backspin, a 73 mph swing at 6 deg attack, a baseball. A caption compares with the paper only here.
PAPER_IMPLICATIONS_CASE = {
    "ball": "baseball",
    "pitch_mph": 85.0,
    "pitch_descent_deg": 6.0,
    "pitch_backspin_rpm": 2000.0,
    "bat_mph": 73.0,
    "attack_deg": 6.0,
}

#: Sec. V.A: the fixed normal COR and friction coefficient with which the paper fitted eta^2
#: (4.75 baseball, 6.30 softball) and drew Figs. 9-10 ("e_y = mu = 0.5 was assumed").
STRONGE_E_Y = 0.5
STRONGE_MU = 0.5

#: Quantities with no published value that the comparison still reports (Sec. IV).
UNPUBLISHED = {"e_y_implied": "1"}


def per_ball(quantity: str, published: Sequence[Published] = PUBLISHED) -> dict[str, float]:
    """Return the published values of a per-ball quantity (no bat), as {ball: value}."""
    return {p.ball: p.value for p in published if p.quantity == quantity and not p.bat}
