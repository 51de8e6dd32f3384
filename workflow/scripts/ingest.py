"""Rule ingest: adapter around ballbat.stages.ingest.run."""

from ballbat.pipeline.ncio import write_job_output
from ballbat.pipeline.runlog import log_exclusions, logged
from ballbat.stages import ingest

with logged(snakemake.log[0], snakemake.rule) as log:
    files = snakemake.params.files  # as the config names them: a missing one is reported by the ingest
    ds = ingest.run(
        ingest.IngestSettings.from_params(dict(snakemake.params)),
        files["impacts"],
        balls=files["balls"],
        bats=files["bats"],
    )
    for text in ingest.warnings(ds):
        log.warning(text)
    log_exclusions(log, ingest.excluded_listing(ds), ds.sizes["impact"])
    write_job_output(
        ds,
        snakemake,
        "impacts",
        f"Measured ball-bat impacts of dataset {snakemake.wildcards.dataset}, checked and in SI",
        config={
            "sha256": snakemake.params.sha256,
            **({"calibration": cal} if (cal := snakemake.params.calibration) else {}),
        },
    )
