"""One chain: a dataset's settings built once, and the one function that runs its stages in memory.

As pvlib's ``ModelChain`` does for a PV system, :class:`DatasetSettings` holds every setting of
every stage of one dataset, typed, built once from the validated config (or from one validated
dataset block), and :func:`run` runs the stages in the workflow's order on it:

* the source: :func:`source` (simulate; simulate, render and reduce; reduce of tracks already
  read; ingest of a measured impacts file), one starting point per kind of input;
* :mod:`~ballbat.stages.normalize`, :mod:`~ballbat.stages.reconstruct` and
  :mod:`~ballbat.stages.fit_ex` (:func:`run`).

The replicate studies (:mod:`ballbat.studies`), ``ballbat check`` (:mod:`ballbat.cli.check`) and the
tests call these; the workflow's rules call the same stages one by one, each writing its file.
No other module chains stages.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .datasets import renders
from .stages import fit_ex, normalize, reconstruct, reduce, render, simulate
from .synthetic import SyntheticSettings

if TYPE_CHECKING:
    import os
    from collections.abc import Mapping

    import xarray as xr

    from .properties import Ball, Bat
    from .tracks.data import Tracks
    from .tracks.reduce import Reduction
    from .tracks.render import RenderSettings
    from .tracks.verdict import Verdict


@dataclass(frozen=True)
class DatasetSettings:
    """Every setting of one dataset's chain (frozen; a change is a :func:`dataclasses.replace`).

    Attributes
    ----------
    name : str
        The dataset's name (config ``datasets.<name>``).
    synthetic : SyntheticSettings or None
        The synthetic experiment (None: a measured dataset).
    render : RenderSettings or None
        The rendering of camera tracks (None: the dataset renders none).
    reduce : ReduceSettings or None
        The reduction of camera tracks (None: no tracks, or a folder of tool files, whose camera
        settings are known once the files are read: :func:`reduce_tool_files`).
    normalize, reconstruct, fit_ex : the stages' settings
        As the workflow's rules build them (:meth:`from_config`), or a study's.
    block : Mapping
        The validated dataset block they were built from: a replicate draws its render seed (and
        the calibration drawn from it) anew from it (:meth:`with_seeds`).
    """

    name: str
    synthetic: SyntheticSettings | None
    render: RenderSettings | None
    reduce: reduce.ReduceSettings | None
    normalize: normalize.NormalizeSettings
    reconstruct: reconstruct.ReconstructSettings
    fit_ex: fit_ex.FitExSettings
    block: Mapping

    @classmethod
    def from_config(cls, config: dict, name: str) -> DatasetSettings:
        """Return the settings the workflow's rules use for dataset ``name`` of the validated config."""
        return cls.from_block(
            config["datasets"][name],
            name,
            normalize.NormalizeSettings.from_config(config),
            fit_ex.FitExSettings.from_config(config),
            systematics=True,
        )

    @classmethod
    def from_block(
        cls,
        block: dict,
        name: str,
        normalize_settings: normalize.NormalizeSettings,
        fit_ex_settings: fit_ex.FitExSettings,
        *,
        systematics: bool,
        where: str | None = None,
    ) -> DatasetSettings:
        """Return the settings of one validated dataset block (a sweep point's: :func:`.studies.sweeps.point_dataset`).

        ``systematics``: reduce rendered or measured tracks again at +-1 sigma of each stated
        calibration uncertainty (the workflow: always; a study: where it draws its calibration).
        ``where`` names the tracks' settings in messages (default: their config key).
        """
        from .tracks.data import camera_block

        synthetic = SyntheticSettings(**block["synthetic"]) if "synthetic" in block else None
        rendered = renders(block)
        red = None
        if rendered:
            at = where or f"datasets.{name}.render"
            red = reduce.ReduceSettings.from_config(camera_block(block["render"]), at, systematics=systematics)
        elif "tracks" in block and "dir" not in block["tracks"]:
            at = where or f"datasets.{name}.tracks"
            red = reduce.ReduceSettings.from_config(block["tracks"], at, systematics=systematics)
        return cls(
            name=name,
            synthetic=synthetic,
            render=render.settings_from_config(block["render"]) if rendered else None,
            reduce=red,
            normalize=normalize_settings,
            reconstruct=reconstruct.ReconstructSettings(),
            fit_ex=fit_ex_settings,
            block=block,
        )

    def with_seeds(self, synthetic_seed: int, render_seed: int) -> DatasetSettings:
        """Return the settings of a replicate: the experiment and the tracks drawn from their own seeds.

        The render settings are built again from the block at ``render_seed``, since a drawn
        calibration (``render.draw_calibration``) is drawn from that seed too.
        """
        if self.synthetic is None:
            raise ValueError(f"dataset {self.name!r} is measured: a replicate needs a synthetic experiment")
        rendered = self.render is not None
        return dataclasses.replace(
            self,
            synthetic=dataclasses.replace(self.synthetic, seed=synthetic_seed),
            render=render.settings_from_config({**self.block["render"], "seed": render_seed}) if rendered else None,
        )


def source(
    settings: DatasetSettings,
    balls: dict[str, Ball],
    bats: dict[str, Bat],
    *,
    tracks: Tracks | None = None,
    source_file: str | None = None,
) -> xr.Dataset:
    """Return the dataset's impacts: its source stage(s) as the workflow runs them.

    * ``tracks`` given: the reduce stage on them (read and checked already: tracks files,
      tool files or a video);
    * a synthetic dataset: simulate, and where it renders tracks, render and reduce them;

    A measured impacts file is read by :func:`ingest` (it takes the file, not settings).

    Raises
    ------
    ballbat.properties.InputError
        A cross-check that stops the dataset.
    """
    if tracks is not None:
        if settings.reduce is None:
            raise ValueError(f"dataset {settings.name!r} has no reduce settings for its tracks")
        return reduce.run(settings.reduce, tracks, balls, bats, source_file=source_file)
    if settings.synthetic is None:
        raise ValueError(f"dataset {settings.name!r} is measured: give its tracks, or ingest its impacts file")
    sim = simulate.run(settings.synthetic, balls, bats)
    if settings.render is None:
        return sim
    return reduce.run(settings.reduce, render.render(settings.render, sim, balls), balls, bats)


