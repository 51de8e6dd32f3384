"""Rule league_workbook: adapter around ballbat.workbook.league_workbook."""

from ballbat.pipeline.ncio import read_dataset
from ballbat.pipeline.runlog import logged
from ballbat.workbook import custom_properties, league_workbook

with logged(snakemake.log[0], snakemake.rule):
    properties = {"rule": snakemake.rule, **custom_properties({"league.nc": snakemake.input.league})}
    league_workbook(snakemake.output.xlsx, read_dataset(snakemake.input.league), properties)
