"""Batted-ball implications (Sec. V.B): collide a pitched ball with a bat, then fly it.

A scenario either sweeps the offset D for a given pitch and swing (the paper's Fig. 11), or
gives launch conditions directly (exit speed, launch angle, spray angle, backspin,
sidespin), on a grid or as a list, so that measured batted balls can be flown too. The
settings are in the paper's units (mph, rpm, deg, in, ft), as in the config; everything is
converted to SI here, once.

References
----------
.. [1] J. R. Kensrud, A. M. Nathan and L. V. Smith, Am. J. Phys. 85, 503 (2017), Sec. V.B.
.. [2] A. M. Nathan, trajectory calculator (drag, lift and spin decay; docs/model.md, "Flight").
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .collision import pitched_ball_collision
from .flight import FlightResult, air_density, fly
from .properties import Ball, Bat
from .units import DEGREE, FOOT, INCH, INHG_IN_MMHG, MPH, RPM, fahrenheit_to_celsius

if TYPE_CHECKING:
    import os

    import xarray as xr

LAUNCH_KEYS = ("exit_speed_mph", "launch_deg", "spray_deg", "backspin_rpm", "sidespin_rpm")


def density_from_conditions(air: dict) -> float:
    """Air density (kg m-3) from the config's conditions (deg F, ft, %, inHg)."""
    return float(
        air_density(
            fahrenheit_to_celsius(air["temperature_F"]),
            air["pressure_inHg"] * INHG_IN_MMHG,
            air["elevation_ft"] * FOOT,
            air["humidity_pct"],
        )
    )


def launch_conditions(launch: dict) -> dict:
    """Launch conditions (SI arrays, one entry per case) from a scenario's ``launch`` block.

    ``combine: grid`` takes every combination of the listed values; ``combine: list`` pairs
    them element by element (lists of length 1 are repeated).
    """
    values = {k: np.atleast_1d(np.asarray(launch[k], dtype=float)) for k in LAUNCH_KEYS}
    if launch["combine"] == "grid":
        grid = list(itertools.product(*(values[k] for k in LAUNCH_KEYS)))
        cols = {k: np.array([g[i] for g in grid]) for i, k in enumerate(LAUNCH_KEYS)}
    else:
        sizes = {k: v.size for k, v in values.items() if v.size > 1}
        if len(set(sizes.values())) > 1:
            lengths = ", ".join(f"{k} has {n}" for k, n in sizes.items())
            raise ValueError(f"launch: with combine: list, the lists must have one length (or 1 value): {lengths}")
        n = max(sizes.values(), default=1)
        cols = {k: np.broadcast_to(v, (n,)).copy() for k, v in values.items()}
    return {
        "exit_speed": cols["exit_speed_mph"] * MPH,
        "launch_angle": cols["launch_deg"] * DEGREE,
        "spray_angle": cols["spray_deg"] * DEGREE,
        "backspin": cols["backspin_rpm"] * RPM,
        "sidespin": cols["sidespin_rpm"] * RPM,
    }


@dataclass(frozen=True)
class ScenarioResult:
    """One scenario's cases (SI): launch conditions, the D sweep's collisions (None: none) and the flights."""

    launch: dict[str, np.ndarray]
    sweep: dict[str, np.ndarray] | None
    flight: FlightResult
    e_x: float
    air_density: float


def run_scenario(
    scenario: dict, balls: dict[str, Ball], bats: dict[str, Bat], air: dict, e_x: float | None = None
) -> ScenarioResult:
    """Run one scenario, one entry per case (the stage :mod:`ballbat.stages.implications` writes it).

    Parameters
    ----------
    scenario : the scenario's config block (paper units).
    balls, bats : property tables (SI records).
    air : atmospheric conditions (``temperature_F``, ``elevation_ft``, ``humidity_pct``,
        ``pressure_inHg``).
    e_x : overrides ``scenario['e_x']`` (e.g. the pooled e_x fitted on a dataset).
    """
    if scenario["ball"] not in balls:
        raise ValueError(f"scenario ball {scenario['ball']!r} is not in the ball table ({', '.join(balls)})")
    if "sweep" in scenario and scenario["bat"] not in bats:
        raise ValueError(f"scenario bat {scenario['bat']!r} is not in the bat table ({', '.join(bats)})")
    ball = balls[scenario["ball"]]
    rho = density_from_conditions(air)
    flight = scenario["flight"]
    e_x_used = float(scenario["e_x"] if e_x is None else e_x)
    if "sweep" in scenario:
        launch, data = _sweep(scenario, ball, bats[scenario["bat"]], e_x_used)
    else:
        launch, data = launch_conditions(scenario["launch"]), None
    res = fly(
        launch["exit_speed"],
        launch["launch_angle"],
        launch["spray_angle"],
        launch["backspin"],
        launch["sidespin"],
        ball_mass=ball.m,
        ball_radius=ball.r,
        rho=rho,
        wind=np.asarray(flight["wind_mph"], dtype=float) * MPH,
        tau=flight["tau_s"],
        method=flight["method"],
        n_points=int(flight["n_points"]),
    )
    return ScenarioResult(launch, data, res, e_x_used, rho)


