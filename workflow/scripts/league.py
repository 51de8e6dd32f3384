"""Rule league: adapter around ballbat.league (the table) and ballbat.plotting_league (the forest plot)."""

from pathlib import Path

from ballbat.league import LeagueSettings, Session, check_fit, csv_text, league
from ballbat.pipeline.checked import sealed_csv
from ballbat.pipeline.ncio import atomic_write_text, read_dataset, write_job_output
from ballbat.pipeline.provenance import job_provenance, png_text, write_sidecar
from ballbat.pipeline.runlog import logged
from ballbat.plotting_league import save_forest
from ballbat.workbook import custom_properties, league_workbook

with logged(snakemake.log[0], snakemake.rule):
    sessions = []
    for path in map(Path, snakemake.input.fits):
        fit = read_dataset(path)
        check_fit(fit, str(path))
        folder, dataset = str(path.parent.parent), path.parent.name
        label = snakemake.params.sessions.get(dataset) or f"{folder}/{dataset}"
        sessions.append(Session(label, folder, dataset, fit))
    ds = league(sessions, LeagueSettings.from_config({"league": snakemake.params.league}))
    write_job_output(ds, snakemake, "nc", "The bats league table: e_x per bat over the test sessions")
    atomic_write_text(snakemake.output.csv, sealed_csv(csv_text(ds)))
    write_sidecar(snakemake.output.prov, [snakemake.output.csv], *job_provenance(snakemake))
    save_forest(ds, snakemake.output.forest, png_text(*job_provenance(snakemake)))
    written = read_dataset(snakemake.output.nc)  # with its provenance, for the workbook's sheet
    league_workbook(snakemake.output.xlsx, written, custom_properties({"league.nc": snakemake.output.nc}))
