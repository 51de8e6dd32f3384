"""Rule league: adapter around ballbat.league (the table)."""

from pathlib import Path

from ballbat.league import LeagueSettings, csv_text, league, read_session
from ballbat.pipeline.checked import sealed_csv
from ballbat.pipeline.ncio import atomic_write_text, write_job_output
from ballbat.pipeline.provenance import job_provenance, write_sidecar
from ballbat.pipeline.runlog import logged

with logged(snakemake.log[0], snakemake.rule):
    sessions = []
    for path in map(Path, snakemake.input.fits):
        folder, dataset = str(path.parent.parent), path.parent.name
        label = snakemake.params.sessions.get(dataset) or f"{folder}/{dataset}"
        sessions.append(read_session(path, label, folder))
    ds = league(sessions, LeagueSettings.from_config({"league": snakemake.params.league}))
    write_job_output(ds, snakemake, "nc", "The bats league table: e_x per bat over the test sessions")
    atomic_write_text(snakemake.output.csv, sealed_csv(csv_text(ds)))
    write_sidecar(snakemake.output.prov, [snakemake.output.csv], *job_provenance(snakemake))
