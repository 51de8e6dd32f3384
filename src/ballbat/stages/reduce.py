"""Stage reduce: ``results/{dataset}/reduce.nc``, the impacts reduced from raw camera tracks (Sec. II).

:func:`reduction_table` declares the file (the impacts table of :mod:`.impacts` with the fits'
diagnostics); :func:`run` reduces the tracks (:func:`ballbat.tracks.reduce.reduce_tracks`),
cross-checks the result (:func:`ballbat.tracks.verdict.cross_check`) and assembles the file.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..pipeline.products import Var, build_dataset, flag_attrs
from ..systematics import SHIFT_UNITS, SIDES
from ..tracks.io import cameras_from_config
from ..tracks.reduce import CONTACT_SHIFTED, FLAG_VAR, ReduceFlag, ReduceOptions, Reduction, reduce_tracks
from ..tracks.verdict import Verdict, cross_check
from .impacts import IMPACT_COORDS, QUANTITIES, measured, truth_var
from .systematics import add_shifts

if TYPE_CHECKING:
    from collections.abc import Sequence

    import xarray as xr

    from ..properties import Ball, Bat
    from ..tracks.data import Camera, Rig, TrackBlocks, Tracks


@dataclass(frozen=True)
class ReduceSettings:
    """Settings of the reduce stage.

    Attributes
    ----------
    cameras : dict of str to Camera
        ``swing`` and ``spin`` camera settings.
    rig : Rig
        Pivot-to-tip and pivot-to-impact distances.
    options : ReduceOptions
        Fewest frames per fit.
    where : str
        Config key of the settings' block, for messages.
    systematics : bool
        Also reduce the tracks again at +-1 sigma of each stated calibration uncertainty
        (:func:`ballbat.systematics.reduce_shifts`): the workflow does, a replicate of a study
        does where it draws its calibration.
    cross_check : bool
        Cross-check the settings against the reduced tracks (:func:`ballbat.tracks.verdict.cross_check`).
        Always, but in a study's truth job: its truth needs no check, and the checks' tight errors
        over some 70000 impacts flag a small bias of the tip's arc at 5 px as a wrong rig.
    population_shifts : bool
        Solve the contact again at +-1 standard error of each ball type's population mean
        (:func:`ballbat.tracks.reduce.contact_shifts`). Always, but in a study's truth job: its
        truth is a value, and the shifts enter only the uncertainties.
    """

    cameras: dict[str, Camera]
    rig: Rig
    options: ReduceOptions
    where: str
    systematics: bool
    cross_check: bool
    population_shifts: bool

    @classmethod
    def from_config(cls, block: dict, where: str, *, systematics: bool) -> ReduceSettings:
        """Return the settings of a dataset's ``tracks`` or ``render`` block (``cameras``, ``rig``, ``min_frames``).

        ``where`` is the block's config key. Raises :class:`~ballbat.properties.InputError`
        naming every wrong camera or rig setting.
        """
        cameras, rig = cameras_from_config(block, where)
        return cls(
            cameras=cameras,
            rig=rig,
            options=reduce_options(block),
            where=where,
            systematics=systematics,
            cross_check=True,
            population_shifts=True,
        )


def reduce_options(cfg: dict) -> ReduceOptions:
    """Return the reduction's options of a validated ``tracks`` or ``render`` block (``min_frames``, filled)."""
    mf = cfg["min_frames"]
    return ReduceOptions(
        min_tip_frames=int(mf["tip"]),
        min_flight_frames=int(mf["flight"]),
        min_spin_frames=int(mf["spin"]),
    )


def reduce_and_check(
    settings: ReduceSettings, tracks: Tracks | TrackBlocks, balls: dict[str, Ball], bats: dict[str, Bat]
) -> tuple[Reduction, Verdict | None]:
    """Reduce tracks and cross-check them (the verdict None where ``settings.cross_check`` is off).

    Where ``settings.systematics`` asks, the tracks are reduced again at +-1 sigma of each stated
    calibration uncertainty (:func:`ballbat.systematics.reduce_shifts`, kept as ``Reduction.shifts``).
    """
    red = reduce_tracks(tracks, settings.cameras, settings.rig, settings.options, settings.population_shifts)
    verdict = cross_check(red, balls, bats, settings.where) if settings.cross_check else None
    if settings.systematics:
        from ..systematics import reduce_shifts

        red.shifts = reduce_shifts(tracks, settings.cameras, settings.rig, settings.options, red)
    return red, verdict


