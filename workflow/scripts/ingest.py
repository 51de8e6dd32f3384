"""Rule ingest: adapter around ballbat.ingest.ingest."""

from ballbat.ingest import excluded_listing, ingest
from ballbat.pipeline.ncio import write_job_output
from ballbat.pipeline.runlog import log_exclusions, logged

with logged(snakemake.log[0], snakemake.rule) as log:
    files = snakemake.params.files  # as the config names them: a missing one is reported by the ingest
    ds, warnings = ingest(files["impacts"], balls_path=files["balls"], bats_path=files["bats"])
    for text in warnings:
        log.warning(text)
    log_exclusions(log, excluded_listing(ds), ds.sizes["impact"])
    write_job_output(
        ds,
        snakemake,
        "impacts",
        f"Measured ball-bat impacts of dataset {snakemake.wildcards.dataset}, checked and in SI",
        config={"sha256": snakemake.params.sha256},
    )
