"""Rule study_design: adapter around ballbat.studies.design.run."""

from ballbat.pipeline.ncio import atomic_write_text, read_dataset, write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.studies import design
from ballbat.studies.settings import StudySettings

with logged(snakemake.log[0], snakemake.rule):
    study = snakemake.wildcards.study
    settings = StudySettings.from_block(snakemake.params.study)
    cov = read_dataset(snakemake.input.coverage)
    des = design.run(cov, settings)  # with one answer over a sweep of impacts per bat (issue 37)
    write_job_output(des, snakemake, "design", f"Study {study}: spread of e_x and impacts per bat needed")
    atomic_write_text(snakemake.output.csv, design.design_csv(des))
