"""Per-impact analysis: normalisation to the reference bat speed and psi reconstruction (Secs. II-III).

Each function takes the impacts as an :class:`xarray.Dataset` (dimension ``impact``, SI
units) and returns the new per-impact arrays by name; the stages :mod:`ballbat.stages.normalize`
and :mod:`ballbat.stages.reconstruct` declare them and add them to the file.
Nothing is dropped: impacts that cannot be reconstructed keep their row, with ``flag`` > 0
and the reason in ``flag_reason``.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .kinematics import (
    FLAG_TEXT,
    ImpactFlag,
    normalize_to_bat_speed,
    offset_from_psi,
    reconstruct_psi,
    spin_bracket,
    tan_psi_minus_theta,
    vtf_bracket,
    vtf_ordinate,
)
from .properties import Ball, Bat, recoil_factors


def impact_labels(ds: xr.Dataset) -> np.ndarray:
    """Return each impact's label for messages: ``impact <id> (<where in the source file>)``.

    The id is ``impact_id`` (a measured file's own, or a tracked impact's); an impact without
    one (a synthetic experiment in the direct-noise mode) is numbered from 1 (``impact #31``),
    never by its 0-based index. The place in the file (``row 32``: its CSV line, the header
    being line 1) is added where the impacts came from a file (``source_row``).
    """
    n = ds.sizes["impact"]
    ids = ds["impact_id"].values.astype(str) if "impact_id" in ds else np.array([f"#{i + 1}" for i in range(n)])
    rows = ds["source_row"].values.astype(str) if "source_row" in ds else np.full(n, "")
    out = [
        f"impact at {r}" if i == r else f"impact {i}" + (f" ({r})" if r else "") for i, r in zip(ids, rows, strict=True)
    ]
    return np.array(out, dtype=str)


def normalize_values(ds: xr.Dataset, v_ref: float) -> dict[str, np.ndarray]:
    """Return spin and exit speed normalised to the reference bat speed (Sec. II, Figs. 3-4).

    ``omega_norm`` and ``v_ball_norm`` (and their propagated standard uncertainties
    when the measurements carry ``*_err``): value * v_ref / v_bat, v_ref in m s-1.
    """
    values = {}
    for k in ("omega", "v_ball"):
        val = normalize_to_bat_speed(ds[k].values, ds["v_bat"].values, v_ref)
        values[f"{k}_norm"] = val
        if f"{k}_err" in ds and "v_bat_err" in ds:
            values[f"{k}_norm_err"] = np.hypot(
                ds[f"{k}_err"].values * v_ref / ds["v_bat"].values,
                np.abs(val) * ds["v_bat_err"].values / ds["v_bat"].values,
            )
    return values


def reconstruct_values(ds: xr.Dataset, balls: dict[str, Ball], bats: dict[str, Bat]) -> dict[str, np.ndarray]:
    """Reconstruct psi and the Sec. III quantities of every impact.

    Returns the ball and bat properties used (r, alpha, R, r_x, r_y), psi (Eq. angmom), the
    flag and its reason, D (Eq. D), v_n and v_t, and the bracket terms of Eq. omega
    (``spin_bracket``) and Eq. vtf (``vtf_x``, with the left side ``vtf_y``), plus
    tan(psi - theta) of Eq. ratio.
    """
    ball_ids = ds["ball"].values.astype(str)
    bat_ids = ds["bat"].values.astype(str)
    missing = sorted(
        {f"ball {b!r}" for b in ball_ids if b not in balls} | {f"bat {t!r}" for t in bat_ids if t not in bats}
    )
    if missing:
        raise ValueError("reconstruct: not in the property tables: " + ", ".join(missing))
    values = property_values(ball_ids, bat_ids, balls, bats)
    psi, flag, geometry = _geometry(ds, values["r"], values["alpha"], values["r_x"], values["R_bat"])
    reasons = np.array([FLAG_TEXT[ImpactFlag(int(f))] for f in flag], dtype=object).astype(str)
    if "ingest_flag" in ds:  # measured data: keep the ingest's exclusions out of every fit
        excluded = ds["ingest_flag"].values != 0
        flag = np.where(excluded, ImpactFlag.EXCLUDED_AT_INGEST, flag).astype(np.int8)
        ingest_reasons = ds["ingest_flag_reason"].values.astype(str)
        reasons = np.where(excluded, np.char.add("excluded at ingest: ", ingest_reasons), reasons)
    values.update({"psi": psi, "flag": flag, "flag_reason": reasons})
    values.update(geometry)
    return values


def property_values(
    ball_ids: np.ndarray, bat_ids: np.ndarray, balls: dict[str, Ball], bats: dict[str, Bat]
) -> dict[str, np.ndarray]:
    """Each impact's ball and bat properties: r, m, alpha, R_bat and the recoil factors r_x, r_y (Eqs. rx, ry)."""
    pairs = {(b, t): recoil_factors(balls[b], bats[t]) for b, t in set(zip(ball_ids, bat_ids, strict=True))}
    return {
        "r": np.array([balls[b].r for b in ball_ids]),
        "m": np.array([balls[b].m for b in ball_ids]),
        "alpha": np.array([balls[b].alpha for b in ball_ids]),
        "R_bat": np.array([bats[t].R for t in bat_ids]),
        "r_x": np.array([pairs[(b, t)][0] for b, t in zip(ball_ids, bat_ids, strict=True)]),
        "r_y": np.array([pairs[(b, t)][1] for b, t in zip(ball_ids, bat_ids, strict=True)]),
    }


def _geometry(ds: xr.Dataset, r, alpha, r_x, R) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    """Return psi (Eq. angmom), its flag, and the derived Sec. III quantities of the measured values of ``ds``."""
    v_bat, v_ball, theta, omega = (ds[k].values for k in ("v_bat", "v_ball", "theta", "omega"))
    psi, flag = reconstruct_psi(v_ball, theta, omega, r, alpha)
    with np.errstate(invalid="ignore"):
        geometry = {
            "D": offset_from_psi(psi, r, R),
            "v_n": v_ball * np.cos(psi - theta),
            "v_t": v_ball * np.sin(psi - theta),
            "v_bat_n": v_bat * np.cos(psi),
            "spin_bracket": spin_bracket(v_bat, psi, r, r_x, alpha),
            "vtf_x": vtf_bracket(psi, r_x),
            "vtf_y": vtf_ordinate(v_ball, theta, omega, v_bat, psi, r),
            "tan_psi": np.tan(psi),
            "tan_psi_minus_theta": tan_psi_minus_theta(v_ball, omega, r, alpha),
        }
    return psi, flag, geometry


def reconstruct_again_values(rec: xr.Dataset) -> dict[str, np.ndarray]:
    """Recompute psi and the derived Sec. III quantities of a reconstructed dataset whose measured values changed.

    The ball and bat properties are those ``reconstruct`` stored per impact (r, alpha, r_x,
    R_bat), so no property table is needed; the flags are kept as they are (the same impacts
    are used). For the calibration systematics (:mod:`ballbat.systematics`).
    """
    values = {k: rec[k].values for k in ("r", "alpha", "r_x", "R_bat")}
    psi, _, geometry = _geometry(rec, values["r"], values["alpha"], values["r_x"], values["R_bat"])
    return {"psi": psi, **geometry}
