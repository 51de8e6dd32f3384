"""Rules plot_*: adapter around ballbat.plotting.draw (figures from NetCDF files only)."""

from ballbat.plotting import draw
from ballbat.runlog import logged

with logged(snakemake.log[0], snakemake.rule):
    draw(
        snakemake.params.figure,
        inputs={k: v for k, v in snakemake.input.items() if k != "code"},
        outputs=dict(snakemake.output.items()),
    )
