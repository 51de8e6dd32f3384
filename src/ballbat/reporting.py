"""Text for the report: the fitted numbers each figure's caption quotes, and HTML tables.

The Snakemake report renders each figure's caption (``workflow/report/*.rst``) as a Jinja
template, then as reStructuredText. Jinja sees the job's input and output paths but not
the contents of files, so the plotting job writes, next to each figure, a short
reStructuredText fragment with the numbers the figure shows (read from the same NetCDF
files the figure is drawn from); the caption pulls it in with an ``.. include::``
directive. The numbers therefore always belong to the run the report describes.

Nothing here imports matplotlib: the comparison tables are built without it.
"""

from __future__ import annotations

import html
import math
from typing import TYPE_CHECKING

import numpy as np

from .compare import (
    COLUMNS,
    NO_SYSTEMATIC_NOTE,
    SYSTEMATIC_NOTE,
    applicable_rows,
    format_measurement,
    read_csv,
    source_parts,
    systematic_note,
    systematic_var,
    total_uncertainty,
)
from .pipeline.ncio import atomic_write_text
from .published import per_ball
from .units import from_si

if TYPE_CHECKING:
    import os

    import xarray as xr
    from numpy.typing import ArrayLike

#: The paper's values the figures and captions quote (from ballbat.published, the one source).
PAPER = {
    "spin_theta_slope": per_ball("spin_theta_slope"),  # rpm/deg, Fig. 3
    "speed_theta_slope": per_ball("speed_theta_slope"),  # mph/deg, Fig. 4
    "fig5_slope": {b: 1.0 + v for b, v in per_ball("e_x_pooled").items()},  # 1 + e_x, Fig. 5
    "tan_ratio_slope": per_ball("tan_ratio_slope"),  # Fig. 6
    "eta2": per_ball("eta2"),  # Sec. V.A, Fig. 9
    "omega_ratio": per_ball("omega_t_over_omega_n"),  # Omega_t / Omega_n, Sec. V.A
}


def _f(x, fmt=".3g") -> str:
    x = float(x)
    return "n/a" if not math.isfinite(x) else format(x, fmt)


def _pm(value, err, fmt=".3g") -> str:
    """Value ± error; the error to two significant figures unless ``fmt`` fixes the decimals."""
    if not math.isfinite(float(err)):
        return _f(value, fmt)
    return f"{_f(value, fmt)} ± {_f(err, '.2g' if fmt.endswith('g') else fmt)}"


def _paper(key, ball, fmt=".3g") -> str:
    value = PAPER[key].get(str(ball))
    return "not given" if value is None else _f(value, fmt)


def excluded_count(impacts: xr.Dataset) -> int:
    """Return the number of impacts flagged as not reconstructable (flag != 0), left out of the figures."""
    return int(np.count_nonzero(impacts["flag"].values != 0))


def _header(impacts) -> list[str]:
    n = impacts.sizes["impact"]
    k = excluded_count(impacts)
    return [f"- Impacts shown: {n - k} of {n} ({k} flagged as not reconstructable and left out)."]


def _slope_lines(fit, var, unit, fmt=".3g") -> list[str]:
    lines = []
    for ball in fit["ball"].values.astype(str):
        v = fit[var].sel(ball=ball)
        if not math.isfinite(float(v)):
            continue
        e = fit[f"{var}_err"].sel(ball=ball)
        lo, hi = (from_si(fit[f"{var}_ci_{s}"].sel(ball=ball).values, unit) for s in ("low", "high"))
        lines.append(
            f"- {ball}: {_pm(from_si(v.values, unit), from_si(e.values, unit), fmt)} {unit}"
            f" (95 % interval {_f(lo, fmt)} to {_f(hi, fmt)}; n = {int(fit[f'{var}_n'].sel(ball=ball))});"
            f" paper {_paper(var, ball, fmt)} {unit}."
        )
    return lines


def _slope_numbers(impacts: xr.Dataset, fit: xr.Dataset, var: str, unit: str) -> str:
    """Fitted slopes ``var`` of fit_ex.nc per ball in ``unit``, beside the paper's (Figs. 3 and 4)."""
    return "\n".join(["Fitted slopes (standard errors):", "", *_slope_lines(fit, var, unit), "", *_header(impacts)])


