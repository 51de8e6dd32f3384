"""Rule study_aggregate: adapter around ballbat.studies.coverage.run."""

from ballbat.pipeline.ncio import atomic_write_text, read_dataset, write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.studies import coverage

with logged(snakemake.log[0], snakemake.rule) as log:
    study = snakemake.wildcards.study
    batches = (read_dataset(p) for p in snakemake.input.batches)
    cov = coverage.run(batches, read_dataset(snakemake.input.truth))
    for line in coverage.coverage_csv(cov).splitlines()[1:]:
        log.info("%s", line)
    write_job_output(cov, snakemake, "coverage", f"Study {study}: coverage of every reported uncertainty")
    atomic_write_text(snakemake.output.csv, coverage.coverage_csv(cov))
