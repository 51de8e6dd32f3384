"""Sweeps of a replicate study: what a sweep may vary and the dataset settings at each point.

Plain dictionaries only (no xarray), so that the config check at every workflow start can use
them without importing the analysis stack (:mod:`ballbat.studies` runs the studies).
"""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Sequence

__all__ = ["SWEEP_PARAMETERS", "check_sweep", "point_dataset"]

#: What a sweep may vary: name -> what it sets in the dataset's settings.
SWEEP_PARAMETERS = {
    "impacts_per_bat": "impacts of every ball on every bat it is swung with",
    "pixel_noise_px": "tracking noise of both cameras (pixels; datasets that render tracks)",
    "swing_fps": "frame rate of the swing camera (datasets that render tracks)",
    "spin_fps": "frame rate of the spin camera (datasets that render tracks)",
    "noise_scale": "factor on every direct measurement noise (datasets that do not render tracks)",
    "e_x": "true e_x of every bat and ball",
}


def check_sweep(dataset: dict, parameter: str | None, values: Sequence[float], where: str) -> list[str]:
    """Problems of a study's sweep against its validated dataset (empty when fine), each naming ``where``."""
    from .pipeline.config import renders as renders_tracks

    if parameter is None:
        return []
    problems = []
    renders = renders_tracks(dataset)
    if parameter in ("pixel_noise_px", "swing_fps", "spin_fps") and not renders:
        problems.append(f"{where}.sweep.parameter: {parameter} needs a dataset that renders camera tracks")
    if parameter == "noise_scale" and renders:
        problems.append(f"{where}.sweep.parameter: noise_scale scales the direct noise, but the dataset renders tracks")
    for i, v in enumerate(values):
        if parameter == "impacts_per_bat" and (v != int(v) or v < 3):
            problems.append(f"{where}.sweep.values[{i}]: impacts per bat must be a whole number >= 3, not {v:g}")
        elif parameter in ("swing_fps", "spin_fps", "pixel_noise_px", "noise_scale") and v <= 0:
            problems.append(f"{where}.sweep.values[{i}]: {parameter} must be positive, not {v:g}")
        elif parameter == "e_x" and not -1.0 < v < 1.0:
            problems.append(f"{where}.sweep.values[{i}]: e_x must lie in (-1, 1), not {v:g}")
    return problems


def point_dataset(dataset: dict, parameter: str | None, value: float) -> dict:
    """Return the dataset's config block with the swept setting at ``value`` (a copy)."""
    ds = copy.deepcopy(dataset)
    if parameter is None:
        return ds
    syn = ds["synthetic"]
    if parameter == "impacts_per_bat":
        syn["impacts"] = {b: {t: int(value) for t in bats} for b, bats in syn["impacts"].items()}
    elif parameter == "e_x":
        syn["e_x"] = {b: {t: float(value) for t in bats} for b, bats in syn["e_x"].items()}
    elif parameter == "noise_scale":
        syn["noise"] = {k: float(v) * value for k, v in syn["noise"].items()}
    elif parameter == "pixel_noise_px":
        for cam in ds["render"]["cameras"].values():
            cam["pixel_noise_px"] = float(value)
    elif parameter in ("swing_fps", "spin_fps"):
        ds["render"]["cameras"][parameter.split("_")[0]]["fps"] = float(value)
    else:
        raise ValueError(f"unknown sweep parameter {parameter!r} (known: {', '.join(SWEEP_PARAMETERS)})")
    return ds