def ingest(
    impacts: str | os.PathLike[str],
    balls: str | os.PathLike[str],
    bats: str | os.PathLike[str],
    calibration: Mapping[str, float] | None = None,
) -> xr.Dataset:
    """Return a measured impacts file read and checked as the ingest rule does (the property tables by path).

    ``calibration``: the dataset's stated instrument calibration uncertainties (config
    ``datasets.<name>.calibration``), each a systematic source.
    """
    from .stages import ingest as ingest_stage

    settings = ingest_stage.IngestSettings(calibration=dict(calibration or {}))
    return ingest_stage.run(settings, impacts, balls=balls, bats=bats)


@dataclass(frozen=True)
class Chain:
    """The Datasets of one run of the chain, one per stage (the workflow's files of the same names)."""

    source: xr.Dataset
    normalize: xr.Dataset
    reconstruct: xr.Dataset
    fit_ex: xr.Dataset
    fit_systematics: fit_ex.FitSystematics | None


def run(settings: DatasetSettings, impacts: xr.Dataset, balls: dict[str, Ball], bats: dict[str, Bat]) -> Chain:
    """Run normalize, reconstruct and fit_ex on a source's impacts (:func:`source`, :func:`ingest`).

    Raises
    ------
    ballbat.fitting.ImplausibleFit
        A fitted e_x outside [-1, 1], where ``settings.fit_ex.check_physical`` asks.
    """
    norm = normalize.run(settings.normalize, impacts)
    rec = reconstruct.run(settings.reconstruct, norm, balls, bats)
    fit, fs = fit_ex.fit(settings.fit_ex, rec)
    return Chain(impacts, norm, rec, fit, fs)


def reconstructed(
    settings: DatasetSettings, impacts: xr.Dataset, balls: dict[str, Ball], bats: dict[str, Bat]
) -> xr.Dataset:
    """Return the impacts normalised and reconstructed (:func:`run` without the fits)."""
    return reconstruct.run(settings.reconstruct, normalize.run(settings.normalize, impacts), balls, bats)


def fit_problems(settings: DatasetSettings, impacts: xr.Dataset, balls: dict, bats: dict) -> list[str]:
    """Return why the workflow's fit_ex would stop on these impacts (empty when it would not).

    The chain itself with the workflow's settings (its fit refuses an e_x outside [-1, 1]), so
    that ``ballbat check`` never calls usable a file that fit_ex refuses. The reference bat
    speed and the friction of the Sec. IV example do not enter e_x.
    """
    from .fitting import ImplausibleFit

    try:
        fit = dataclasses.replace(settings.fit_ex, systematic=False)
        run(dataclasses.replace(settings, fit_ex=fit), impacts, balls, bats)
    except ImplausibleFit as exc:
        return [str(exc)]
    return []


def schema_settings(block: dict, name: str) -> DatasetSettings:
    """Return the settings of a dataset block with the workflow's defaults for the rest (the config schema's).

    For ``ballbat check``, which has a dataset but no workflow config.
    """
    from .pipeline.config import checked_block

    config = {"normalize": checked_block({}, "normalize"), "analysis": checked_block({}, "analysis")}
    return DatasetSettings.from_block(
        block,
        name,
        normalize.NormalizeSettings.from_config(config),
        fit_ex.FitExSettings.from_config(config),
        systematics=True,
    )


def reduce_tracks_block(
    block: dict,
    where: str,
    balls: dict[str, Ball],
    bats: dict[str, Bat],
    tracks_path: str | os.PathLike[str] | None = None,
    impacts_path: str | os.PathLike[str] | None = None,
) -> tuple[Reduction, Verdict]:
    """Read a ``tracks`` block's tracks as the workflow does, then reduce and cross-check them (``ballbat check``).

    A folder of tool files (``dir``, unless ``tracks_path`` is given) is imported as the
    import_tracks rule does, the camera settings found in the files completing the block's
    (a problem of a setting the files gave names it as read from them); a tracks file (``file``
    or ``tracks_path``, with ``impacts`` or ``impacts_path``) is read as the reduce rule reads
    it, its settings checked before the file is read. No calibration reruns: a check needs none.

    Raises
    ------
    ballbat.properties.InputError
        Every problem of the files and settings, or a cross-check that stops the dataset.
    """
    from .properties import InputError
    from .tracks.data import camera_block, name_found_settings, with_found_settings
    from .tracks.io import load_tracks

    if "dir" not in block or tracks_path is not None:
        settings = reduce.ReduceSettings.from_config(block, where, systematics=False)  # before the files are read
        tracks = load_tracks(tracks_path or block["file"], impacts_path or block.get("impacts"), balls, bats)
        return reduce.reduce_and_check(settings, tracks, balls, bats)
    from .tracks.formats.layout import import_block
    from .video.importer import clip_reader

    tracks, imported = import_block(block, where, balls, bats, clip_reader=clip_reader)
    found = imported.settings_yaml()
    try:
        settings = reduce.ReduceSettings.from_config(
            with_found_settings(camera_block(block), found), where, systematics=False
        )
        return reduce.reduce_and_check(settings, tracks, balls, bats)
    except InputError as exc:
        raise InputError(name_found_settings(exc.problems, found)) from None
