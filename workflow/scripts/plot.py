"""Rules plot_*: adapter around ballbat.plotting.draw (figures from NetCDF files only)."""

from ballbat.pipeline.provenance import data_inputs, job_provenance, png_text
from ballbat.pipeline.runlog import logged
from ballbat.plotting import draw

with logged(snakemake.log[0], snakemake.rule):
    draw(
        snakemake.params.figure,
        inputs=data_inputs(snakemake.input),
        outputs=dict(snakemake.output.items()),
        provenance=png_text(*job_provenance(snakemake)),
    )
