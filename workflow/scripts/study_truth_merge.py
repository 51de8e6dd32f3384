"""Rule study_truth: adapter around ballbat.studies.truth.merge_truths (the truth files of every sweep point)."""

from ballbat.pipeline.ncio import read_dataset, write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.studies.truth import merge_truths

with logged(snakemake.log[0], snakemake.rule):
    study = snakemake.wildcards.study
    ds = merge_truths(read_dataset(p) for p in snakemake.input.points)
    write_job_output(ds, snakemake, "truth", f"Study {study}: the design's truth of every quantity")
