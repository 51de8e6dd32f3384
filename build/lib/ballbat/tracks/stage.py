"""The two workflow stages of the raw-track chain, for the thin scripts of workflow/rules/tracks.smk."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from ..properties import load_balls, load_bats
from .io import cameras_from_config, load_tracks, tracks_dataset
from .reduce import FLAG_VAR, ReduceOptions, reduce_tracks, reduction_dataset
from .render import render_tracks, settings_from_config

if TYPE_CHECKING:
    import os

#: Truth of a synthetic experiment that rendered tracks carry to the reduced file.
SIMULATED_TRUTH = ("v_bat", "v_ball", "theta", "omega", "psi", "e_x", "e_y")


def render_stage(simulated: xr.Dataset, balls_path: str | os.PathLike[str], render_cfg: dict) -> xr.Dataset:
    """Render both cameras' tracks of a synthetic experiment (``simulate.nc``).

    Parameters
    ----------
    simulated : xarray.Dataset
        The synthetic experiment, with its ``truth_*`` variables.
    balls_path : path-like
        Ball table (radii).
    render_cfg : dict
        The dataset's ``render`` config block.

    Returns
    -------
    xarray.Dataset
        ``tracks.nc``: long rows and the impact table with the truth.
    """
    balls = load_balls(balls_path)
    truth = {k: simulated[f"truth_{k}"].values for k in SIMULATED_TRUTH if f"truth_{k}" in simulated}
    r = np.array([balls[b].r for b in simulated["ball"].values.astype(str)])
    tracks = render_tracks(
        truth,
        r,
        settings_from_config(render_cfg),
        simulated["impact"].values.astype(str),
        simulated["ball"].values,
        simulated["bat"].values,
    )
    return tracks_dataset(tracks)


def reduce_stage(
    tracks_path: str | os.PathLike[str],
    impacts_path: str | os.PathLike[str] | None,
    cfg: dict,
    balls_path: str | os.PathLike[str],
    bats_path: str | os.PathLike[str],
    where: str,
) -> xr.Dataset:
    """Read, check and reduce a dataset's tracks; return ``reduce.nc``.

    Parameters
    ----------
    tracks_path, impacts_path : path-like
        The tracks (CSV or NetCDF) and impacts (None: the tracks NetCDF's own table).
    cfg : dict
        ``cameras`` and ``rig`` (and optional ``min_frames``) as in the config.
    balls_path, bats_path : path-like
        Property tables (every ball and bat must be in them).
    where : str
        Config key of ``cfg``, for messages.

    Returns
    -------
    xarray.Dataset
    """
    cameras, rig = cameras_from_config(cfg, where)
    tracks = load_tracks(tracks_path, impacts_path, load_balls(balls_path), load_bats(bats_path))
    mf = cfg.get("min_frames", {})
    options = ReduceOptions(
        min_tip_frames=int(mf.get("tip", 5)),
        min_flight_frames=int(mf.get("flight", 5)),
        min_spin_frames=int(mf.get("spin", 4)),
    )
    ds = reduction_dataset(reduce_tracks(tracks, cameras, rig, options))
    ds.attrs["source_file"] = str(tracks_path)
    return ds


def excluded_listing(ds: xr.Dataset) -> list[str]:
    """One line per excluded impact: id and why."""
    bad = np.flatnonzero(ds[FLAG_VAR].values != 0)
    return [f"impact {ds['impact_id'].values[i]}: {ds[f'{FLAG_VAR}_reason'].values[i]}" for i in bad]
