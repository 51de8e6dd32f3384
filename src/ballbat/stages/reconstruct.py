"""Stage reconstruct: ``results/{dataset}/reconstruct.nc``, psi and the Sec. III quantities of every impact.

The normalised impacts with :data:`RECONSTRUCT_TABLE` added (:func:`ballbat.analysis.reconstruct_values`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..analysis import property_values, reconstruct_values
from ..columns import Columns
from ..kinematics import ImpactFlag
from ..pipeline.products import Var, add_variables, flag_attrs
from ..properties import ball_variants, bat_record, bat_variants
from ..systematics import PROPERTY_SHIFTED
from .systematics import append_sources

if TYPE_CHECKING:
    import xarray as xr

    from ..properties import Ball, Bat


@dataclass(frozen=True)
class ReconstructSettings:
    """Settings of the reconstruct stage: none (the property tables are inputs)."""

    @classmethod
    def from_config(cls, config: dict) -> ReconstructSettings:
        """Return the workflow's settings from the validated config."""
        return cls()


#: Variables that ``reconstruct`` adds.
RECONSTRUCT_TABLE = {
    "r": Var(("impact",), "m", "ball radius"),
    "m": Var(("impact",), "kg", "ball mass"),
    "alpha": Var(("impact",), "1", "ball moment of inertia over m r^2 (Eq. iball)"),
    "R_bat": Var(("impact",), "m", "bat radius R at the impact location (Table II)"),
    "r_x": Var(("impact",), "1", "tangential recoil factor r_x (Eq. rx)"),
    "r_y": Var(("impact",), "1", "normal recoil factor r_y (Eq. ry)"),
    "psi": Var(("impact",), "rad", "impact angle psi reconstructed from Eq. angmom"),
    "flag": Var(("impact",), "1", "reconstruction flag (0: usable)", flag_attrs(ImpactFlag)),
    "flag_reason": Var(("impact",), None, "why the impact is not used (ok if it is)"),
    "D": Var(("impact",), "m", "ball-bat offset D (Eq. D)"),
    "v_n": Var(("impact",), "m s-1", "normal component of the exit velocity"),
    "v_t": Var(("impact",), "m s-1", "tangential component of the exit velocity"),
    "v_bat_n": Var(("impact",), "m s-1", "normal component of the bat velocity"),
    "spin_bracket": Var(("impact",), "rad s-1", "bracket of Eq. omega: v_bat sin psi / (r (1 + r_x)(1 + alpha))"),
    "vtf_x": Var(("impact",), "1", "bracket of Eq. vtf: tan psi / (1 + r_x)"),
    "vtf_y": Var(("impact",), "1", "left side of Eq. vtf: (v_ball,t + r omega) / v_bat,n"),
    "tan_psi": Var(("impact",), "1", "tan psi (Fig. 6 abscissa)"),
    "tan_psi_minus_theta": Var(
        ("impact",), "1", "tan(psi - theta) = v_ball,t / v_ball,n (Eqs. muk, ratio; Fig. 6 ordinate)"
    ),
}


def run(settings: ReconstructSettings, impacts: xr.Dataset, balls: dict[str, Ball], bats: dict[str, Bat]) -> xr.Dataset:
    """Reconstruct psi and the Sec. III quantities of every impact (:func:`ballbat.analysis.reconstruct_values`).

    Adds the ball and bat properties used (r, alpha, R, r_x, r_y), psi (Eq. angmom), the
    flag and its reason, D (Eq. D), v_n and v_t, and the bracket terms of Eq. omega
    (``spin_bracket``) and Eq. vtf (``vtf_x``, with the left side ``vtf_y``), plus
    tan(psi - theta) of Eq. ratio. The attribute ``bat_properties`` records the dataset's bats:
    each one's table convention, its cells as given and the paper-convention values used
    (:func:`ballbat.properties.bat_record`).
    """
    out = add_variables(impacts, RECONSTRUCT_TABLE, reconstruct_values(Columns(impacts), balls, bats))
    used = sorted(set(impacts["bat"].values.astype(str)))
    out.attrs["bat_properties"] = bat_record({k: bats[k] for k in used})
    return append_sources(out, *property_shifts(out, balls, bats))


def property_shifts(
    rec: xr.Dataset, balls: dict[str, Ball], bats: dict[str, Bat]
) -> tuple[list[str], np.ndarray, dict[str, np.ndarray], dict[str, str]]:
    """Return the property sources of a dataset: one per stated uncertainty (``<column>_err``) of a bat or ball it uses.

    Returns the sources' names (``bat:<bat>:<column>``, ``ball:<ball>:<column>``), their
    relative standard uncertainties, per :data:`~ballbat.systematics.PROPERTY_SHIFTED` name the
    shifts of every impact's properties at +1 and -1 sigma (source, side, impact: nonzero only for
    that bat's, or ball's, impacts) and each source's description. Empty when none is stated.
    """
    rec = Columns(rec)  # plain arrays, not a DataArray per read
    ball_ids, bat_ids = rec["ball"].values.astype(str), rec["bat"].values.astype(str)
    nominal = {k: rec[k].values for k in PROPERTY_SHIFTED}
    names, rel, what = [], [], {}
    shifts: dict[str, list[np.ndarray]] = {k: [] for k in PROPERTY_SHIFTED}
    variants = [("bat", k, v, bats) for k in sorted(set(bat_ids)) for v in bat_variants(bats[k])]
    variants += [("ball", k, v, balls) for k in sorted(set(ball_ids)) for v in ball_variants(balls[k])]
    for kind, key, (col, value, sigma, plus, minus), _ in variants:
        sides = []
        for moved in (plus, minus):
            sides.append(property_values(ball_ids, bat_ids, *_with(kind, key, moved, balls, bats)))
        name = f"{kind}:{key}:{col}"
        names.append(name)
        rel.append(sigma / abs(value) if value else math.nan)
        what[name] = f"{kind} {key}'s {col} = {value:g} +- {sigma:g} (the {kind} table's {col}_err)"
        for k in PROPERTY_SHIFTED:
            shifts[k].append(np.stack([side[k] - nominal[k] for side in sides]))
    return names, np.array(rel, dtype=float), {k: np.array(v) for k, v in shifts.items()}, what


def _with(kind: str, key: str, moved: Ball | Bat, balls: dict, bats: dict) -> tuple[dict, dict]:
    """Return the tables with one bat (or ball) replaced by ``moved``."""
    if kind == "bat":
        return balls, {**bats, key: moved}
    return {**balls, key: moved}, bats