def fig3_numbers(impacts: xr.Dataset, fit: xr.Dataset) -> str:
    """Fitted slopes of normalised spin against launch angle (Fig. 3)."""
    return _slope_numbers(impacts, fit, "spin_theta_slope", "rpm/deg")


def fig4_numbers(impacts: xr.Dataset, fit: xr.Dataset) -> str:
    """Fitted slopes of normalised exit speed against launch angle (Fig. 4)."""
    return _slope_numbers(impacts, fit, "speed_theta_slope", "mph/deg")


def _ex_text(fit: xr.Dataset, pre: str, offset: float = 0.0, **sel: str) -> str:
    """Return e_x (plus ``offset``) with its errors as text.

    The standard error and, for tracked data, the calibration systematic (every source in
    quadrature) and the total, rounded as the field does (errors to two significant digits,
    the value to match).
    """
    f = fit.sel(**sel)
    v, e = float(f[pre]) + offset, float(f[f"{pre}_err"])
    syst_var = systematic_var(f, pre)
    syst = float(f[syst_var]) if syst_var else math.nan
    if not math.isfinite(syst):
        value, err = format_measurement(v, e)
        return f"{value} ± {err}" if err else value
    value, err, sys_, total = format_measurement(v, e, syst, total_uncertainty(e, syst))
    return f"{value} ± {err} (stat) ± {sys_} (syst) = {value} ± {total} (total)"


def fig5_numbers(impacts: xr.Dataset, fit: xr.Dataset) -> str:
    """Pooled and per-bat e_x (Fig. 5, Eq. ex, Table II), with the calibration systematic of tracked data."""
    syst_var = systematic_var(fit, "e_x")
    tracked = syst_var is not None and bool(np.isfinite(fit[syst_var].values).any())
    what = "standard errors and the calibration systematic" if tracked else "standard errors"
    if tracked and systematic_note(fit) != SYSTEMATIC_NOTE:
        what = "standard errors and the systematic"
    lines = [f"Slopes 1 + e_x of the pooled fits through the origin ({what}):", ""]
    for ball in fit["ball"].values.astype(str):
        v = float(fit["e_x_pooled"].sel(ball=ball))
        if not math.isfinite(v):
            continue
        lines.append(
            f"- {ball}: e_x = {_ex_text(fit, 'e_x_pooled', ball=ball)} (n = {int(fit['e_x_pooled_n'].sel(ball=ball))});"
            f" slope 1 + e_x = {_ex_text(fit, 'e_x_pooled', 1.0, ball=ball).split(' (stat)')[0]},"
            f" paper slope {_paper('fig5_slope', ball, '.4g')}."
        )
    lines += ["", "e_x per bat (Table II):", ""]
    for ball in fit["ball"].values.astype(str):
        for bat in fit["bat"].values.astype(str):
            v = float(fit["e_x"].sel(ball=ball, bat=bat))
            if math.isfinite(v):
                lines.append(
                    f"- {ball}, {bat}: {_ex_text(fit, 'e_x', ball=ball, bat=bat)}"
                    f" (n = {int(fit['e_x_n'].sel(ball=ball, bat=bat))})"
                )
    if tracked:
        lines += ["", f"The systematic is {systematic_note(fit)}; the two add in quadrature to the total."]
        lines += _source_lines(fit)
    else:
        lines += ["", f"syst. —: {NO_SYSTEMATIC_NOTE}."]
    return "\n".join([*lines, "", *_header(impacts)])


def _source_lines(fit: xr.Dataset) -> list[str]:
    """Return the pooled e_x's systematic split by source, one line per ball (none for camera-tracked data alone)."""
    if systematic_note(fit) == SYSTEMATIC_NOTE:  # the default run's caption as it was
        return []
    lines = []
    for ball in fit["ball"].values.astype(str):
        parts = source_parts(fit.sel(ball=ball), "e_x_pooled")
        if parts:
            lines.append(f"- by source, pooled e_x of the {ball}: " + ", ".join(f"{n} {v:.2g}" for n, v in parts))
    return ["", *lines] if lines else []


