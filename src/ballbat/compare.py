"""The paper-comparison table: every published number beside ours (and the truth).

Columns: ``quantity, ball, bat, paper, paper_uncertainty, value, uncertainty, systematic,
truth, unit``, in the paper's units. ``uncertainty`` is the statistical standard error;
``systematic`` the systematic error reported apart from it (a dataset reduced from camera
tracks: every stated calibration uncertainty, in quadrature; :mod:`ballbat.systematics`).
One row per published number (``ballbat.published``) and one per result of ours that the
paper does not publish (e.g. e_x of a bat not in the paper, or e_y implied by Eq. ratio).
Cells that do not apply are empty.
"""

from __future__ import annotations

import csv
import io
import math
from typing import TYPE_CHECKING

import numpy as np

from .kinematics import offset_from_psi
from .published import PUBLISHED, UNPUBLISHED
from .units import from_si

if TYPE_CHECKING:
    import os
    from collections.abc import Iterable, Mapping, Sequence

    import xarray as xr

    from .published import Published

# The calibration systematics in the results (ballbat.systematics): how the tables, the summary
# and the front page find and describe them.


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
#: What a dataset without any systematic says in place of one ("syst. —").
NO_SYSTEMATIC_NOTE = (
    "no calibration uncertainty stated (no camera tracks, no datasets.<name>.calibration of the instruments) and "
    "no property uncertainty (no *_err column in the bat and ball tables), so no systematic is estimated"
)
#: The kinds of systematic source (ballbat.systematics): a source name's prefix or set -> what, for the notes.
_SOURCE_KINDS = (
    (
        "cameras",
        "the cameras' and rig's calibrations (pixel scale, frame rate, the rig's lengths; tracks reduced again)",
    ),
    (
        "instruments",
        "the instruments' calibrations (datasets.<name>.calibration: speed scale, spin scale, angle offset)",
    ),
    ("properties", "the bat and ball properties' uncertainties (the tables' *_err columns, tables converted again)"),
)


def _source_kind(name: str) -> str:
    from .instruments import INSTRUMENT_SOURCES

    if name.startswith(("bat:", "ball:")):
        return "properties"
    return "instruments" if name in INSTRUMENT_SOURCES else "cameras"


def systematic_note(ds: xr.Dataset) -> str:
    """Return what the combined systematic of ``ds`` holds (:data:`SYSTEMATIC_NOTE` for camera-tracked data alone).

    Only the kinds of source with a stated uncertainty are named; :data:`NO_SYSTEMATIC_NOTE` when none is.
    """
    if "systematic" not in ds.coords:
        return SYSTEMATIC_NOTE if "e_x_err_scale" in ds else NO_SYSTEMATIC_NOTE
    names = ds["systematic"].values.astype(str)
    stated = [n for n, r in zip(names, ds["systematic_rel_sigma"].values, strict=True) if r != 0]
    kinds = {_source_kind(n) for n in stated}
    if kinds <= {"cameras"}:
        return SYSTEMATIC_NOTE
    parts = [what for kind, what in _SOURCE_KINDS if kind in kinds]
    return (
        "every stated uncertainty: "
        + "; ".join(parts)
        + "; each propagated by refitting at ± one standard uncertainty of that one source (shared by every "
        "impact of its bat or ball, or by every impact), combined in quadrature; apart from the standard error"
    )


def source_parts(ds: xr.Dataset, var: str) -> list[tuple[str, float]]:
    """Each stated source's part of ``var``'s systematic in ``ds`` (a selection of one cell), largest first."""
    if f"{var}_syst_by_source" not in ds:
        return []
    per = ds[f"{var}_syst_by_source"].values
    rel = ds["systematic_rel_sigma"].values
    names = ds["systematic"].values.astype(str)
    parts = [(str(n), float(v)) for n, r, v in zip(names, rel, per, strict=True) if r != 0 and math.isfinite(v)]
    return sorted(parts, key=lambda nv: -nv[1])


COLUMNS = (
    "quantity",
    "ball",
    "bat",
    "paper",
    "paper_uncertainty",
    "value",
    "uncertainty",
    "systematic",
    "truth",
    "unit",
)

