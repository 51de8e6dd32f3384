"""The paper's figures, drawn from the workflow's NetCDF files alone.

Each ``fig*`` function takes the datasets a figure needs (as read by
:func:`ballbat.pipeline.ncio.read_dataset`) and returns a matplotlib Figure; nothing here fits or
recomputes a model, so restyling a figure never reruns a fit. Axes are in the paper's units
(:func:`ballbat.units.from_si`). As in the paper, closed markers are baseballs and open
markers softballs; the marker shape tells the bat. Fitted lines are dashed, the paper's
published lines dotted.

:func:`draw` is the one entry point of the workflow: it reads the inputs, draws a figure
(or two), saves PNG files deterministically (no timestamp or software version in the
metadata, so the same data give the same bytes) and writes the caption numbers
(:mod:`ballbat.reporting`).

Together with :mod:`ballbat.plotting_tracks` (the QA figures of the camera tracks, drawn with
this module's :func:`save_figure`) this is the plotting layer: the only modules that import
matplotlib (with the non-interactive Agg backend, set here). ``tests/test_lint.py`` checks it.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from . import reporting
from .pipeline.atomic import atomic_target
from .pipeline.ncio import atomic_write_text, read_dataset
from .units import from_si

if TYPE_CHECKING:
    import os
    from collections.abc import Mapping, Sequence

    import xarray as xr

#: Colour of each ball; baseballs are drawn with closed markers, softballs with open ones.
BALL_COLOR = {"baseball": "#1f3b73", "softball": "#c0392b"}
OTHER_COLORS = ("#2e7d32", "#6a1b9a", "#ef6c00", "#00838f")
#: Marker of each bat of Table II (others take the remaining shapes in order).
BAT_MARKER = {"wood": "o", "metal_rough": "s", "metal_smooth": "^", "softball_composite": "D"}
OTHER_MARKERS = ("v", "P", "X", "<", ">", "p", "*", "h")
FIGSIZE = (6.4, 4.8)
#: Data figures with the legend outside, on the right.
WIDE = (8.6, 4.8)
DPI = 110


def ball_color(ball: str, order: Sequence[str] = ()) -> str:
    """Return the colour of a ball type: the paper's two fixed, others from a palette in ``order``."""
    if ball in BALL_COLOR:
        return BALL_COLOR[ball]
    others = [b for b in order if b not in BALL_COLOR]
    return OTHER_COLORS[others.index(ball) % len(OTHER_COLORS)] if ball in others else "0.3"


def is_closed(ball: str) -> bool:
    """Tell whether a ball gets closed markers: baseballs (and all but softballs), as in the paper."""
    return ball != "softball"


def bat_marker(bat: str, order: Sequence[str] = ()) -> str:
    """Return the marker of a bat: Table II's four fixed, others from a list in ``order``."""
    if bat in BAT_MARKER:
        return BAT_MARKER[bat]
    others = [b for b in order if b not in BAT_MARKER]
    return OTHER_MARKERS[others.index(bat) % len(OTHER_MARKERS)] if bat in others else "o"


def _marker_kw(ball, bat, balls=(), bats=(), size=5.5):
    c = ball_color(ball, balls)
    return {
        "marker": bat_marker(bat, bats),
        "markersize": size,
        "markeredgecolor": c,
        "markerfacecolor": c if is_closed(ball) else "white",
        "color": c,
        "linestyle": "none",
    }


def _new(figsize=FIGSIZE):
    fig = Figure(figsize=figsize, dpi=DPI, layout="constrained")
    return fig, fig.add_subplot()


def _usable(impacts):
    return impacts.isel(impact=np.flatnonzero(impacts["flag"].values == 0))


def _groups(impacts):
    """(ball, bat, index array) for each ball and bat present, in a stable order."""
    balls = impacts["ball"].values.astype(str)
    bats = impacts["bat"].values.astype(str)
    ball_order = sorted(set(balls), key=lambda b: (b not in BALL_COLOR, b))
    bat_order = sorted(
        set(bats), key=lambda b: (b not in BAT_MARKER, list(BAT_MARKER).index(b) if b in BAT_MARKER else 0, b)
    )
    out = []
    for ball in ball_order:
        for bat in bat_order:
            idx = np.flatnonzero((balls == ball) & (bats == bat))
            if idx.size:
                out.append((ball, bat, idx))
    return out, ball_order, bat_order


def _errorbars(ax, impacts, x, y, xerr=None, yerr=None):
    """Draw data points with error bars, one legend entry per ball and bat (only usable impacts)."""
    groups, ball_order, bat_order = _groups(impacts)
    for ball, bat, idx in groups:
        kw = _marker_kw(ball, bat, ball_order, bat_order)
        ax.errorbar(
            x[idx],
            y[idx],
            xerr=None if xerr is None else xerr[idx],
            yerr=None if yerr is None else yerr[idx],
            elinewidth=0.7,
            capsize=0,
            alpha=0.9,
            label=f"{ball}, {bat} (n = {idx.size})",
            **kw,
        )
    return ball_order


