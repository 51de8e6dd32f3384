"""Rule clips_quality: adapter around ballbat.video.qa.camera_quality and ballbat.plotting_tracks.quality_figure."""

from ballbat.pipeline.ncio import read_dataset
from ballbat.pipeline.provenance import job_provenance, png_text
from ballbat.pipeline.runlog import logged
from ballbat.plotting_tracks import quality_figure, save_figure
from ballbat.stages.quality import QUALITY_TABLE, quality_columns
from ballbat.video.qa import camera_quality

with logged(snakemake.log[0], snakemake.rule) as log:
    cams = camera_quality(quality_columns(read_dataset(snakemake.input.quality, require=tuple(QUALITY_TABLE))))
    for q in cams:
        log.info(
            "%s: %d clips, %d frames, %d points found, %d left out", q.camera, q.clips, q.frames, q.found, q.left_out
        )
    save_figure(quality_figure(cams), snakemake.output.figure, png_text(*job_provenance(snakemake)))
