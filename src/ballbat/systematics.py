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

``e_x_err_scale`` and ``e_x_pooled_err_scale`` keep their meaning: the systematic of e_x from
the swing camera's pixel scale (now the ``swing_m_per_px`` source, by the exact rerun; it was
a linear rescale of v_bat and v_ball).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

if TYPE_CHECKING:
    from .tracks.data import Camera, Rig, Tracks
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


def reduce_shifts(
    tracks: Tracks, cameras: dict[str, Camera], rig: Rig, options: ReduceOptions | None, nominal: Reduction
) -> Shifts:
    """Reduce ``tracks`` again at +-1 sigma of each source with a stated uncertainty; return the shifts.

    Parameters
    ----------
    tracks : Tracks
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
    from .tracks.reduce import reduce_tracks

    rel = relative_sigmas(cameras, rig)
    n = tracks.n
    out = {k: np.zeros((len(SOURCES), len(SIDES), n)) for k in SHIFTED}
    for i, source in enumerate(SOURCES):
        if rel[i] == 0:
            continue
        for j, side in enumerate(SIDES):
            cams, rg = shifted_settings(cameras, rig, source, 1.0 + side * rel[i])
            red = reduce_tracks(tracks, cams, rg, options)
            with np.errstate(invalid="ignore"):
                for k in SHIFTED:
                    d = red.values[k] - nominal.values[k]
                    out[k][i, j] = np.angle(np.exp(1j * d)) if k == "theta" else d
    return Shifts(rel, out)


def has_shifts(ds: xr.Dataset) -> bool:
    """Return whether ``ds`` carries the calibration shifts of :func:`add_shifts`."""
    return "systematic_rel_sigma" in ds and all(f"{k}_shift" in ds for k in SHIFTED)


def shifted_impacts(rec: xr.Dataset, source: int, side: int) -> xr.Dataset:
    """Reconstructed impacts with the measured values of one calibration shift, normalised and reconstructed again.

    Parameters
    ----------
    rec : xarray.Dataset
        Reconstructed impacts carrying the shifts (:func:`has_shifts`).
    source, side : int
        Indices along ``systematic`` and ``shift``.

    Returns
    -------
    xarray.Dataset
        The same impacts and flags, without the ``truth_*`` variables (the estimators' truth
        is no systematic).
    """
    from .analysis import normalize_values, reconstruct_again_values

    out = rec.drop_vars([k for k in rec.data_vars if k.startswith("truth_")])
    for k in SHIFTED:
        out[k] = (rec[k].dims, rec[k].values + rec[f"{k}_shift"].values[source, side], rec[k].attrs)
    # the normalize and reconstruct stages' steps, at the nominal reference speed and properties
    out = out.assign({k: ("impact", v) for k, v in normalize_values(out, float(rec.attrs["v_ref"])).items()})
    return out.assign({k: ("impact", v) for k, v in reconstruct_again_values(out).items()})


@dataclass
class FitSystematics:
    """Per source (first axis), the systematic of each quantity of :data:`FIT_QUANTITIES`."""

    by_source: dict[str, np.ndarray]
    rel_sigma: np.ndarray
    #: The same with its sign: half of (the estimate at +1 sigma) - (the estimate at -1 sigma), so that
    #: ``by_source == abs(signed)``; a quantity's first-order change when source k is off by z_k sigma
    #: is sum_k z_k signed[k] (:func:`ballbat.studies.run_replicate`).
    signed: dict[str, np.ndarray]
