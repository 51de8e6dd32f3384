"""Rule implications: adapter around ballbat.scenario_bands.scenario_with_bands (the stage, with e_x's bands)."""

from ballbat.pipeline.ncio import read_dataset, write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls, load_bats
from ballbat.scenario_bands import dataset_e_x, scenario_with_bands
from ballbat.stages import implications

with logged(snakemake.log[0], snakemake.rule):
    settings = implications.ImplicationsSettings.from_config(snakemake.config, snakemake.wildcards.scenario)
    scenario = settings.scenario
    ex = None
    if "fit" in snakemake.input.keys():  # e_x_from_dataset: the bat's own e_x there, or the ball's pooled one
        fit = read_dataset(snakemake.input.fit, require=("e_x", "e_x_err", "e_x_pooled", "e_x_pooled_err"))
        ex = dataset_e_x(fit, scenario["ball"], scenario.get("bat"), scenario["e_x_from_dataset"])
    ds = scenario_with_bands(
        settings, balls=load_balls(snakemake.input.balls), bats=load_bats(snakemake.input.bats), ex=ex
    )
    write_job_output(
        ds,
        snakemake,
        "scenario",
        f"Batted-ball scenario {snakemake.wildcards.scenario}: collision and flight (Sec. V.B)",
    )
