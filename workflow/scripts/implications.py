"""Rule implications: adapter around ballbat.implications.run_scenario."""

from ballbat.implications import pooled_e_x, run_scenario
from ballbat.pipeline.ncio import write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls, load_bats

with logged(snakemake.log[0], snakemake.rule):
    scenario = snakemake.params.scenario
    ds = run_scenario(
        scenario,
        balls=load_balls(snakemake.input.balls),
        bats=load_bats(snakemake.input.bats),
        air=snakemake.params.air,
        e_x=pooled_e_x(snakemake.input.fit, scenario["ball"]) if "fit" in snakemake.input.keys() else None,
    )
    write_job_output(
        ds,
        snakemake,
        "scenario",
        f"Batted-ball scenario {snakemake.wildcards.scenario}: collision and flight (Sec. V.B)",
    )