def _sweep(scenario: dict, ball: Ball, bat: Bat, e_x: float) -> tuple[dict, dict]:
    """Collide the pitched ball with the bat over the scenario's sweep of D (Sec. V.B).

    Returns the launch conditions (SI, one per D) and the sweep's own arrays (D, psi, the
    friction the impacts need and whether it exceeds mu).
    """
    sw = scenario["sweep"]
    D = np.linspace(sw["D_in"]["start"], sw["D_in"]["stop"], int(sw["D_in"]["num"])) * INCH
    col = pitched_ball_collision(
        D,
        v_pitch=sw["pitch_mph"] * MPH,
        pitch_descent=sw["pitch_descent_deg"] * DEGREE,
        pitch_spin=-sw["pitch_backspin_rpm"] * RPM,  # a pitch's backspin is topspin for the batted ball
        v_bat=sw["bat_mph"] * MPH,
        attack_angle=sw["attack_deg"] * DEGREE,
        e_x=e_x,
        e_y=scenario["e_y"],
        ball=ball,
        bat=bat,
        mu=scenario["mu"],
    )
    n = D.size
    launch = {
        "exit_speed": col.exit_speed,
        "launch_angle": col.launch_angle,
        "spray_angle": np.full(n, scenario["flight"]["spray_deg"] * DEGREE),
        "backspin": col.backspin,
        "sidespin": np.zeros(n),
    }
    data = {"D": D, "psi": col.psi, "friction_ratio": col.friction_ratio, "exceeds_mu": col.exceeds_mu.astype(np.int8)}
    return launch, data


def comparison_rows(ds: xr.Dataset) -> list[dict]:
    """Rows of ``results/implications/paper_comparison.csv`` for a D sweep (paper units).

    carry_max (ft) and D_at_carry_max (in), to set against the paper's "400-ft home run at
    intermediate D"; D_at_exit_speed_max (in) against "exit speed peaks ... D ~ 0";
    exit_speed_max (mph); backspin_at_D0 (rpm, negative: topspin at D = 0). Published
    values: ``ballbat.published.PUBLISHED_IMPLICATIONS``. Only balls launched forward
    (launch angle below 90 deg) count for carry_max.
    """
    carry = ds["carry"].values
    forward = ds["launch_angle"].values < np.pi / 2  # a ball going backwards is no home run
    i = int(np.argmax(np.where(forward, carry, -np.inf)))
    j = int(np.argmax(ds["exit_speed"].values))
    k = int(np.argmin(np.abs(ds["D"].values)))
    ball, bat = ds.attrs["ball"], ds.attrs["bat"]
    row = {"ball": ball, "bat": bat}
    return [
        {**row, "quantity": "carry_max", "value": carry[i] / FOOT, "unit": "ft"},
        {**row, "quantity": "D_at_carry_max", "value": ds["D"].values[i] / INCH, "unit": "in"},
        {**row, "quantity": "D_at_exit_speed_max", "value": ds["D"].values[j] / INCH, "unit": "in"},
        {**row, "quantity": "exit_speed_max", "value": ds["exit_speed"].values[j] / MPH, "unit": "mph"},
        {**row, "quantity": "backspin_at_D0", "value": ds["backspin"].values[k] / RPM, "unit": "rpm"},
    ]


def pooled_e_x(fit_path: str | os.PathLike[str], ball: str) -> float:
    """Return the pooled e_x of ``ball`` fitted on a dataset (its ``fit_ex.nc``)."""
    from .pipeline.ncio import read_dataset

    fit = read_dataset(fit_path, require=("e_x_pooled",))
    if ball not in fit["ball"].values:
        raise ValueError(f"{fit_path}: no pooled e_x for ball {ball!r} (balls: {', '.join(map(str, fit.ball.values))})")
    value = float(fit["e_x_pooled"].sel(ball=ball))
    if value != value:
        raise ValueError(f"{fit_path}: the pooled e_x of ball {ball!r} is NaN (fit failed)")
    return value
