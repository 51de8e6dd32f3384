"""Rule render_tracks: adapter around ballbat.tracks.stage.render_stage."""

from ballbat.pipeline.ncio import read_dataset, write_dataset
from ballbat.pipeline.provenance import data_inputs
from ballbat.pipeline.runlog import logged
from ballbat.tracks.stage import render_stage

with logged(snakemake.log[0], snakemake.rule) as log:
    ds = render_stage(read_dataset(snakemake.input.truth), snakemake.input.balls, snakemake.params.settings)
    log.info("%d impacts, %d tracked points", ds.sizes["impact"], ds.sizes["row"])
    write_dataset(
        ds,
        snakemake.output.tracks,
        title=f"Synthetic raw camera tracks of dataset {snakemake.wildcards.dataset}",
        rule=snakemake.rule,
        inputs=data_inputs(snakemake.input),
        config=dict(snakemake.params),
    )