def _excluded_note(ax, n_excluded):
    ax.text(
        0.99,
        0.01,
        f"{n_excluded} flagged impact{'s' if n_excluded != 1 else ''} not shown",
        transform=ax.transAxes,
        ha="right",
        va="bottom",
        fontsize=7,
        color="0.35",
    )


def _legend(ax, **kw):
    ax.legend(fontsize=7, frameon=False, **kw)


def _axes_from_origin(ax, xlabel: str, ylabel: str, title: str) -> None:
    """Label a plot whose data start at the origin (both axes from 0)."""
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)


def _legend_outside(fig, ax):
    """Legend to the right of the axes, so it never hides data points."""
    fig.legend(*ax.get_legend_handles_labels(), loc="outside right center", fontsize=7, frameon=False)


def _slope_figure(impacts, fit, yvar, var, unit_y, ylabel, what):
    """Figs. 3 and 4: a normalised quantity against theta with fitted and published lines.

    ``var`` is the slope's name in ``fit`` and in :data:`reporting.PAPER`; slopes are drawn in
    ``unit_y`` per degree.
    """
    unit_slope = f"{unit_y}/deg"
    published = reporting.PAPER[var]
    n_excluded = reporting.excluded_count(impacts)
    imp = _usable(impacts)
    x = from_si(imp["theta"].values, "deg")
    y = from_si(imp[yvar].values, unit_y)
    xerr = from_si(imp["theta_err"].values, "deg") if "theta_err" in imp else None
    yerr = from_si(imp[f"{yvar}_err"].values, unit_y) if f"{yvar}_err" in imp else None
    fig, ax = _new(WIDE)
    balls = _errorbars(ax, imp, x, y, xerr, yerr)
    ball_of = imp["ball"].values.astype(str)
    for ball in balls:
        if ball not in fit["ball"].values or not np.isfinite(float(fit[var].sel(ball=ball))):
            continue
        sel = ball_of == ball
        xs = np.linspace(x[sel].min(), x[sel].max(), 50)
        slope = float(fit[var].sel(ball=ball))
        err = float(fit[f"{var}_err"].sel(ball=ball))
        icpt = float(fit[f"{var}_intercept"].sel(ball=ball))
        s_paper = from_si(slope, unit_slope)
        ax.plot(
            xs,
            from_si(icpt + slope * np.radians(xs), unit_y),
            "--",
            color=ball_color(ball, balls),
            lw=1.5,
            label=f"{ball} fit: {s_paper:.3g} ± {from_si(err, unit_slope):.2g} {unit_slope}",
        )
        if ball in published:
            # The paper gives the slope only: draw it through the centroid of our data.
            xm, ym = x[sel].mean(), y[sel].mean()
            ax.plot(
                xs,
                ym + published[ball] * (xs - xm),
                ":",
                color=ball_color(ball, balls),
                lw=2.2,
                alpha=0.6,
                label=f"{ball} paper: {published[ball]:g} {unit_slope} (through our mean)",
            )
    ax.set_xlabel("launch angle θ (deg)")
    ax.set_ylabel(ylabel)
    ax.set_title(what, fontsize=10)
    _legend_outside(fig, ax)
    _excluded_note(ax, n_excluded)
    return fig


#: Figs. 3 and 4: what each plots against theta (variable, slope's name, unit, axis label, title).
_SLOPE_FIGURES = {
    "fig3": (
        "omega_norm",
        "spin_theta_slope",
        "rpm",
        "normalised spin ω (rpm)",
        "Fig. 3: normalised spin vs launch angle",
    ),
    "fig4": (
        "v_ball_norm",
        "speed_theta_slope",
        "mph",
        "normalised exit speed (mph)",
        "Fig. 4: normalised exit speed vs launch angle",
    ),
}


def fig3_spin_vs_theta(impacts: xr.Dataset, fit: xr.Dataset) -> Figure:
    """Fig. 3: normalised spin against launch angle, with the fitted and published slopes."""
    return _slope_figure(impacts, fit, *_SLOPE_FIGURES["fig3"])


def fig4_speed_vs_theta(impacts: xr.Dataset, fit: xr.Dataset) -> Figure:
    """Fig. 4: normalised exit speed against launch angle, with the fitted and published slopes."""
    return _slope_figure(impacts, fit, *_SLOPE_FIGURES["fig4"])


def _lines_through_origin(ax, x, imp, balls, fit, var, paper_key, offset, name):
    """Figs. 5 and 6: each ball's fitted line through the origin (slope ``offset + fit[var]``) and the paper's."""
    ball_of = imp["ball"].values.astype(str)
    for ball in balls:
        if ball not in fit["ball"].values or not np.isfinite(float(fit[var].sel(ball=ball))):
            continue
        xb = np.linspace(0.0, np.nanmax(x[ball_of == ball]) * 1.05, 50)
        slope, err = offset + float(fit[var].sel(ball=ball)), float(fit[f"{var}_err"].sel(ball=ball))
        c = ball_color(ball, balls)
        ax.plot(xb, slope * xb, "--", color=c, lw=1.5, label=f"{ball} fit: {name}{slope:.3f} ± {err:.3f}")
        paper = reporting.PAPER[paper_key].get(ball)
        if paper is not None:
            ax.plot(xb, paper * xb, ":", color=c, lw=2.2, alpha=0.6, label=f"{ball} paper: {paper:g}")


