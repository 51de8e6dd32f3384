"""A replicate study's settings (:class:`StudySettings`), read from the validated config.

Apart from :mod:`ballbat.studies` so that the workflow reads them when it builds its jobs
(``workflow/rules/common.smk``) without importing what the studies compute with (xarray).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .sweeps import point_dataset, study_dataset, sweep_points, truth_counts


@dataclass(frozen=True)
class StudySettings:
    """One study, as in the config's ``studies.<name>`` (paper units), built once from the validated config.

    No field has a default: the defaults are the config schema's alone (:meth:`from_block`
    reads the validated config, every default filled).

    Attributes
    ----------
    dataset : dict
        The synthetic dataset's config block (``synthetic`` and optional ``render``).
    replicates : int
        Replicate experiments per sweep point.
    seed : int
        The study's seed (every replicate's seeds derive from it).
    batch_size : int
        Replicates per batch job.
    parameter : str, tuple of str or None
        Swept setting (a key of :data:`ballbat.studies.sweeps.SWEEP_PARAMETERS`), None for no sweep;
        for a grid sweep the tuple of its settings.
    values : tuple
        Its values (one point, NaN, without a sweep); for a grid one tuple per point, every
        combination of the settings' values (:func:`ballbat.studies.sweeps.sweep_points`).
    v_ref_mph, mu_k_example : float
        The workflow's ``normalize.v_ref_mph`` and ``analysis.mu_k_example``.
    stronge : dict
        The workflow's ``stronge`` section (``e_y``, ``mu``, ``vary_e_y``, ``vary_mu``).
    truth_impacts : int
        Impacts per ball and bat, on average over the pairs, of the large noise-free experiment
        that gives the design's truth (:meth:`truth_counts`).
    delta_e_x, confidence, power : float
        The design table's difference in e_x to detect and its test's confidence and power.
    draw_properties : bool
        Every replicate draws its true bat and ball properties from the tables' stated
        uncertainties (``<column>_err``) and is analysed with the tables' values
        (:func:`ballbat.studies.replicates.run_replicate`; config ``studies.<name>.draw_properties``).
    """

    dataset: dict
    replicates: int
    seed: int
    batch_size: int
    parameter: str | None
    values: tuple
    v_ref_mph: float
    mu_k_example: float
    stronge: dict
    truth_impacts: int
    delta_e_x: float
    confidence: float
    power: float
    draw_properties: bool

    @classmethod
    def from_config(cls, config: dict, name: str) -> StudySettings:
        """Return the settings of study ``name`` from the validated workflow config."""
        return cls.from_block(study_block(config, name))

    @classmethod
    def from_block(cls, block: dict) -> StudySettings:
        """Return the settings from a study's block of the validated config (:func:`study_block`; the rules' params)."""
        s = block["study"]
        sweep = s.get("sweep")  # optional, no default: None is no sweep
        names, points = sweep_points(sweep)
        grid = bool(sweep) and "grid" in sweep
        return cls(
            dataset=study_dataset(block["dataset"], s),
            replicates=int(s["replicates"]),
            seed=int(s["seed"]),
            batch_size=int(s["batch_size"]),
            parameter=(names if grid else names[0]) if sweep else None,
            values=(tuple(points) if grid else tuple(p[0] for p in points)) if sweep else (math.nan,),
            v_ref_mph=float(block["normalize"]["v_ref_mph"]),
            mu_k_example=float(block["analysis"]["mu_k_example"]),
            stronge={k: block["stronge"][k] for k in ("e_y", "mu", "vary_e_y", "vary_mu")},
            truth_impacts=int(s["truth_impacts"]),
            delta_e_x=float(s["delta_e_x"]),
            confidence=float(s["confidence"]),
            power=float(s["power"]),
            draw_properties=bool(s["draw_properties"]),
        )

    @property
    def parameters(self) -> tuple[str, ...]:
        """Names of the swept settings (one for a one-parameter sweep, none without a sweep)."""
        if self.parameter is None:
            return ()
        return (self.parameter,) if isinstance(self.parameter, str) else tuple(self.parameter)

    @property
    def is_grid(self) -> bool:
        """Whether the sweep is a grid (several settings at once)."""
        return self.parameter is not None and not isinstance(self.parameter, str)

    def point_settings(self) -> np.ndarray:
        """Return the settings at every point (point x setting; one column of NaN without a sweep)."""
        return np.asarray([v if self.is_grid else (v,) for v in self.values], dtype=float).reshape(self.n_points, -1)

    @property
    def n_points(self) -> int:
        """Sweep points (1 without a sweep)."""
        return len(self.values)

    @property
    def total(self) -> int:
        """Replicates over all sweep points."""
        return self.replicates * self.n_points

    @property
    def n_batches(self) -> int:
        """Batch jobs."""
        return -(-self.total // self.batch_size)

    def point_dataset(self, point: int) -> dict:
        """Return the dataset's block with the swept setting at sweep point ``point`` (a copy)."""
        return point_dataset(self.dataset, self.parameter, self.values[point])

    def truth_counts(self, point: int) -> tuple[int, dict[str, dict[str, int]]]:
        """Return the truth job's scale and impacts per ball and bat at sweep point ``point``.

        The one rule for the truth's size: :func:`ballbat.studies.sweeps.truth_counts`.
        """
        return truth_counts(self.point_dataset(point), self.truth_impacts)

    def truth_size(self, point: int) -> int:
        """Return the impacts of the truth job's experiment at sweep point ``point`` (its plans scale with it)."""
        return sum(n for bats in self.truth_counts(point)[1].values() for n in bats.values())

    def truth_mem_mb(self, point: int) -> int:
        """Return the truth job's memory plan at sweep point ``point`` (MB): 500 MB and the chain's per impact."""
        from ..config_checks import impact_bytes

        return 500 + math.ceil(self.truth_size(point) * impact_bytes(self.dataset) / 1e6)

    def truth_runtime_min(self, point: int) -> int:
        """Return the truth job's run-time plan at sweep point ``point`` (minutes).

        Measured about 2 CPU minutes for the calibration study's 70 000 rendered impacts; with room.
        """
        return max(30, math.ceil(4 * self.truth_size(point) / 70_000) + 10)

    def batch_range(self, batch: int) -> range:
        """Global replicate indices of batch ``batch`` (point = index // replicates)."""
        if not 0 <= batch < self.n_batches:
            raise ValueError(f"batch {batch} out of range (0..{self.n_batches - 1})")
        return range(batch * self.batch_size, min((batch + 1) * self.batch_size, self.total))


def study_block(config: dict, name: str) -> dict:
    """Everything study ``name`` depends on, from the validated config: its block, its dataset's and the chain's.

    The study rules' ``study`` param (so that a change of any of it reruns them) and what
    :meth:`StudySettings.from_block` reads.
    """
    s = config["studies"][name]
    return {
        "study": s,
        "dataset": config["datasets"][s["dataset"]],
        "normalize": config["normalize"],
        "analysis": config["analysis"],
        "stronge": config["stronge"],
    }
