"""The two workflow stages of the raw-track chain, for the thin scripts of workflow/rules/tracks.smk."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from ..properties import load_balls, load_bats
from .checks import Verdict, cross_check
from .data import Tracks
from .io import cameras_from_config, load_tracks, tracks_dataset
from .reduce import FLAG_VAR, ReduceOptions, Reduction, reduce_tracks, reduction_dataset
from .render import render_tracks, settings_from_config

if TYPE_CHECKING:
    import os

#: Truth of a synthetic experiment that rendered tracks carry to the reduced file.
SIMULATED_TRUTH = ("v_bat", "v_ball", "theta", "omega", "psi", "e_x", "e_y")


def render_in_memory(simulated: xr.Dataset, balls: dict, render_cfg: dict) -> Tracks:
    """Render both cameras' tracks of a synthetic experiment, in memory (the workflow and the studies).

    Parameters
    ----------
    simulated : xarray.Dataset
        The synthetic experiment, with its ``truth_*`` variables.
    balls : dict
        Ball table (radii).
    render_cfg : dict
        The dataset's ``render`` config block.

    Returns
    -------
    Tracks
    """
    truth = {k: simulated[f"truth_{k}"].values for k in SIMULATED_TRUTH if f"truth_{k}" in simulated}
    r = np.array([balls[b].r for b in simulated["ball"].values.astype(str)])
    return render_tracks(
        truth,
        r,
        settings_from_config(render_cfg),
        simulated["impact"].values.astype(str),
        simulated["ball"].values,
        simulated["bat"].values,
    )


def render_stage(simulated: xr.Dataset, balls_path: str | os.PathLike[str], render_cfg: dict) -> xr.Dataset:
    """Render both cameras' tracks of a synthetic experiment (``simulate.nc``); return ``tracks.nc``.

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
    return tracks_dataset(render_in_memory(simulated, load_balls(balls_path), render_cfg))


def reduce_options(cfg: dict) -> ReduceOptions:
    """Return the reduction's options of a validated ``tracks`` or ``render`` block (``min_frames``, filled)."""
    mf = cfg["min_frames"]
    return ReduceOptions(
        min_tip_frames=int(mf["tip"]),
        min_flight_frames=int(mf["flight"]),
        min_spin_frames=int(mf["spin"]),
    )


def reduce_in_memory(
    tracks: Tracks, cfg: dict, balls: dict, bats: dict, where: str, systematics: bool = False
) -> tuple[Reduction, Verdict]:
    """Reduce and cross-check tracks already read (the reduce rule, the checker and the studies).

    Parameters
    ----------
    tracks : Tracks
        Both cameras' tracks and the impact table.
    cfg : dict
        ``cameras`` and ``rig`` (and optional ``min_frames``) as in the config.
    balls, bats : dict
        Property tables.
    where : str
        Config key of ``cfg``, for messages.
    systematics : bool
        Also reduce the tracks again at +-1 sigma of each stated calibration uncertainty
        (:func:`ballbat.systematics.reduce_shifts`; the reduce rule, not the replicate studies).

    Returns
    -------
    (Reduction, Verdict)

    Raises
    ------
    ballbat.properties.InputError
        A setting wrong or a cross-check that stops the dataset (:func:`.checks.cross_check`).
    """
    cameras, rig = cameras_from_config(cfg, where)
    red = reduce_tracks(tracks, cameras, rig, reduce_options(cfg))
    verdict = cross_check(red, balls, bats, where)
    if systematics:
        from ..systematics import reduce_shifts

        red.shifts = reduce_shifts(tracks, cameras, rig, reduce_options(cfg), red)
    return red, verdict


def reduce_checked(
    tracks_path: str | os.PathLike[str],
    impacts_path: str | os.PathLike[str] | None,
    cfg: dict,
    balls_path: str | os.PathLike[str],
    bats_path: str | os.PathLike[str],
    where: str,
) -> tuple[Reduction, Verdict]:
    """Read, check, reduce and cross-check a dataset's tracks (the reduce rule and ``ballbat check --kind tracks``).

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
    (Reduction, Verdict)

    Raises
    ------
    ballbat.properties.InputError
        Every problem of the files and settings, or a cross-check that stops the dataset
        (:func:`.checks.cross_check`).
    """
    balls, bats = load_balls(balls_path), load_bats(bats_path)
    cameras_from_config(cfg, where)  # the settings are checked before the files are read
    tracks = load_tracks(tracks_path, impacts_path, balls, bats)
    return reduce_in_memory(tracks, cfg, balls, bats, where, systematics=True)


def reduce_stage(
    tracks_path: str | os.PathLike[str],
    impacts_path: str | os.PathLike[str] | None,
    cfg: dict,
    balls_path: str | os.PathLike[str],
    bats_path: str | os.PathLike[str],
    where: str,
) -> xr.Dataset:
    """Read, check, reduce and cross-check a dataset's tracks; return ``reduce.nc`` (:func:`reduce_checked`).

    The cross-checks' figures are the attribute ``reduce_checks`` (one per line), their
    warnings ``reduce_warnings``.
    """
    red, verdict = reduce_checked(tracks_path, impacts_path, cfg, balls_path, bats_path, where)
    ds = reduction_dataset(red)
    ds.attrs["source_file"] = str(tracks_path)
    ds.attrs["reduce_checks"] = "\n".join(verdict.lines)
    ds.attrs["reduce_warnings"] = "\n".join(verdict.warnings)
    return ds


def excluded_listing(ds: xr.Dataset) -> list[str]:
    """One line per excluded impact: id and why."""
    bad = np.flatnonzero(ds[FLAG_VAR].values != 0)
    return [f"impact {ds['impact_id'].values[i]}: {ds[f'{FLAG_VAR}_reason'].values[i]}" for i in bad]