#: quantity -> (variable in fit_ex.nc, unit of the table); value's error is ``<var>_err``.
FIT_QUANTITIES = {
    "e_x": ("e_x", "1"),
    "e_x_pooled": ("e_x_pooled", "1"),
    "spin_theta_slope": ("spin_theta_slope", "rpm/deg"),
    "speed_theta_slope": ("speed_theta_slope", "mph/deg"),
    "tan_ratio_slope": ("tan_ratio_slope", "1"),
    "e_y_implied": ("e_y_implied", "1"),
    "mu_k_lower_bound": ("mu_k_lower_bound", "1"),
    "gross_slip_psi": ("gross_slip_psi", "deg"),
    "gross_slip_theta": ("gross_slip_theta", "deg"),
    "gross_slip_omega": ("gross_slip_omega", "rpm"),
}


def format_number(x: float | None) -> str:
    """Return a number as the tables print it (6 significant digits; empty for None, NaN or inf)."""
    if x is None:
        return ""
    x = float(x)
    return "" if not math.isfinite(x) else f"{x:.6g}"


def uncertainty_decimals(*errors: float | None, digits: int = 2) -> int | None:
    """Return the decimals that show the finest of ``errors`` to ``digits`` significant digits.

    The field's rule: an uncertainty to two significant digits, the value to the same decimal
    place. With a statistical and a systematic error the finer one sets the place. ``None``
    when no error is finite and positive. (0.00996 rounds to 0.010: two digits, three decimals.)
    """
    places = []
    for e in errors:
        if e is None or not math.isfinite(float(e)) or float(e) <= 0:
            continue
        e = float(e)
        d = digits - 1 - math.floor(math.log10(e))
        if round(e, d) >= 10 ** (digits - d):  # rounding carried into a new digit (0.00996 -> 0.010)
            d -= 1
        places.append(d)
    return max(places) if places else None


def format_measurement(value: float, *errors: float | None, digits: int = 2) -> list[str]:
    """Return ``value`` and each of ``errors`` as text rounded as the field does (:func:`uncertainty_decimals`).

    Errors that are missing or not finite come back as empty strings; with no usable error the
    value is given to 3 significant digits.
    """
    d = uncertainty_decimals(*errors, digits=digits)
    v = float(value)
    if not math.isfinite(v):
        return ["", *("" for _ in errors)]
    if d is None:
        return [f"{v:.3g}", *("" for _ in errors)]
    d = max(d, 0)
    out = [f"{v:.{d}f}"]
    for e in errors:
        ok = e is not None and math.isfinite(float(e)) and float(e) > 0
        out.append(f"{float(e):.{d}f}" if ok else "")
    return out


def total_uncertainty(statistical: float, systematic: float | None) -> float:
    """Return the statistical and systematic errors added in quadrature (the statistical one if no systematic)."""
    if systematic is None or not math.isfinite(float(systematic)):
        return float(statistical)
    return math.hypot(float(statistical), float(systematic))


def _pick(ds, var, ball, bat):
    if var not in ds:
        return None
    v = ds[var]
    if "ball" in v.dims:
        if ball not in ds["ball"].values:
            return None
        v = v.sel(ball=ball)
    if "bat" in v.dims:
        if bat not in ds["bat"].values:
            return None
        v = v.sel(bat=bat)
    return float(v.values)


def fit_rows(fit: xr.Dataset) -> list[dict]:
    """Rows for the quantities of ``fit_ex.nc`` (values in SI converted to the table's units)."""
    rows = []
    balls = [str(b) for b in fit["ball"].values]
    bats = [str(b) for b in fit["bat"].values]
    for q, (var, unit) in FIT_QUANTITIES.items():
        per_bat = "bat" in fit[var].dims
        for ball in balls:
            for bat in bats if per_bat else [""]:
                val = _pick(fit, var, ball, bat or None)
                if val is None or (per_bat and not np.isfinite(val) and _pick(fit, f"{var}_n", ball, bat) == 0):
                    continue
                err = _pick(fit, f"{var}_err", ball, bat or None)
                tru = _pick(fit, f"truth_{var}", ball, bat or None)
                syst = systematic_var(fit, var)
                sys_ = _pick(fit, syst, ball, bat or None) if syst else None
                conv = (lambda x, unit=unit: None if x is None else from_si(x, unit)) if unit != "1" else (lambda x: x)
                rows.append(
                    {
                        "quantity": q,
                        "ball": ball,
                        "bat": bat,
                        "value": conv(val),
                        "uncertainty": conv(err),
                        "systematic": conv(sys_),
                        "truth": conv(tru),
                        "unit": unit,
                    }
                )
    return rows