def fig5_spin_vs_bracket(impacts: xr.Dataset, fit: xr.Dataset) -> Figure:
    """Fig. 5: spin against the bracket of Eq. omega; slopes 1 + e_x, and the unit slope."""
    n_excluded = reporting.excluded_count(impacts)
    imp = _usable(impacts)
    x = from_si(imp["spin_bracket"].values, "rpm")
    y = from_si(imp["omega"].values, "rpm")
    yerr = from_si(imp["omega_err"].values, "rpm") if "omega_err" in imp else None
    fig, ax = _new(WIDE)
    balls = _errorbars(ax, imp, x, y, None, yerr)
    xs = np.linspace(0.0, np.nanmax(x) * 1.05, 50)
    ax.plot(xs, xs, "-", color="0.2", lw=1.0, label="unit slope (e_x = 0)")
    _lines_through_origin(ax, x, imp, balls, fit, "e_x_pooled", "fig5_slope", offset=1.0, name="1 + e_x = ")
    # e_x per bat (Table II) in a corner.
    rows = []
    for ball in fit["ball"].values.astype(str):
        for bat in fit["bat"].values.astype(str):
            v, e = float(fit["e_x"].sel(ball=ball, bat=bat)), float(fit["e_x_err"].sel(ball=ball, bat=bat))
            if np.isfinite(v):
                rows.append(f"{ball[:4]} {bat}: {v:.3f} ± {e:.3f}")
    if rows:
        ax.text(
            0.99,
            0.06,
            "e_x per bat\n" + "\n".join(rows),
            transform=ax.transAxes,
            ha="right",
            va="bottom",
            fontsize=6.5,
            family="monospace",
            bbox={"facecolor": "white", "edgecolor": "0.8", "alpha": 0.9},
        )
    _axes_from_origin(
        ax, "v_bat sin ψ / [r (1 + r_x)(1 + α)]  (rpm)", "spin ω (rpm)", "Fig. 5: spin vs the bracket of Eq. (omega)"
    )
    _legend_outside(fig, ax)
    _excluded_note(ax, n_excluded)
    return fig


def fig6_tan_ratio(impacts: xr.Dataset, fit: xr.Dataset) -> Figure:
    """Fig. 6: tan(ψ − θ) against tan ψ, with the fitted and published slopes (Eq. ratio)."""
    n_excluded = reporting.excluded_count(impacts)
    imp = _usable(impacts)
    x = imp["tan_psi"].values
    y = imp["tan_psi_minus_theta"].values
    fig, ax = _new(WIDE)
    balls = _errorbars(ax, imp, x, y)
    _lines_through_origin(ax, x, imp, balls, fit, "tan_ratio_slope", "tan_ratio_slope", offset=0.0, name="")
    _axes_from_origin(ax, "tan ψ", "tan(ψ − θ)", "Fig. 6: tan(ψ − θ) vs tan ψ (Eq. ratio)")
    _legend_outside(fig, ax)
    _excluded_note(ax, n_excluded)
    return fig


# --- Sec. V.A: Stronge's model (results/{dataset}/stronge.nc) ---------------------------------


def _stronge_balls(stronge):
    balls = [str(b) for b in stronge["ball"].values]
    return sorted(balls, key=lambda b: (b not in BALL_COLOR, b))


def _stronge_data(ax, stronge, balls, size=5.5):
    data_ball = stronge["data_ball"].values.astype(str)
    for ball in balls:
        idx = np.flatnonzero(data_ball == ball)
        if not idx.size:
            continue
        kw = _marker_kw(ball, "wood", balls, size=size)
        ax.errorbar(
            stronge["data_vtf_x"].values[idx],
            stronge["data_vtf_y"].values[idx],
            yerr=stronge["data_vtf_y_err"].values[idx],
            elinewidth=0.7,
            label=f"{ball} data (n = {idx.size})",
            **kw,
        )


def _boundaries(s):
    """(psi, label) of the regime boundaries of one ball; one line when the two coincide."""
    stick, gross = float(s["psi_stick_boundary"]), float(s["psi_gross_slip_boundary"])
    if np.isfinite(stick) and np.isfinite(gross) and abs(stick - gross) < np.radians(0.5):
        return [(stick, "stick ends, gross slip")]
    return [(b, n) for b, n in ((stick, "stick ends"), (gross, "gross slip")) if np.isfinite(b)]


def _eta2_paper(s, ball):
    """Return the paper's eta^2 for a ball: from the file when it says, else Sec. V.A's."""
    if "eta2_published" in s and np.isfinite(float(s["eta2_published"])):
        return float(s["eta2_published"])
    return reporting.PAPER["eta2"].get(ball)


