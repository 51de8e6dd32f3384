"""A synthetic experiment that mirrors the paper's (Sec. II and Tables I-II).

A swinging bat hits a ball at rest. For each impact a true bat speed and impact angle psi
are drawn, the outgoing ball follows from the Sec. III forward model
(:func:`ballbat.kinematics.ball_at_rest_collision`) with the configured true e_x and e_y,
and Gaussian measurement noise is added to bat speed, exit speed, angle and spin. The
truth is kept beside the measurements (variables ``truth_*``) so recovery can be checked.
Seeded: the same settings give the same numbers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kinematics import ball_at_rest_collision
from .properties import Ball, Bat, recoil_factors
from .units import DEGREE, MPH, RPM


@dataclass(frozen=True)
class SyntheticSettings:
    """Settings of a synthetic experiment, in the paper's units (as in the config).

    Every field is required: the defaults live in the config schema alone (the workflow
    passes the validated config; :func:`ballbat.config_checks.load_config` gives it to
    other callers).

    ``impacts[ball][bat]`` is the number of impacts; ``e_x[ball][bat]`` the true tangential
    COR (default: Table II); ``e_y[ball]`` the true normal COR; ``psi_deg[ball]`` the range
    of psi drawn uniformly (default [0, psi_max of Table I]); ``noise`` the standard
    deviations of the measurement noise; ``e_x_scatter`` an intrinsic impact-to-impact
    standard deviation of the true e_x.
    """

    impacts: dict
    e_x: dict
    e_y: dict
    seed: int
    v_bat_mph: tuple
    psi_deg: dict
    noise: dict
    e_x_scatter: float


@dataclass(frozen=True)
class Experiment:
    """A drawn synthetic experiment, one entry per impact (SI).

    ``measured``, ``sd`` and ``truth`` map a quantity (``v_bat``, ``v_ball``, ``theta``,
    ``omega``; the truth also ``psi``, ``e_x``, ``e_y``) to its per-impact values.
    """

    ball: np.ndarray
    bat: np.ndarray
    measured: dict[str, np.ndarray]
    sd: dict[str, np.ndarray]
    truth: dict[str, np.ndarray]
    seed: int


def draw_experiment(settings: SyntheticSettings, balls: dict[str, Ball], bats: dict[str, Bat]) -> Experiment:
    """Draw a synthetic experiment (the stage :mod:`ballbat.stages.simulate` writes it as simulate.nc).

    Raises ``KeyError``-free ``ValueError`` naming any ball or bat missing from the
    property tables or from the e_x/e_y settings.
    """
    rng = np.random.default_rng(settings.seed)
    problems = []
    rows = []
    for ball_id, per_bat in settings.impacts.items():
        if ball_id not in balls:
            problems.append(f"impacts: ball {ball_id!r} is not in the ball table ({', '.join(balls)})")
            continue
        if ball_id not in settings.e_y:
            problems.append(f"e_y: no value for ball {ball_id!r}")
        for bat_id, n in per_bat.items():
            if bat_id not in bats:
                problems.append(f"impacts.{ball_id}: bat {bat_id!r} is not in the bat table ({', '.join(bats)})")
            if bat_id not in settings.e_x.get(ball_id, {}):
                problems.append(f"e_x.{ball_id}: no value for bat {bat_id!r}")
            rows += [(ball_id, bat_id)] * int(n)
    if problems:
        raise ValueError("synthetic experiment settings: " + "; ".join(problems))
    n = len(rows)
    ball_ids = np.array([b for b, _ in rows], dtype=object)
    bat_ids = np.array([t for _, t in rows], dtype=object)

    r = np.array([balls[b].r for b in ball_ids])
    alpha = np.array([balls[b].alpha for b in ball_ids])
    rx_ry = np.array([recoil_factors(balls[b], bats[t]) for b, t in rows]).reshape(n, 2)
    r_x, r_y = rx_ry[:, 0], rx_ry[:, 1]

    psi_lo = np.empty(n)
    psi_hi = np.empty(n)
    for b in set(ball_ids):
        sel = ball_ids == b
        lo, hi = settings.psi_deg.get(b, (0.0, balls[b].psi_max / DEGREE))
        if not np.isfinite(hi):
            raise ValueError(f"psi_deg: no range for ball {b!r} and no psi_max in the ball table")
        psi_lo[sel], psi_hi[sel] = lo * DEGREE, hi * DEGREE

    v_bat = rng.uniform(settings.v_bat_mph[0] * MPH, settings.v_bat_mph[1] * MPH, n)
    psi = rng.uniform(psi_lo, psi_hi)
    e_x = np.array([settings.e_x[b][t] for b, t in rows], dtype=float)
    e_x = e_x + settings.e_x_scatter * rng.standard_normal(n)
    e_y = np.array([settings.e_y[b] for b in ball_ids], dtype=float)
    out = ball_at_rest_collision(v_bat, psi, e_x, e_y, r, r_x, r_y, alpha)

    noise = settings.noise
    sd = {
        "v_bat": noise["v_bat_mph"] * MPH,
        "v_ball": noise["v_ball_mph"] * MPH,
        "theta": noise["theta_deg"] * DEGREE,
        "omega": noise["omega_rpm"] * RPM,
    }
    true = {"v_bat": v_bat, "v_ball": out.v_ball, "theta": out.theta, "omega": out.omega}
    meas = {k: true[k] + sd[k] * rng.standard_normal(n) for k in ("v_bat", "v_ball", "theta", "omega")}

    return Experiment(
        ball=ball_ids.astype(str),
        bat=bat_ids.astype(str),
        measured=meas,
        sd={k: np.full(n, sd[k]) for k in sd},
        truth={**true, "psi": psi, "e_x": e_x, "e_y": e_y},
        seed=int(settings.seed),
    )
