"""Calibration systematics: every stated calibration uncertainty to every reported quantity.

A lab calibrates each camera once (its pixel scale ``m_per_px`` and its frame rate ``fps``)
and measures the rig once (the pivot-to-tip and pivot-to-impact distances). An error in one
of them is shared by every impact, so it does not average out and is no part of the
statistical error. Each stated uncertainty (``m_per_px_err`` and ``fps_err`` of each camera,
relative; ``pivot_to_tip_err_in`` and ``pivot_to_impact_err_in`` of the rig, inches; absent is
0) is a *source* (:data:`SOURCES`), propagated the same way, exactly rather than linearised:

1. **Reduction** (:func:`reduce_shifts`, the reduce rule): the tracks are reduced again with
   that one calibration at +1 sigma and at -1 sigma (a new :class:`~ballbat.tracks.data.Camera`
   or :class:`~ballbat.tracks.data.Rig`, everything else as stated), and each impact keeps the
   shift of every measured quantity the later stages read (v_bat, v_ball, theta, omega and
   their standard uncertainties: ``<name>_shift`` in reduce.nc, dimensions ``systematic``,
   ``shift``, ``impact``; units of the quantity). The impacts' flags are the nominal ones.
2. **Every reported quantity** (:func:`ballbat.stages.fit_ex.fit_systematics` for fit_ex.nc,
   :func:`~ballbat.stages.stronge.stronge_systematics` for stronge.nc): the measured
   values shifted to +1 sigma and to -1 sigma of each source (:func:`shifted_impacts`) go
   through normalize and reconstruct again and through the same estimator; half the
   difference of the two estimates is that source's systematic (``<q>_syst_by_source``), the
   sources combined in quadrature ``<q>_syst`` (independent calibrations), and statistical and
   systematic in quadrature ``<q>_err_total``. A source whose uncertainty is 0 costs nothing
   and gives 0.

The same machinery carries two more kinds of source, each appended to the ``systematic``
dimension only where an uncertainty is stated, so a dataset without any keeps its sources as
they were (docs/model.md, "Property and instrument systematics"):

* **instrument calibrations of a measured impacts file** (:data:`INSTRUMENT_SOURCES`, config
  ``datasets.<name>.calibration``): a speed scale and a spin scale (relative) and an angle
  offset (absolute), each a shift of every impact's measured values (:func:`instrument_shifts`);
* **bat and ball properties** (a ``<column>_err`` in the property tables): one source per
  property and bat (``bat:<bat>:<column>``) or ball (``ball:<ball>:<column>``), the property
  moved by +-1 sigma for every impact of that bat (ball) and the per-impact properties that
  reconstruct stored (``r``, ``m``, ``alpha``, ``R_bat``, ``r_x``, ``r_y``: :data:`PROPERTY_SHIFTED`)
  shifted accordingly (``<name>_shift``, reconstruct.nc; :func:`ballbat.stages.reconstruct.property_shifts`).

``e_x_err_scale`` and ``e_x_pooled_err_scale`` keep their meaning: the systematic of e_x from
the swing camera's pixel scale (now the ``swing_m_per_px`` source, by the exact rerun; it was
a linear rescale of v_bat and v_ball).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from .instruments import INSTRUMENT_SOURCES

if TYPE_CHECKING:
    from .columns import Columns
    from .tracks.data import Camera, Rig, TrackBlocks, Tracks
    from .tracks.reduce import ReduceOptions, Reduction

#: The calibration sources, in the order of the ``systematic`` dimension: name -> what.
SOURCES = {
    "swing_m_per_px": "pixel scale of the swing camera (cameras.swing.m_per_px_err)",
    "spin_m_per_px": "pixel scale of the spin camera (cameras.spin.m_per_px_err)",
    "swing_fps": "frame rate of the swing camera (cameras.swing.fps_err)",
    "spin_fps": "frame rate of the spin camera (cameras.spin.fps_err)",
    "pivot_to_tip": "pivot-to-tip distance of the rig (rig.pivot_to_tip_err_in)",
    "pivot_to_impact": "pivot-to-impact distance of the rig (rig.pivot_to_impact_err_in)",
}
#: The two calibrations of each source, in standard uncertainties (the ``shift`` dimension).
SIDES = (1, -1)
#: The measured quantities (and uncertainties) whose shifts reduce.nc keeps: what later stages read.
SHIFTED = ("v_bat", "v_ball", "theta", "omega", "v_bat_err", "v_ball_err", "theta_err", "omega_err")
SHIFT_UNITS = {"v_bat": "m s-1", "v_ball": "m s-1", "theta": "rad", "omega": "rad s-1"}

#: Per-impact properties that reconstruct stores and a property source shifts (:mod:`ballbat.stages.reconstruct`).
PROPERTY_SHIFTED = ("r", "m", "alpha", "R_bat", "r_x", "r_y")
PROPERTY_UNITS = {"r": "m", "m": "kg", "alpha": "1", "R_bat": "m", "r_x": "1", "r_y": "1"}

#: Quantities of fit_ex.nc that get systematics.
FIT_QUANTITIES = (
    "e_x",
    "e_x_pooled",
    "tan_ratio_slope",
    "spin_theta_slope",
    "spin_theta_slope_intercept",
    "speed_theta_slope",
    "speed_theta_slope_intercept",
    "e_y_implied",
    "mu_k_lower_bound",
    "gross_slip_psi",
    "gross_slip_theta",
    "gross_slip_omega",
)


def relative_sigmas(cameras: dict[str, Camera], rig: Rig) -> np.ndarray:
    """Each source's relative standard uncertainty (order of :data:`SOURCES`)."""
    return np.array(
        [
            cameras["swing"].m_per_px_err,
            cameras["spin"].m_per_px_err,
            cameras["swing"].fps_err,
            cameras["spin"].fps_err,
            rig.pivot_to_tip_err / rig.pivot_to_tip,
            rig.pivot_to_impact_err / rig.pivot_to_impact,
        ],
        dtype=float,
    )


