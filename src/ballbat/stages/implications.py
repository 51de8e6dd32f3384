"""Stage implications: ``results/implications/{scenario}.nc``, a batted-ball scenario (Sec. V.B).

:func:`scenario_table` declares the file (the D sweep's collisions when the scenario sweeps D, the
launch conditions and the flights); :func:`run` runs the scenario
(:func:`ballbat.implications.run_scenario`) and assembles it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from ..implications import run_scenario
from ..pipeline.products import Var, build_dataset

if TYPE_CHECKING:
    from collections.abc import Mapping

    from ..properties import Ball, Bat

C, CP = ("case",), ("case", "point")


@dataclass(frozen=True)
class ImplicationsSettings:
    """Settings of one batted-ball scenario.

    Attributes
    ----------
    scenario : dict
        Its config block (``implications.scenarios.<name>``, paper units).
    air : dict
        The atmospheric conditions (``implications.air``).
    """

    scenario: dict
    air: dict

    @classmethod
    def from_config(cls, config: dict, name: str) -> ImplicationsSettings:
        """Return scenario ``name``'s settings from the validated config."""
        block = config["implications"]
        return cls.from_params({"scenario": block["scenarios"][name], "air": block["air"]})

    @classmethod
    def from_params(cls, params: Mapping) -> ImplicationsSettings:
        """Return a scenario's settings from its rule's params (``scenario``, ``air``)."""
        return cls(scenario=params["scenario"], air=params["air"])


def scenario_table(sweep: bool, mu: float | None = None) -> dict[str, Var]:
    """Return the variables of a scenario's file: the D sweep's (``sweep``, friction ``mu``), then the flights'."""
    table: dict[str, Var] = {}
    if sweep:
        table["D"] = Var(C, "m", "ball-bat offset D (along the relative velocity)")
        table["psi"] = Var(C, "rad", "impact angle psi")
        table["friction_ratio"] = Var(C, "1", "required friction |J_t / J_n|")
        table["exceeds_mu"] = Var(
            C,
            "1",
            f"1 where the impact needs more friction than mu = {mu} (e_x model kept as is)",
            {
                "flag_values": np.array([0, 1], dtype=np.int8),
                "flag_meanings": "within_friction needs_more_friction_than_mu",
            },
        )
    table["exit_speed"] = Var(C, "m s-1", "exit speed of the batted ball")
    table["launch_angle"] = Var(C, "rad", "launch angle above the horizontal")
    table["spray_angle"] = Var(C, "rad", "spray angle from centre field toward first base")
    table["backspin"] = Var(C, "rad s-1", "backspin (negative: topspin)")
    table["sidespin"] = Var(C, "rad s-1", "sidespin (positive curves toward third base)")
    table["carry"] = Var(C, "m", "carry: horizontal distance from home plate at landing")
    table["apex"] = Var(C, "m", "apex height above the ground")
    table["hang_time"] = Var(C, "s", "hang time")
    table["landing_x"] = Var(C, "m", "landing point x (toward first base)")
    table["landing_y"] = Var(C, "m", "landing point y (toward centre field)")
    table["trajectory_t"] = Var(CP, "s", "time since contact")
    for axis in "xyz":
        table[f"trajectory_{axis}"] = Var(CP, "m", f"trajectory {axis}")
    return table


def run(
    settings: ImplicationsSettings, balls: dict[str, Ball], bats: dict[str, Bat], e_x: float | None = None
) -> xr.Dataset:
    """Run one scenario; return its Dataset, one entry per case.

    ``e_x`` overrides the scenario's (e.g. the pooled e_x fitted on a dataset:
    :func:`ballbat.implications.pooled_e_x`).
    """
    scenario = settings.scenario
    got = run_scenario(scenario, balls, bats, settings.air, e_x=e_x)
    res = got.flight
    values = dict(got.sweep or {})
    values.update(got.launch)
    values.update(carry=res.carry, apex=res.apex, hang_time=res.hang_time)
    values.update(landing_x=res.landing[..., 0], landing_y=res.landing[..., 1], trajectory_t=res.t)
    for i, axis in enumerate("xyz"):
        values[f"trajectory_{axis}"] = res.points[..., i]
    table = scenario_table("sweep" in scenario, scenario.get("mu"))
    n = np.size(got.launch["exit_speed"])
    coords = {
        "case": ("case", np.arange(n, dtype=np.int64), {"units": "1", "long_name": "case number"}),
        "point": (
            "point",
            np.arange(res.points.shape[-2], dtype=np.int64),
            {"units": "1", "long_name": "trajectory sample"},
        ),
    }
    return build_dataset(
        table,
        {name: values[name] for name in table},
        coords=coords,
        attrs={
            "ball": scenario["ball"],
            "bat": scenario.get("bat", ""),
            "kind": "D sweep" if "sweep" in scenario else "launch conditions",
            "e_x": got.e_x,
            "air_density": got.air_density,
            "air_density_units": "kg m-3",
            "flight_method": scenario["flight"]["method"],
        },
    )