def fig6_numbers(impacts: xr.Dataset, fit: xr.Dataset) -> str:
    """Eq. ratio slopes, implied e_y and the mu_k lower bound (Fig. 6)."""
    lines = [
        "Fitted slopes through the origin (standard errors):",
        "",
        *_slope_lines(fit, "tan_ratio_slope", "1"),
    ]
    lines += ["", "What they imply (Eqs. ratio and muk):", ""]
    for ball in fit["ball"].values.astype(str):
        if not math.isfinite(float(fit["tan_ratio_slope"].sel(ball=ball))):
            continue
        lines.append(
            f"- {ball}: e_y = {_pm(fit['e_y_implied'].sel(ball=ball), fit['e_y_implied_err'].sel(ball=ball))},"
            f" mu_k ≥ {_f(fit['mu_k_lower_bound'].sel(ball=ball))}"
        )
    return "\n".join([*lines, "", *_header(impacts)])


def fig9_numbers(stronge: xr.Dataset) -> str:
    """Fitted eta^2 of Stronge's model beside the paper's (Fig. 9, Sec. V.A)."""
    lines = ["Fitted tangential-stiffness parameter η² (standard error, 95 % interval):", ""]
    for ball in stronge["ball"].values.astype(str):
        s = stronge.sel(ball=ball)
        paper = _paper("eta2", ball)
        if "eta2_published" in s and math.isfinite(float(s["eta2_published"])):
            paper = _f(s["eta2_published"])
        lines.append(
            f"- {ball}: η² = {_pm(s['eta2'], s['eta2_err'])} ({_f(s['eta2_ci_low'])} to {_f(s['eta2_ci_high'])});"
            f" paper {paper}; with e_y = {_f(s['e_y'])}, μ = {_f(s['mu'])}."
            f" Initial stick ends at ψ = {_f(np.degrees(s['psi_stick_boundary']), '.1f')}°,"
            f" gross slip from ψ = {_f(np.degrees(s['psi_gross_slip_boundary']), '.1f')}°."
        )
    return "\n".join(lines)


def fig10_numbers(stronge: xr.Dataset) -> str:
    """Frequency ratio and the stick period of the time histories (Fig. 10)."""
    psi = stronge.attrs["psi_history_deg"]
    lines = [f"At ψ = {_f(psi)}° with the fitted η²:", ""]
    t = stronge["t_over_tc"].values
    for ball in stronge["ball"].values.astype(str):
        s = stronge.sel(ball=ball)
        start, end = stick_period(t, s["stick"].values)
        sep = t[np.isfinite(s["stick"].values)]
        stick = "no initial stick" if start is None else f"initial stick until t/t_c = {_f(end)}"
        lines.append(
            f"- {ball}: Ω_t/Ω_n = {_f(s['omega_ratio'])} (paper {_paper('omega_ratio', ball)}); {stick};"
            f" separation at t/t_c = {_f(sep[-1]) if sep.size else 'n/a'}."
        )
    return "\n".join(lines)


def stick_period(t: ArrayLike, stick: ArrayLike) -> tuple[float | None, float | None]:
    """Start and end (in units of ``t``) of the first run of ``stick == 1``; (None, None) if none."""
    stuck = np.asarray(stick) == 1
    if not stuck.any():
        return None, None
    i0 = int(np.argmax(stuck))
    rest = ~stuck[i0:]
    i1 = i0 + int(np.argmax(rest)) if rest.any() else len(t) - 1
    return float(t[i0]), float(t[i1])


def _case_note(scenario: xr.Dataset) -> str:
    """Return a note on a D sweep that is not Sec. V.B's case (empty for the paper's case)."""
    a = scenario.attrs
    if "pitch_mph" not in a:
        return "The pitch and swing are not recorded: the paper's Sec. V.B numbers are not quoted."
    case = f"{_f(a['pitch_mph'], '.0f')} mph pitch, {_f(a['bat_mph'], '.0f')} mph swing"
    if int(a.get("paper_case", 0)):
        return ""
    return f"Not the paper's case ({case}; Sec. V.B: 85 mph pitch, 73 mph swing): its numbers are not compared."


def _band_text(scenario: xr.Dataset, q: str, i: int, unit: str, fmt: str) -> str:
    if f"{q}_low68" not in scenario:
        return ""
    v = {t: from_si(scenario[f"{q}_{t}"].values[i], unit) for t in ("low68", "high68", "low95", "high95")}
    return (
        f" (68 %: {_f(v['low68'], fmt)} to {_f(v['high68'], fmt)}, 95 %: {_f(v['low95'], fmt)} to"
        f" {_f(v['high95'], fmt)} {unit} from e_x's uncertainty)"
    )


