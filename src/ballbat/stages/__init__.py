"""The stage layer: one module per results file, between the compute modules and the rule scripts.

Each stage module owns the declared table of variables of its file (name -> :class:`~ballbat.pipeline.products.Var`),
its settings (a frozen dataclass built once from the validated config: ``from_config``) and one public
``run(settings, **inputs) -> xarray.Dataset``: it calls the compute modules (which return arrays and
dataclasses only) and assembles the Dataset (:func:`~ballbat.pipeline.products.build_dataset`, attributes,
the warnings carried from a measured file). The rule scripts in ``workflow/scripts/`` read the inputs, call
one ``run`` and write its Dataset (:func:`~ballbat.pipeline.ncio.write_job_output`); the replicate studies
(:mod:`ballbat.studies`) call the same ``run`` functions in memory.

* :mod:`.simulate`: ``simulate.nc`` (compute: :mod:`ballbat.synthetic`)
* :mod:`.ingest`: ``ingest.nc`` (:mod:`ballbat.ingest`)
* :mod:`.render`: ``tracks.nc`` (:mod:`ballbat.tracks.render`); its :func:`.render.tracks_dataset` also
  lays out ``imported_tracks.nc`` (:mod:`ballbat.tracks.formats`)
* :mod:`.clip_tracks`: ``clip_tracks/batch_{k}.nc``, one batch of a dataset's clips tracked (the batches:
  :mod:`ballbat.video.plan`); the import gathers them (:class:`.clip_tracks.GatheredClips`)
* :mod:`.quality`: ``imported_quality.nc``, the video tracker's quality of every point of a dataset's clips
  (gathered from the batches by the import)
* :mod:`.reduce`: ``reduce.nc`` (:mod:`ballbat.tracks.io`, :mod:`ballbat.tracks.reduce`, :mod:`ballbat.tracks.checks`)
* :mod:`.normalize`: ``normalize.nc`` (:mod:`ballbat.analysis`)
* :mod:`.reconstruct`: ``reconstruct.nc`` (:mod:`ballbat.analysis`)
* :mod:`.fit_ex`: ``fit_ex.nc`` (:mod:`ballbat.fitting`)
* :mod:`.stronge`: ``stronge.nc`` (:mod:`ballbat.stronge.analysis`)
* :mod:`.implications`: ``implications/{scenario}.nc`` (:mod:`ballbat.implications`)

:mod:`.impacts` holds the one table of the impacts every source stage writes (simulate, ingest, reduce).
"""
