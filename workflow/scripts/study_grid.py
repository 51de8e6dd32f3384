"""Rule study_grid: adapter around ballbat.plotting.grid_coverage_figure."""

from ballbat.pipeline.ncio import read_dataset
from ballbat.pipeline.provenance import job_provenance, png_text
from ballbat.pipeline.runlog import logged
from ballbat.plotting import grid_coverage_figure, save_figure

with logged(snakemake.log[0], snakemake.rule):
    fig = grid_coverage_figure(read_dataset(snakemake.input.coverage))
    save_figure(fig, snakemake.output.png, png_text(*job_provenance(snakemake)))
