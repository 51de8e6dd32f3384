"""Rule study_design: adapter around ballbat.studies.design."""

from ballbat.pipeline.ncio import atomic_write_text, read_dataset, write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.plotting import design_figure, save_figure
from ballbat.studies import StudySettings, design, design_csv, study_config

with logged(snakemake.log[0], snakemake.rule):
    study = snakemake.wildcards.study
    cfg = snakemake.params.study
    settings = StudySettings.from_config(study_config(cfg), study)
    s = cfg["study"]
    des = design(read_dataset(snakemake.input.coverage), settings, s["delta_e_x"], s["confidence"], s["power"])
    write_job_output(des, snakemake, "design", f"Study {study}: spread of e_x and impacts per bat needed")
    atomic_write_text(snakemake.output.csv, design_csv(des))
    save_figure(design_figure(des), snakemake.output.png)
