"""Sweeps of a replicate study: what a sweep may vary and the dataset settings at each point.

A sweep varies one setting (``parameter``, ``values``) or several at once over the product
of their values (``grid``: setting -> values). Plain dictionaries only (no xarray), so that the
config check at every workflow start can use them without importing the analysis stack
(:mod:`ballbat.studies` runs the studies).
"""

from __future__ import annotations

import copy
import itertools
import math
from typing import TYPE_CHECKING

from ..datasets import renders

if TYPE_CHECKING:
    from collections.abc import Sequence

__all__ = [
    "CONTACT_HALF_WIDTH_MS",
    "SWEEP_PARAMETERS",
    "check_study_sweep",
    "check_sweep",
    "point_dataset",
    "study_dataset",
    "sweep_points",
    "truth_counts",
]


#: What a sweep may vary: name -> what it sets in the dataset's settings.
SWEEP_PARAMETERS = {
    "impacts_per_bat": "impacts of every ball on every bat it is swung with",
    "pixel_noise_px": "tracking noise of both cameras (pixels; datasets that render tracks)",
    "swing_fps": "frame rate of the swing camera (datasets that render tracks)",
    "spin_fps": "frame rate of the spin camera (datasets that render tracks)",
    "noise_scale": "factor on every direct measurement noise (datasets that do not render tracks)",
    "e_x": "true e_x of every bat and ball",
    "contact_ms": "rendered contact time (ms): drawn uniformly within CONTACT_HALF_WIDTH_MS of the value",
    "e_x_scatter": "intrinsic impact-to-impact standard deviation of every bat's true e_x",
    "psi_max_scale": "factor on the upper end of every ball's psi range (1: as configured; 0.4: a narrow range)",
    "spin_pixel_noise_px": "tracking noise of the spin camera alone (pixels; datasets that render tracks)",
}

#: A ``contact_ms`` sweep point c draws the renderer's contact times uniformly from
#: [c - 0.05, c + 0.05] ms (``render.contact_ms``): a narrow range about c, not one value, so
#: that the impacts of a point still differ a little, as real ones do.
CONTACT_HALF_WIDTH_MS = 0.05

#: Settings that need a dataset that renders camera tracks.
RENDER_PARAMETERS = ("pixel_noise_px", "swing_fps", "spin_fps", "contact_ms", "spin_pixel_noise_px")


def sweep_points(sweep: dict | None) -> tuple[tuple[str, ...], list[tuple[float, ...]]]:
    """Names of a sweep's settings and the settings at each of its points.

    Parameters
    ----------
    sweep : dict or None
        A study's ``sweep`` block: ``{parameter, values}`` or ``{grid: {name: values}}``.

    Returns
    -------
    (names, points)
        ``()`` and ``[]`` without a sweep; one name and one-element points for a one-parameter
        sweep; for a grid the names in the config's order and every combination of their
        values (the first name varies slowest).
    """
    if not sweep:
        return (), []
    if "grid" in sweep:
        names = tuple(sweep["grid"])
        return names, [tuple(float(v) for v in p) for p in itertools.product(*sweep["grid"].values())]
    return (sweep["parameter"],), [(float(v),) for v in sweep["values"]]


def _value_problem(parameter: str, v: float) -> str | None:
    if not math.isfinite(v):
        return f"{parameter} must be a finite number, not {v}"
    if parameter == "impacts_per_bat" and (v != int(v) or v < 3):
        return f"impacts per bat must be a whole number >= 3, not {v:g}"
    if parameter in ("swing_fps", "spin_fps", "noise_scale") and v <= 0:
        return f"{parameter} must be positive, not {v:g}"
    if parameter in ("pixel_noise_px", "spin_pixel_noise_px") and v <= 0:  # the schema allows 0, a study not
        return (
            f"{parameter} must be positive in a study, not {v:g}: a study measures how the tracking "
            "noise spreads the estimates around the truth, and without noise there is no spread to measure"
        )
    if parameter == "e_x_scatter" and not 0.0 <= v < 0.5:
        return f"e_x_scatter must lie in [0, 0.5), not {v:g}"
    if parameter == "psi_max_scale" and not 0.0 < v <= 2.0:
        return f"psi_max_scale must lie in (0, 2], not {v:g}"
    if parameter == "e_x" and not -1.0 < v < 1.0:
        return f"e_x must lie in (-1, 1), not {v:g}"
    from ..tracks.data import CONTACT_PRIOR  # the reduction's prior: the renderer's contacts must lie in it

    lo, hi = (1e3 * v for v in CONTACT_PRIOR)
    h = CONTACT_HALF_WIDTH_MS
    if parameter == "contact_ms" and not lo + h <= v <= hi - h:
        return (
            f"contact_ms must lie in [{lo + h:g}, {hi - h:g}] ms (its contacts are drawn within {h:g} ms of it, "
            f"inside the reduction's prior {lo:g}-{hi:g} ms), not {v:g}"
        )
    return None


def check_sweep(
    dataset: dict, parameter: str | None, values: Sequence[float], where: str, at: str | None = None
) -> list[str]:
    """Problems of a one-parameter sweep against its validated dataset (empty when fine), each naming ``where``.

    ``at`` is the config key of the values (default ``{where}.sweep.values``; a grid's
    ``{where}.sweep.grid.{parameter}``).
    """
    if parameter is None:
        return []
    at = at or f"{where}.sweep.values"
    name_at = f"{where}.sweep.parameter" if at.endswith(".values") else at
    problems = []
    rendered = renders(dataset)
    if parameter in RENDER_PARAMETERS and not rendered:
        problems.append(f"{name_at}: {parameter} needs a dataset that renders camera tracks")
    if parameter == "noise_scale" and rendered:
        problems.append(f"{name_at}: noise_scale scales the direct noise, but the dataset renders tracks")
    for i, v in enumerate(values):
        why = _value_problem(parameter, float(v))
        if why:
            problems.append(f"{at}[{i}]: {why}")
    return problems


