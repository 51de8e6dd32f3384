"""Rule simulate: adapter around ballbat.synthetic.simulate_experiment."""

from ballbat.pipeline.ncio import write_dataset
from ballbat.pipeline.provenance import data_inputs
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls, load_bats
from ballbat.synthetic import SyntheticSettings, simulate_experiment

with logged(snakemake.log[0], snakemake.rule):
    ds = simulate_experiment(
        SyntheticSettings(**snakemake.params.settings),
        balls=load_balls(snakemake.input.balls),
        bats=load_bats(snakemake.input.bats),
    )
    write_dataset(
        ds,
        snakemake.output.impacts,
        title=f"Synthetic ball-bat impacts of dataset {snakemake.wildcards.dataset}",
        rule=snakemake.rule,
        inputs=data_inputs(snakemake.input),
        config=dict(snakemake.params),
    )
