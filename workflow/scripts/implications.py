"""Rule implications: adapter around ballbat.stages.implications.run, with e_x's bands (ballbat.scenario_bands)."""

from ballbat.pipeline.ncio import read_dataset, write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls, load_bats
from ballbat.scenario_bands import dataset_e_x, with_bands
from ballbat.stages import implications

with logged(snakemake.log[0], snakemake.rule):
    settings = implications.ImplicationsSettings.from_params(dict(snakemake.params))
    scenario = settings.scenario
    ex = None
    if "fit" in snakemake.input.keys():  # e_x_from_dataset: the bat's own e_x there, or the ball's pooled one
        fit = read_dataset(snakemake.input.fit, require=("e_x", "e_x_err", "e_x_pooled", "e_x_pooled_err"))
        ex = dataset_e_x(fit, scenario["ball"], scenario.get("bat"), scenario["e_x_from_dataset"])
    balls, bats = load_balls(snakemake.input.balls), load_bats(snakemake.input.bats)
    ds = implications.run(settings, balls, bats, e_x=None if ex is None else ex.value)
    ds = with_bands(ds, settings, balls, bats, ex)
    write_job_output(
        ds,
        snakemake,
        "scenario",
        f"Batted-ball scenario {snakemake.wildcards.scenario}: collision and flight (Sec. V.B)",
    )
