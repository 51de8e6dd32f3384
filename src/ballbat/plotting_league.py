"""The league table's forest plot (part of the plotting layer, with :mod:`ballbat.plotting`).

One panel per ball: each bat's e_x in each test session (small markers; thick bar the
statistical error, thin bar stat. and syst. in quadrature) and over its sessions (diamond),
the reference bat's e_x with the equivalence margin shaded.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from .league import ranked
from .plotting import ball_color, save_figure

if TYPE_CHECKING:
    import os

    import xarray as xr


def _panel(ax, ds: xr.Dataset, ball: str, ref: str | None) -> None:
    rows = [i for i in ranked(ds) if str(ds["ball"].values[i]) == ball][::-1]
    color = ball_color(ball)
    margin = float(ds.attrs["league_margin"])
    labels = []
    for y, i in enumerate(rows):
        bat = str(ds["bat"].values[i])
        labels.append(bat)
        mine = np.flatnonzero((ds["entry_ball"].values == ball) & (ds["entry_bat"].values == bat))
        offs = np.linspace(-0.25, 0.25, len(mine) + 2)[1:-1] if len(mine) > 1 else [0.0]
        for off, j in zip(offs, mine, strict=True):
            x, s = ds["entry_e_x"].values[j], ds["entry_e_x_stat"].values[j]
            t = np.hypot(s, ds["entry_e_x_syst"].values[j])
            ax.errorbar(x, y + off, xerr=t, fmt="none", ecolor=color, elinewidth=0.8, alpha=0.6)
            ax.errorbar(x, y + off, xerr=s, fmt="o", ms=3.5, color=color, elinewidth=2.0, alpha=0.8)
        if len(mine) > 1 and np.isfinite(ds["e_x"].values[i]):
            ax.errorbar(
                ds["e_x"].values[i],
                y,
                xerr=ds["e_x_err_total"].values[i],
                fmt="D",
                ms=7,
                mfc="white",
                mec=color,
                ecolor=color,
                elinewidth=1.2,
                zorder=3,
            )
        if bat == ref:
            ax.axvspan(ds["e_x"].values[i] - margin, ds["e_x"].values[i] + margin, color=color, alpha=0.12, lw=0)
    ax.set_yticks(range(len(rows)), labels)
    ax.set_ylim(-0.7, len(rows) - 0.3)
    ax.set_title(f"{ball} (shaded: reference {ref} +-{margin:g})" if ref else ball, fontsize=10)
    ax.grid(axis="x", alpha=0.3)


def forest_figure(ds: xr.Dataset) -> Figure:
    """Draw the forest plot of a league Dataset (:func:`ballbat.league.league`): one panel per ball."""
    balls = list(dict.fromkeys(str(b) for b in ds["ball"].values))
    refs = dict(part.split(": ") for part in ds.attrs["league_reference_bats"].split("; "))
    heights = [max(1, int((ds["ball"].values == b).sum())) + 1 for b in balls]
    fig = Figure(figsize=(7.2, 1.0 + 0.45 * sum(heights)), layout="constrained")
    axes = fig.subplots(len(balls), 1, squeeze=False, gridspec_kw={"height_ratios": heights})[:, 0]
    for ax, ball in zip(axes, balls, strict=True):
        ref = refs.get(ball)
        _panel(ax, ds, ball, None if ref in (None, "None") else ref)
    axes[-1].set_xlabel("e_x (dots: a test session, thick bar stat., thin stat.+syst.; diamond: over sessions)")
    fig.suptitle("League table: e_x per bat", fontsize=11)
    return fig


def save_forest(ds: xr.Dataset, path: str | os.PathLike[str], provenance: dict | None = None) -> None:
    """Draw :func:`forest_figure` and save it as a deterministic PNG at ``path``."""
    save_figure(forest_figure(ds), path, provenance)