def fig9a_stronge_fit(stronge: xr.Dataset) -> Figure:
    """Fig. 9a: the data of Eq. vtf and Stronge's model with the fitted η², over the data's range."""
    balls = _stronge_balls(stronge)
    fig, ax = _new()
    _stronge_data(ax, stronge, balls)
    data_ball = stronge["data_ball"].values.astype(str)
    for ball in balls:
        s = stronge.sel(ball=ball)
        xd = stronge["data_vtf_x"].values[data_ball == ball]
        xmax = np.nanmax(xd) * 1.05 if xd.size else np.inf
        x = s["vtf_x_model"].values
        keep = x <= xmax
        lines = [("vtf_y_model", "--", f"{ball} fit: η² = {float(s['eta2']):.2f} ± {float(s['eta2_err']):.2f}")]
        if "vtf_y_published" in s:
            paper = _eta2_paper(s, ball)
            lines.append(("vtf_y_published", ":", f"{ball} paper: η² = {paper:g}" if paper else f"{ball} paper η²"))
        for var, style, label in lines:
            ax.plot(x[keep], s[var].values[keep], style, color=ball_color(ball, balls), lw=1.5, label=label)
    _axes_from_origin(
        ax, "tan ψ / (1 + r_x)", "(v_ball,t + r ω) / v_bat,n", "Fig. 9a: data and Stronge's model (fitted η²)"
    )
    _legend(ax, loc="upper left")
    return fig


def fig9b_stronge_extrapolation(stronge: xr.Dataset) -> Figure:
    """Fig. 9b: the model extrapolated to ψ = 85° (fitted and published η²), regime boundaries marked."""
    balls = _stronge_balls(stronge)
    fig = Figure(figsize=(6.4, 7.0), dpi=DPI, layout="constrained")
    top, bottom = fig.subplots(2, 1, height_ratios=(3, 2))
    _stronge_data(top, stronge, balls, size=3.5)
    psi = np.degrees(stronge["psi_grid"].values)
    styles = (("-", 1.0), ("--", 2.5))
    for k, ball in enumerate(balls):
        s = stronge.sel(ball=ball)
        c = ball_color(ball, balls)
        x = s["vtf_x_model"].values
        top.plot(x, s["vtf_y_model"].values, "--", color=c, lw=1.5, label=f"{ball} fit η² = {float(s['eta2']):.2f}")
        bottom.plot(psi, s["e_x_model"].values, "--", color=c, lw=1.5, label=f"{ball} fit")
        paper = _eta2_paper(s, ball)
        if "vtf_y_published" in s:
            top.plot(x, s["vtf_y_published"].values, ":", color=c, lw=1.5, label=f"{ball} paper η² = {paper:g}")
        if "e_x_published" in s:
            bottom.plot(psi, s["e_x_published"].values, ":", color=c, lw=1.5, label=f"{ball} paper")
        ls = styles[k % 2][0]
        for b, name in _boundaries(s):
            bottom.axvline(np.degrees(b), color=c, lw=0.8, ls=ls, alpha=0.7)
            bottom.text(
                np.degrees(b),
                0.98 - 0.1 * k,
                f" {name} ({ball})",
                transform=bottom.get_xaxis_transform(),
                color=c,
                fontsize=6.5,
                va="top",
                ha="right",
            )
            top.axvline(np.interp(b, stronge["psi_grid"].values, x), color=c, lw=0.8, ls=ls, alpha=0.7)
    top.set_xlim(left=0)
    top.set_ylim(bottom=0)
    top.set_xlabel("tan ψ / (1 + r_x)")
    top.set_ylabel("(v_ball,t + r ω) / v_bat,n")
    top.set_title("Fig. 9b: Stronge's model extrapolated to ψ = 85°", fontsize=10)
    _legend(top, loc="lower right")
    bottom.set_xlim(0, 90)
    bottom.set_xlabel("impact angle ψ (deg); vertical lines: end of initial stick, onset of gross slip")
    bottom.set_ylabel("e_x")
    bottom.axhline(0, color="0.6", lw=0.6)
    _legend(bottom, loc="lower left")
    return fig


