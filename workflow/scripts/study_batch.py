"""Rule study_batch: adapter around ballbat.studies.batch.run."""

from ballbat.pipeline.ncio import write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls, load_bats
from ballbat.studies import batch
from ballbat.studies.settings import StudySettings

with logged(snakemake.log[0], snakemake.rule) as log:
    study, number = snakemake.wildcards.study, int(snakemake.wildcards.batch)
    settings = StudySettings.from_block(snakemake.params.study)
    step = max(1, settings.batch_size // 10)

    def progress(done, n):
        """Log every tenth of the batch."""
        if done % step == 0 or done == n:
            log.info("%d of %d replicates", done, n)

    ds = batch.run(settings, number, load_balls(snakemake.input.balls), load_bats(snakemake.input.bats), progress)
    for why in ds["refusal"].values.astype(str):
        if why:
            log.warning("data refused, counted in the coverage table's n_refused: %s", why)
    write_job_output(ds, snakemake, "batch", f"Study {study}, batch {number}: replicate estimates, errors and truths")