def _frame(frame0: np.ndarray, col):
    return np.where(col >= 0, frame0 + col, -1).astype(np.int64)


def _v(units, long_name, role=None, **extra):
    attrs = dict(extra)
    if role:
        attrs["ballbat_role"] = role
    return Var(("impact",), units, long_name, attrs)


def _measured_table() -> dict[str, Var]:
    """Return the measured values of reduce.nc with their uncertainties, angles and contact times."""
    table: dict[str, Var] = {}
    for k in QUANTITIES:
        anc = f"{k}_err {k}_err_scale" if k in ("v_bat", "v_ball") else f"{k}_err"
        table[k] = measured(k, " (from the camera tracks)", ancillary_variables=anc)
        table[f"{k}_err"] = measured(f"{k}_err", " (from the fit)")
    for k in ("v_bat", "v_ball"):
        table[f"{k}_err_scale"] = _v(
            "m s-1",
            f"systematic uncertainty of measured {QUANTITIES[k][1]} from the swing camera's pixel scale "
            "(common to every impact)",
            "systematic",
        )
    table["swing_plane_angle"] = _v("rad", "angle of the bat's velocity above the horizontal before impact")
    table["swing_plane_angle_err"] = _v("rad", "standard uncertainty of the swing-plane angle")
    table["launch_angle"] = _v("rad", "angle of the batted ball above the horizontal (in the swing direction)")
    table["launch_angle_err"] = _v("rad", "standard uncertainty of the launch angle")
    table["contact_time"] = _v("s", "duration of the ball-bat contact, fitted from the ball's departure from rest")
    table["contact_time_err"] = _v("s", "standard uncertainty of the fitted contact time")
    table["contact_start_time"] = _v(
        "s", "fitted time the contact began (end of the bat-tip fit), from the swing camera's frame origin"
    )
    table["contact_start_time_err"] = _v("s", "standard uncertainty of the fitted contact start")
    return table


def _motion_table() -> dict[str, Var]:
    """Return the frames and fitted motions of reduce.nc: impact, separation, flights, the tip's fit."""
    table: dict[str, Var] = {}
    for cam in ("swing", "spin"):
        table[f"impact_frame_{cam}"] = _v("1", f"first {cam}-camera frame with the ball moving (-1: none)")
        table[f"separation_frame_{cam}"] = _v("1", f"first {cam}-camera frame of the ball's free flight (-1: none)")
        table[f"n_frames_flight_{cam}"] = _v("1", f"{cam}-camera frames in the ball's free-flight fit")
        table[f"flight_rms_{cam}"] = _v(
            "m", f"rms distance of the ball's tracked centre from its fitted free flight, {cam} camera"
        )
    table["n_frames_tip"] = _v("1", "swing-camera frames before impact in the bat-tip fit")
    table["tip_rms"] = _v("m", "rms residual of the bat-tip fit along the swing")
    table["bat_alignment_time"] = _v(
        "s", "fitted time the bat is aligned with the swing camera, from its frame origin (tau)"
    )
    for cam in ("swing", "spin"):
        table[f"frame0_{cam}"] = _v("1", f"{cam}-camera frame number of time 0 of the fitted motions")
        table[f"flight_t_ref_{cam}"] = _v("s", f"separation time in the {cam} camera (reference of its flight fit)")
        for c, what in (("x", "along the swing"), ("y", "upward")):
            table[f"flight_{c}0_{cam}"] = _v("m", f"fitted ball position {what} at separation, {cam} camera")
            table[f"flight_v{c}_{cam}"] = _v("m s-1", f"fitted ball velocity {what} at separation, {cam} camera")
    return table