def fig11_numbers(scenario: xr.Dataset) -> str:
    """Exit speed, spin and carry of a D sweep (Fig. 11, Sec. V.B); the paper's words only for its own case."""
    D = from_si(scenario["D"].values, "in")
    speed = from_si(scenario["exit_speed"].values, "mph")
    carry = from_si(scenario["carry"].values, "ft")
    spin = from_si(scenario["backspin"].values, "rpm")
    i_v, i_c, i_0 = int(np.nanargmax(speed)), int(np.nanargmax(carry)), int(np.argmin(np.abs(D)))
    note = _case_note(scenario)
    paper = not note
    lines = [
        f"Ball {scenario.attrs.get('ball', '?')}, bat {scenario.attrs.get('bat', '?')},"
        f" e_x = {_f(scenario.attrs.get('e_x', np.nan))}:",
        "",
        f"- Largest exit speed {_f(speed[i_v], '.1f')} mph"
        + _band_text(scenario, "exit_speed", i_v, "mph", ".1f")
        + f" at D = {_f(D[i_v], '.2f')} in"
        + (" (paper: peaks near D = 0)." if paper else "."),
        f"- Spin at D = {_f(D[i_0], '.2f')} in: {_f(spin[i_0], '.0f')} rpm (negative: topspin).",
        f"- Longest carry {_f(carry[i_c], '.0f')} ft"
        + _band_text(scenario, "carry", i_c, "ft", ".0f")
        + f" at D = {_f(D[i_c], '.2f')} in,"
        f" launch angle {_f(np.degrees(scenario['launch_angle'].values[i_c]), '.1f')}°"
        + (" (paper: about 400 ft)." if paper else "."),
    ]
    if "exceeds_mu" in scenario:
        n = int(np.count_nonzero(scenario["exceeds_mu"].values == 1))
        lines.append(f"- {n} of {scenario.sizes['case']} offsets would need more friction than μ allows (shaded).")
    if note:
        lines += ["", note]
    return "\n".join(lines)


def launch_numbers(scenario: xr.Dataset) -> str:
    """Carry of each launch condition of a launch-conditions scenario."""
    lines = ["Carry of each launch condition:", ""]
    for i in range(scenario.sizes["case"]):
        c = scenario.isel(case=i)
        lines.append(
            f"- {_f(from_si(c['exit_speed'].values, 'mph'), '.1f')} mph,"
            f" {_f(np.degrees(c['launch_angle'].values), '.1f')}°,"
            f" {_f(from_si(c['backspin'].values, 'rpm'), '.0f')} rpm:"
            f" carry {_f(from_si(c['carry'].values, 'ft'), '.0f')} ft"
        )
    return "\n".join(lines)


def comparison_html(csv_path: str | os.PathLike[str], html_path: str | os.PathLike[str], title: str) -> str:
    """Write a paper-comparison CSV as a self-contained HTML table (for the report)."""
    rows, left_out = applicable_rows(read_csv(csv_path))
    head = "".join(f"<th>{html.escape(c)}</th>" for c in COLUMNS)
    body = "\n".join(
        "<tr>" + "".join(f"<td>{html.escape(str(r.get(c, '')))}</td>" for c in COLUMNS) + "</tr>" for r in rows
    )
    text = (
        "<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>"
        + html.escape(title)
        + "</title><style>body{font-family:sans-serif;font-size:13px}table{border-collapse:collapse}"
        "td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}"
        "td:nth-child(-n+3),th{text-align:left}tr:nth-child(even){background:#f4f4f4}</style></head>\n<body><h3>"
        + html.escape(title)
        + "</h3>\n<table>\n<tr>"
        + head
        + "</tr>\n"
        + body
        + "\n</table>"
        + (
            "<p>Rows that do not apply to this dataset (paper_comparison.csv keeps them):</p><ul>"
            + "".join(f"<li>{html.escape(n)}</li>" for n in left_out)
            + "</ul>"
            if left_out
            else ""
        )
        + "</body></html>\n"
    )
    atomic_write_text(html_path, text)
    return text
