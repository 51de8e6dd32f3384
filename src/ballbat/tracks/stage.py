"""Read, check, reduce and cross-check a dataset's tracks in one call (``ballbat check --kind tracks``).

The reduce rule takes the same steps through the stage :mod:`ballbat.stages.reduce`, which also
writes the results file ``reduce.nc`` (its options: :func:`reduce_options`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..properties import load_balls, load_bats
from .checks import Verdict, cross_check
from .io import cameras_from_config, load_tracks
from .reduce import ReduceOptions, Reduction, reduce_tracks

if TYPE_CHECKING:
    import os

    from .data import Camera, Rig, Tracks


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
    return reduce_and_check(tracks, cameras, rig, reduce_options(cfg), balls, bats, where, systematics)


def reduce_and_check(
    tracks: Tracks,
    cameras: dict[str, Camera],
    rig: Rig,
    options: ReduceOptions,
    balls: dict,
    bats: dict,
    where: str,
    systematics: bool,
) -> tuple[Reduction, Verdict]:
    """Reduce and cross-check tracks with settings already built (:func:`reduce_in_memory`, the reduce stage).

    ``systematics``: also reduce the tracks again at +-1 sigma of each stated calibration
    uncertainty (:func:`ballbat.systematics.reduce_shifts`, kept as ``Reduction.shifts``).
    """
    red = reduce_tracks(tracks, cameras, rig, options)
    verdict = cross_check(red, balls, bats, where)
    if systematics:
        from ..systematics import reduce_shifts

        red.shifts = reduce_shifts(tracks, cameras, rig, options, red)
    return red, verdict


def reduce_checked(
    tracks_path: str | os.PathLike[str],
    impacts_path: str | os.PathLike[str] | None,
    cfg: dict,
    balls_path: str | os.PathLike[str],
    bats_path: str | os.PathLike[str],
    where: str,
) -> tuple[Reduction, Verdict]:
    """Read and check a dataset's tracks files, then :func:`reduce_in_memory` (``ballbat check --kind tracks``).

    ``tracks_path`` and ``impacts_path`` are the tracks (CSV or NetCDF) and impacts (None: the
    tracks NetCDF's own table), ``balls_path`` and ``bats_path`` the property tables (every ball
    and bat must be in them); ``cfg`` and ``where`` as for :func:`reduce_in_memory`. Every
    problem of the files and settings is raised at once (:class:`~ballbat.properties.InputError`).
    """
    balls, bats = load_balls(balls_path), load_bats(bats_path)
    cameras_from_config(cfg, where)  # the settings are checked before the files are read
    tracks = load_tracks(tracks_path, impacts_path, balls, bats)
    return reduce_in_memory(tracks, cfg, balls, bats, where)  # a check needs no calibration reruns
