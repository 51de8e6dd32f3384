"""Rule tracks_qa: adapter around ballbat.tracks.qa."""

from ballbat.pipeline.ncio import read_dataset
from ballbat.pipeline.runlog import logged
from ballbat.tracks.io import load_tracks
from ballbat.tracks.qa import impacts_figure, save_figure, summary_figure

with logged(snakemake.log[0], snakemake.rule):
    red = read_dataset(snakemake.input.reduced)
    tracks = load_tracks(snakemake.input.tracks, snakemake.input.get("impacts"))
    save_figure(impacts_figure(red, tracks), snakemake.output.impacts)
    save_figure(summary_figure(red), snakemake.output.summary)
