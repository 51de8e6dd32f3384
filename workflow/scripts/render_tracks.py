"""Rule render_tracks: adapter around ballbat.stages.render.run."""

from ballbat.pipeline.ncio import read_dataset, write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls
from ballbat.stages import render

with logged(snakemake.log[0], snakemake.rule) as log:
    settings = render.from_params(snakemake.params.settings)
    ds = render.run(settings, read_dataset(snakemake.input.truth), load_balls(snakemake.input.balls))
    log.info("%d impacts, %d tracked points", ds.sizes["impact"], ds.sizes["row"])
    write_job_output(ds, snakemake, "tracks", f"Synthetic raw camera tracks of dataset {snakemake.wildcards.dataset}")
