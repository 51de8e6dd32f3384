"""Measured impacts from a user's file: read, check every row, convert to SI.

A measured dataset is a CSV file (or a NetCDF file with the same content) with one row per
impact and the columns of :data:`REQUIRED` in the paper's units (mph, deg, rpm), optional
``impact_id`` and optional per-row standard uncertainties ``<column>_err``. :func:`read_measured`
checks the file whole against the ball and bat tables and returns the impacts in SI; the
stage :mod:`ballbat.stages.ingest` writes them with the variable names of a synthetic
experiment (``v_bat``, ``v_ball``, ``theta``, ``omega`` and ``*_err``), so every later
stage treats both alike.

Two kinds of problems (docs/ingest.md):

* **Stop** (:class:`~ballbat.properties.InputError` listing every problem, each naming the
  file, the row (CSV line number; the header is line 1) and the column): an unreadable
  file, missing, unknown or repeated columns, empty or non-numeric cells, non-finite
  values, non-positive speeds, angles outside (-90, 90) deg, negative uncertainties, a
  ball or bat not in the property tables, duplicate impact ids, a bad property table, and
  a file in which no bat x ball pair has :data:`MIN_FIT_IMPACTS` usable impacts. These
  are mistakes a person must fix; guessing would hide them.
* **Exclude** (the row is kept with ``ingest_flag`` > 0 and ``ingest_flag_reason``):
  well-formed measurements the physics cannot use, i.e. impacts whose psi cannot be
  reconstructed (|alpha r omega / v_ball| > 1, Eq. angmom) or lands at |psi| >= 90 deg.

Warnings (log and the ``ingest_warnings`` attribute) flag what is possible but suspicious:
a bat x ball pair with fewer than :data:`MIN_FIT_IMPACTS` usable impacts (not fitted per
bat), only some of the four uncertainty columns (the fits are then unweighted), and values
that betray a unit mistake (:func:`unit_warnings`).

References
----------
.. [1] J. R. Kensrud, A. M. Nathan and L. V. Smith, "Oblique collisions of baseballs and
   softballs with a bat", Am. J. Phys. 85, 503 (2017), Secs. II-III.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from .kinematics import (
    FLAG_TEXT,
    ImpactFlag,
    angmom_argument,
    reconstruct_psi,
    spin_bracket,
)
from .linefit import MIN_FIT_IMPACTS
from .properties import (
    EXTRA,
    Ball,
    Bat,
    InputError,
    cell_number,
    cell_text,
    check_impact_id,
    header_problems,
    load_balls,
    load_bats,
    read_csv_table,
    recoil_factors,
    table_keys,
)
from .units import DEGREE, MPH, RPM

if TYPE_CHECKING:
    import os

    from numpy.typing import ArrayLike

#: Required columns of an impacts file.
REQUIRED = ("bat", "ball", "v_bat_mph", "v_ball_mph", "theta_deg", "omega_rpm")

#: Measured columns: file column -> (variable in SI, factor to SI); the variables are declared
#: in the impacts table (:data:`ballbat.stages.impacts.IMPACTS`).
MEASURED_COLUMNS = {
    "v_bat_mph": ("v_bat", MPH),
    "v_ball_mph": ("v_ball", MPH),
    "theta_deg": ("theta", DEGREE),
    "omega_rpm": ("omega", RPM),
}

#: Optional columns: an impact's own id and the standard uncertainty of each measurement.
OPTIONAL = ("impact_id", *(f"{c}_err" for c in MEASURED_COLUMNS))


#: Range of e_x (Eq. omega) that real ball-bat impacts can show; used only to spot unit mistakes.
E_X_PLAUSIBLE = (-0.5, 1.0)
#: Least median normal COR e_y the impacts of a bat x ball pair may imply (Eq. vballn: the
#: ball's normal exit speed v_ball cos(psi - theta) = (1 + e_y) / (1 + r_y) v_bat cos psi).
#: Balls on bats have e_y of 0.3-0.6 (the paper: 0.32 and 0.45 for its balls; the maple
#: example's impacts imply 0.42-0.47); with v_bat and v_ball swapped they imply 0.07-0.41,
#: median 0.15, so a median below 0.2 betrays that mistake.
E_Y_MIN = 0.2
#: Fastest bat (at the impact point) and batted ball, mph, that count as measured: swing
#: machines and the fastest swings stay below 100 mph at the impact point and the hardest-hit
#: balls below 125 mph, so faster values point to a unit mistake (km/h read as mph).
SPEED_MAX_MPH = {"v_bat": 110.0, "v_ball": 140.0}
#: Robust outliers: a spin residual (about its group's median) above this many 1.4826 MAD (a
#: normal sigma) of the whole file's residuals. Spin in rad/s (z ~ 12) or of the wrong sign
#: (z ~ 25) in some rows stands far above it.
OUTLIER_Z = 6.0
#: Fewest impacts of a bat x ball group for the robust comparison.
OUTLIER_MIN_GROUP = 6
#: A file with more implausible rows than this fraction is an error: a fit would rest on them.
IMPLAUSIBLE_MAX_FRACTION = 0.5
#: Impacts with |psi| below this are too head-on for an implied e_x (sin psi ~ 0).
PSI_MIN_FOR_E_X = 10.0 * DEGREE
#: A check that fails for more than this fraction of impacts triggers a unit warning ...
UNIT_WARN_FRACTION = 0.5
#: ... and a suspected mistake is named when correcting it leaves at most this fraction.
UNIT_FIX_FRACTION = 0.2
#: A kept row this many robust standard deviations off its group's line is checked for a unit
#: mistake of its own (:func:`row_unit_hints`) ...
UNIT_ROW_Z = 3.0
#: ... and named when a correction brings it within this many (and a third of its distance).
UNIT_ROW_FIT_Z = 1.5
#: Most rows checked one by one for a unit mistake (more: a file-wide mistake, :func:`unit_warnings`).
UNIT_ROW_MAX = 50
#: 1 mph in km/h (exact: 1.609344 km per mile).
KMH_PER_MPH = 1.609344


# ---------------------------------------------------------------------------------------
# Reading: every cell as text, with the label of its row


def _read_netcdf(path: Path) -> tuple[list[str], list[tuple[str, dict]]]:
    try:
        with xr.open_dataset(path) as ds:
            ds = ds.load()
    except (OSError, ValueError) as exc:
        raise InputError([f"{path}: cannot be read as NetCDF ({exc})"]) from None
    dims = sorted({d for v in ds.variables.values() for d in v.dims})
    if len(dims) != 1:
        raise InputError([f"{path}: expected one dimension (impact), found {', '.join(dims) or 'none'}"])
    dim = dims[0]
    header = [str(k) for k, v in ds.variables.items() if v.dims == (dim,) and k != dim]
    problems = []
    for col in MEASURED_COLUMNS:
        expected = col.rsplit("_", 1)[1]
        for name in (col, f"{col}_err"):  # an uncertainty has the unit of its value
            units = ds[name].attrs.get("units") if name in ds else None
            if units is not None and units != expected:
                problems.append(f"{path}: variable {name}: units {units!r}, expected {expected!r}")
    if problems:
        raise InputError(problems)
    cols = {k: ds[k].values for k in header}
    rows = [(f"entry {i + 1}", {k: cell_text(cols[k][i]) for k in header}) for i in range(ds.sizes[dim])]
    return header, rows


def read_impacts_table(path: str | os.PathLike[str]) -> tuple[list[str], list[tuple[str, dict]]]:
    """Header and rows (label, {column: text}) of a CSV or NetCDF impacts file.

    A CSV row's label is its line number (``row 5``; the header is line 1); a NetCDF row's
    is its place along the impact dimension, counted from 1 (``entry 4``).
    """
    path = Path(path)
    if path.suffix.lower() in (".nc", ".nc4", ".netcdf") and path.is_file():
        return _read_netcdf(path)
    return read_csv_table(path, REQUIRED)


# ---------------------------------------------------------------------------------------
# Checks


#: What an empty measured cell says: every impact needs every value.
EMPTY_CELL = "empty (every impact needs a value; delete the row or fill it in)"


def _measured_cells(row: dict, at: str, problems: list[str]) -> dict[str, float]:
    """Return the four measured cells of a row as numbers (file units): speeds > 0, |theta| < 90 deg."""
    vals = {c: cell_number(row.get(c, ""), f"{at}, column {c}", problems, EMPTY_CELL) for c in MEASURED_COLUMNS}
    for c in ("v_bat_mph", "v_ball_mph"):
        if vals[c] <= 0:
            problems.append(f"{at}, column {c}: {row[c]} mph; a speed must be positive")
    if abs(vals["theta_deg"]) >= 90:
        problems.append(
            f"{at}, column theta_deg: {row['theta_deg']} deg is outside the physical range (-90, 90) "
            "(the ball leaves the bat forwards)"
        )
    return vals


def _zero_uncertainty_problems(path, zeros: dict[str, list[str]], n_rows: int) -> list[str]:
    """One problem per uncertainty column with zeros (``zeros``: column -> row labels)."""
    problems = []
    for c, labels in zeros.items():
        if not labels:
            continue
        where = "every row" if len(labels) == n_rows else ", ".join(labels[:5]) + (" ..." if len(labels) > 5 else "")
        problems.append(
            f"{path}: column {c}: zero uncertainty in {where}: a zero standard uncertainty says the measurement is "
            "exact, which none is (the weighted fits would divide by it); give the real uncertainties, or leave "
            "the column out (the fits are then unweighted)"
        )
    return problems


def check_rows(
    path: str | os.PathLike[str], header: list[str], rows: list[dict], balls: dict | None, bats: dict | None
) -> tuple[dict, list[str]]:
    """Check header and cells; return (columns as arrays in the file's units, problems).

    ``balls`` / ``bats`` None (their table was bad) skip the membership checks.
    """
    problems = header_problems(path, header, REQUIRED, OPTIONAL)
    if any(c not in header for c in REQUIRED):
        return {}, problems
    if not rows:
        problems.append(f"{path}: no impacts (only a header)")
        return {}, problems
    errs = [c for c in OPTIONAL if c.endswith("_err") and c in header]
    out: dict = {c: [] for c in ("label", "bat", "ball", "impact_id", *MEASURED_COLUMNS, *errs)}
    seen_ids: dict[str, str] = {}
    seen_rows: dict[tuple, str] = {}
    zeros: dict[str, list[str]] = {c: [] for c in errs}
    for label, row in rows:
        at = f"{path}: {label}"
        if EXTRA in row:
            problems.append(f"{at}: {row[EXTRA]} more cell(s) than the header has columns")
        for key, name in table_keys(row, at, balls, bats, problems).items():
            out[key].append(name)
        for c, val in _measured_cells(row, at, problems).items():
            out[c].append(val)
        for c in errs:
            e = cell_number(row.get(c, ""), f"{at}, column {c}", problems, EMPTY_CELL)
            if e < 0:
                problems.append(f"{at}, column {c}: {row[c]} is negative; an uncertainty must be >= 0")
            elif e == 0:
                zeros[c].append(label)
            out[c].append(e)
        iid = row.get("impact_id", "") if "impact_id" in header else label
        if "impact_id" in header:
            check_impact_id(iid, at, label, seen_ids, problems)
        out["impact_id"].append(iid)
        out["label"].append(label)
        # The same measurement twice (rows pasted twice) would shrink every standard error by
        # sqrt(2): the bat, ball and every measured value and uncertainty, to the digit.
        # (With an impact_id column, a pasted row repeats its id, which is reported above.)
        key = tuple(row.get(c, "").strip() for c in ("bat", "ball", *MEASURED_COLUMNS, *errs))
        if "impact_id" not in header and key in seen_rows:
            problems.append(
                f"{at}: the same measurement as {seen_rows[key]} (bat, ball and every value): "
                "a row pasted twice? Remove one, or give the impacts an impact_id column if these really are "
                "two impacts that measured alike"
            )
        else:
            seen_rows[key] = label
    problems += _zero_uncertainty_problems(path, zeros, len(rows))
    return {k: np.asarray(v) for k, v in out.items()}, problems


def exclusions(
    v_ball: ArrayLike, theta: ArrayLike, omega: ArrayLike, r: ArrayLike, alpha: ArrayLike
) -> tuple[np.ndarray, np.ndarray]:
    """Per impact: ``(ingest_flag, ingest_flag_reason)`` for impacts psi cannot use (SI inputs).

    The flag is that of :func:`ballbat.kinematics.reconstruct_psi` (an
    :class:`~ballbat.kinematics.ImpactFlag`); the reason quotes the offending number.
    """
    _psi, flag = reconstruct_psi(v_ball, theta, omega, r, alpha)
    q = angmom_argument(v_ball, omega, r, alpha)
    with np.errstate(invalid="ignore"):
        psi_clipped = theta + np.arcsin(np.clip(q, -1, 1))
    words = {
        ImpactFlag.PSI_UNDEFINED: lambda qq, p: (
            f"alpha r omega / v_ball = {qq:.3g}: psi cannot be reconstructed (Eq. angmom)"
        ),
        ImpactFlag.BAD_SPEED: lambda qq, p: FLAG_TEXT[ImpactFlag.BAD_SPEED],
        ImpactFlag.BAT_BEHIND_BALL: lambda qq, p: (
            f"reconstructed psi = {np.degrees(p):.1f} deg: the bat cannot reach the ball there"
        ),
    }
    reason = np.array(
        ["ok" if f == 0 else words[ImpactFlag(f)](qq, p) for f, qq, p in zip(flag, q, psi_clipped, strict=True)],
        dtype=object,
    ).astype(str)
    return flag, reason


@dataclass(frozen=True)
class Measured:
    """Impacts in SI: the four measured quantities and the ball's and bat's properties of each.

    ``r`` and ``alpha`` are the ball's (Table I, Eq. iball); ``r_x`` and ``r_y`` the recoil
    factors of its bat (Eqs. rx and ry). The properties may be scalars or per-impact arrays.
    """

    v_bat: ArrayLike
    v_ball: ArrayLike
    theta: ArrayLike
    omega: ArrayLike
    r: ArrayLike
    alpha: ArrayLike
    r_x: ArrayLike
    r_y: ArrayLike

    def take(self, sel: ArrayLike) -> Measured:
        """Return the impacts ``sel`` (an index or boolean mask along the impacts); scalars stay as they are."""
        values = (np.asarray(getattr(self, f.name)) for f in fields(self))
        return Measured(*(a[sel] if a.ndim else a for a in values))


def implausible(m: Measured) -> dict[str, tuple[int, int]]:
    """Physics checks that betray unit mistakes: name -> (failing, checked) impact counts (SI).

    Notes
    -----
    * ``psi``: Eq. angmom has a solution with |psi| < 90 deg.
    * ``ratio_high``: v_ball / v_bat <= 2 / (1 + r_y): with e_y, e_x <= 1, Eqs. vballn and vxf
      bound the exit speed of a ball at rest.
    * ``ratio_low``: v_ball / v_bat >= cos psi / (1 + r_y): the normal component alone
      (Eq. vballn, e_y >= 0).
    * ``e_x``: the e_x each impact implies through Eq. omega lies in :data:`E_X_PLAUSIBLE`
      (impacts with |psi| >= :data:`PSI_MIN_FOR_E_X` only).
    """
    c = _collision_checks(m)
    n = c.psi.size
    return {
        "psi": (int((~c.ok).sum()), n),
        "ratio_high": (int(c.ratio_high.sum()), n),
        "ratio_low": (int(c.ratio_low.sum()), int(c.ok.sum())),
        "e_x": (int(c.e_x_out.sum()), int(c.use_ex.sum())),
    }


@dataclass(frozen=True)
class _Checks:
    """Per impact: reconstructed psi, implied e_x and the collision's bounds (SI)."""

    psi: np.ndarray
    ok: np.ndarray  # psi reconstructed (Eq. angmom)
    ratio: np.ndarray  # v_ball / v_bat
    e_x: np.ndarray  # implied through Eq. omega
    use_ex: np.ndarray  # ok and |psi| >= PSI_MIN_FOR_E_X
    ratio_high: np.ndarray  # v_ball / v_bat > 2 / (1 + r_y)
    ratio_low: np.ndarray  # ok and v_ball / v_bat < cos psi / (1 + r_y)
    e_x_out: np.ndarray  # use_ex and implied e_x outside E_X_PLAUSIBLE
    e_y: np.ndarray  # implied through Eq. vballn


def _collision_checks(m: Measured) -> _Checks:
    """Return the bounds a collision of a ball at rest sets (:func:`implausible`), impact by impact."""
    v_bat, v_ball, theta, omega = (np.asarray(a, dtype=float) for a in (m.v_bat, m.v_ball, m.theta, m.omega))
    r, alpha, r_x, r_y = m.r, m.alpha, m.r_x, m.r_y
    psi, flag = reconstruct_psi(v_ball, theta, omega, r, alpha)
    ok = flag == ImpactFlag.OK
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = v_ball / v_bat
        e_x = omega / spin_bracket(v_bat, psi, r, r_x, alpha) - 1.0
        use_ex = ok & (np.abs(psi) >= PSI_MIN_FOR_E_X)
        e_y = (1.0 + r_y) * ratio * np.cos(psi - theta) / np.cos(psi) - 1.0
        return _Checks(
            e_y=np.broadcast_to(e_y, psi.shape),
            psi=psi,
            ok=ok,
            ratio=ratio,
            e_x=e_x,
            use_ex=use_ex,
            ratio_high=np.broadcast_to(ratio > 2.0 / (1.0 + r_y), psi.shape),
            ratio_low=np.broadcast_to(ok & (ratio < np.cos(psi) / (1.0 + r_y)), psi.shape),
            e_x_out=use_ex & ~((e_x >= E_X_PLAUSIBLE[0]) & (e_x <= E_X_PLAUSIBLE[1])),
        )


def implausible_rows(
    m: Measured, groups: ArrayLike, sigma: dict | None = None, coarse: ArrayLike | None = None
) -> np.ndarray:
    """Return, per impact, why its measurement is implausible ("" when it is not); SI inputs.

    ``sigma`` maps ``v_bat``, ``theta`` and ``omega`` to their stated standard uncertainties
    (SI, per impact) when the file gives them: the group outliers below are then judged
    against each impact's own uncertainty, else against the file's robust spread.

    Row by row, so that a file with a unit mistake in some rows is caught where it is:

    * a speed above :data:`SPEED_MAX_MPH` (km/h read as mph?);
    * v_ball / v_bat above 2 / (1 + r_y) or below cos psi / (1 + r_y): beyond what any collision
      of a ball at rest gives (Eqs. vballn, vxf with 0 <= e_y <= 1, e_x <= 1);
    * the e_x the impact implies through Eq. omega outside :data:`E_X_PLAUSIBLE` (for |psi| >=
      10 deg, where sin psi is not ~ 0): no tangential COR exceeds 1, and ball-bat impacts do
      not reverse the contact point's slip by more than half;
    * its spin an outlier of its bat x ball group (``groups``): the residual of Eq. omega,
      omega - (1 + e_x) x with the group's median (1 + e_x), more than :data:`OUTLIER_Z` robust
      standard deviations from the group's median residual, the spread (1.4826 MAD) taken over
      the file's groups of at least :data:`OUTLIER_MIN_GROUP` impacts (spin in rad/s or of the
      wrong sign in some rows). A group of fewer than :data:`OUTLIER_MIN_GROUP` impacts is
      judged against its ``coarse`` group (the ball's impacts on every bat) when that has enough:
      bats differ in e_x by a tenth, a row in km/h or rad/s by a factor of 1.6 or 10.

    Impacts psi cannot reconstruct are left to :func:`exclusions` ("" here), but for an exit
    speed above 2/(1 + r_y) of the bat's, which needs no psi: a ball that leaves faster than any
    collision sends it (a bat tip tracked on a still spot measures a bat at rest) is named so,
    not as a psi beyond 90 deg.
    """
    v_bat, v_ball, omega = (np.asarray(a, dtype=float) for a in (m.v_bat, m.v_ball, m.omega))
    c = _collision_checks(m)
    off = _group_outliers(m, c, np.asarray(groups), sigma, None if coarse is None else np.asarray(coarse))
    robust = np.any(list(off.values()), axis=0) if off else np.zeros(v_bat.shape, dtype=bool)
    out = np.full(v_bat.shape, "", dtype=object)
    for i in np.flatnonzero(c.ok | c.ratio_high):
        words = []
        for k, top in SPEED_MAX_MPH.items():
            speed = (v_bat if k == "v_bat" else v_ball)[i] / MPH
            if speed > top:
                words.append(f"{k} = {speed:.1f} mph is faster than any {k[2:]} reaches (above {top:g}; km/h?)")
        if c.ratio_high[i]:
            words.append(f"v_ball/v_bat = {c.ratio[i]:.2f} exceeds 2/(1 + r_y), the most any collision gives")
        elif c.ratio_low[i]:
            words.append(f"v_ball/v_bat = {c.ratio[i]:.2f} is below cos(psi)/(1 + r_y), the least any collision gives")

        if c.e_x_out[i]:
            lo, hi = E_X_PLAUSIBLE
            words.append(f"implied e_x = {c.e_x[i]:.2f} (Eq. omega) is outside [{lo:g}, {hi:g}], where impacts lie")
        elif robust[i]:
            planes_off = " and ".join(k for k, v in off.items() if v[i])
            words.append(
                f"{planes_off} far from its bat x ball group's line (spin {omega[i] / RPM:.0f} rpm, implied"
                f" e_x = {c.e_x[i]:.2f}; robust z > {OUTLIER_Z:g})"
            )
        out[i] = "; ".join(words)
    return out.astype(str)


def _group_outliers(m: Measured, c: _Checks, groups, sigma: dict | None, coarse) -> dict[str, np.ndarray]:
    """Per plane, the impacts far from their group's line (:func:`implausible_rows`, last bullet).

    Returns plane name -> boolean per impact, for the planes where any group could be judged.
    """
    return {k: np.isfinite(z) & (z > OUTLIER_Z) for k, z in _group_z(m, c, groups, sigma, coarse).items()}


def _group_z(m: Measured, c: _Checks, groups, sigma: dict | None, coarse) -> dict[str, np.ndarray]:
    """Per plane, each impact's distance from its group's line in robust standard deviations (NaN: not judged).

    The standard deviation is the impact's own (from the stated uncertainties) or the file's
    robust spread (:func:`implausible_rows`, last bullet).
    """
    v_bat, theta, omega = (np.asarray(a, dtype=float) for a in (m.v_bat, m.theta, m.omega))
    ok, use_ex = c.ok, c.use_ex
    # Group outliers on the spin residual of Eq. omega, omega - (1 + e_x) x with x its bracket:
    # spin noise is the same for every impact, so the residuals share one spread (the implied
    # e_x does not: its noise grows as sin psi -> 0), and a robust spread (MAD) of the group
    # is not pulled by the outliers themselves.
    with np.errstate(invalid="ignore", divide="ignore"):
        x = spin_bracket(v_bat, c.psi, m.r, m.r_x, m.alpha)
    # Two planes where a group's impacts lie close to a line through the origin: Eq. omega
    # (spin against its bracket) and Fig. 3 (spin per bat speed against theta, the paper's
    # "remarkably linear" relation). Rows in the wrong unit fall off at least one of them; the
    # second also catches them at small psi, where the bracket itself follows the bad spin.
    with np.errstate(invalid="ignore", divide="ignore"):
        planes = {"spin vs its Eq. omega bracket": (omega, x), "spin vs theta (Fig. 3)": (omega / v_bat, theta)}
    if sigma is not None and all(k in sigma for k in ("v_bat", "theta", "omega")):
        s_om, s_th, s_vb = (np.asarray(sigma[k], dtype=float) for k in ("omega", "theta", "v_bat"))
        own = {"spin vs its Eq. omega bracket": s_om, "spin vs theta (Fig. 3)": None}
    else:
        own = {}
    off = {}
    for name, (y, xx) in planes.items():
        dev = np.full(v_bat.shape, np.nan)
        for g in np.unique(groups):
            sel = ok & (groups == g)
            ref = sel
            if sel.sum() < OUTLIER_MIN_GROUP and coarse is not None and sel.any():
                ref = ok & (coarse == coarse[np.flatnonzero(sel)[0]])
            fit = use_ex & ref
            if ref.sum() < OUTLIER_MIN_GROUP or not fit.any():
                continue
            slope = np.median(y[fit] / xx[fit])
            res = y[sel] - slope * xx[sel]
            dev[sel] = np.abs(res - np.median(y[ref] - slope * xx[ref]))
            if name in own:  # the residual's own standard uncertainty from the stated ones
                sd = own[name]
                if sd is None:
                    sd = np.hypot(np.hypot(s_om / v_bat, omega * s_vb / v_bat**2), slope * s_th)
                dev[sel] = dev[sel] / np.maximum(sd[sel], 1e-12)
        if not np.isfinite(dev).any():
            continue
        if name in own:
            off[name] = dev
        else:  # one spread for the file: a MAD of a dozen impacts is too uncertain
            off[name] = dev / max(1.4826 * np.median(dev[np.isfinite(dev)]), 1e-12)
    return off


_CHECK_WORDS = {
    "psi": "psi cannot be reconstructed (Eq. angmom)",
    "ratio_high": "exit speed above 2/(1 + r_y) times the bat speed, more than any collision allows",
    "ratio_low": "exit speed below cos(psi)/(1 + r_y) times the bat speed, less than any collision allows",
    "e_x": f"implied e_x (Eq. omega) outside [{E_X_PLAUSIBLE[0]:g}, {E_X_PLAUSIBLE[1]:g}]",
}

#: Suspected unit mistakes: (columns, what went wrong, correction of the SI measurements).
_MISTAKES = (
    ("omega_rpm", "spin in rad/s, not rpm", lambda m: replace(m, omega=m.omega / RPM)),
    ("v_bat_mph", "bat speed in m/s, not mph", lambda m: replace(m, v_bat=m.v_bat / MPH)),
    ("v_ball_mph", "exit speed in m/s, not mph", lambda m: replace(m, v_ball=m.v_ball / MPH)),
    (
        "v_bat_mph, v_ball_mph",
        "speeds in m/s, not mph",
        lambda m: replace(m, v_bat=m.v_bat / MPH, v_ball=m.v_ball / MPH),
    ),
    ("theta_deg", "angle in radians, not degrees", lambda m: replace(m, theta=m.theta / DEGREE)),
    (
        "v_bat_mph, v_ball_mph",
        "the two speed columns swapped (v_bat_mph holds the exit speeds)",
        lambda m: replace(m, v_bat=m.v_ball, v_ball=m.v_bat),
    ),
    # last: on a tie the mistakes above are the likelier
    ("omega_rpm", "spin with the opposite sign (omega > 0 is backspin, Fig. 2)", lambda m: replace(m, omega=-m.omega)),
)


#: Per-row unit mistakes (:func:`row_unit_hints`): the file-wide ones and the other units labs use.
_ROW_MISTAKES = (
    *_MISTAKES[:-1],
    ("omega_rpm", "spin in rev/s, not rpm", lambda m: replace(m, omega=m.omega * 60.0)),
    ("v_bat_mph", "bat speed in km/h, not mph", lambda m: replace(m, v_bat=m.v_bat / KMH_PER_MPH)),
    ("v_ball_mph", "exit speed in km/h, not mph", lambda m: replace(m, v_ball=m.v_ball / KMH_PER_MPH)),
    _MISTAKES[-1],
)


def _with_row(m: Measured, i: int, fixed: Measured) -> Measured:
    """Return ``m`` with impact ``i`` taken from ``fixed`` (scalars stay as they are)."""
    values = {}
    for f in fields(m):
        a = np.asarray(getattr(m, f.name))
        if a.ndim:
            a = a.astype(float, copy=True)
            a[i] = np.asarray(getattr(fixed, f.name))[i]
        values[f.name] = a
    return Measured(**values)


def _max_z(m: Measured, groups, sigma: dict | None, coarse) -> np.ndarray:
    """Per impact, its largest distance from its group's line over the planes (:func:`_group_z`; 0: not judged)."""
    z = _group_z(m, _collision_checks(m), groups, sigma, coarse)
    if not z:
        return np.zeros(np.shape(m.v_bat))
    return np.nan_to_num(np.abs(np.array(list(z.values()))), nan=0.0).max(axis=0)


def row_unit_hints(m: Measured, groups: ArrayLike, coarse: ArrayLike | None, why: np.ndarray) -> dict[int, str]:
    """Per impact whose values fit another unit far better than the file's: which (SI inputs).

    Rows excluded as implausible (``why`` not empty, :func:`implausible_rows`) and kept rows at
    least :data:`UNIT_ROW_Z` from their group's line are undone in turn for each mistake of
    :data:`_ROW_MISTAKES` (that row alone). An excluded row is named when a correction makes it
    plausible; a kept one when a correction brings it within :data:`UNIT_ROW_FIT_Z` and a third of
    its distance. More than :data:`UNIT_ROW_MAX` such rows is a file-wide mistake
    (:func:`unit_warnings`): none is named. Judged against the file's robust spread, not the
    row's stated uncertainties (which share the row's unit mistake when they were converted alike).
    """
    z0 = _max_z(m, groups, None, coarse)
    rows = np.flatnonzero((why != "") | (z0 > UNIT_ROW_Z))
    hints: dict[int, str] = {}
    for i in rows[: UNIT_ROW_MAX if rows.size <= UNIT_ROW_MAX else 0]:
        fits = []  # (distance corrected, order, columns, mistake) of each correction that fits
        for k, (cols, what, fix) in enumerate(_ROW_MISTAKES):
            m1 = _with_row(m, int(i), fix(m))
            if not _collision_checks(m1).ok[i]:
                continue
            z1 = _max_z(m1, groups, None, coarse)[i]
            if why[i]:
                good = implausible_rows(m1, groups, coarse=coarse)[i] == ""
            else:
                good = z1 < UNIT_ROW_FIT_Z and z1 < z0[i] / 3.0
            if good:
                fits.append((z1, k, cols, what))
        if fits:  # the best first; the others fit too, and the data cannot tell them apart
            fits.sort()
            z1, _, cols, what = fits[0]
            also = "".join(f" (or column {c}: {w})" for _, _, c, w in fits[1:])
            hints[int(i)] = f"column {cols}: the row fits {what} far better{also}" + (
                " (corrected for that, it passes every check)"
                if why[i]
                else f" (off its group's line by {z0[i]:.1f} robust sd; corrected, {z1:.1f})"
            )
    return hints


def swapped_speeds(path: str | os.PathLike[str], m: Measured, usable: np.ndarray, groups: np.ndarray) -> list[str]:
    """Problems naming bat x ball pairs whose impacts imply a median e_y below :data:`E_Y_MIN` (SI).

    Such impacts came out slower, against the bat's speed, than any ball-bat collision sends
    a ball: most often the columns v_bat_mph and v_ball_mph are swapped; the message says
    what the median would be with them swapped back.
    """
    c = _collision_checks(m)
    back = _collision_checks(replace(m, v_bat=m.v_ball, v_ball=m.v_bat))
    problems = []
    for g in np.unique(groups):
        sel = usable & (groups == g) & c.ok & np.isfinite(c.e_y)
        if sel.sum() < 3:
            continue
        med = float(np.median(c.e_y[sel]))
        if med < E_Y_MIN:
            other = back.e_y[sel & back.ok]
            then = f"; swapped back it would be {np.median(other):.2f}" if other.size else ""
            problems.append(
                f"{path}: {g}: the {int(sel.sum())} usable impacts imply a median e_y of {med:.2f} (Eq. vballn), "
                f"below the {E_Y_MIN:g} no ball-bat collision goes under: the exit speeds are too slow for the bat "
                f"speeds. Are the columns v_bat_mph and v_ball_mph swapped{then}?"
            )
    return problems


def _score(checks: dict) -> float:
    """Largest fraction of impacts failing one check (checks with fewer than 3 impacts skipped)."""
    return max((bad / n for bad, n in checks.values() if n >= 3), default=0.0)


def unit_warnings(path: str | os.PathLike[str], m: Measured) -> list[str]:
    """Warnings naming a column whose values look like a unit mistake (SI measurements).

    When a physics check of :func:`implausible` fails for most impacts, each suspected
    mistake of :data:`_MISTAKES` is undone in turn; one that makes the data plausible is
    named with its column. Only warnings: such values are possible, just unlikely.
    """
    theta_deg = np.abs(m.theta) / DEGREE
    if theta_deg.size >= 5 and np.all(theta_deg < 90 * DEGREE) and np.ptp(theta_deg) > 0:
        return [
            f"{path}: column theta_deg: every |theta| is below {90 * DEGREE:.2f} deg, a range no oblique "
            "impacts span: the values look like radians, not degrees"
        ]
    raw = implausible(m)
    if _score(raw) <= UNIT_WARN_FRACTION:
        return []
    failing = "; ".join(f"{_CHECK_WORDS[k]} for {bad} of {n}" for k, (bad, n) in raw.items() if bad)
    best = None
    for cols, what, fix in _MISTAKES:
        s = _score(implausible(fix(m)))
        if s <= UNIT_FIX_FRACTION and (best is None or s < best[0]):
            best = (s, cols, what)
    if best is None:
        return [
            f"{path}: most impacts are physically implausible ({failing}); check the units of "
            "v_bat_mph and v_ball_mph (mph), theta_deg (deg) and omega_rpm (rpm, positive for backspin)"
        ]
    s, cols, what = best
    return [
        f"{path}: column {cols}: most impacts are physically implausible ({failing}); the values look like "
        f"{what} (corrected for that, every check passes for at least {100 * (1 - s):.0f} % of impacts)"
    ]


# ---------------------------------------------------------------------------------------
# The whole file


@dataclass(frozen=True)
class Ingested:
    """A measured file read and checked (:func:`read_measured`), one entry per impact.

    ``columns`` are the file's columns in its units (``label``: each impact's place in the
    file; ``impact_id``; ``<column>_err`` where given), ``measured`` the impacts in SI,
    ``flag`` and ``reason`` the exclusions (:class:`~ballbat.kinematics.ImpactFlag`),
    ``warnings`` what is possible but suspicious.
    """

    columns: dict
    measured: Measured
    flag: np.ndarray
    reason: np.ndarray
    ball: np.ndarray
    bat: np.ndarray
    warnings: list[str]


def read_measured(
    impacts_path: str | os.PathLike[str], balls_path: str | os.PathLike[str], bats_path: str | os.PathLike[str]
) -> Ingested:
    """Read and check a measured dataset (the stage :mod:`ballbat.stages.ingest` writes it as ingest.nc).

    Raises :class:`~ballbat.properties.InputError` listing every problem that stops the
    dataset (bad property tables included). Impacts psi cannot use are kept with a flag > 0
    and the reason.
    """
    cols, balls, bats = _read_checked(impacts_path, balls_path, bats_path)
    ball_ids, bat_ids = cols["ball"].astype(str), cols["bat"].astype(str)
    m = _measured(cols, ball_ids, bat_ids, balls, bats)
    flag, reason, notes = _flags(impacts_path, cols, m, ball_ids, bat_ids)
    warnings = notes + _dataset_checks(impacts_path, cols, m, flag, ball_ids, bat_ids)
    return Ingested(cols, m, flag, reason, ball_ids, bat_ids, warnings)


def _read_checked(impacts_path, balls_path, bats_path) -> tuple[dict, dict[str, Ball], dict[str, Bat]]:
    """Read the property tables and the impacts file, checked whole (:func:`check_rows`).

    Returns the impacts' columns in the file's units and the two tables; raises one
    :class:`~ballbat.properties.InputError` with the problems of all three files.
    """
    problems: list[str] = []
    balls: dict[str, Ball] | None = None
    bats: dict[str, Bat] | None = None
    try:
        balls = load_balls(balls_path)
    except InputError as exc:
        problems += exc.problems
    try:
        bats = load_bats(bats_path)
    except InputError as exc:
        problems += exc.problems
    try:
        header, rows = read_impacts_table(impacts_path)
    except InputError as exc:
        raise InputError(problems + exc.problems) from None
    cols, row_problems = check_rows(impacts_path, header, rows, balls, bats)
    problems += row_problems
    if problems:
        raise InputError(problems)
    return cols, balls, bats


def _measured(cols: dict, ball_ids, bat_ids, balls: dict[str, Ball], bats: dict[str, Bat]) -> Measured:
    """Return the impacts in SI with each one's ball radius, alpha and recoil factors (Eqs. rx, ry)."""
    si = {name: cols[c] * factor for c, (name, factor) in MEASURED_COLUMNS.items()}
    r = np.array([balls[b].r for b in ball_ids])
    alpha = np.array([balls[b].alpha for b in ball_ids])
    rxy = {(b, t): recoil_factors(balls[b], bats[t]) for b, t in set(zip(ball_ids, bat_ids, strict=True))}
    r_x = np.array([rxy[(b, t)][0] for b, t in zip(ball_ids, bat_ids, strict=True)])
    r_y = np.array([rxy[(b, t)][1] for b, t in zip(ball_ids, bat_ids, strict=True)])
    return Measured(si["v_bat"], si["v_ball"], si["theta"], si["omega"], r, alpha, r_x, r_y)


def _flags(impacts_path, cols: dict, m: Measured, ball_ids, bat_ids) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Per impact: ``(ingest_flag, reason)`` from :func:`exclusions` and :func:`implausible_rows`, and warnings.

    An excluded row whose values fit another unit far better says so in its reason; a kept one
    is a warning (:func:`row_unit_hints`).

    A file with more than :data:`IMPLAUSIBLE_MAX_FRACTION` implausible impacts is an
    :class:`~ballbat.properties.InputError` (its units are likely wrong).
    """
    flag, reason = exclusions(m.v_ball, m.theta, m.omega, m.r, m.alpha)
    sigma = {si: cols[f"{c}_err"] * factor for c, (si, factor) in MEASURED_COLUMNS.items() if f"{c}_err" in cols}
    groups = np.char.add(ball_ids, bat_ids)
    why = implausible_rows(m, groups, sigma=sigma, coarse=ball_ids)
    hints = row_unit_hints(m, groups, ball_ids, why)
    bad = why != ""
    notes = [
        f"{impacts_path}: {cols['label'][i]}: {h}: a unit mistake in this row? It is kept and fitted; correct it "
        "or delete the row"
        for i, h in sorted(hints.items())
        if not bad[i]
    ]
    why = np.array([f"{w}; likely a unit mistake: {hints[i]}" if w and i in hints else w for i, w in enumerate(why)])
    flag = np.where(bad, ImpactFlag.IMPLAUSIBLE, flag).astype(np.int8)
    reason = np.where(bad, np.char.add("implausible: ", why.astype(str)), reason)
    if bad.sum() > IMPLAUSIBLE_MAX_FRACTION * bad.size:
        listing = [f"{impacts_path}: {lab}: {w}" for lab, w in zip(cols["label"][bad], why[bad], strict=True)][:10]
        raise InputError(
            [
                f"{impacts_path}: {int(bad.sum())} of {bad.size} impacts are measurements no ball-bat collision "
                "can produce, more than half: the file's units are likely wrong (mph, deg, rpm expected)",
                *unit_warnings(impacts_path, m),
                *listing,
            ]
        )
    return flag, reason, notes


def _dataset_checks(impacts_path, cols: dict, m: Measured, flag: np.ndarray, ball_ids, bat_ids) -> list[str]:
    """Check the file as a whole: swapped speeds and no pair to fit stop it; the rest warns.

    Returns the warnings: pairs with fewer than :data:`MIN_FIT_IMPACTS` usable impacts, some
    but not all uncertainty columns, suspected unit mistakes (:func:`unit_warnings`).
    """
    warnings: list[str] = []
    usable = flag == 0
    pairs = np.array([f"ball {str(b)!r} on bat {str(t)!r}" for b, t in zip(ball_ids, bat_ids, strict=True)], dtype=str)
    swapped = swapped_speeds(impacts_path, m, usable, pairs)
    if swapped:
        raise InputError(swapped)
    groups = sorted({(str(b), str(t)) for b, t in zip(ball_ids, bat_ids, strict=True)})
    counts = {g: int((usable & (ball_ids == g[0]) & (bat_ids == g[1])).sum()) for g in groups}
    for (b, t), k in counts.items():
        if k < MIN_FIT_IMPACTS:
            warnings.append(
                f"{impacts_path}: ball {b!r} on bat {t!r}: {k} usable impact(s), fewer than {MIN_FIT_IMPACTS}: "
                "e_x of this bat is not fitted (reported as NaN); its impacts still enter the pooled fit"
            )
    if not any(k >= MIN_FIT_IMPACTS for k in counts.values()):
        raise InputError(
            [
                f"{impacts_path}: no ball x bat pair has {MIN_FIT_IMPACTS} usable impacts "
                f"({', '.join(f'{b} on {t}: {k}' for (b, t), k in counts.items())}): nothing to fit"
            ]
        )
    errs = [c for c in MEASURED_COLUMNS if f"{c}_err" in cols]
    if errs and len(errs) < len(MEASURED_COLUMNS):
        given = ", ".join(f"{c}_err" for c in errs)
        warnings.append(
            f"{impacts_path}: only {given} of the four uncertainty columns given: the fits are unweighted "
            "and their reduced chi-square undefined"
        )
    warnings += unit_warnings(impacts_path, m)
    return warnings
