"""Rule plot_study_design: adapter around ballbat.plotting.design_figure."""

from ballbat.pipeline.ncio import read_dataset
from ballbat.pipeline.provenance import job_provenance, png_text
from ballbat.pipeline.runlog import logged
from ballbat.plotting import design_figure, save_figure

with logged(snakemake.log[0], snakemake.rule):
    fig = design_figure(read_dataset(snakemake.input.design))
    save_figure(fig, snakemake.output.png, png_text(*job_provenance(snakemake)))