def result_row(quantity: str, ball: str, value: object, unit: str, bat: str = "", **cells: object) -> dict:
    """Return one row of ours: ``quantity`` of ``ball`` (and ``bat``), its value and unit; ``cells``: other columns."""
    return {"quantity": quantity, "ball": ball, "bat": bat, "value": value, **cells, "unit": unit}


def _largest(values: np.ndarray | None, unit: str) -> float | None:
    """Return the largest of ``values`` in ``unit``; None when there are none."""
    return None if values is None or values.size == 0 else from_si(values.max(), unit)


def impact_rows(rec: xr.Dataset) -> list[dict]:
    """Rows from the reconstructed impacts: psi_max, D_max, n_impacts (usable) and n_excluded per ball."""
    rows = []
    ok = rec["flag"].values == 0
    ball = rec["ball"].values.astype(str)
    has_truth = "truth_psi" in rec
    for b in sorted(set(ball)):
        sel = ok & (ball == b)
        tpsi = rec["truth_psi"].values[ball == b] if has_truth else None
        tD = offset_from_psi(tpsi, rec["r"].values[ball == b], rec["R_bat"].values[ball == b]) if has_truth else None
        rows += [
            result_row("psi_max", b, _largest(rec["psi"].values[sel], "deg"), "deg", truth=_largest(tpsi, "deg")),
            result_row("D_max", b, _largest(rec["D"].values[sel], "in"), "in", truth=_largest(tD, "in")),
            result_row("n_impacts", b, int(sel.sum()), "1", truth=int((ball == b).sum()) if has_truth else None),
            # impacts kept in reconstruct.nc with flag > 0 (the reasons are there)
            result_row("n_excluded", b, int((~ok & (ball == b)).sum()), "1"),
        ]
    return rows


def comparison_table(rows: list[dict], published: Sequence[Published] = PUBLISHED) -> list[dict]:
    """Merge our rows with the published values: one row per published number, plus ours."""
    ours = {(r["quantity"], r["ball"], r["bat"]): r for r in rows}
    table = []
    for p in published:
        key = (p.quantity, p.ball, p.bat)
        r = ours.pop(key, {})
        table.append(
            {
                **{c: None for c in COLUMNS},
                **r,
                "quantity": p.quantity,
                "ball": p.ball,
                "bat": p.bat,
                "paper": p.value,
                "paper_uncertainty": p.uncertainty,
                "unit": p.unit,
            }
        )
    for key, r in ours.items():  # results with no published counterpart
        unit = r.get("unit") or UNPUBLISHED.get(key[0], "")
        table.append({**{c: None for c in COLUMNS}, **r, "unit": unit})
    return table