def check_study_sweep(dataset: dict, study: dict, where: str) -> list[str]:
    """Problems of a study's sweep (one parameter or a grid) and of its ``draw_calibration``, each naming its key."""
    sweep = study.get("sweep") or {}
    problems = []
    if "grid" in sweep:
        for name, values in sweep["grid"].items():
            problems += check_sweep(dataset, name, values, where, at=f"{where}.sweep.grid.{name}")
            if len(set(map(float, values))) != len(values):
                problems.append(f"{where}.sweep.grid.{name}: a value is repeated ({list(values)}); give each once")
    else:
        problems += check_sweep(dataset, sweep.get("parameter"), sweep.get("values", ()), where)
    if study["draw_calibration"]:  # the validated study block (its defaults filled)
        if not renders(dataset):
            problems.append(f"{where}.draw_calibration: needs a dataset that renders camera tracks")
        else:
            render = dataset["render"]
            blocks = [*render["cameras"].values(), render["rig"]]
            stated = [k for b in blocks for k, v in b.items() if k.endswith(("_err", "_err_in")) and float(v) > 0]
            if not stated:
                problems.append(
                    f"{where}.draw_calibration: the dataset states no calibration uncertainty "
                    "(every m_per_px_err and fps_err of render.cameras and the rig's *_err_in are 0): "
                    "there is nothing to draw"
                )
    return problems


def study_dataset(dataset: dict, study: dict) -> dict:
    """Return the dataset's config block as a study replicates it (a copy): ``draw_calibration`` set in ``render``."""
    ds = copy.deepcopy(dataset)
    if study["draw_calibration"]:
        ds["render"]["draw_calibration"] = True
    return ds


def point_dataset(dataset: dict, parameter: str | Sequence[str] | None, value: float | Sequence[float]) -> dict:
    """Return the dataset's config block with the swept setting at ``value`` (a copy).

    A grid point gives the names and values as sequences (each set in turn, on one copy).
    """
    ds = copy.deepcopy(dataset)
    if parameter is None:
        return ds
    if isinstance(parameter, str):
        _set_swept(ds, parameter, value)
        return ds
    for name, v in zip(parameter, value, strict=True):
        _set_swept(ds, name, v)
    return ds


def _set_swept(ds: dict, parameter: str, value: float) -> None:
    """Set the swept setting ``parameter`` of the dataset block ``ds`` (in place) to ``value``."""
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
    elif parameter == "e_x_scatter":
        syn["e_x_scatter"] = float(value)
    elif parameter == "psi_max_scale":
        syn["psi_deg"] = {b: [float(lo), float(value) * float(hi)] for b, (lo, hi) in syn["psi_deg"].items()}
    elif parameter == "spin_pixel_noise_px":
        ds["render"]["cameras"]["spin"]["pixel_noise_px"] = float(value)
    elif parameter == "contact_ms":
        ds["render"]["contact_ms"] = [float(value) - CONTACT_HALF_WIDTH_MS, float(value) + CONTACT_HALF_WIDTH_MS]
    else:
        raise ValueError(f"unknown sweep parameter {parameter!r} (known: {', '.join(SWEEP_PARAMETERS)})")


def truth_counts(dataset: dict, truth_impacts: int) -> tuple[int, dict[str, dict[str, int]]]:
    """Return the impacts per ball and bat of a study's truth job, for the dataset at one sweep point.

    The one rule for the truth's size: the truth job runs it, and the memory plan, the run-time
    plan and the size guard read it. The truth repeats the point's design ``k`` times (every
    pair ``k`` times its own count), so that pooled quantities keep the design's proportions of
    bats, and ``k = ceil(P T / N)`` for ``P`` pairs of ``N`` impacts in all and ``T =
    truth_impacts``: the truth holds about ``T`` impacts per pair on average, whatever the
    balance of the design (``P T`` in all). The truth's sampling error relative to a replicate's
    standard error is the same for every pair, about the replicates' noise-free spread over their
    error divided by sqrt(k), since a pair of ``n`` impacts in a replicate has ``k n`` in the truth
    (``truth_error_over_se`` of the coverage table reports it).

    Parameters
    ----------
    dataset : dict
        The validated synthetic dataset's block at the sweep point (:func:`point_dataset`).
    truth_impacts : int
        The study's ``truth_impacts``.

    Returns
    -------
    (k, counts)
        The scale and ball -> bat -> impacts (a pair of no impacts keeps 0).
    """
    impacts = dataset["synthetic"]["impacts"]
    design = {b: {t: int(n) for t, n in (bats or {}).items()} for b, bats in impacts.items()}
    counts = [n for bats in design.values() for n in bats.values() if n > 0]
    if not counts:
        raise ValueError("the study's dataset has no impacts (every count is 0): nothing to take the truth of")
    k = max(1, math.ceil(len(counts) * int(truth_impacts) / sum(counts)))
    return k, {b: {t: n * k for t, n in bats.items()} for b, bats in design.items()}
