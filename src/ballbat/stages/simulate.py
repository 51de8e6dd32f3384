"""Stage simulate: ``results/{dataset}/simulate.nc``, a synthetic experiment like the paper's (Sec. II).

The impacts table (:mod:`.impacts`: the measurements, their uncertainties) and the truth of every
impact (``truth_*``), drawn by :func:`ballbat.synthetic.draw_experiment`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import xarray as xr

from ..pipeline.products import build_dataset
from ..synthetic import SyntheticSettings, draw_experiment
from .impacts import IMPACTS, QUANTITIES, SIMULATED_TRUTH, impact_coords, truth_var

if TYPE_CHECKING:
    from collections.abc import Mapping

    from ..pipeline.products import Var
    from ..properties import Ball, Bat

__all__ = ["SyntheticSettings", "from_config", "from_params", "run", "simulate_table"]


def from_config(config: dict, dataset: str) -> SyntheticSettings:
    """Return the settings of dataset ``dataset``'s synthetic experiment from the validated config."""
    return from_params(config["datasets"][dataset]["synthetic"])


def from_params(block: Mapping) -> SyntheticSettings:
    """Return the settings of a synthetic experiment from its rule's params (the dataset's ``synthetic`` block)."""
    return SyntheticSettings(**block)


def simulate_table() -> dict[str, Var]:
    """Return the variables of simulate.nc: the impacts table and the truth."""
    return {**IMPACTS, **{f"truth_{k}": truth_var(f"truth_{k}") for k in SIMULATED_TRUTH}}


def run(settings: SyntheticSettings, balls: dict[str, Ball], bats: dict[str, Bat]) -> xr.Dataset:
    """Draw a synthetic experiment; return one row per impact (dimension ``impact``).

    Raises ``KeyError``-free ``ValueError`` naming any ball or bat missing from the
    property tables or from the e_x/e_y settings.
    """
    exp = draw_experiment(settings, balls, bats)
    values = {}
    for k in QUANTITIES:
        values[k] = exp.measured[k]
        values[f"{k}_err"] = exp.sd[k]
    values.update({f"truth_{k}": exp.truth[k] for k in SIMULATED_TRUTH})
    return build_dataset(
        simulate_table(), values, coords=impact_coords(exp.ball, exp.bat), attrs={"synthetic_seed": exp.seed}
    )
