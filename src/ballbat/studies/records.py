"""What a study's files record: the ``quantity`` coordinate, the sweep's attributes and table, the units.

Shared by the batch, truth and coverage files (:mod:`ballbat.studies.batch`, :mod:`.truth`, :mod:`.coverage`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..pipeline.products import Var
from .settings import StudySettings

if TYPE_CHECKING:
    from collections.abc import Sequence

    from numpy.typing import ArrayLike


#: Attributes of a variable whose values along ``quantity`` are in different units: SI, the unit of each
#: quantity in the coordinate ``units`` (CF has no units attribute for such a variable; ``units_from``
#: names the coordinate, :func:`ballbat.pipeline.ncio.check_metadata`).
PER_QUANTITY_UNITS = {"units_from": "units"}


def row_labels(rows: list[dict]) -> list[str]:
    """Return ``quantity:ball:bat`` of each row of :func:`run_replicate` (the batches' quantity labels)."""
    return [f"{r['quantity']}:{r['ball']}:{r['bat']}" for r in rows]


#: Largest fraction of a batch's replicates whose data the chain may refuse before the batch stops.


def quantity_coords(labels: list[str], parts: list[list[str]], units: list[str]) -> dict:
    """Return the ``quantity`` coordinate and its companions (name, ball, bat, SI unit) of a study's files."""
    return {
        "quantity": (Var(("quantity",), None, "quantity:ball:bat, as in paper_comparison.csv"), np.array(labels)),
        "quantity_name": (Var(("quantity",), None, "quantity"), np.array([p[0] for p in parts])),
        "ball": (Var(("quantity",), None, "ball type"), np.array([p[1] for p in parts])),
        "bat": (Var(("quantity",), None, "bat (empty: per ball)"), np.array([p[2] for p in parts])),
        "units": (Var(("quantity",), None, "SI unit of the quantity (UDUNITS)"), np.array(units, dtype=str)),
    }


def display_unit(quantity: str) -> str:
    """Return the unit the tables print a study quantity in (paper_comparison.csv's: rpm/deg, mph/deg; else 1)."""
    from ..compare import FIT_QUANTITIES

    return FIT_QUANTITIES[quantity][1] if quantity in FIT_QUANTITIES else "1"


def study_attrs(settings: StudySettings, batch: int | None = None) -> dict:
    """Return the study's attributes: a grid's settings are comma-joined, its values flattened point by point."""
    attrs = {
        "study_seed": settings.seed,
        "replicates_per_point": settings.replicates,
        "sweep_parameter": ",".join(settings.parameters),
        "sweep_values": settings.point_settings().ravel(),
    }
    if batch is not None:
        attrs["batch"] = batch
    return attrs


def sweep_table(attrs: dict) -> tuple[tuple[str, ...], np.ndarray]:
    """Return the swept settings' names and their values at every point (point x setting) from a file's attrs.

    Without a sweep: no name and one point of NaN.
    """
    names = tuple(n for n in str(attrs.get("sweep_parameter", "")).split(",") if n)
    flat = np.atleast_1d(np.asarray(attrs["sweep_values"], dtype=float))
    return names, flat.reshape(-1, max(1, len(names)))


def _setting_column(names: tuple[str, ...], table: np.ndarray) -> np.ndarray:
    """Return the ``setting`` of a file: the swept value at each point; NaN for a grid (see ``grid_setting``)."""
    return table[:, 0] if len(names) <= 1 else np.full(table.shape[0], np.nan)


def _grid_coords(names: tuple[str, ...], table: np.ndarray) -> dict:
    """Return a grid's coordinates: ``parameter`` (its settings) and ``grid_setting`` (point x parameter), or none."""
    if len(names) <= 1:
        return {}
    return {
        "parameter": (Var(("parameter",), None, "swept setting of the grid"), np.array(names)),
        "grid_setting": (Var(("point", "parameter"), "1", "value of each swept setting at each point"), table),
    }


def combined_dof(uncertainty: ArrayLike, systematic: ArrayLike, dof: ArrayLike) -> np.ndarray:
    """Degrees of freedom of sqrt(uncertainty^2 + systematic^2) (Welch-Satterthwaite; GUM, JCGM 100:2008, G.4).

    The systematic is a stated calibration uncertainty, known exactly (infinite degrees of
    freedom), so nu_eff = nu (u^2 + s^2)^2 / u^4: where the systematic dominates, the combined
    interval's quantile tends to the normal one. Holding the statistical t quantile for the
    combined uncertainty widened it by up to 14 % at 12 impacts per bat and over-covered (99-100 %
    at 1-3 px in the robustness grid).
    """
    u2 = np.asarray(uncertainty, dtype=float) ** 2
    total = u2 + np.asarray(systematic, dtype=float) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(u2 > 0, np.asarray(dof, dtype=float) * (total / u2) ** 2, np.inf)


def point_label(names: Sequence[str], values: Sequence[float]) -> str:
    """``name = value, ...`` of a sweep point (empty without a sweep)."""
    return ", ".join(f"{n} = {v:g}" for n, v in zip(names, values, strict=True) if np.isfinite(v))
