"""Rule simulate: adapter around ballbat.stages.simulate.run."""

from ballbat.pipeline.ncio import write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls, load_bats
from ballbat.stages import simulate

with logged(snakemake.log[0], snakemake.rule):
    ds = simulate.run(
        simulate.from_params(snakemake.params.settings),
        balls=load_balls(snakemake.params.files["balls"]),
        bats=load_bats(snakemake.params.files["bats"]),
    )
    write_job_output(ds, snakemake, "impacts", f"Synthetic ball-bat impacts of dataset {snakemake.wildcards.dataset}")
