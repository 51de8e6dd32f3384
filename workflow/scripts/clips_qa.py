"""Rule clips_qa: adapter around ballbat.video.qa.sheet_rows and ballbat.plotting_tracks.contact_sheet."""

from ballbat.pipeline.ncio import read_dataset
from ballbat.pipeline.provenance import job_provenance, png_text
from ballbat.pipeline.runlog import logged
from ballbat.plotting_tracks import contact_sheet, pick_impacts, save_figure
from ballbat.tracks.io import load_tracks
from ballbat.video.qa import block_clips, sheet_rows

with logged(snakemake.log[0], snakemake.rule) as log:
    tracks = load_tracks(snakemake.input.tracks)
    rows = sheet_rows(
        block_clips(snakemake.params.settings), tracks, pick_impacts(read_dataset(snakemake.input.reduced))
    )
    log.info("%d clips, %d frames shown", len(rows), sum(len(r.frames) for r in rows))
    save_figure(contact_sheet(rows), snakemake.output.sheet, png_text(*job_provenance(snakemake)))
