"""QA figures of the raw-track reduction (rule ``tracks_qa``): labs must be able to eyeball their tracks.

* :func:`impacts_figure` — for a few impacts (usable ones and, if any, excluded ones): the
  swing camera's view (tracked tip dot and ball, the fitted tip motion and ball flight,
  frames used marked), the spin camera's view (ball and dots, fitted centre path), and
  each dot's unwrapped angle about the fitted centre against time with the fitted spin.
* :func:`summary_figure` — residuals of every fit across impacts, and the flags.
* :func:`contact_sheet` (rule ``clips_qa``) — a few frames of a few clips with the points tracked in them.
* :func:`quality_figure` (rule ``clips_quality``) — the video tracker's quality per camera: the
  ball's edge-fit residuals, the points' contrasts, the points found and left out per reason.

Drawn from ``reduce.nc`` (the fitted parameters) and the tracks (the points); nothing is
refitted. Part of the plotting layer (with :mod:`ballbat.plotting`, which sets matplotlib's
Agg backend): the measurement chain (:mod:`ballbat.tracks`) never imports matplotlib. Figures
are saved deterministically by :func:`ballbat.plotting.save_figure`.
"""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from .plotting import save_figure
from .tracks.data import Camera, TrackBlocks, Tracks
from .tracks.reduce import FLAG_VAR, ReduceFlag, physical
from .units import G

__all__ = ["contact_sheet", "impacts_figure", "pick_impacts", "quality_figure", "save_figure", "summary_figure"]


def _cameras(red: xr.Dataset) -> dict[str, Camera]:
    return {
        c: Camera(
            float(red.attrs[f"{c}_fps"]),
            float(red.attrs[f"{c}_m_per_px"]),
            bool(red.attrs[f"{c}_mirror"]),
            float(red.attrs[f"{c}_m_per_px_rel_err"]),
            0.0,  # fps_err: the figures draw the tracks, not the systematics
            0.0,  # exposure_s: only the tip's fit uses it, and the figures draw the fits reduce.nc holds
        )
        for c in ("swing", "spin")
    }


def pick_impacts(red: xr.Dataset, n_ok: int = 2, n_excluded: int = 1) -> list[int]:
    """Return the indices of the impacts to show: the first usable ones and the first excluded ones."""
    flag = red[FLAG_VAR].values
    ok = list(np.flatnonzero(flag == 0)[:n_ok])
    bad = list(np.flatnonzero(flag != 0)[:n_excluded])
    return ok + bad


def _to_px(X, Y, cam: Camera):
    return cam.sign * X / cam.m_per_px, -Y / cam.m_per_px


