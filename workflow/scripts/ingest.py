"""Rule ingest: adapter around ballbat.ingest.ingest."""

from ballbat.ingest import excluded_listing, ingest
from ballbat.pipeline.ncio import write_job_output
from ballbat.pipeline.runlog import logged

with logged(snakemake.log[0], snakemake.rule) as log:
    ds, warnings = ingest(snakemake.input.impacts, balls_path=snakemake.input.balls, bats_path=snakemake.input.bats)
    for text in warnings:
        log.warning(text)
    excluded = excluded_listing(ds)
    log.info("%d of %d impacts excluded (kept in the file, flagged)", len(excluded), ds.sizes["impact"])
    for line in excluded:
        log.info("excluded: %s", line)
    write_job_output(
        ds,
        snakemake,
        "impacts",
        f"Measured ball-bat impacts of dataset {snakemake.wildcards.dataset}, checked and in SI",
        config={},
    )
