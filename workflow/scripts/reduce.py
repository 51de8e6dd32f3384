"""Rule reduce: adapter around ballbat.tracks.stage.reduce_stage."""

from ballbat.pipeline.ncio import write_dataset
from ballbat.pipeline.provenance import data_inputs
from ballbat.pipeline.runlog import logged
from ballbat.tracks.stage import excluded_listing, reduce_stage

with logged(snakemake.log[0], snakemake.rule) as log:
    inp = snakemake.input
    ds = reduce_stage(
        inp.tracks,
        inp.get("impacts"),
        snakemake.params.settings,
        inp.balls,
        inp.bats,
        where=snakemake.params.where,
    )
    excluded = excluded_listing(ds)
    log.info("%d of %d impacts excluded (kept in the file, flagged)", len(excluded), ds.sizes["impact"])
    for line in excluded:
        log.info("excluded: %s", line)
    write_dataset(
        ds,
        snakemake.output.impacts,
        title=f"Impacts of dataset {snakemake.wildcards.dataset} reduced from raw camera tracks (Sec. II)",
        rule=snakemake.rule,
        inputs=data_inputs(inp),
        config=dict(snakemake.params),
    )
