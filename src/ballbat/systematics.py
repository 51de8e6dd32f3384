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
2. **Every reported quantity** (:func:`fit_systematics` for fit_ex.nc, :func:`stronge_systematics`
   for stronge.nc): the measured values shifted to +1 sigma and to -1 sigma of each source
   (:func:`shifted_impacts`) go through normalize and reconstruct again and through the same
   estimator; half the difference of the two estimates is that source's systematic
   (``<q>_syst_by_source``), the sources combined in quadrature ``<q>_syst`` (independent
   calibrations), and statistical and systematic in quadrature ``<q>_err_total``. A source whose
   uncertainty is 0 costs nothing and gives 0.

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
    from .fitting import Sec4
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
_UNITS = {"v_bat": "m s-1", "v_ball": "m s-1", "theta": "rad", "omega": "rad s-1"}

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


def _coords() -> dict[str, tuple]:
    return {
        "systematic": (
            ("systematic",),
            np.array(list(SOURCES), dtype=str),
            {"long_name": "calibration source of a systematic: " + "; ".join(f"{k}: {v}" for k, v in SOURCES.items())},
        ),
    }


def _rel_sigma_var(rel: np.ndarray) -> tuple:
    return (
        ("systematic",),
        np.asarray(rel, dtype=float),
        {"units": "1", "long_name": "relative standard uncertainty of each calibration source (0: none stated)"},
    )


def add_shifts(ds: xr.Dataset, shifts: Shifts | None) -> xr.Dataset:
    """Return reduce.nc's dataset with the shifts of :func:`reduce_shifts` (unchanged for None)."""
    if shifts is None:
        return ds
    out = ds.assign_coords(
        **_coords(),
        shift=(
            ("shift",),
            np.array(SIDES, dtype=np.int8),
            {"units": "1", "long_name": "calibration shifted by this many standard uncertainties"},
        ),
    )
    out["systematic_rel_sigma"] = _rel_sigma_var(shifts.rel_sigma)
    for k in SHIFTED:
        base = k.removesuffix("_err")
        what = f"the standard uncertainty of {base}" if k.endswith("_err") else base
        out[f"{k}_shift"] = (
            ("systematic", "shift", "impact"),
            shifts.shift[k],
            {
                "units": _UNITS[base],
                "long_name": f"change of {what} when the tracks are reduced with one calibration shifted "
                "(systematic; 0 where the source has no uncertainty)",
                "ballbat_role": "systematic",
            },
        )
    return out


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


def _combine(by_source: np.ndarray) -> np.ndarray:
    return np.sqrt(np.sum(by_source**2, axis=0))


def _systematic_vars(ds: xr.Dataset, by_source: dict[str, np.ndarray], what: str, rel: np.ndarray) -> xr.Dataset:
    """``ds`` with ``<q>_syst_by_source``, ``<q>_syst`` and (where ``<q>_err`` is) ``<q>_err_total``."""
    out = ds.assign_coords(**_coords()) if "systematic" not in ds.coords else ds
    out["systematic_rel_sigma"] = _rel_sigma_var(rel)
    for q, per in by_source.items():
        dims, attrs = ds[q].dims, ds[q].attrs
        units = {"units": attrs["units"]} if "units" in attrs else {}
        syst = _combine(per)
        out[f"{q}_syst_by_source"] = (
            ("systematic", *dims),
            per,
            {
                **units,
                "long_name": f"systematic error of {q} from each calibration source: half the change of {q} "
                f"between that calibration at +1 and at -1 standard uncertainty ({what})",
                "ballbat_role": "systematic",
            },
        )
        out[f"{q}_syst"] = (
            dims,
            syst,
            {
                **units,
                "long_name": f"systematic error of {q}: every calibration source in quadrature "
                "(shared by every impact; not in the standard error)",
                "ballbat_role": "systematic",
            },
        )
        if f"{q}_err" in ds:
            out[f"{q}_err_total"] = (
                dims,
                np.hypot(ds[f"{q}_err"].values, syst),
                {**units, "long_name": f"standard error and systematic error of {q} in quadrature"},
            )
    return out


# ---------------------------------------------------------------------------------------
# fit_ex.nc
@dataclass
class FitSystematics:
    """Per source (first axis), the systematic of each quantity of :data:`FIT_QUANTITIES`."""

    by_source: dict[str, np.ndarray]
    rel_sigma: np.ndarray


