"""The impacts table: what every source stage (simulate, ingest, reduce) writes and every later stage reads.

Declared once here. One row per impact (dimension ``impact``), in SI: the four measured quantities
(:data:`QUANTITIES`), their standard uncertainties (``*_err``), the coordinates ``impact``, ``ball`` and
``bat`` (:data:`IMPACT_COORDS`), and, for a synthetic experiment, the truth (``truth_*``, :func:`truth_var`).
Each source stage adds its own variables beside these (ingest: the file's ids and exclusions; reduce: the
fits' diagnostics).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from ..pipeline.products import Var

#: The measured quantities of an impact (SI): name -> (units, what).
QUANTITIES = {
    "v_bat": ("m s-1", "bat speed at the impact point"),
    "v_ball": ("m s-1", "exit speed of the ball"),
    "theta": ("rad", "angle of the batted ball from the bat's direction of travel"),
    "omega": ("rad s-1", "spin of the batted ball (positive: backspin, Fig. 2)"),
}

#: The measurements and their standard uncertainties, in the order of the files.
IMPACTS: dict[str, Var] = {}
for _k, (_units, _what) in QUANTITIES.items():
    IMPACTS[_k] = Var(("impact",), _units, f"measured {_what}", {"ballbat_role": "measurement"})
    IMPACTS[f"{_k}_err"] = Var(
        ("impact",), _units, f"standard uncertainty of measured {_what}", {"ballbat_role": "uncertainty"}
    )

#: The coordinates of an impacts file.
IMPACT_COORDS = {
    "impact": Var(("impact",), "1", "impact number"),
    "ball": Var(("impact",), None, "ball type (key of the ball table)"),
    "bat": Var(("impact",), None, "bat (key of the bat table)"),
}

#: The truth of a synthetic impact (``truth_<name>``): name -> (units, what). The first block is
#: what the synthetic experiment draws; the second what the rendering of camera tracks adds.
TRUTH = {
    **{k: (u, w) for k, (u, w) in QUANTITIES.items()},
    "psi": ("rad", "impact angle psi between bat velocity and normal"),
    "e_x": ("1", "tangential coefficient of restitution e_x"),
    "e_y": ("1", "normal coefficient of restitution e_y"),
    "swing_plane": ("rad", "swing-plane angle (rendering)"),
    "launch_angle": ("rad", "launch angle to the horizontal (rendering)"),
    "contact_time": ("s", "contact time (rendering)"),
    "bat_slowdown": ("1", "fraction of the bat's angular speed lost in the collision (rendering)"),
    "spin_axis_tilt": ("rad", "tilt of the spin axis from the line of sight (rendering)"),
    "dot_a_radius": ("m", "distance of dot_a from the spin axis (rendering)"),
    "dot_b_radius": ("m", "distance of dot_b from the spin axis (rendering)"),
}

#: The truth a synthetic experiment draws (simulate.nc), in its order.
SIMULATED_TRUTH = ("v_bat", "v_ball", "theta", "omega", "psi", "e_x", "e_y")


def truth_var(name: str) -> Var:
    """Return the declaration of the truth variable ``name`` (``truth_<quantity>``; unknown: dimensionless)."""
    base = name[len("truth_") :]
    units, what = TRUTH.get(base, ("1", base))
    return Var(("impact",), units, f"true {what}", {"ballbat_role": "truth"})


def measured(name: str, suffix: str, **attrs: Any) -> Var:
    """Return the declaration of ``IMPACTS[name]`` with ``suffix`` added to its long name and ``attrs`` put first."""
    var = IMPACTS[name]
    return replace(var, long_name=var.long_name + suffix, attrs={**attrs, **var.attrs})


def impact_coords(ball: np.ndarray, bat: np.ndarray) -> dict[str, tuple]:
    """Return the coordinates of :data:`IMPACT_COORDS` as xarray takes them, impacts numbered from 0.

    ``impact`` carries ``long_name`` before ``units`` (the order simulate.nc and ingest.nc have always had).
    """
    n = len(ball)
    imp = IMPACT_COORDS["impact"]
    return {
        "impact": ("impact", np.arange(n, dtype=np.int64), {"long_name": imp.long_name, "units": imp.units}),
        "ball": ("impact", np.asarray(ball), IMPACT_COORDS["ball"].attributes()),
        "bat": ("impact", np.asarray(bat), IMPACT_COORDS["bat"].attributes()),
    }
