# Raw camera tracks (Sec. II): a dataset that names `tracks` (a lab's tracked points), or a
# synthetic dataset with `render: {enabled: true}`, starts from camera tracks; `reduce`
# turns them into the impacts every later stage reads (get_source in common.smk).


rule render_tracks:
    """Render both cameras' raw tracks of a synthetic experiment (Sec. II rig)."""
    input:
        truth=f"{R}/{{dataset}}/simulate.nc",
        balls=get_balls_table,
        code=code("render_tracks.py"),
    output:
        tracks=f"{R}/{{dataset}}/tracks.nc",
    log:
        f"{R}/{{dataset}}/logs/render_tracks.log",
    benchmark:
        f"{R}/{{dataset}}/benchmarks/render_tracks.tsv"
    group:
        "dataset"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=dataset_mem_mb,
        runtime=10,
    params:
        settings=get_render_settings,
        sha256=data_hashes,
    script:
        "../scripts/render_tracks.py"


rule render_clips:
    """Film a synthetic experiment: both cameras' high-speed clips of every impact (render.video; docs/video.md)."""
    input:
        truth=f"{R}/{{dataset}}/simulate.nc",
        balls=get_balls_table,
        code=code("render_clips.py"),
    output:
        clips=directory(f"{R}/{{dataset}}/clips"),
    log:
        f"{R}/{{dataset}}/logs/render_clips.log",
    benchmark:
        f"{R}/{{dataset}}/benchmarks/render_clips.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=dataset_mem_mb,
        runtime=60,
    params:
        settings=get_render_settings,
        sha256=data_hashes,
    script:
        "../scripts/render_clips.py"


rule import_tracks:
    """Read a lab's tracking-tool files (Tracker, Kinovea; one per impact and camera) into long tracks."""
    input:
        unpack(get_tool_files),
        balls=get_balls_table,
        bats=get_bats_table,
        code=code("import_tracks.py"),
    output:
        tracks=f"{R}/{{dataset}}/imported_tracks.nc",
        cameras=f"{R}/{{dataset}}/imported_cameras.yaml",
    log:
        f"{R}/{{dataset}}/logs/import_tracks.log",
    wildcard_constraints:
        dataset="|".join(NOT_FILMED) or "^$",
    group:
        "dataset"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=dataset_mem_mb,
        runtime=10,
    params:
        settings=get_import_settings,
        where=get_reduce_where,
        sha256=tool_file_hashes,
    script:
        "../scripts/import_tracks.py"


# A folder of clips (tracks.format: video, or a filmed synthetic dataset) is tracked one job per batch
# of video.clips_per_job clips (ballbat.video.plan: the clips known from the folder, or the config, when
# the workflow is read), one thread each: `-c2` runs two side by side, a cluster profile submits each
# as its own job (docs/video.md). Not in the group "dataset", so that they are separate jobs there too.
rule track_clips:
    """Track one batch of a dataset's clips: each point found with its quality, each left out with why."""
    input:
        unpack(get_batch_clips),
        balls=get_balls_table,
        code=code("track_clips.py"),
    output:
        batch=f"{R}/{{dataset}}/clip_tracks/batch_{{batch}}.nc",
    log:
        f"{R}/{{dataset}}/logs/track_clips_{{batch}}.log",
    benchmark:
        f"{R}/{{dataset}}/benchmarks/track_clips_{{batch}}.tsv"
    wildcard_constraints:
        dataset="|".join(FILMED) or "^$",
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=clip_batch_mem_mb,
        runtime=clip_batch_runtime,
    params:
        tracker=get_tracker_settings,
        sha256=batch_hashes,
    script:
        "../scripts/track_clips.py"


