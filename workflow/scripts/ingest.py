"""Rule ingest: adapter around ballbat.ingest.ingest."""

from ballbat.ingest import excluded_listing, ingest
from ballbat.pipeline.ncio import write_job_output
from ballbat.pipeline.runlog import logged

with logged(snakemake.log[0], snakemake.rule) as log:
    files = snakemake.params.files  # as the config names them: a missing one is reported by the ingest
    ds, warnings = ingest(files["impacts"], balls_path=files["balls"], bats_path=files["bats"])
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
        config={"sha256": snakemake.params.sha256},
    )