def shifted_settings(cameras: dict[str, Camera], rig: Rig, source: str, factor: float) -> tuple[dict[str, Camera], Rig]:
    """Return the settings with the calibration of ``source`` multiplied by ``factor`` (1 + side x sigma)."""
    cams = dict(cameras)
    if source in ("pivot_to_tip", "pivot_to_impact"):
        return cams, replace(rig, **{source: getattr(rig, source) * factor})
    cam, key = source.split("_", 1)
    cams[cam] = replace(cams[cam], **{key: getattr(cams[cam], key) * factor})
    return cams, rig


@dataclass
class Shifts:
    """Per source, side and impact, the shift of each measured quantity (:data:`SHIFTED`) and the sources' sigmas."""

    rel_sigma: np.ndarray  # (source,)
    shift: dict[str, np.ndarray]  # name -> (source, side, impact)
    names: list[str] | None = None  # the sources (None: the calibration ones, :data:`SOURCES`)


def reduce_shifts(
    tracks: Tracks | TrackBlocks,
    cameras: dict[str, Camera],
    rig: Rig,
    options: ReduceOptions | None,
    nominal: Reduction,
) -> Shifts:
    """Reduce ``tracks`` again at +-1 sigma of each source with a stated uncertainty; return the shifts.

    Parameters
    ----------
    tracks : Tracks or TrackBlocks
        The tracks as read (the reduction removes its glitches itself).
    cameras, rig, options
        The settings of the nominal reduction.
    nominal : Reduction
        The nominal reduction of ``tracks``.

    Returns
    -------
    Shifts
        Zero for a source without uncertainty (not reduced again). theta's shift is wrapped to
        (-pi, pi].
    """
    from .tracks.reduce import reduce_tracks, value_change

    rel = relative_sigmas(cameras, rig)
    n = tracks.n
    out = {k: np.zeros((len(SOURCES), len(SIDES), n)) for k in SHIFTED}
    for i, source in enumerate(SOURCES):
        if rel[i] == 0:
            continue
        for j, side in enumerate(SIDES):
            cams, rg = shifted_settings(cameras, rig, source, 1.0 + side * rel[i])
            red = reduce_tracks(tracks, cams, rg, options, population_shifts=False, like=nominal)
            with np.errstate(invalid="ignore"):
                for k in SHIFTED:
                    out[k][i, j] = value_change(k, red.values[k], nominal.values[k])
    return Shifts(rel, out)


def has_shifts(ds: xr.Dataset) -> bool:
    """Return whether ``ds`` carries the calibration shifts of :func:`add_shifts`."""
    return "systematic_rel_sigma" in ds and all(f"{k}_shift" in ds for k in SHIFTED)


def shifted_impacts(rec: xr.Dataset, source: int, side: int) -> Columns:
    """Reconstructed impacts with the measured values of one calibration shift, normalised and reconstructed again.

    Parameters
    ----------
    rec : xarray.Dataset
        Reconstructed impacts carrying the shifts (:func:`has_shifts`).
    source, side : int
        Indices along ``systematic`` and ``shift``.

    Returns
    -------
    Columns
        The same impacts and flags, without the ``truth_*`` variables (the estimators' truth
        is no systematic), read as :class:`~ballbat.columns.Columns` (plain arrays: no Dataset is
        built, which cost a replicate study with the calibration drawn a third of its time). The
        per-impact properties move too where the dataset has property sources
        (:data:`PROPERTY_SHIFTED`).
    """
    from .columns import Columns

    v = rec.variables
    moved = {
        k: xr.Variable(v[k].dims, v[k].values + v[f"{k}_shift"].values[source, side], v[k].attrs)
        for k in (*SHIFTED, *PROPERTY_SHIFTED)
        if f"{k}_shift" in v  # the properties: only where a property source is stated
    }
    return _renormalized(Columns(Columns(rec).dropped(lambda k: k.startswith("truth_")), moved), rec)


