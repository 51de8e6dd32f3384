"""Rule import_tracks: adapter around ballbat.tracks.formats.layout.import_block (clips: ballbat.video.importer)."""

from functools import partial

import yaml

from ballbat.pipeline.ncio import atomic_write_text, write_dataset
from ballbat.pipeline.provenance import data_inputs
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls, load_bats
from ballbat.stages.render import tracks_dataset
from ballbat.tracks.formats.layout import import_block
from ballbat.video.importer import clip_reader

with logged(snakemake.log[0], snakemake.rule) as log:
    inp = snakemake.input
    tracks, imported = import_block(
        snakemake.params.settings,
        snakemake.params.where,
        load_balls(inp.balls),
        load_bats(inp.bats),
        clip_reader=partial(clip_reader, workers=snakemake.threads),  # clips tracked side by side
    )
    found = imported.settings_yaml()
    log.info("%d files, %d impacts, %d tracked points", found["files"], tracks.n, found["rows"])
    for cam, vals in found["cameras"].items():
        log.info("camera %s: %s", cam, vals)
    for path, names in imported.ignored.items():
        log.info("%s: tracks left out (not in points): %s", path, ", ".join(names))
    write_dataset(
        tracks_dataset(tracks),
        snakemake.output.tracks,
        title=f"Camera tracks of dataset {snakemake.wildcards.dataset} read from the lab's tracking-tool files",
        rule=snakemake.rule,
        inputs=data_inputs(inp),
        config=dict(snakemake.params),
    )
    atomic_write_text(snakemake.output.cameras, yaml.safe_dump(found, sort_keys=False))
