"""Rule plot_league: adapter around ballbat.plotting_league (the forest plot, from league.nc alone)."""

from ballbat.pipeline.ncio import read_dataset
from ballbat.pipeline.provenance import job_provenance, png_text
from ballbat.pipeline.runlog import logged
from ballbat.plotting_league import save_forest

with logged(snakemake.log[0], snakemake.rule):
    save_forest(read_dataset(snakemake.input.league), snakemake.output.png, png_text(*job_provenance(snakemake)))
