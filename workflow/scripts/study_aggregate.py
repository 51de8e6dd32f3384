"""Rule study_aggregate: adapter around ballbat.studies (combine, population_truth, coverage)."""

from ballbat.pipeline.ncio import atomic_write_text, read_dataset, write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.plotting import coverage_figure, save_figure
from ballbat.properties import load_balls, load_bats
from ballbat.studies import StudySettings, combine, coverage, coverage_csv, population_truth, study_config

with logged(snakemake.log[0], snakemake.rule) as log:
    study = snakemake.wildcards.study
    settings = StudySettings.from_config(study_config(snakemake.params.study), study)
    balls, bats = load_balls(snakemake.input.balls), load_bats(snakemake.input.bats)
    reps = combine(read_dataset(p) for p in snakemake.input.batches)
    truths = [population_truth(settings, p, balls, bats) for p in range(settings.n_points)]
    cov = coverage(reps, truths)
    for line in coverage_csv(cov).splitlines()[1:]:
        log.info("%s", line)
    write_job_output(cov, snakemake, "coverage", f"Study {study}: coverage of every reported uncertainty")
    atomic_write_text(snakemake.output.csv, coverage_csv(cov))
    save_figure(coverage_figure(cov, point=0), snakemake.output.png)
