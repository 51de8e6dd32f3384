"""Rule study_truth: adapter around ballbat.studies.truth_dataset."""

from ballbat.pipeline.ncio import write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls, load_bats
from ballbat.studies import StudySettings, truth_dataset

with logged(snakemake.log[0], snakemake.rule) as log:
    study = snakemake.wildcards.study
    settings = StudySettings.from_block(snakemake.params.study)
    log.info("%d sweep point(s), about %d impacts per ball and bat each", settings.n_points, settings.truth_impacts)
    ds = truth_dataset(settings, load_balls(snakemake.input.balls), load_bats(snakemake.input.bats))
    write_job_output(ds, snakemake, "truth", f"Study {study}: the design's truth of every quantity")
