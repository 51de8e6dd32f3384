"""Helpers shared by test modules (no test module imports another): small synthetic experiments,
their rendered tracks, and fake study replicates.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ballbat.pipeline.config import checked_block
from ballbat.properties import load_balls, load_bats
from ballbat.stages import simulate
from ballbat.synthetic import SyntheticSettings
from ballbat.tracks.render import render_tracks, settings_from_config
from workflow_helpers import ROOT

#: A small design (impacts per ball and bat) for the stages' tests.
SMALL = {"baseball": {"wood": 8, "metal_rough": 8}, "softball": {"wood": 8}}

BALLS = load_balls(ROOT / "config" / "balls.csv")
BATS = load_bats(ROOT / "config" / "bats.csv")


def render_cfg(**over):
    cfg = {
        "cameras": {
            "swing": {"fps": 3000, "m_per_px": 0.00074, "mirror": False, "tee_px": [540, 480], "pixel_noise_px": 0.5},
            "spin": {
                "fps": 1000,
                "m_per_px": 0.00125,
                "mirror": False,
                "tee_px": [600, 480],
                "pre_impact_frames": 5,
                "pixel_noise_px": 0.5,
            },
        },
        "rig": {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0},
        "seed": 1,
        "tilted_fraction": 0.0,
    }
    for k, v in over.items():
        if k in ("swing", "spin"):
            cfg["cameras"][k] = {**cfg["cameras"][k], **v}
        else:
            cfg[k] = v
    return cfg


def experiment(seed=0, per_bat=8):
    settings = SyntheticSettings(
        impacts={"baseball": {"wood": per_bat, "metal_rough": per_bat}, "softball": {"softball_composite": per_bat}},
        e_x={"baseball": {"wood": 0.464, "metal_rough": 0.356}, "softball": {"softball_composite": 0.128}},
        e_y={"baseball": 0.45, "softball": 0.32},
        seed=seed,
        v_bat_mph=(63.0, 88.0),  # the schema's defaults (SyntheticSettings takes every field)
        psi_deg={},
        e_x_scatter=0.0,
        noise={"v_bat_mph": 0.5, "v_ball_mph": 0.5, "theta_deg": 0.5, "omega_rpm": 75.0},
    )
    return simulate.run(settings, BALLS, BATS)


def render(ds, cfg, truth_over=None):
    s = settings_from_config(checked_block(cfg, "render"))  # the schema's defaults, as the workflow's config has them
    truth = {k: ds[f"truth_{k}"].values.copy() for k in ("v_bat", "v_ball", "theta", "omega", "psi")}
    truth.update(truth_over or {})
    r = np.array([BALLS[b].r for b in ds["ball"].values])
    tr = render_tracks(truth, r, s, ds["impact"].values.astype(str), ds["ball"].values, ds["bat"].values)
    return tr, s


def fake_replicates(n, se, spread, truth=1.0, dof=np.inf, seed=0):
    """Return n replicates of one quantity: estimates truth + N(0, spread) reporting ``se``."""
    rng = np.random.default_rng(seed)
    ds = xr.Dataset(
        {
            "value": (("replicate", "quantity"), truth + spread * rng.standard_normal((n, 1))),
            "uncertainty": (("replicate", "quantity"), np.full((n, 1), se)),
            "truth": (("replicate", "quantity"), np.full((n, 1), truth)),
            "dof": (("replicate", "quantity"), np.full((n, 1), dof)),
            "point": (("replicate",), np.zeros(n, dtype=int)),
        },
        coords={
            "quantity": ["e_x:baseball:wood"],
            "quantity_name": ("quantity", ["e_x"]),
            "ball": ("quantity", ["baseball"]),
            "bat": ("quantity", ["wood"]),
            "units": ("quantity", ["1"]),
        },
        attrs={"sweep_values": np.array([np.nan]), "study_seed": 0, "replicates_per_point": n, "sweep_parameter": ""},
    )
    return ds
