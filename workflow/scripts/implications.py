"""Rule implications: adapter around ballbat.stages.implications.run."""

from ballbat.implications import pooled_e_x
from ballbat.pipeline.ncio import write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls, load_bats
from ballbat.stages import implications

with logged(snakemake.log[0], snakemake.rule):
    settings = implications.ImplicationsSettings.from_params(dict(snakemake.params))
    ds = implications.run(
        settings,
        balls=load_balls(snakemake.input.balls),
        bats=load_bats(snakemake.input.bats),
        e_x=pooled_e_x(snakemake.input.fit, settings.scenario["ball"]) if "fit" in snakemake.input.keys() else None,
    )
    write_job_output(
        ds,
        snakemake,
        "scenario",
        f"Batted-ball scenario {snakemake.wildcards.scenario}: collision and flight (Sec. V.B)",
    )