def impacts_figure(red: xr.Dataset, tracks: Tracks | TrackBlocks, impacts: list[int] | None = None) -> Figure:
    """Both camera views and the dot angles of a few impacts, with the fitted motions.

    Parameters
    ----------
    red : xarray.Dataset
        ``reduce.nc``.
    tracks : Tracks or TrackBlocks
        The tracks it was reduced from (same impact order); only the shown impacts' blocks are read.
    impacts : list of int, optional
        Impact indices to show (default :func:`pick_impacts`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    idx = pick_impacts(red) if impacts is None else impacts
    cams = _cameras(red)
    fig = Figure(figsize=(13, 3.4 * max(len(idx), 1)), layout="constrained")
    axes = fig.subplots(max(len(idx), 1), 3, squeeze=False)
    for row, i in enumerate(idx):
        block, k = tracks.locate(i)  # the impact's block of the tracks (all of them when one)
        _swing_panel(axes[row, 0], red, block, cams["swing"], i, k)
        _spin_panel(axes[row, 1], red, block, cams["spin"], i, k)
        _dot_angle_panel(axes[row, 2], red, block, cams["spin"], i, k)
    return fig


def _camera_axes(ax, title: str) -> None:
    """Title, pixel labels (y down, as in the image) and the legend of a camera view."""
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("x (px)")
    ax.set_ylabel("y (px, down)")
    ax.invert_yaxis()
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize=7, loc="best")


def _swing_panel(ax, red: xr.Dataset, tracks: Tracks, cam: Camera, i: int, k: int) -> None:
    """Swing camera: tracked tip dot and ball, the fitted pre-impact tip motion and the ball flight.

    ``i``: the impact in ``red``; ``k``: its row in ``tracks`` (its block).
    """
    flag = int(red[FLAG_VAR].values[i])
    status = "usable" if flag == 0 else f"EXCLUDED ({ReduceFlag(flag).name.lower()})"
    ct = tracks.cameras["swing"]
    t = np.arange(ct.n_columns) / cam.fps
    for p, style in (
        ("bat_tip", dict(color="tab:brown", marker="s")),
        ("ball", dict(color="tab:blue", marker="o")),
    ):
        ax.scatter(
            ct.x[p][k],
            ct.y[p][k],
            s=9,
            facecolors="none",
            edgecolors=style["color"],
            marker=style["marker"],
            linewidths=0.7,
            label=f"{p} (tracked)",
        )
    pivot_to_tip = float(red.attrs["pivot_to_tip_m"])
    plane_angle = red["swing_plane_angle"].values[i]
    alignment_time = red["bat_alignment_time"].values[i]
    angular_speed = red["bat_angular_speed"].values[i]
    if np.isfinite(angular_speed):
        used = (t - alignment_time) <= 0
        along = red["tip_offset"].values[i] + pivot_to_tip * np.sin(angular_speed * (t - alignment_time))
        X = red["tip_centroid_x"].values[i] + along * np.cos(plane_angle)
        Y = red["tip_centroid_y"].values[i] + along * np.sin(plane_angle)
        x, y = _to_px(X, Y, cam)
        ax.plot(x[used], y[used], color="tab:brown", lw=1.2, label="tip fit (pre-impact)")
    _flight_line(ax, red, i, "swing", t, cam, ct.x["ball"][k])
    iid = red["impact_id"].values[i]
    contact = ""
    if "contact_time" in red and np.isfinite(red["contact_time"].values[i]):
        tc, tc_err = red["contact_time"].values[i], red["contact_time_err"].values[i]
        contact = f"\ncontact {1e3 * tc:.2f} ± {1e3 * tc_err:.2f} ms (fitted)"
    _camera_axes(ax, f"impact {iid}: swing camera ({cam.fps:g} fps) — {status}{contact}")


def _spin_panel(ax, red: xr.Dataset, tracks: Tracks, cam: Camera, i: int, k: int) -> None:
    """Spin camera: tracked ball and dots, and the fitted path of the ball's centre."""
    ct = tracks.cameras["spin"]
    t = np.arange(ct.n_columns) / cam.fps
    for p, c in (("ball", "tab:blue"), ("dot_a", "tab:red"), ("dot_b", "tab:green")):
        ax.scatter(ct.x[p][k], ct.y[p][k], s=9, color=c, label=p)
    _flight_line(ax, red, i, "spin", t, cam, ct.x["ball"][k])
    _camera_axes(ax, f"spin camera ({cam.fps:g} fps)")


def _dot_angle_panel(ax, red: xr.Dataset, tracks: Tracks, cam: Camera, i: int, k: int) -> None:
    """Each dot's unwrapped angle about the fitted centre against time, with the fitted spin."""
    ct = tracks.cameras["spin"]
    t = np.arange(ct.n_columns) / cam.fps
    cx, cy = _flight_xy(red, i, "spin", t)
    sep = red["separation_frame_spin"].values[i] - red["frame0_spin"].values[i]
    omega = red["omega"].values[i]
    for p, c in (("dot_a", "tab:red"), ("dot_b", "tab:green")):
        X, Y = physical(ct, cam, p)
        phi = np.arctan2(Y[k] - cy, X[k] - cx)
        ok = np.isfinite(phi) & (np.arange(t.size) >= sep)
        if ok.sum() < 2:
            continue
        phase = red[f"{p}_phase"].values[i]
        unwrapped = np.unwrap(phi[ok])
        unwrapped += 2 * np.pi * np.round((phase + omega * t[ok][0] - unwrapped[0]) / (2 * np.pi))
        ax.plot(1e3 * t[ok], np.degrees(unwrapped), "o", ms=3, color=c, label=f"{p} (tracked)")
        ax.plot(1e3 * t[ok], np.degrees(phase + omega * t[ok]), "-", color=c, lw=1)
    rpm = omega * 60 / (2 * np.pi)
    err = red["omega_err"].values[i] * 60 / (2 * np.pi)
    ax.set_title(f"dot angle about the centre: spin {rpm:.0f} ± {err:.0f} rpm", fontsize=9)
    ax.set_xlabel("time from the spin camera's first frame (ms)")
    ax.set_ylabel("angle (deg, counter-clockwise for a +x swing)")
    ax.legend(fontsize=7, loc="best")
    if int(red[FLAG_VAR].values[i]) != 0:
        ax.text(
            0.02,
            0.02,
            red[f"{FLAG_VAR}_reason"].values[i][:110],
            transform=ax.transAxes,
            fontsize=6,
            color="tab:red",
            wrap=True,
        )