def _renormalized(moved: Columns, rec: xr.Dataset) -> Columns:
    """Return ``moved`` through the normalize and reconstruct stages' steps again, at ``rec``'s reference speed."""
    from .analysis import normalize_values, reconstruct_again_values
    from .columns import Columns

    def variables(values: dict) -> dict:
        return {k: xr.Variable(("impact",), v) for k, v in values.items()}

    out = Columns(moved, variables(normalize_values(moved, float(rec.attrs["v_ref"]))))
    return Columns(out, variables(reconstruct_again_values(out)))


#: reduce.nc's variables of the contact population's shifts: ``contact_shift_<name>`` (shift, impact)
#: for the names of :data:`ballbat.tracks.reduce.CONTACT_SHIFTED` (the others do not move).
CONTACT_SHIFT = "contact_shift_"


def has_contact_shifts(ds: xr.Dataset) -> bool:
    """Return whether ``ds`` carries the contact population's shifts (reduce.nc of camera tracks)."""
    return any(f"{CONTACT_SHIFT}{k}" in ds for k in SHIFTED)


def contact_shifted_impacts(rec: xr.Dataset, side: int) -> Columns:
    """Reconstructed impacts with every ball type's contact population at one side (index along ``shift``).

    As :func:`shifted_impacts` for a calibration source, read as :class:`~ballbat.columns.Columns`
    (plain arrays, no Dataset built: the studies run this twice a replicate): the measured values
    moved by their ``contact_shift_<name>``, normalised and reconstructed again, without
    ``truth_*`` and the shifts themselves.
    """
    from .columns import Columns

    cols = Columns(rec).dropped(lambda k: k.startswith("truth_") or k.startswith(CONTACT_SHIFT))
    moved = {
        k: xr.Variable(("impact",), cols[k].values + rec[f"{CONTACT_SHIFT}{k}"].values[side])
        for k in SHIFTED
        if f"{CONTACT_SHIFT}{k}" in rec
    }
    return _renormalized(Columns(cols, moved), rec)


@dataclass
class FitSystematics:
    """Per source (first axis), the systematic of each quantity of :data:`FIT_QUANTITIES`."""

    by_source: dict[str, np.ndarray]
    rel_sigma: np.ndarray
    #: The same with its sign: half of (the estimate at +1 sigma) - (the estimate at -1 sigma), so that
    #: ``by_source == abs(signed)``; a quantity's first-order change when source k is off by z_k sigma
    #: is sum_k z_k signed[k] (:func:`ballbat.studies.replicates.run_replicate`).
    signed: dict[str, np.ndarray]
    #: The sources, in the order of the first axis (the dataset's ``systematic`` coordinate), and its long name.
    names: list[str] | None = None
    long_name: str | None = None


def source_names(ds: xr.Dataset) -> list[str]:
    """Return the systematic sources of a dataset carrying shifts (its ``systematic`` coordinate), in order."""
    return [str(v) for v in ds["systematic"].values]


def instrument_shifts(values: dict[str, np.ndarray], calibration: dict[str, float]) -> Shifts | None:
    """Return the shifts of every impact's measured values at +-1 sigma of each stated instrument calibration.

    Parameters
    ----------
    values : dict
        The measured values in SI (v_bat, v_ball, theta, omega; ``*_err`` where given).
    calibration : dict
        Config ``calibration``: ``speed_scale_pct`` and ``spin_scale_pct`` (relative standard
        uncertainties in %: every speed, or every spin, times 1 +- sigma; their standard
        uncertainties scale alike) and ``angle_offset_deg`` (every theta +- sigma). Absent or 0: no source.

    Returns
    -------
    Shifts or None
        Only the stated sources (:attr:`Shifts.names`), None when none is stated; rel_sigma is
        NaN for the angle offset (an absolute uncertainty; its sigma is in the source's long name).
    """
    names, rel, shift = [], [], {k: [] for k in SHIFTED}
    n = len(values["v_bat"])
    for source, (key, _) in INSTRUMENT_SOURCES.items():
        sigma = float(calibration.get(key, 0.0) or 0.0)
        if sigma == 0:
            continue
        scaled = {"speed_scale": ("v_bat", "v_ball"), "spin_scale": ("omega",)}.get(source, ())
        per = {k: np.zeros((len(SIDES), n)) for k in SHIFTED}
        for j, side in enumerate(SIDES):
            for k in scaled:
                per[k][j] = side * sigma / 100.0 * values[k]
                if f"{k}_err" in values:
                    per[f"{k}_err"][j] = side * sigma / 100.0 * values[f"{k}_err"]
            if source == "angle_offset":
                per["theta"][j] = side * np.deg2rad(sigma)
        names.append(source)
        rel.append(math.nan if source == "angle_offset" else sigma / 100.0)
        for k in SHIFTED:
            shift[k].append(per[k])
    if not names:
        return None
    return Shifts(np.array(rel), {k: np.array(v) for k, v in shift.items()}, names)
