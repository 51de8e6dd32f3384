"""Rules plot_*: adapter around ballbat.plotting.draw (figures from NetCDF files only)."""

from ballbat.plotting import draw
from ballbat.provenance import data_inputs
from ballbat.runlog import logged

with logged(snakemake.log[0], snakemake.rule):
    draw(
        snakemake.params.figure,
        inputs=data_inputs(snakemake.input),
        outputs=dict(snakemake.output.items()),
    )
