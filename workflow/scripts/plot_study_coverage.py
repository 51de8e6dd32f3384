"""Rule plot_study_coverage: adapter around ballbat.plotting.coverage_figure."""

from ballbat.pipeline.ncio import read_dataset
from ballbat.pipeline.provenance import job_provenance, png_text
from ballbat.pipeline.runlog import logged
from ballbat.plotting import coverage_figure, save_figure

with logged(snakemake.log[0], snakemake.rule):
    fig = coverage_figure(read_dataset(snakemake.input.coverage), point=0)
    save_figure(fig, snakemake.output.png, png_text(*job_provenance(snakemake)))
