"""Trajectories for a lab's own bat: a scenario's e_x from a dataset, with its uncertainty as bands.

A D-sweep scenario with ``e_x_from_dataset`` takes the e_x of its bat from that dataset's
``fit_ex.nc`` (:func:`dataset_e_x`: the bat's own e_x when the dataset fitted that bat with the
scenario's ball, else the ball's pooled e_x) with its statistical and systematic errors. The
scenario is run at the fitted e_x and again at e_x + z sigma, sigma the two in quadrature, for z
on a grid over [-1.96, 1.96] (:data:`Z_GRID`); the 68 % (95 %) band of exit speed, launch angle,
backspin and carry at each D is the range of the runs with |z| <= 1 (1.96). Where a quantity is
monotone in e_x over the band (docs/flight.md "Bands from e_x"), that range is exactly the
quantity at the e_x interval's ends, so it has the interval's coverage; where it is not, the
range still holds every value the interval's e_x give on the grid.

:func:`scenario_with_bands` is the one entry: the workflow's implications rule and ``ballbat hit``
both call it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .stages import implications as stage

if TYPE_CHECKING:
    import xarray as xr

    from .properties import Ball, Bat

#: 68.27 % and 95 % of a normal distribution: the bands' half widths in standard errors.
Z68, Z95 = 1.0, 1.959963984540054
#: The e_x offsets (in standard errors) at which the scenario is run again.
Z_GRID = (-Z95, -1.5, -Z68, -0.5, 0.5, Z68, 1.5, Z95)
#: The quantities that get bands: name -> units (those of the scenario file).
BANDED = {"exit_speed": "m s-1", "launch_angle": "rad", "backspin": "rad s-1", "carry": "m"}


@dataclass(frozen=True)
class DatasetEx:
    """The e_x a scenario takes from a dataset: value, statistical and systematic error, and where from."""

    value: float
    stat: float
    syst: float
    source: str  # "bat" (the bat's own e_x) or "pooled" (the ball's pooled e_x)
    dataset: str

    @property
    def sigma(self) -> float:
        """The standard uncertainty of e_x: statistical and systematic in quadrature."""
        return float(np.hypot(self.stat, self.syst))


def _finite_or_zero(ds: xr.Dataset, name: str, **sel: str) -> float:
    if name not in ds:
        return 0.0
    v = float(ds[name].sel(**sel))
    return v if np.isfinite(v) else 0.0


def dataset_e_x(fit: xr.Dataset, ball: str, bat: str | None, dataset: str) -> DatasetEx:
    """Return the e_x of ``bat`` with ``ball`` in a dataset's fit_ex.nc, or the ball's pooled e_x.

    The bat's own e_x when the dataset has a value of it (``e_x_status`` 0); else the pooled e_x
    of the ball. Raises ValueError naming the dataset when neither has a value.
    """
    balls = [str(b) for b in fit["ball"].values]
    if ball not in balls:
        raise ValueError(f"dataset {dataset}: no e_x for ball {ball!r} (its balls: {', '.join(balls)})")
    if bat is not None and bat in fit["bat"].values and np.isfinite(float(fit["e_x"].sel(ball=ball, bat=bat))):
        sel = {"ball": ball, "bat": bat}
        value, stat = float(fit["e_x"].sel(**sel)), float(fit["e_x_err"].sel(**sel))
        return DatasetEx(value, stat, _finite_or_zero(fit, "e_x_syst", **sel), "bat", dataset)
    value = float(fit["e_x_pooled"].sel(ball=ball))
    if not np.isfinite(value):
        raise ValueError(f"dataset {dataset}: the pooled e_x of ball {ball!r} is NaN (fit failed)")
    stat = float(fit["e_x_pooled_err"].sel(ball=ball))
    return DatasetEx(value, stat, _finite_or_zero(fit, "e_x_pooled_syst", ball=ball), "pooled", dataset)


def case_attrs(scenario: dict) -> dict:
    """Return a D sweep's pitch and swing as attributes, and ``paper_case`` (1: Sec. V.B's case, 0: another one)."""
    from .published import PAPER_IMPLICATIONS_CASE

    if "sweep" not in scenario:
        return {}
    out = {k: float(scenario["sweep"][k]) for k in PAPER_IMPLICATIONS_CASE if k != "ball"}
    same = scenario["ball"] == PAPER_IMPLICATIONS_CASE["ball"] and all(
        np.isclose(v, PAPER_IMPLICATIONS_CASE[k]) for k, v in out.items()
    )
    return {**out, "paper_case": int(same)}


def bands(
    settings: stage.ImplicationsSettings, balls: dict[str, Ball], bats: dict[str, Bat], ex: DatasetEx
) -> dict[str, np.ndarray]:
    """Return ``{q}_low68``, ``{q}_high68``, ``{q}_low95``, ``{q}_high95`` for each banded quantity (SI).

    The scenario at e_x + z sigma for each z of :data:`Z_GRID` and at e_x itself; the range over
    |z| <= 1 and over |z| <= 1.96 at each case.
    """
    runs = {0.0: stage.run(settings, balls, bats, e_x=ex.value)}
    for z in Z_GRID:
        runs[z] = stage.run(settings, balls, bats, e_x=float(np.clip(ex.value + z * ex.sigma, -1.0, 1.0)))
    out = {}
    for q in BANDED:
        for tag, zmax in (("68", Z68), ("95", Z95)):
            stack = np.stack([r[q].values for z, r in runs.items() if abs(z) <= zmax + 1e-12])
            out[f"{q}_low{tag}"] = np.nanmin(stack, axis=0)
            out[f"{q}_high{tag}"] = np.nanmax(stack, axis=0)
    return out


def scenario_with_bands(
    settings: stage.ImplicationsSettings, balls: dict[str, Ball], bats: dict[str, Bat], ex: DatasetEx | None = None
) -> xr.Dataset:
    """Run a scenario (:func:`ballbat.stages.implications.run`); with ``ex``, at its e_x and with its bands.

    ``ex`` None: the scenario's own e_x, no bands (the stage's file, unchanged). A launch-conditions
    scenario has no e_x in it, so it gets no bands either.
    """
    ds = stage.run(settings, balls, bats, e_x=None if ex is None else ex.value)
    return with_bands(ds, settings, balls, bats, ex)


def with_bands(
    ds: xr.Dataset,
    settings: stage.ImplicationsSettings,
    balls: dict[str, Ball],
    bats: dict[str, Bat],
    ex: DatasetEx | None = None,
) -> xr.Dataset:
    """Return a scenario's Dataset (run at ``ex``'s e_x) with its case attributes and, with ``ex``, its bands."""
    ds.attrs.update(case_attrs(settings.scenario))
    if ex is None:
        return ds
    ds.attrs.update(
        e_x_stat=ex.stat,
        e_x_syst=ex.syst,
        e_x_source=f"{ex.source} e_x of dataset {ex.dataset}",
        e_x_dataset=ex.dataset,
    )
    if "sweep" not in settings.scenario or ex.sigma == 0:
        return ds
    for name, values in bands(settings, balls, bats, ex).items():
        q, tag = name.rsplit("_", 1)
        side = "lower" if tag.startswith("low") else "upper"
        level = tag.removeprefix("low").removeprefix("high")
        ds[name] = (
            ("case",),
            values,
            {
                "units": BANDED[q],
                "long_name": f"{side} end of the {level} % band of {q} from e_x's uncertainty "
                f"(stat. {ex.stat:.4g} and syst. {ex.syst:.4g} in quadrature)",
            },
        )
        ds[q].attrs["ancillary_variables"] = " ".join(f"{q}_{t}" for t in ("low68", "high68", "low95", "high95"))
    return ds