def to_csv(table: list[dict]) -> str:
    """Return the comparison table as CSV text (columns :data:`COLUMNS`)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(COLUMNS)
    for r in table:
        w.writerow([r[c] if c in ("quantity", "ball", "bat", "unit") else format_number(r[c]) for c in COLUMNS])
    return buf.getvalue()


#: What an ``uncertainty`` is where it is not the standard error of a fit (notes under the Markdown
#: table; the replicate studies' ``error_kind``). Every other uncertainty is :data:`STANDARD_ERROR`.
STANDARD_ERROR = "a standard error of the fit (covariance scaled by the reduced chi-square)"
UNCERTAINTY_NOTES = {
    "mu_k_lower_bound": (
        "the measurement uncertainty of the largest tan(psi - theta), not a standard error of a sample "
        "maximum: it says how well the largest value of these impacts is measured (docs/studies.md)"
    ),
    "e_x": (
        "a sandwich (HC3) standard error of the fit with the bat's intrinsic-scatter term in its weights; "
        "from camera tracks with the contact population's error in quadrature (docs/model.md)"
    ),
    "e_x_pooled": (
        "a sandwich (HC3) standard error centred within bats, of the fit with the intrinsic scatter within "
        "bats; from camera tracks with the contact population's error in quadrature (docs/model.md)"
    ),
    "tan_ratio_slope": (
        "a standard error of the fit with the intrinsic scatter within bats (Paule-Mandel); from camera "
        "tracks with the contact population's error in quadrature (docs/model.md)"
    ),
    "e_y_implied": "a leverage-corrected (HC2) sandwich standard error (the impacts' influences through the Eq. "
    "ratio slope and e_x per bat); from camera tracks with the contact population's error in quadrature",
    "spin_theta_slope": "a sandwich (HC3) standard error",
    "speed_theta_slope": "a sandwich (HC3) standard error",
    "eta2": (
        "a sandwich (HC3) standard error centred within bats, with Bell-McCaffrey degrees of freedom "
        "(eta2_dof in stronge.nc) for its Student's t interval"
    ),
}


def _has_value(row: Mapping[str, object]) -> bool:
    return row.get("value") not in (None, "")


def applicable_rows(table: Sequence[Mapping[str, object]]) -> tuple[list[Mapping[str, object]], list[str]]:
    """Return the rows of a comparison that apply to the dataset, and a note on each kind left out.

    The dataset's balls are those with a value of ours, its bats per ball those with an e_x of ours.
    A published row of a ball the dataset has no impacts of, or of a bat it did not test, has no value
    of ours to compare and is left out, with a note saying why. A per-ball quantity (e_x pooled, the
    Figs. 3-6 slopes, ...) that the paper pooled over other bats than the dataset's stays, with a note
    naming both sets of bats. A dataset of the paper's balls and bats keeps every row and gets no note.
    """
    balls = {str(r["ball"]) for r in table if _has_value(r) and r.get("ball")}
    bats = {
        b: {str(r["bat"]) for r in table if r["quantity"] == "e_x" and r["ball"] == b and _has_value(r)} for b in balls
    }
    paper_bats: dict[str, set[str]] = {}
    for r in table:
        if r["quantity"] == "e_x" and r.get("paper") not in (None, ""):
            paper_bats.setdefault(str(r["ball"]), set()).add(str(r["bat"]))
    kept, no_ball, no_bat = [], {}, {}
    for r in table:
        ball, bat = str(r.get("ball") or ""), str(r.get("bat") or "")
        if _has_value(r) or not ball:
            kept.append(r)
        elif ball not in balls:
            no_ball[ball] = no_ball.get(ball, 0) + 1
        elif bat and bat not in bats[ball]:
            no_bat.setdefault(ball, []).append(bat)
        else:
            kept.append(r)
    notes = [
        f"{ball}: this dataset has no impacts of it; the paper's {n} rows of it are left out"
        for ball, n in sorted(no_ball.items())
    ]
    notes += [
        f"e_x of {ball} on {', '.join(dict.fromkeys(missing))}: bats this dataset did not test; left out"
        for ball, missing in sorted(no_bat.items())
    ]
    for ball in sorted(balls & set(paper_bats)):
        if bats[ball] and bats[ball] != paper_bats[ball]:
            notes.append(
                f"{ball}'s per-ball quantities (e_x_pooled, the slopes, eta2, ...): ours pool the bats "
                f"{', '.join(sorted(bats[ball]))}, the paper's {', '.join(sorted(paper_bats[ball]))}: not the same bats"
            )
    return kept, notes


def to_markdown(table: list[dict], title: str) -> str:
    """Return the comparison table as a Markdown table under the heading ``title``, with notes on the uncertainties."""
    shown, left_out = applicable_rows(table)
    lines = [f"# {title}", "", "| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    for r in shown:
        cells = [r[c] or "" if c in ("quantity", "ball", "bat", "unit") else format_number(r[c]) for c in COLUMNS]
        if r.get("value") is not None and r.get("uncertainty") is not None:
            # rounded as the field does (the CSV keeps 6 significant digits)
            rounded = format_measurement(r["value"], r["uncertainty"], r.get("systematic"))
            for c, text in zip(("value", "uncertainty", "systematic"), rounded, strict=True):
                cells[COLUMNS.index(c)] = text
        lines.append("| " + " | ".join(cells) + " |")
    present = {r["quantity"] for r in table if r.get("uncertainty") is not None}
    notes = [f"- `{q}`: uncertainty is {UNCERTAINTY_NOTES[q]}" for q in UNCERTAINTY_NOTES if q in present]
    if any(r.get("systematic") is not None for r in table):
        notes.append(f"- `systematic`: {SYSTEMATIC_NOTE}")
    notes.append(
        "- `value`, `uncertainty`, `systematic`: rounded as the field does (the uncertainty to two significant "
        "digits, the value to match); paper_comparison.csv has them to 6 significant digits"
    )
    if notes:
        lines += [
            "",
            f"Every uncertainty is {STANDARD_ERROR} (95 % intervals with Student's t), except:",
            "",
            *notes,
        ]
    if left_out:  # a dataset of other balls or bats than the paper's (paper_comparison.csv keeps every row)
        lines += ["", "Rows that do not apply to this dataset (paper_comparison.csv keeps them):", ""]
        lines += [f"- {n}" for n in left_out]
    return "\n".join(lines) + "\n"


def read_csv(path: str | os.PathLike[str]) -> list[dict]:
    """Read a comparison CSV back (strings), verified whole (its checked last line: :mod:`ballbat.pipeline.checked`)."""
    from .pipeline.ncio import read_table_csv

    return list(csv.DictReader(io.StringIO(read_table_csv(path), newline="")))


def write_comparison(
    fit: xr.Dataset,
    impacts: xr.Dataset,
    csv_path: str | os.PathLike[str],
    md_path: str | os.PathLike[str],
    title: str,
    extra_rows: Iterable[dict] = (),
) -> list[dict]:
    """Build the comparison from ``fit_ex.nc`` and ``reconstruct.nc``; write CSV and Markdown."""
    from .pipeline.ncio import read_dataset

    rec = read_dataset(impacts)
    warnings = [w for w in rec.attrs.get("ingest_warnings", "").split("\n") if w]
    rows = [
        *fit_rows(read_dataset(fit)),
        *impact_rows(rec),
        *extra_rows,
        result_row("n_warnings", "", len(warnings), "1"),
    ]
    return write_table(rows, csv_path, md_path, title, warnings=warnings)


def write_table(
    rows: list[dict],
    csv_path: str | os.PathLike[str],
    md_path: str | os.PathLike[str],
    title: str,
    published: Sequence[Published] = PUBLISHED,
    warnings: Sequence[str] = (),
) -> list[dict]:
    """Merge ``rows`` with the published values; write the CSV and its Markdown rendering.

    ``warnings`` (those of the measured file, carried from ingest.nc) are listed under the
    Markdown table; the CSV has their count as the row ``n_warnings``.
    """
    from .pipeline.checked import sealed_csv
    from .pipeline.ncio import atomic_write_text

    table = comparison_table(rows, published)
    atomic_write_text(csv_path, sealed_csv(to_csv(table)))  # its check line: a table cut short is never used
    md = to_markdown(table, title)
    if warnings:
        md += "\n## Warnings\n\n" + "".join(f"- {w}\n" for w in warnings)
    atomic_write_text(md_path, md)
    return table


def stronge_rows(stronge: xr.Dataset) -> list[dict]:
    """Rows from ``stronge.nc``: eta2 (with its standard error), Omega_t/Omega_n and the Fig. 10 times per ball.

    The event times are named by the file's ``psi_history_deg`` (e.g. ``stick_end_time_psi30``),
    so they meet the paper's values (Sec. V.A, psi = 30 deg) only when the histories are at that psi.
    """
    rows = []
    at = f"_psi{stronge.attrs['psi_history_deg']:g}"  # the paper's timeline is at psi = 30 deg
    for b in map(str, stronge["ball"].values):
        s = stronge.sel(ball=b)
        rows += [
            result_row(
                "eta2",
                b,
                float(s.eta2),
                "1",
                uncertainty=float(s.eta2_err),
                systematic=float(s.eta2_syst) if "eta2_syst" in s else None,
            ),
            result_row("omega_t_over_omega_n", b, float(s.omega_ratio), "1"),
            result_row("stretch_max_time" + at, b, float(s.t_stretch_max), "t_c"),
            result_row("stick_end_time" + at, b, float(s.t_stick_end), "t_c"),
            result_row("separation_time" + at, b, float(s.t_separation), "t_c"),
        ]
    return rows
