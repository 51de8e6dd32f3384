"""Stage render_tracks: ``results/{dataset}/tracks.nc``, both cameras' raw tracks of a synthetic experiment (Sec. II).

:func:`render` draws the tracks in memory (:func:`ballbat.tracks.render.render_tracks`; the replicate
studies reduce them as they are); :func:`tracks_dataset` is the file's layout (long rows and the
impact table), which the import_tracks rule writes too (tool files read by
:func:`ballbat.tracks.formats.layout.import_block`); :func:`run` is both.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..pipeline.products import Var, build_dataset
from ..tracks.data import to_long
from ..tracks.render import RenderSettings, render_tracks, settings_from_config
from .impacts import IMPACT_COORDS, SIMULATED_TRUTH, truth_var

if TYPE_CHECKING:
    from collections.abc import Mapping

    import xarray as xr

    from ..properties import Ball
    from ..tracks.data import Tracks

__all__ = ["RenderSettings", "from_config", "from_params", "render", "render_inputs", "run", "tracks_dataset"]


#: The variables of a tracks file (long rows along ``row``, the impact table along ``impact``);
#: a rendered file adds the truth of each impact (:func:`.impacts.truth_var`).
TRACKS_TABLE = {
    "camera": Var(("row",), None, "camera of the row (swing: Camera 1, spin: Camera 2)"),
    "point": Var(("row",), None, "tracked point (bat_tip, ball, dot_a, dot_b)"),
    "frame": Var(("row",), "1", "frame number of that camera (origin arbitrary)"),
    "x_px": Var(("row",), "1", "image x of the point (pixels, to the right)"),
    "y_px": Var(("row",), "1", "image y of the point (pixels, downward)"),
    "impact_id": Var(("row",), None, "impact of the row"),
    "bat": IMPACT_COORDS["bat"],
    "ball": IMPACT_COORDS["ball"],
}


def from_config(config: dict, dataset: str) -> RenderSettings:
    """Return the rendering settings of dataset ``dataset`` from the validated config (its ``render`` block)."""
    return from_params(config["datasets"][dataset]["render"])


def from_params(block: Mapping) -> RenderSettings:
    """Return the rendering settings from the rule's params (the dataset's ``render`` block)."""
    return settings_from_config(block)


def render(settings: RenderSettings, simulated: xr.Dataset, balls: dict[str, Ball]) -> Tracks:
    """Render both cameras' tracks of a synthetic experiment, in memory (the workflow and the studies).

    Parameters
    ----------
    settings : RenderSettings
    simulated : xarray.Dataset
        The synthetic experiment (``simulate.nc``), with its ``truth_*`` variables.
    balls : dict
        Ball table (radii).

    Returns
    -------
    Tracks
    """
    truth, r, ids, ball, bat = render_inputs(simulated, balls)
    return render_tracks(truth, r, settings, ids, ball, bat)


def render_inputs(simulated: xr.Dataset, balls: dict[str, Ball]) -> tuple[dict, np.ndarray, np.ndarray, ...]:
    """Return what the renderers take of a synthetic experiment: (truth, ball radii, impact ids, balls, bats)."""
    truth = {k: simulated[f"truth_{k}"].values for k in SIMULATED_TRUTH if f"truth_{k}" in simulated}
    r = np.array([balls[b].r for b in simulated["ball"].values.astype(str)])
    return truth, r, simulated["impact"].values.astype(str), simulated["ball"].values, simulated["bat"].values


def tracks_dataset(tracks: Tracks) -> xr.Dataset:
    """Return the rendered tracks as NetCDF: long rows (dimension ``row``) and the impact table (``impact``).

    Parameters
    ----------
    tracks : Tracks

    Returns
    -------
    xarray.Dataset
    """
    rows = to_long(tracks)
    table = dict(TRACKS_TABLE)
    values = {
        "camera": rows["camera"].astype(str),
        "point": rows["point"].astype(str),
        "frame": rows["frame"].astype(np.int64),
        "x_px": rows["x_px"],
        "y_px": rows["y_px"],
        "impact_id": rows["impact_id"].astype(str),
        "bat": tracks.bat.astype(str),
        "ball": tracks.ball.astype(str),
    }
    for k, v in tracks.truth.items():
        table[k] = truth_var(k)
        values[k] = v
    ds = build_dataset(
        table,
        values,
        coords={"impact": (Var(("impact",), None, "impact id"), tracks.impact_id.astype(str))},
        attrs={"n_impacts": int(tracks.n), "n_rows": int(rows["frame"].size)},
    )
    return ds


def run(settings: RenderSettings, simulated: xr.Dataset, balls: dict[str, Ball]) -> xr.Dataset:
    """Render both cameras' tracks of a synthetic experiment (``simulate.nc``); return ``tracks.nc``.

    Long rows (dimension ``row``) and the impact table with the truth (dimension ``impact``).
    """
    return tracks_dataset(render(settings, simulated, balls))
