"""Rule track_clips: adapter around ballbat.stages.clip_tracks (one batch of a dataset's clips tracked)."""

from ballbat.pipeline.ncio import write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls
from ballbat.stages import clip_tracks

with logged(snakemake.log[0], snakemake.rule) as log:
    inp = snakemake.input
    batch = clip_tracks.run(snakemake.params.tracker, load_balls(inp.balls))
    log.info("%d clips tracked: %d points found", batch.attrs["n_clips"], batch.attrs["n_found"])
    write_job_output(
        batch,
        snakemake,
        "batch",
        f"Batch {snakemake.wildcards.batch} of dataset {snakemake.wildcards.dataset}'s clips, tracked",
    )