# The batches gathered, as import_tracks reads tool files (the same script, one more output): the
# tracks, the camera settings found, and the tracker's quality of every point (docs/video.md).
use rule import_tracks as import_clips with:
    input:
        unpack(get_tool_files),
        batches=get_clip_batch_files,
        balls=get_balls_table,
        bats=get_bats_table,
        code=code("import_tracks.py"),
    output:
        tracks=f"{R}/{{dataset}}/imported_tracks.nc",
        cameras=f"{R}/{{dataset}}/imported_cameras.yaml",
        quality=f"{R}/{{dataset}}/imported_quality.nc",
    log:
        f"{R}/{{dataset}}/logs/import_clips.log",
    wildcard_constraints:
        dataset="|".join(FILMED) or "^$",


rule reduce:
    """Reduce camera tracks to v_bat, v_ball, theta, omega per impact, with fitted uncertainties."""
    input:
        unpack(get_tracks_inputs),
        balls=get_balls_table,
        bats=get_bats_table,
        code=code("reduce.py"),
    output:
        impacts=f"{R}/{{dataset}}/reduce.nc",
    log:
        f"{R}/{{dataset}}/logs/reduce.log",
    benchmark:
        f"{R}/{{dataset}}/benchmarks/reduce.tsv"
    group:
        "dataset"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=dataset_mem_mb,
        runtime=10,
    params:
        settings=get_reduce_settings,
        where=get_reduce_where,
        files=data_files,
        sha256=data_hashes,
    script:
        "../scripts/reduce.py"


rule tracks_qa:
    """QA figures of the reduction: a few impacts' camera views and spin fits; residuals and flags."""
    input:
        unpack(get_tracks_inputs),
        reduced=rules.reduce.output.impacts,
        code=code("tracks_qa.py"),
    output:
        impacts=report(
            f"{R}/{{dataset}}/figures/tracks_impacts.png",
            caption="../report/tracks_impacts.rst",
            category="Dataset {dataset}",
            subcategory="Camera tracks",
            labels={"figure": "tracks QA", "shows": "camera views and spin fits of a few impacts"},
        ),
        summary=report(
            f"{R}/{{dataset}}/figures/tracks_summary.png",
            caption="../report/tracks_summary.rst",
            category="Dataset {dataset}",
            subcategory="Camera tracks",
            labels={"figure": "tracks summary", "shows": "fit residuals and exclusions"},
        ),
    log:
        f"{R}/{{dataset}}/logs/tracks_qa.log",
    conda:
        ENV
    script:
        "../scripts/tracks_qa.py"


rule clips_qa:
    """Contact sheet of a dataset's clips: a few frames of a few impacts, with the points tracked in them."""
    input:
        unpack(get_tool_files),
        tracks=f"{R}/{{dataset}}/imported_tracks.nc",
        reduced=rules.reduce.output.impacts,
        code=code("clips_qa.py"),
    output:
        sheet=report(
            f"{R}/{{dataset}}/figures/clips_contact_sheet.png",
            caption="../report/clips_contact_sheet.rst",
            category="Dataset {dataset}",
            subcategory="Camera tracks",
            labels={"figure": "clips contact sheet", "shows": "frames of a few impacts with the points tracked"},
        ),
    log:
        f"{R}/{{dataset}}/logs/clips_qa.log",
    conda:
        ENV
    params:
        settings=get_import_settings,
    script:
        "../scripts/clips_qa.py"


rule clips_quality:
    """The video tracker's quality per camera: the ball's edge-fit residuals, contrasts, points left out and why."""
    input:
        quality=f"{R}/{{dataset}}/imported_quality.nc",
        code=code("clips_quality.py"),
    output:
        figure=report(
            f"{R}/{{dataset}}/figures/clips_quality.png",
            caption="../report/clips_quality.rst",
            category="Dataset {dataset}",
            subcategory="Camera tracks",
            labels={
                "figure": "clips tracking quality",
                "shows": "tracking residuals, contrasts, points left out per camera",
            },
        ),
    log:
        f"{R}/{{dataset}}/logs/clips_quality.log",
    conda:
        ENV
    script:
        "../scripts/clips_quality.py"
