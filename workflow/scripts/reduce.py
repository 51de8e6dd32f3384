"""Rule reduce: adapter around ballbat.tracks.stage.reduce_stage."""

from ballbat.pipeline.checked import verify_netcdf
from ballbat.pipeline.ncio import write_dataset
from ballbat.pipeline.provenance import data_inputs
from ballbat.pipeline.runlog import logged
from ballbat.tracks.stage import excluded_listing, reduce_stage

with logged(snakemake.log[0], snakemake.rule) as log:
    inp = snakemake.input
    files = snakemake.params.files  # as the config names them: a missing one is reported by the reader
    lab = "tracks" in files  # a lab's tracks; else the rendered tracks.nc, which holds its impact table
    if not lab:
        verify_netcdf(inp.tracks)  # the workflow's own product: checked whole before use
    ds = reduce_stage(
        files["tracks"] if lab else inp.tracks,
        files["tracks_impacts"] if lab else None,
        snakemake.params.settings,
        files["balls"],
        files["bats"],
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
        config={k: v for k, v in snakemake.params.items() if k != "files"},
    )
