"""Rules import_tracks and import_clips: adapter around ballbat.tracks.formats.layout.import_block.

Clips (import_clips): tracked by rule track_clips, one batch a job; their tracks and quality read back from
the batch files (ballbat.stages.clip_tracks.GatheredClips), the quality table to imported_quality.nc
(ballbat.stages.quality).
"""

import yaml

from ballbat.pipeline.ncio import atomic_write_text, read_dataset, write_dataset
from ballbat.pipeline.provenance import data_inputs
from ballbat.pipeline.runlog import logged
from ballbat.properties import InputError, load_balls, load_bats
from ballbat.stages.clip_tracks import GatheredClips
from ballbat.stages.quality import quality_dataset
from ballbat.stages.render import tracks_dataset
from ballbat.tracks.formats.layout import import_block

with logged(snakemake.log[0], snakemake.rule) as log:
    inp, out = snakemake.input, snakemake.output
    clips = GatheredClips(read_dataset(b) for b in inp.batches) if hasattr(inp, "batches") else None
    tracks, imported = import_block(
        snakemake.params.settings,
        snakemake.params.where,
        load_balls(inp.balls),
        load_bats(inp.bats),
        clip_reader=clips,
    )
    if clips is not None and clips.unread():
        raise InputError([f"{p}: tracked by a batch, but no longer in the folder (run again)" for p in clips.unread()])
    found = imported.settings_yaml()
    log.info("%d files, %d impacts, %d tracked points", found["files"], tracks.n, found["rows"])
    for cam, vals in found["cameras"].items():
        log.info("camera %s: %s", cam, vals)
    for path, names in imported.ignored.items():
        log.info("%s: tracks left out (not in points): %s", path, ", ".join(names))
    provenance = {"rule": snakemake.rule, "inputs": data_inputs(inp), "config": dict(snakemake.params)}
    name = snakemake.wildcards.dataset
    if hasattr(out, "quality"):  # import_clips: the tracker's quality of every point
        quality = quality_dataset(clips.quality())
        log.info("tracker: %d points found, %d left out", quality.attrs["n_found"], quality.attrs["n_left_out"])
        title = f"The video tracker's quality of every point of dataset {name}'s clips, found or left out"
        write_dataset(quality, out.quality, title=title, **provenance)
    write_dataset(
        tracks_dataset(tracks),
        out.tracks,
        title=f"Camera tracks of dataset {name} read from the lab's tracking-tool files",
        **provenance,
    )
    atomic_write_text(out.cameras, yaml.safe_dump(found, sort_keys=False))
