"""Stage normalize: ``results/{dataset}/normalize.nc``, spin and exit speed at the reference bat speed (Sec. II).

The impacts file of the source stage with :data:`NORMALIZE_TABLE` added
(:func:`ballbat.analysis.normalize_values`) and the reference bat speed as the attribute ``v_ref`` (SI).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..analysis import normalize_values
from ..columns import Columns
from ..pipeline.config import SectionSettings
from ..pipeline.products import Var, add_variables
from ..units import MPH

if TYPE_CHECKING:
    from collections.abc import Mapping

    import xarray as xr


@dataclass(frozen=True)
class NormalizeSettings(SectionSettings):
    """Settings of the normalize stage: the reference bat speed ``v_ref_mph`` (config ``normalize.v_ref_mph``)."""

    SECTION = "normalize"

    v_ref_mph: float

    @classmethod
    def from_params(cls, params: Mapping) -> NormalizeSettings:
        """Return the workflow's settings from the rule's params (``v_ref_mph``, as config ``normalize``)."""
        return cls(v_ref_mph=float(params["v_ref_mph"]))


#: Variables that ``normalize`` adds.
NORMALIZE_TABLE = {
    "omega_norm": Var(("impact",), "rad s-1", "spin normalised to the reference bat speed"),
    "omega_norm_err": Var(("impact",), "rad s-1", "standard uncertainty of normalised spin"),
    "v_ball_norm": Var(("impact",), "m s-1", "exit speed normalised to the reference bat speed"),
    "v_ball_norm_err": Var(("impact",), "m s-1", "standard uncertainty of normalised exit speed"),
}


def run(settings: NormalizeSettings, impacts: xr.Dataset) -> xr.Dataset:
    """Add spin and exit speed normalised to the reference bat speed (Sec. II, Figs. 3-4).

    Adds ``omega_norm`` and ``v_ball_norm`` (and their propagated standard uncertainties
    when the measurements carry ``*_err``): value * v_ref / v_bat, with v_ref =
    ``v_ref_mph`` (the config's value, in mph) recorded in SI as the attribute ``v_ref``.
    """
    v_ref = settings.v_ref_mph * MPH
    out = add_variables(impacts, NORMALIZE_TABLE, normalize_values(Columns(impacts), v_ref))
    out.attrs["v_ref"] = float(v_ref)
    out.attrs["v_ref_units"] = "m s-1"
    return out