def _spin_table() -> dict[str, Var]:
    """Return the tip's and the spin's fitted parameters, the glitches removed and the flag."""
    table: dict[str, Var] = {}
    table["tip_offset"] = _v("m", "fitted tip position along the swing at the alignment time (from the tip centroid)")
    table["tip_centroid_x"] = _v("m", "centroid of the fitted tip positions along the image x (swing-positive)")
    table["tip_centroid_y"] = _v("m", "centroid of the fitted tip positions, upward")
    table["bat_angular_speed"] = _v("rad s-1", "fitted angular speed of the bat about the pivot before impact")
    for p in ("dot_a", "dot_b"):
        table[f"{p}_phase"] = _v("rad", f"fitted angle of {p} about the ball's centre at time 0 (unwrapped)")
    table["n_frames_spin"] = _v("1", "spin-camera dot frames in the spin fit (both dots)")
    table["dot_angle_rms"] = _v("rad", "rms residual of the dot angles about the fitted spin")
    for p in ("dot_a", "dot_b"):
        table[f"{p}_radius"] = _v("m", f"mean distance of {p} from the ball's centre after separation")
        table[f"{p}_radius_sd"] = _v("m", f"standard deviation of the distance of {p} from the ball's centre")
    for cam in ("swing", "spin"):
        table[f"n_outliers_{cam}"] = _v(
            "1", f"single-frame tracking glitches removed from the {cam} camera's tracks before the fits"
        )
    table[FLAG_VAR] = Var(
        ("impact",), "1", "exclusion flag set when the camera tracks were reduced (0: usable)", flag_attrs(ReduceFlag)
    )
    table[f"{FLAG_VAR}_reason"] = Var(("impact",), None, "why the impact is excluded (ok if it is not)")
    return table


def _contact_table(shifts: bool) -> dict[str, Var]:
    """Return the contact population's variables: its mean and error, and (``shifts``) each impact's shifts."""
    table = {
        "contact_population_mean": _v(
            "s", "mean contact time of the impact's ball type (the fitted population of contact times)"
        ),
        "contact_population_mean_err": _v(
            "s",
            "standard error of that mean (from the pooled fit; 0: the frames say nothing of the contacts and the "
            "uniform distribution is kept)",
        ),
    }
    if not shifts:
        return table
    for k in CONTACT_SHIFTED:
        base = k.removesuffix("_err")
        what = f"the standard uncertainty of {base}" if k.endswith("_err") else base
        table[f"contact_shift_{k}"] = Var(
            ("shift", "impact"),
            SHIFT_UNITS[base],
            f"change of {what} when the reduction is solved again with the ball type's contact population mean at "
            "+1 and -1 standard error (a statistical error shared by the ball type's impacts)",
            {"ballbat_role": "statistical"},
        )
    return table


def reduction_table(truth_names: Sequence[str] = (), contact_shifts: bool = True) -> dict[str, Var]:
    """Return the declared variables of ``reduce.nc`` (``contact_shifts``: with the contact population's shifts)."""
    table = {**_measured_table(), **_motion_table(), **_spin_table(), **_contact_table(contact_shifts)}
    for k in truth_names:
        table[k] = truth_var(k)
    return table