def _flight_xy(red, i, cam_name, t):
    u = t - red[f"flight_t_ref_{cam_name}"].values[i]
    X = red[f"flight_x0_{cam_name}"].values[i] + red[f"flight_vx_{cam_name}"].values[i] * u
    Y = red[f"flight_y0_{cam_name}"].values[i] + red[f"flight_vy_{cam_name}"].values[i] * u - 0.5 * G * u**2
    return np.where(u >= 0, X, np.nan), np.where(u >= 0, Y, np.nan)


def _flight_line(ax, red, i, cam_name, t, cam, tracked):
    X, Y = _flight_xy(red, i, cam_name, t)
    seen = np.flatnonzero(np.isfinite(tracked))
    if seen.size:  # draw over the tracked frames only
        X, Y = np.where(np.arange(t.size) <= seen[-1], X, np.nan), np.where(np.arange(t.size) <= seen[-1], Y, np.nan)
    x, y = _to_px(X, Y, cam)
    ax.plot(x, y, color="tab:blue", lw=1.0, label="ball flight fit")


def summary_figure(red: xr.Dataset) -> Figure:
    """Residuals of the fits across impacts (in pixels and degrees) and the exclusion flags.

    Parameters
    ----------
    red : xarray.Dataset
        ``reduce.nc``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = Figure(figsize=(15, 3.2), layout="constrained")
    axes = fig.subplots(1, 5)
    ok = red[FLAG_VAR].values == 0
    panels = (
        ("tip_rms", red.attrs["swing_m_per_px"], "bat-tip fit rms (swing px)"),
        ("flight_rms_swing", red.attrs["swing_m_per_px"], "ball flight rms distance (swing px)"),
        ("flight_rms_spin", red.attrs["spin_m_per_px"], "ball flight rms distance (spin px)"),
        ("dot_angle_rms", np.pi / 180, "dot angle rms (deg)"),
    )
    for ax, (name, scale, label) in zip(axes[:4], panels, strict=True):
        v = red[name].values / scale
        bins = np.linspace(0, np.nanmax(v[np.isfinite(v)], initial=1.0) * 1.05, 25)
        ax.hist(v[ok & np.isfinite(v)], bins=bins, color="tab:blue", label="usable")
        ax.hist(v[~ok & np.isfinite(v)], bins=bins, color="tab:red", alpha=0.7, label="excluded")
        ax.set_xlabel(label)
        ax.set_ylabel("impacts")
        ax.legend(fontsize=7)
    ax = axes[4]
    flags = red[FLAG_VAR].values
    names = [f.name.lower().replace("_", " ") for f in ReduceFlag]
    counts = [int((flags == int(f)).sum()) for f in ReduceFlag]
    ax.barh(range(len(names)), counts, color=["tab:blue"] + ["tab:red"] * (len(names) - 1))
    ax.set_yticks(range(len(names)), names, fontsize=7)
    for k, c in enumerate(counts):
        ax.text(c, k, f" {c}", va="center", fontsize=7)
    ax.set_xlabel("impacts")
    ax.set_title(f"{int(ok.sum())} usable of {ok.size}", fontsize=9)
    return fig


#: Marker of each point on the contact sheet.
SHEET_MARKERS = {"ball": ("o", "tab:orange"), "bat_tip": ("s", "tab:cyan"), "dot_a": ("+", "tab:red")}
SHEET_MARKERS["dot_b"] = ("x", "tab:green")


def contact_sheet(rows: list) -> Figure:
    """Draw a contact sheet of clips: a few frames of each clip (a row), with the points tracked in each.

    Parameters
    ----------
    rows : list of :class:`ballbat.video.qa.SheetRow`
        Each clip's label and frames (frame number, image, point -> (x, y) in pixels).

    Returns
    -------
    matplotlib.figure.Figure
    """
    ncol = max((len(r.frames) for r in rows), default=1) or 1
    fig = Figure(figsize=(2.6 * ncol, 1.7 * max(len(rows), 1)), layout="constrained")
    axes = fig.subplots(max(len(rows), 1), ncol, squeeze=False)
    for ax in axes.ravel():
        ax.set_axis_off()
    for r, row in enumerate(rows):
        for c, (frame, img, points) in enumerate(row.frames):
            ax = axes[r, c]
            ax.imshow(img, cmap="gray", interpolation="nearest")
            for p, (x, y) in points.items():
                marker, color = SHEET_MARKERS.get(p, (".", "k"))
                ax.plot(x, y, marker, color=color, ms=5, mfc="none", mew=1.0, label=p)
            ax.set_title(f"{row.label}, frame {frame}", fontsize=7)
    handles = {
        p: axes[0, 0].plot([], [], m, color=col, mfc="none", label=p)[0] for p, (m, col) in SHEET_MARKERS.items()
    }
    fig.legend(handles.values(), handles.keys(), loc="outside lower center", ncol=4, fontsize=7)
    return fig


def quality_figure(cameras: list) -> Figure:
    """Draw the video tracker's quality per camera (a row each): residuals, contrasts, points found and left out.

    Parameters
    ----------
    cameras : list of :class:`ballbat.video.qa.CameraQuality`
        Each camera's quality (:func:`ballbat.video.qa.camera_quality`).

    Returns
    -------
    matplotlib.figure.Figure
        Per camera: the histogram of the ball's edge-fit RMS residual (px), the contrast of each
        point type (box plots), and the points found and left out per reason (bars, counts written).
    """
    n_bars = max((len(q.counts) for q in cameras), default=1)
    fig = Figure(figsize=(15, max(2.6, 0.22 * n_bars + 1.2) * max(len(cameras), 1)), layout="constrained")
    axes = fig.subplots(max(len(cameras), 1), 3, squeeze=False, width_ratios=(1, 1, 1.4))
    for row, q in zip(axes, cameras, strict=False):
        _residual_panel(row[0], q)
        _contrast_panel(row[1], q)
        _counts_panel(row[2], q)
    clips = sum(q.clips for q in cameras)
    frames = sum(q.frames for q in cameras)
    fig.suptitle(f"Tracking quality per camera: {clips} clips, {frames} frames", fontsize=11)
    return fig


def _residual_panel(ax, q) -> None:
    r = q.residual_px
    if r.size:
        ax.hist(r, bins=np.linspace(0.0, max(float(r.max()) * 1.05, 0.05), 30), color="tab:blue")
        ax.axvline(float(np.median(r)), color="k", lw=0.8, ls="--", label=f"median {np.median(r):.3f} px")
        ax.legend(fontsize=7)
    else:
        ax.text(0.5, 0.5, "no ball found", ha="center", va="center", transform=ax.transAxes)
    ax.set_xlabel("ball edge-fit RMS residual (px)")
    ax.set_ylabel("balls found")
    ax.set_title(f"{q.camera}: {q.clips} clips, {q.frames} frames", fontsize=9)


def _contrast_panel(ax, q) -> None:
    have = {t: v for t, v in q.contrast.items() if v.size}
    if have:
        ax.boxplot(list(have.values()), orientation="horizontal", tick_labels=list(have), widths=0.6)
        ax.invert_yaxis()  # the point types top down, as the counts' bars
        for k, v in enumerate(have.values(), start=1):
            ax.text(float(np.max(v)), k, f"  {v.size}", va="center", fontsize=7)
    else:
        ax.text(0.5, 0.5, "no point found", ha="center", va="center", transform=ax.transAxes)
    ax.set_xlabel("contrast (grey levels of the clip)")
    ax.set_title(f"{q.camera}: contrast of the points found", fontsize=9)


def _counts_panel(ax, q) -> None:
    labels = [f"{p}: {what}" for p, what in q.counts]
    counts = list(q.counts.values())
    colors = ["tab:blue" if what == "found" else "tab:red" for _, what in q.counts]
    ax.barh(range(len(counts)), counts, color=colors)
    ax.set_yticks(range(len(counts)), labels, fontsize=7)
    ax.invert_yaxis()
    for k, c in enumerate(counts):
        ax.text(c, k, f" {c}", va="center", fontsize=7)
    ax.set_xlabel("points")
    ax.set_title(f"{q.camera}: {q.found} found, {q.left_out} left out", fontsize=9)
