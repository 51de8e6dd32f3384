"""Rule simulate: adapter around ballbat.synthetic.simulate_experiment."""

from ballbat.pipeline.ncio import write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls, load_bats
from ballbat.synthetic import SyntheticSettings, simulate_experiment

with logged(snakemake.log[0], snakemake.rule):
    ds = simulate_experiment(
        SyntheticSettings(**snakemake.params.settings),
        balls=load_balls(snakemake.params.files["balls"]),
        bats=load_bats(snakemake.params.files["bats"]),
    )
    write_job_output(ds, snakemake, "impacts", f"Synthetic ball-bat impacts of dataset {snakemake.wildcards.dataset}")