def reduction_dataset(red: Reduction) -> xr.Dataset:
    """Return the reduced impacts as the chain reads them (dimension ``impact``), with fit diagnostics.

    Parameters
    ----------
    red : Reduction

    Returns
    -------
    xarray.Dataset
    """
    tr = red.tracks
    values = dict(red.values)
    for cam in ("swing", "spin"):
        frame0 = tr.frame0(cam)
        values[f"impact_frame_{cam}"] = _frame(frame0, red.onset[cam].onset)
        values[f"separation_frame_{cam}"] = _frame(frame0, red.flight[cam].separation)
        values[f"n_frames_flight_{cam}"] = red.flight[cam].n
        values[f"flight_rms_{cam}"] = red.flight[cam].sigma * np.sqrt(
            2 * np.maximum(red.flight[cam].n - 2, 0) / np.maximum(red.flight[cam].n, 1)
        )
    for cam in ("swing", "spin"):
        fl = red.flight[cam]
        values[f"frame0_{cam}"] = tr.frame0(cam).astype(np.int64)
        values[f"flight_t_ref_{cam}"] = fl.t_ref
        values[f"flight_x0_{cam}"], values[f"flight_y0_{cam}"] = fl.x0, fl.y0
        values[f"flight_vx_{cam}"], values[f"flight_vy_{cam}"] = fl.vx, fl.vy
    values["tip_offset"] = red.swing.a
    values["tip_centroid_x"], values["tip_centroid_y"] = red.swing.cx, red.swing.cy
    values["bat_angular_speed"] = red.swing.omega
    for p in ("dot_a", "dot_b"):
        values[f"{p}_phase"] = red.spin.intercept[p]
    values["n_frames_tip"] = red.swing.n
    values["tip_rms"] = red.swing.rms
    values["bat_alignment_time"] = red.swing.tau
    if red.contact is not None:
        values["contact_start_time"] = red.contact.t_start
        values["contact_start_time_err"] = red.contact.t_start_err
    values["n_frames_spin"] = red.spin.n
    values["dot_angle_rms"] = red.spin.rms
    for p in ("dot_a", "dot_b"):
        values[f"{p}_radius"] = red.spin.radius[p]
        values[f"{p}_radius_sd"] = red.spin.radius_sd[p]
    values[FLAG_VAR] = red.flag
    values[f"{FLAG_VAR}_reason"] = red.reason
    for cam in ("swing", "spin"):
        values[f"n_outliers_{cam}"] = red.n_outliers[cam]
    truth = {k: v for k, v in tr.truth.items() if k.startswith("truth_")}
    values.update(truth)
    n = tr.n
    coords = {
        "impact": (IMPACT_COORDS["impact"], np.arange(n, dtype=np.int64)),
        "impact_id": (Var(("impact",), None, "impact id given in the tracks"), tr.impact_id.astype(str)),
        "ball": (IMPACT_COORDS["ball"], tr.ball.astype(str)),
        "bat": (IMPACT_COORDS["bat"], tr.bat.astype(str)),
    }
    attrs = {"n_impacts": int(n), "n_excluded": int((red.flag != 0).sum())}
    attrs["n_outliers"] = int(sum(int(v.sum()) for v in red.n_outliers.values()))
    for cam, c in red.cameras.items():
        attrs[f"{cam}_fps"] = float(c.fps)
        attrs[f"{cam}_m_per_px"] = float(c.m_per_px)
        attrs[f"{cam}_mirror"] = int(bool(c.mirror))
        attrs[f"{cam}_m_per_px_rel_err"] = float(c.m_per_px_err)
        attrs[f"{cam}_exposure_s"] = float(c.exposure_s)
    attrs["pivot_to_tip_m"] = float(red.rig.pivot_to_tip)
    attrs["pivot_to_impact_m"] = float(red.rig.pivot_to_impact)
    _contact_values(red, values, coords)
    table = reduction_table(sorted(truth), red.contact_shift is not None)
    return add_shifts(build_dataset(table, values, coords, attrs), red.shifts)


def _contact_values(red: Reduction, values: dict, coords: dict) -> None:
    """Put the contact population's variables (:func:`_contact_table`) in ``values``, its ``shift`` in ``coords``."""
    nan = np.full(red.tracks.n, np.nan)
    values["contact_population_mean"], values["contact_population_mean_err"] = red.contact_mean or (nan, nan)
    for k, sides in (red.contact_shift or {}).items():
        values[f"contact_shift_{k}"] = np.stack(sides)
    if red.contact_shift is not None:
        what = "calibration or estimate shifted by this many standard uncertainties"
        coords["shift"] = (("shift",), np.array(SIDES, dtype=np.int8), {"units": "1", "long_name": what})


def run(
    settings: ReduceSettings,
    tracks: Tracks | TrackBlocks,
    balls: dict[str, Ball],
    bats: dict[str, Bat],
    source_file: str | None = None,
) -> xr.Dataset:
    """Reduce and cross-check a dataset's tracks (read and checked: :func:`ballbat.tracks.io.load_tracks`).

    Returns ``reduce.nc``: the impacts and the fits' diagnostics. The cross-checks' figures are
    the attribute ``reduce_checks`` (one per line), their warnings ``reduce_warnings``;
    ``source_file`` (the tracks file read) the attribute of that name.

    Raises
    ------
    ballbat.properties.InputError
        A cross-check that stops the dataset (:func:`ballbat.tracks.verdict.cross_check`).
    """
    red, verdict = reduce_and_check(settings, tracks, balls, bats)
    ds = reduction_dataset(red)
    if source_file is not None:
        ds.attrs["source_file"] = str(source_file)
    if verdict is not None:
        ds.attrs["reduce_checks"] = "\n".join(verdict.lines)
        ds.attrs["reduce_warnings"] = "\n".join(verdict.warnings)
    return ds


def excluded_listing(ds: xr.Dataset) -> list[str]:
    """One line per excluded impact: id and why."""
    bad = np.flatnonzero(ds[FLAG_VAR].values != 0)
    return [f"impact {ds['impact_id'].values[i]}: {ds[f'{FLAG_VAR}_reason'].values[i]}" for i in bad]