def fig10_time_history(stronge: xr.Dataset) -> Figure:
    """Fig. 10: forces (curves, left) and tangential velocity (points, right) against t/t_c."""
    balls = _stronge_balls(stronge)
    t = stronge["t_over_tc"].values
    fig, ax = _new(WIDE)
    right = ax.twinx()
    curve = {0: ":", 1: "--"}
    step = max(1, len(t) // 40)
    # The paper's styles: baseball dotted, softball dashed; drawn last-first so that the
    # baseball's dotted curve stays visible where the two coincide (same e_y: same N(t)).
    for k, ball in reversed(list(enumerate(balls))):
        s = stronge.sel(ball=ball)
        c = ball_color(ball, balls)
        ls = curve.get(k, "-.")
        ax.plot(t, s["normal_force"].values, ls, color=c, lw=2.2 if k == 0 else 1.6, label=f"{ball} N/N_max")
        ax.plot(t, s["tangential_force"].values, ls, color=c, lw=1.0, alpha=0.8, label=f"{ball} F/N_max")
        kw = _marker_kw(ball, "wood", balls, size=4)
        right.plot(t[::step], s["tangential_velocity"].values[::step], label=f"{ball} tangential velocity", **kw)
        start, end = reporting.stick_period(t, s["stick"].values)
        if start is not None:
            y = 1.22 + 0.07 * k
            ax.plot([start, end], [y, y], "-", color=c, lw=2.5, solid_capstyle="butt")
            ax.text(end, y, f"  initial stick ({ball})", color=c, fontsize=7, va="center")
    right.axhline(0, color="0.3", ls="--", lw=0.8)
    psi = stronge.attrs["psi_history_deg"]
    ax.set_xlabel("t / t_c")
    ax.set_ylabel("force / peak normal force (curves)")
    right.set_ylabel("tangential velocity / initial normal speed (points)")
    ax.set_ylim(top=max(1.42, ax.get_ylim()[1]))
    ax.set_xlim(right=t[-1] * 1.22)  # room for the labels of the stick bars
    ax.set_title(f"Fig. 10: time histories at ψ = {psi:g}° (fitted η²)", fontsize=10)
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = right.get_legend_handles_labels()
    order = sorted(range(len(l1)), key=lambda i: l1[i])  # baseball first, as drawn in reverse
    h1, l1 = [h1[i] for i in order], [l1[i] for i in order]
    order = sorted(range(len(l2)), key=lambda i: l2[i])
    h2, l2 = [h2[i] for i in order], [l2[i] for i in order]
    fig.legend(h1 + h2, l1 + l2, fontsize=7, frameon=False, loc="outside right center")
    return fig


# --- Sec. V.B: batted balls (results/implications/{scenario}.nc) ------------------------------


def fig11a_exit_vs_D(scenario: xr.Dataset) -> Figure:
    """Fig. 11a: exit speed (left) and backspin (right) against D; launch angle on the top axis."""
    D = from_si(scenario["D"].values, "in")
    fig, ax = _new()
    right = ax.twinx()
    l1 = ax.plot(D, from_si(scenario["exit_speed"].values, "mph"), "-", color="#1f3b73", lw=1.8, label="exit speed")
    l2 = right.plot(D, from_si(scenario["backspin"].values, "rpm"), "--", color="#c0392b", lw=1.8, label="backspin")
    right.axhline(0, color="0.6", lw=0.6)
    handles = l1 + l2
    handles += _e_x_bands(ax, right, D, scenario)
    if "exceeds_mu" in scenario and np.any(scenario["exceeds_mu"].values == 1):
        bad = scenario["exceeds_mu"].values == 1
        ax.fill_between(D, 0, 1, where=bad, transform=ax.get_xaxis_transform(), color="0.85", step="mid", lw=0)
        handles.append(Rectangle((0, 0), 1, 1, color="0.85", label="needs more friction than μ"))
    ax.set_xlim(D.min(), D.max())
    ax.set_xlabel("offset D (in)")
    ax.set_ylabel("exit speed (mph), solid")
    right.set_ylabel("backspin (rpm), dashed")
    # Launch angle at the bottom axis's ticks, on a top axis.
    top = ax.twiny()
    top.set_xlim(ax.get_xlim())
    ticks = [d for d in ax.get_xticks() if D.min() <= d <= D.max()]
    top.set_xticks(ticks)
    top.set_xticklabels([f"{np.degrees(np.interp(d, D, scenario['launch_angle'].values)):.0f}" for d in ticks])
    top.set_xlabel("launch angle θ (deg)")
    ax.legend(handles=handles, fontsize=7, frameon=False, loc="center left")
    ax.set_title(f"Fig. 11a: {scenario.attrs.get('ball', '')} on the {scenario.attrs.get('bat', '')} bat", fontsize=10)
    return fig


def _e_x_bands(ax, right, D, scenario: xr.Dataset) -> list:
    """Shade exit speed's and backspin's 68 % and 95 % bands from e_x's uncertainty, where the file has them."""
    if "exit_speed_low68" not in scenario:
        return []
    for axis, q, unit, color in ((ax, "exit_speed", "mph", "#1f3b73"), (right, "backspin", "rpm", "#c0392b")):
        for tag, alpha in (("95", 0.12), ("68", 0.25)):
            lo, hi = (from_si(scenario[f"{q}_{s}{tag}"].values, unit) for s in ("low", "high"))
            axis.fill_between(D, lo, hi, color=color, alpha=alpha, lw=0)
    return [Rectangle((0, 0), 1, 1, color="#1f3b73", alpha=0.3, label="68 % / 95 % bands from e_x")]


def _pick_offsets(D_in, targets=(0.0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 2.0)):
    idx = []
    for d in targets:
        if D_in.min() - 1e-9 <= d <= D_in.max() + 1e-9:
            i = int(np.argmin(np.abs(D_in - d)))
            if i not in idx:
                idx.append(i)
    return idx


def fig11b_trajectories(scenario: xr.Dataset) -> Figure:
    """Fig. 11b: height against horizontal distance for a handful of offsets D, labelled on each curve."""
    D = from_si(scenario["D"].values, "in")
    fig, ax = _new((7.2, 4.2))
    cmap = matplotlib.colormaps["viridis"]
    idx = _pick_offsets(D)
    for k, i in enumerate(idx):
        c = cmap(k / max(1, len(idx) - 1) * 0.9)
        x = from_si(np.hypot(scenario["trajectory_x"].values[i], scenario["trajectory_y"].values[i]), "ft")
        z = from_si(scenario["trajectory_z"].values[i], "ft")
        ok = np.isfinite(x) & np.isfinite(z)
        ax.plot(x[ok], z[ok], "-", color=c, lw=1.5)
        j = int(np.nanargmax(np.where(ok, z, -np.inf)))
        ax.annotate(f"D = {D[i]:.2f} in", (x[j], z[j]), xytext=(2, 3), textcoords="offset points", fontsize=7, color=c)
    _axes_from_origin(ax, "horizontal distance (ft)", "height (ft)", "Fig. 11b: trajectories for several offsets D")
    return fig


def launch_carry(scenario: xr.Dataset) -> Figure:
    """Launch-conditions scenario: trajectories (left) and carry against launch angle (right)."""
    fig = Figure(figsize=(9.0, 4.0), dpi=DPI, layout="constrained")
    left, right = fig.subplots(1, 2)
    speed = from_si(scenario["exit_speed"].values, "mph")
    angle = np.degrees(scenario["launch_angle"].values)
    spin = from_si(scenario["backspin"].values, "rpm")
    carry = from_si(scenario["carry"].values, "ft")
    cmap = matplotlib.colormaps["viridis"]
    n = scenario.sizes["case"]
    for i in range(n):
        c = cmap(i / max(1, n - 1) * 0.9)
        x = from_si(np.hypot(scenario["trajectory_x"].values[i], scenario["trajectory_y"].values[i]), "ft")
        z = from_si(scenario["trajectory_z"].values[i], "ft")
        ok = np.isfinite(x) & np.isfinite(z)
        label = f"{speed[i]:.0f} mph, {angle[i]:.0f}°, {spin[i]:.0f} rpm" if n <= 12 else None
        left.plot(x[ok], z[ok], "-", color=c, lw=1.2, label=label)
    left.set_xlim(left=0)
    left.set_ylim(bottom=0)
    left.set_xlabel("horizontal distance (ft)")
    left.set_ylabel("height (ft)")
    if n <= 12:
        left.legend(fontsize=6.5, frameon=False)
    keys = sorted({(round(float(s), 3), round(float(w), 1)) for s, w in zip(speed, spin, strict=True)})
    for k, (s, w) in enumerate(keys):
        sel = (np.round(speed, 3) == s) & (np.round(spin, 1) == w)
        order = np.argsort(angle[sel])
        c = cmap(k / max(1, len(keys) - 1) * 0.9)
        right.plot(angle[sel][order], carry[sel][order], "o-", color=c, ms=4, label=f"{s:.0f} mph, {w:.0f} rpm")
    right.set_xlabel("launch angle (deg)")
    right.set_ylabel("carry (ft)")
    right.legend(fontsize=7, frameon=False)
    fig.suptitle("Batted balls for given launch conditions", fontsize=10)
    return fig


# --- the workflow's entry point --------------------------------------------------------------

#: figure -> (input names, {output name: function}, caption-numbers function)
FIGURES = {
    "fig3": (("impacts", "fit"), {"png": fig3_spin_vs_theta}, reporting.fig3_numbers),
    "fig4": (("impacts", "fit"), {"png": fig4_speed_vs_theta}, reporting.fig4_numbers),
    "fig5": (("impacts", "fit"), {"png": fig5_spin_vs_bracket}, reporting.fig5_numbers),
    "fig6": (("impacts", "fit"), {"png": fig6_tan_ratio}, reporting.fig6_numbers),
    "fig9": (("stronge",), {"fig9a": fig9a_stronge_fit, "fig9b": fig9b_stronge_extrapolation}, reporting.fig9_numbers),
    "fig10": (("stronge",), {"png": fig10_time_history}, reporting.fig10_numbers),
    "fig11": (("scenario",), {"fig11a": fig11a_exit_vs_D, "fig11b": fig11b_trajectories}, reporting.fig11_numbers),
    "launch": (("scenario",), {"png": launch_carry}, reporting.launch_numbers),
}


def _quantity_labels(cov: xr.Dataset) -> list[str]:
    """``quantity ball bat`` of each quantity of a study's coverage file (the figures' row labels)."""
    names = zip(cov["quantity_name"].values, cov["ball"].values, cov["bat"].values, strict=True)
    return [f"{q} {b} {t}".strip() for q, b, t in names]


def coverage_figure(cov: xr.Dataset, point: int = 0) -> Figure:
    """Coverage of a replicate study at one sweep point: 68 % and 95 % coverage and spread / SE per quantity.

    Parameters
    ----------
    cov : xarray.Dataset
        ``results/studies/{name}/coverage.nc``.
    point : int
        Sweep point to draw.

    Returns
    -------
    Figure
    """
    labels = _quantity_labels(cov)
    y = np.arange(len(labels))[::-1]
    fig = Figure(figsize=(10.0, 0.28 * len(labels) + 1.6), dpi=DPI, layout="constrained")
    axes = fig.subplots(1, 3, sharey=True)
    c = cov.isel(point=point)
    panels = (
        ("coverage_95", 0.95, (0.93, 0.97), "95 % intervals covering the truth"),
        ("coverage_68", 0.6827, (0.6627, 0.7027), "68 % intervals covering the truth"),
        ("spread_over_se", 1.0, (0.9, 1.1), "spread / mean standard error"),
    )
    for ax, (var, target, band, title) in zip(axes, panels, strict=True):
        ax.axvspan(*band, color="0.9", zorder=0)
        ax.axvline(target, color="0.4", lw=0.8, ls=":")
        ax.errorbar(c[var].values, y, xerr=c[f"{var}_err"].values, fmt="o", ms=4, color="#1f3b73", capsize=2)
        ax.set_title(title, fontsize=9)
        ax.grid(axis="x", alpha=0.3)
    axes[0].set_yticks(y, labels, fontsize=7)
    n = int(np.nanmax(c["n_replicates"].values)) if c["n_replicates"].size else 0
    setting = float(c["setting"])
    where = "" if not np.isfinite(setting) else f", {cov.attrs.get('sweep_parameter', '')} = {setting:g}"
    if "grid_setting" in c:  # a grid: this point's settings (the whole grid: grid_coverage_figure)
        vals = c["grid_setting"].values
        names = c["parameter"].values
        where = f", grid point {point + 1} of {cov.sizes['point']}: " + ", ".join(
            f"{n} = {v:g}" for n, v in zip(names, vals, strict=True)
        )
    fig.suptitle(f"Replicate study: {n} replicates{where} (grey: target)", fontsize=10)
    return fig


#: How a grid figure's axis names a swept setting's value.
GRID_LABELS = {
    "pixel_noise_px": "{v:g} px",
    "impacts_per_bat": "n {v:g}",
    "contact_ms": "{v:g} ms",  # the unit names it; short enough for 27 columns
    "swing_fps": "cam1 {v:g} fps",
    "spin_fps": "cam2 {v:g} fps",
    "noise_scale": "noise x{v:g}",
    "e_x": "e_x {v:g}",
    "e_x_scatter": "tau {v:g}",
    "psi_max_scale": "psi x{v:g}",
    "spin_pixel_noise_px": "cam2 {v:g} px",
}


def grid_coverage_figure(cov: xr.Dataset, band: tuple[float, float] = (0.93, 0.97)) -> Figure:
    """Draw a grid study's 95 % coverage at a glance: quantities x grid points, statistical and combined intervals.

    The statistical interval is judged around the value with the drawn calibration's first-order
    effect taken out, where the replicates draw their calibration (``coverage_95_calibrated``:
    what the statistical error claims to cover), around the value otherwise; the combined one
    around the value. Colour: the coverage (white at 95 %, blue above, red below). A cell whose coverage lies
    outside ``band`` by more than two binomial errors is marked with a cross, one outside the
    band but within two errors with a dot; a grey cell has no value (the combined interval of
    a quantity without a systematic, or no replicate).

    Parameters
    ----------
    cov : xarray.Dataset
        ``results/studies/{name}/coverage.nc`` of a study whose sweep is a grid (or any sweep;
        one-parameter sweeps give one row of labels).

    Returns
    -------
    Figure
    """
    from matplotlib.colors import TwoSlopeNorm

    labels = _quantity_labels(cov)
    if "grid_setting" in cov:
        names = [str(n) for n in cov["parameter"].values]
        table = cov["grid_setting"].values
    else:
        names = [str(cov.attrs.get("sweep_parameter") or "setting")]
        table = cov["setting"].values[:, None]
    fmt = [GRID_LABELS.get(n, n + " {v:g}") for n in names]
    cols = ["\n".join(f.format(v=v) for f, v in zip(fmt, row, strict=True)) for row in table]
    npt, nq = cov.sizes["point"], cov.sizes["quantity"]
    fig = Figure(figsize=(max(8.0, 0.42 * npt + 3.5), 2 * (0.2 * nq + 1.0) + 1.2), dpi=DPI, layout="constrained")
    axes = fig.subplots(2, 1, sharex=True)
    norm = TwoSlopeNorm(vmin=0.85, vcenter=0.95, vmax=1.0)
    cmap = matplotlib.colormaps["RdBu"].with_extremes(bad="0.8")
    image = None
    for ax, (var, title) in zip(
        axes,
        (
            ("coverage_95", "statistical 95 % interval (drawn calibration's effect taken out)"),
            ("coverage_95_combined", "combined 95 % interval (stat. and syst. in quadrature)"),
        ),
        strict=True,
    ):
        c = cov[var].values.T  # quantity x point
        e = cov[f"{var}_err"].values.T
        cal = f"{var}_calibrated"
        if cal in cov:  # the statistical interval where the calibration is drawn
            drawn = np.isfinite(cov[cal].values.T)
            c = np.where(drawn, cov[cal].values.T, c)
            e = np.where(drawn, cov[f"{cal}_err"].values.T, e)
        if var == "coverage_95" and not (cal in cov and drawn.any()):
            title = "statistical 95 % interval"
        image = ax.imshow(np.ma.masked_invalid(c), cmap=cmap, norm=norm, aspect="auto", interpolation="nearest")
        with np.errstate(invalid="ignore"):
            far = (c + 2 * e < band[0]) | (c - 2 * e > band[1])
            near = ((c < band[0]) | (c > band[1])) & ~far
        yq, xp = np.nonzero(far)
        ax.plot(xp, yq, "x", color="k", ms=5, mew=1.2, ls="none")
        yq, xp = np.nonzero(near)
        ax.plot(xp, yq, ".", color="k", ms=4, ls="none")
        if len(names) > 1:  # the first setting varies slowest: separate its blocks
            first = table[:, 0]
            for k in np.flatnonzero(first[1:] != first[:-1]):
                ax.axvline(k + 0.5, color="k", lw=0.8)
        ax.set_yticks(np.arange(nq), labels, fontsize=6.5)
        n = int(np.nanmax(cov["n_replicates"].values)) if cov["n_replicates"].size else 0
        ax.set_title(f"{title}; {n} replicates per point", fontsize=9)
    axes[1].set_xticks(np.arange(npt), cols, fontsize=6)
    bar = fig.colorbar(image, ax=axes, shrink=0.6, label="95 % coverage (below 85 %: darkest red)", extend="min")
    for b in band:
        bar.ax.axhline(b, color="k", lw=1.0)
    fig.suptitle(
        f"95 % coverage over the grid; target {band[0]:.0%}-{band[1]:.0%} (lines on the colour bar)\n"
        "x: outside it by more than 2 binomial errors; dot: outside within 2; grey: no value",
        fontsize=9,
    )
    return fig


def design_figure(des: xr.Dataset) -> Figure:
    """Draw a sweep's spread of e_x per bat and ball against the swept setting, and the impacts needed.

    Parameters
    ----------
    des : xarray.Dataset
        ``results/studies/{name}/design.nc``.

    Returns
    -------
    Figure
    """
    fig = Figure(figsize=(10.0, 4.4), dpi=DPI, layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    x = des["setting"].values
    balls = list(dict.fromkeys(des["ball"].values.astype(str)))
    bats = list(dict.fromkeys(des["bat"].values.astype(str)))
    param = des.attrs.get("sweep_parameter", "setting")
    for j, (ball, bat) in enumerate(zip(des["ball"].values.astype(str), des["bat"].values.astype(str), strict=True)):
        kw = {**_marker_kw(ball, bat, balls, bats, size=5), "linestyle": "-", "lw": 0.8}
        s = des["sigma_e_x"].values[:, j]
        ax1.errorbar(x, s, yerr=des["sigma_e_x_err"].values[:, j], label=f"{ball}, {bat}", **kw)
        ax2.plot(x, des["impacts_required"].values[:, j], **kw)
        if "impacts_required_answer" in des:  # one answer over the sweep, with its interval (ballbat.pilot)
            ax2.axhspan(
                des["impacts_required_answer_low"].values[j],
                des["impacts_required_answer_high"].values[j],
                color=kw.get("color", "0.5"),
                alpha=0.12,
                lw=0,
            )
            ax2.axhline(des["impacts_required_answer"].values[j], color=kw.get("color", "0.5"), lw=1.2, ls="--")
    if param == "impacts_per_bat":
        ax1.set_xscale("log")
        ax1.set_yscale("log")
        ax2.set_xscale("log")
    ax1.set_xlabel(param)
    ax1.set_ylabel("standard deviation of e_x over replicates")
    ax1.grid(alpha=0.3, which="both")
    ax1.legend(fontsize=7)
    delta, conf, power = (des.attrs[k] for k in ("delta_e_x", "confidence", "power"))
    ax2.set_xlabel(param)
    ax2.set_ylabel("impacts per bat needed")
    ax2.set_title(f"to tell two bats {delta:g} apart in e_x ({conf:.0%} confidence, {power:.0%} power)", fontsize=9)
    ax2.grid(alpha=0.3, which="both")
    return fig


def save_figure(fig: Figure, path: str | os.PathLike[str], provenance: Mapping[str, str] | None = None) -> Path:
    """Save ``fig`` as PNG atomically, without timestamp or software metadata (same data, same bytes).

    ``provenance`` (:func:`ballbat.pipeline.provenance.png_text`: the rule, each input with its
    sha256, the config, the versions, the commit) goes into PNG text chunks, one per key.
    """
    path = Path(path)
    with atomic_target(path, suffix=".png") as tmp:
        fig.savefig(tmp, format="png", dpi=DPI, metadata={"Software": None, **(provenance or {})})
    return path


def draw(figure: str, inputs: dict, outputs: dict, provenance: Mapping[str, str] | None = None) -> dict[str, Figure]:
    """Draw ``figure`` (a key of :data:`FIGURES`) from NetCDF ``inputs`` into PNG ``outputs``.

    ``inputs`` maps the figure's input names to paths; ``outputs`` maps each of its output
    names to a PNG path, and ``numbers`` to the caption fragment (reStructuredText).
    ``provenance`` goes into each PNG's text chunks (:func:`save_figure`).
    """
    try:
        names, pngs, numbers = FIGURES[figure]
    except KeyError:
        raise ValueError(f"unknown figure {figure!r}; known: {', '.join(FIGURES)}") from None
    data = {name: read_dataset(inputs[name]) for name in names}
    figs = {}
    for out, func in pngs.items():
        figs[out] = func(**data)
        save_figure(figs[out], outputs[out], provenance)
    if "numbers" in outputs:
        atomic_write_text(outputs["numbers"], numbers(**data) + "\n")
    return figs
