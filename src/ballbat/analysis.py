"""Per-impact analysis stages: normalisation to 77 mph and psi reconstruction (Secs. II-III).

Each function takes the impacts as an :class:`xarray.Dataset` (dimension ``impact``, SI
units) and returns a copy with new variables, every one with units and a long name.
Nothing is dropped: impacts that cannot be reconstructed keep their row, with ``flag`` > 0
and the reason in ``flag_reason``.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .kinematics import (
    RECONSTRUCT_FLAGS,
    V_BAT_REF,
    normalize_to_bat_speed,
    offset_from_psi,
    reconstruct_psi,
    spin_bracket,
    vtf_bracket,
    vtf_ordinate,
)
from .properties import Ball, Bat, recoil_factors

#: Values of ``flag`` in reconstruct.nc: those of Eq. angmom, and impacts excluded when a
#: measured file was read (``ingest_flag`` > 0; the reason names the ingest reason).
FLAGS = {**RECONSTRUCT_FLAGS, 4: "excluded when the measured file was read (see ingest_flag_reason)"}
FLAG_INGEST = 4


def _attrs(units, long_name, **extra):
    return {"units": units, "long_name": long_name, **extra}


def normalize(ds: xr.Dataset, v_ref: float = V_BAT_REF) -> xr.Dataset:
    """Add spin and exit speed normalised to bat speed ``v_ref`` (Sec. II, Figs. 3-4).

    Adds ``omega_norm`` and ``v_ball_norm`` (and their propagated standard uncertainties
    when the measurements carry ``*_err``): value * v_ref / v_bat.
    """
    out = ds.copy()
    for k, units, what in (("omega", "rad s-1", "spin"), ("v_ball", "m s-1", "exit speed")):
        val = normalize_to_bat_speed(ds[k].values, ds["v_bat"].values, v_ref)
        out[f"{k}_norm"] = ("impact", val, _attrs(units, f"{what} normalised to the reference bat speed"))
        if f"{k}_err" in ds and "v_bat_err" in ds:
            err = np.hypot(
                ds[f"{k}_err"].values * v_ref / ds["v_bat"].values,
                np.abs(val) * ds["v_bat_err"].values / ds["v_bat"].values,
            )
            out[f"{k}_norm_err"] = ("impact", err, _attrs(units, f"standard uncertainty of normalised {what}"))
    out.attrs["v_ref"] = float(v_ref)
    out.attrs["v_ref_units"] = "m s-1"
    return out


def reconstruct(ds: xr.Dataset, balls: dict[str, Ball], bats: dict[str, Bat]) -> xr.Dataset:
    """Reconstruct psi and the Sec. III quantities of every impact.

    Adds the ball and bat properties used (r, alpha, R, r_x, r_y), psi (Eq. angmom), the
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
    pairs = {(b, t): recoil_factors(balls[b], bats[t]) for b, t in set(zip(ball_ids, bat_ids, strict=True))}
    r = np.array([balls[b].r for b in ball_ids])
    m = np.array([balls[b].m for b in ball_ids])
    alpha = np.array([balls[b].alpha for b in ball_ids])
    R = np.array([bats[t].R for t in bat_ids])
    r_x = np.array([pairs[(b, t)][0] for b, t in zip(ball_ids, bat_ids, strict=True)])
    r_y = np.array([pairs[(b, t)][1] for b, t in zip(ball_ids, bat_ids, strict=True)])

    v_bat, v_ball, theta, omega = (ds[k].values for k in ("v_bat", "v_ball", "theta", "omega"))
    psi, flag = reconstruct_psi(v_ball, theta, omega, r, alpha)
    reasons = np.array([RECONSTRUCT_FLAGS[int(f)] for f in flag], dtype=object).astype(str)
    if "ingest_flag" in ds:  # measured data: keep the ingest's exclusions out of every fit
        excluded = ds["ingest_flag"].values != 0
        flag = np.where(excluded, FLAG_INGEST, flag).astype(np.int8)
        ingest_reasons = ds["ingest_flag_reason"].values.astype(str)
        reasons = np.where(excluded, np.char.add("excluded at ingest: ", ingest_reasons), reasons)

    out = ds.copy()
    out["r"] = ("impact", r, _attrs("m", "ball radius"))
    out["m"] = ("impact", m, _attrs("kg", "ball mass"))
    out["alpha"] = ("impact", alpha, _attrs("1", "ball moment of inertia over m r^2 (Eq. iball)"))
    out["R"] = ("impact", R, _attrs("m", "bat radius at the impact location"))
    out["r_x"] = ("impact", r_x, _attrs("1", "tangential recoil factor r_x (Eq. rx)"))
    out["r_y"] = ("impact", r_y, _attrs("1", "normal recoil factor r_y (Eq. ry)"))
    out["psi"] = ("impact", psi, _attrs("rad", "impact angle psi reconstructed from Eq. angmom"))
    out["flag"] = (
        "impact",
        flag,
        {
            "units": "1",
            "long_name": "reconstruction flag (0: usable)",
            "flag_values": np.array(sorted(FLAGS), dtype=np.int8),
            "flag_meanings": " ".join(f"{k}:{v.replace(' ', '_')}" for k, v in sorted(FLAGS.items())),
        },
    )
    out["flag_reason"] = ("impact", reasons, {"long_name": "why the impact is not used (ok if it is)"})
    with np.errstate(invalid="ignore"):
        out["D"] = ("impact", offset_from_psi(psi, r, R), _attrs("m", "ball-bat offset D (Eq. D)"))
        out["v_n"] = ("impact", v_ball * np.cos(psi - theta), _attrs("m s-1", "normal component of the exit velocity"))
        out["v_t"] = (
            "impact",
            v_ball * np.sin(psi - theta),
            _attrs("m s-1", "tangential component of the exit velocity"),
        )
        out["v_bat_n"] = ("impact", v_bat * np.cos(psi), _attrs("m s-1", "normal component of the bat velocity"))
        out["spin_bracket"] = (
            "impact",
            spin_bracket(v_bat, psi, r, r_x, alpha),
            _attrs("rad s-1", "bracket of Eq. omega: v_bat sin psi / (r (1 + r_x)(1 + alpha))"),
        )
        out["vtf_x"] = ("impact", vtf_bracket(psi, r_x), _attrs("1", "bracket of Eq. vtf: tan psi / (1 + r_x)"))
        out["vtf_y"] = (
            "impact",
            vtf_ordinate(v_ball, theta, omega, v_bat, psi, r),
            _attrs("1", "left side of Eq. vtf: (v_ball,t + r omega) / v_bat,n"),
        )
        out["tan_psi"] = ("impact", np.tan(psi), _attrs("1", "tan psi (Fig. 6 abscissa)"))
        out["tan_psi_minus_theta"] = (
            "impact",
            np.tan(psi - theta),
            _attrs("1", "tan(psi - theta) = v_ball,t / v_ball,n (Eqs. muk, ratio; Fig. 6 ordinate)"),
        )
    return out
