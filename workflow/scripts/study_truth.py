"""Rule study_truth_point: adapter around ballbat.studies.truth.run (one sweep point, or every point)."""

from ballbat.pipeline.ncio import write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls, load_bats
from ballbat.studies import truth
from ballbat.studies.settings import StudySettings

with logged(snakemake.log[0], snakemake.rule) as log:
    study = snakemake.wildcards.study
    point = int(snakemake.wildcards.point) if "point" in snakemake.wildcards.keys() else None
    settings = StudySettings.from_block(snakemake.params.study)
    where = "every point" if point is None else f"point {point}"
    log.info("%s of %d, about %d impacts per ball and bat", where, settings.n_points, settings.truth_impacts)
    points = None if point is None else [point]
    ds = truth.run(settings, load_balls(snakemake.input.balls), load_bats(snakemake.input.bats), points=points)
    write_job_output(ds, snakemake, "truth", f"Study {study}, {where}: the design's truth")
