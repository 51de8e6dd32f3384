"""Rule render_clips: adapter around ballbat.stages.clips.render_clips."""

from ballbat.pipeline.ncio import read_dataset
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls
from ballbat.stages import clips, render

with logged(snakemake.log[0], snakemake.rule) as log:
    block = snakemake.params.settings
    written, n_frames = clips.render_clips(
        render.from_params(block),
        block["video"],
        read_dataset(snakemake.input.truth),
        load_balls(snakemake.input.balls),
        snakemake.output.clips,
    )
    log.info("%d clips, %d frames (%s)", len(written), n_frames, block["video"]["format"])
