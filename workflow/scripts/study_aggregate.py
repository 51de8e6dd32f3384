"""Rule study_aggregate: adapter around ballbat.studies (combine, coverage)."""

from ballbat.pipeline.ncio import atomic_write_text, read_dataset, write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.studies.coverage import combine, coverage, coverage_csv
from ballbat.studies.truth import truth_scales_from_dataset, truths_from_dataset

with logged(snakemake.log[0], snakemake.rule) as log:
    study = snakemake.wildcards.study
    reps = combine(read_dataset(p) for p in snakemake.input.batches)
    truth = read_dataset(snakemake.input.truth)
    cov = coverage(reps, truths_from_dataset(truth), truth_scales_from_dataset(truth))
    for line in coverage_csv(cov).splitlines()[1:]:
        log.info("%s", line)
    write_job_output(cov, snakemake, "coverage", f"Study {study}: coverage of every reported uncertainty")
    atomic_write_text(snakemake.output.csv, coverage_csv(cov))