def fit_systematics(rec: xr.Dataset, res: Sec4) -> FitSystematics:
    """Every quantity of fit_ex.nc at +-1 sigma of each source; half the differences.

    Parameters
    ----------
    rec : xarray.Dataset
        Reconstructed impacts carrying the shifts (:func:`has_shifts`).
    res : Sec4
        The nominal fits (labels, mu_k of the example).

    Returns
    -------
    FitSystematics
    """
    from .fitting import analyze_impacts
    from .stages.fit_ex import results_dataset  # the same table of quantities as fit_ex.nc

    nominal = results_dataset(res)
    rel = rec["systematic_rel_sigma"].values
    out = {q: np.zeros((len(SOURCES), *nominal[q].shape)) for q in FIT_QUANTITIES}
    for q in FIT_QUANTITIES:  # no value, no systematic
        out[q][:, ~np.isfinite(nominal[q].values)] = np.nan
    for i in range(len(SOURCES)):
        if rel[i] == 0:
            continue
        fits = [
            results_dataset(analyze_impacts(shifted_impacts(rec, i, j), res.mu_k_example, systematic=False))
            for j in range(len(SIDES))
        ]
        for q in FIT_QUANTITIES:
            out[q][i] = 0.5 * np.abs(fits[0][q].values - fits[1][q].values)
    return FitSystematics(out, rel)


def scale_entries(fs: FitSystematics) -> dict[str, np.ndarray]:
    """``e_x_err_scale`` and ``e_x_pooled_err_scale``: the swing camera's pixel-scale systematic of e_x."""
    i = list(SOURCES).index("swing_m_per_px")
    return {"e_x_err_scale": fs.by_source["e_x"][i], "e_x_pooled_err_scale": fs.by_source["e_x_pooled"][i]}


def add_fit_systematics(ds: xr.Dataset, fs: FitSystematics | None) -> xr.Dataset:
    """fit_ex.nc's dataset with the systematics of :func:`fit_systematics` (unchanged for None)."""
    if fs is None:
        return ds
    what = "the tracks reduced again, then normalize, reconstruct and the fit"
    return _systematic_vars(ds, fs.by_source, what, fs.rel_sigma)


# ---------------------------------------------------------------------------------------
# stronge.nc
def stronge_systematics(
    ds: xr.Dataset, rec: xr.Dataset, *, e_y: float, mu: float, vary_e_y: bool, vary_mu: bool
) -> xr.Dataset:
    """stronge.nc's dataset with the systematics of eta^2 (and of e_y and mu when fitted).

    Each ball of ``ds`` is fitted again (:func:`ballbat.stronge.analysis.fit_ball`, no interval)
    on its usable impacts at +-1 sigma of each source. ``ds`` is returned unchanged when
    ``rec`` carries no shifts (no camera tracks).
    """
    if not has_shifts(rec):
        return ds
    from .stronge.analysis import fit_ball, vtf_data

    names = ["eta2"] + (["e_y"] if vary_e_y else []) + (["mu"] if vary_mu else [])
    balls = ds["ball"].values.astype(str)
    rel = rec["systematic_rel_sigma"].values
    out = {q: np.zeros((len(SOURCES), balls.size)) for q in names}
    for q in names:
        out[q][:, ~np.isfinite(ds[q].values)] = np.nan
    usable = rec["flag"].values == 0
    ball_of = rec["ball"].values.astype(str)
    for i in range(len(SOURCES)):
        if rel[i] == 0:
            continue
        fits = []
        for j in range(len(SIDES)):
            sh = shifted_impacts(rec, i, j)
            fits.append(
                [
                    fit_ball(
                        vtf_data(sh, usable & (ball_of == b)),
                        e_y=e_y,
                        mu=mu,
                        vary_e_y=vary_e_y,
                        vary_mu=vary_mu,
                        interval=False,
                    )
                    for b in balls
                ]
            )
        for q in names:
            plus, minus = (np.array([getattr(f, q) for f in side]) for side in fits)
            out[q][i] = 0.5 * np.abs(plus - minus)
    what = "the tracks reduced again, then normalize, reconstruct and the eta^2 fit"
    return _systematic_vars(ds, out, what, rel)


# ---------------------------------------------------------------------------------------
# readers of the results (tables, summary, front page)
def systematic_var(ds: xr.Dataset, var: str) -> str | None:
    """Return the name of the combined systematic of ``var`` in ``ds``, or None when it has none.

    ``<var>_syst`` (every calibration source), else ``<var>_err_scale`` (the pixel-scale one
    of e_x, in files made before the other sources were propagated).
    """
    for name in (f"{var}_syst", f"{var}_err_scale"):
        if name in ds:
            return name
    return None


#: What the combined systematic holds, in the tables' notes.
SYSTEMATIC_NOTE = (
    "every stated calibration uncertainty (pixel scale and frame rate of each camera, the rig's lengths), "
    "each propagated by reducing the tracks again at ± one standard uncertainty, combined in quadrature; "
    "shared by every impact, apart from the standard error"
)
