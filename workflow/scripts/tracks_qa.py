"""Rule tracks_qa: adapter around ballbat.plotting_tracks."""

from ballbat.pipeline.ncio import read_dataset
from ballbat.pipeline.provenance import job_provenance, png_text
from ballbat.pipeline.runlog import logged
from ballbat.plotting_tracks import impacts_figure, save_figure, summary_figure
from ballbat.tracks.io import load_tracks

with logged(snakemake.log[0], snakemake.rule):
    red = read_dataset(snakemake.input.reduced)
    tracks = load_tracks(snakemake.input.tracks, snakemake.input.get("impacts"))
    provenance = png_text(*job_provenance(snakemake))
    save_figure(impacts_figure(red, tracks), snakemake.output.impacts, provenance)
    save_figure(summary_figure(red), snakemake.output.summary, provenance)
