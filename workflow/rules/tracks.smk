# Raw camera tracks (Sec. II): a dataset that names `tracks` (a lab's tracked points), or a
# synthetic dataset with `render: {enabled: true}`, starts from camera tracks; `reduce`
# turns them into the impacts every later stage reads (get_source in common.smk).
from ballbat.tracks.stage import camera_block


def uses_tracks(name):
    """Whether a dataset starts from raw camera tracks (reduce.nc is its source)."""
    d = config["datasets"][name]
    return "tracks" in d or bool((d.get("render") or {}).get("enabled", False))


TRACKED = [d for d in DATASETS if uses_tracks(d)]


def get_render_settings(wildcards):
    return dataset_config(wildcards)["render"]


def get_tracks_inputs(wildcards):
    """A lab's tracks and impacts files, or the rendered tracks.nc (which holds its impact table)."""
    d = dataset_config(wildcards)
    if "tracks" in d:
        return {"tracks": d["tracks"]["file"], "impacts": d["tracks"]["impacts"]}
    return {"tracks": f"results/{wildcards.dataset}/tracks.nc"}


def get_reduce_settings(wildcards):
    d = dataset_config(wildcards)
    return camera_block(d["tracks"] if "tracks" in d else d["render"])


def get_reduce_where(wildcards):
    key = "tracks" if "tracks" in dataset_config(wildcards) else "render"
    return f"config datasets.{wildcards.dataset}.{key}"


rule render_tracks:
    """Render both cameras' raw tracks of a synthetic experiment (Sec. II rig)."""
    input:
        truth="results/{dataset}/simulate.nc",
        balls=get_balls_table,
        code=code("render_tracks.py"),
    output:
        tracks="results/{dataset}/tracks.nc",
    params:
        settings=get_render_settings,
    log:
        "results/{dataset}/logs/render_tracks.log",
    benchmark:
        "results/{dataset}/benchmarks/render_tracks.tsv"
    script:
        "../scripts/render_tracks.py"


rule reduce:
    """Reduce camera tracks to v_bat, v_ball, theta, omega per impact, with fitted uncertainties."""
    input:
        unpack(get_tracks_inputs),
        balls=get_balls_table,
        bats=get_bats_table,
        code=code("reduce.py"),
    output:
        impacts="results/{dataset}/reduce.nc",
    params:
        settings=get_reduce_settings,
        where=get_reduce_where,
    log:
        "results/{dataset}/logs/reduce.log",
    benchmark:
        "results/{dataset}/benchmarks/reduce.tsv"
    script:
        "../scripts/reduce.py"


TARGETS += expand("results/{dataset}/figures/tracks_{fig}.png", dataset=TRACKED, fig=["impacts", "summary"])


rule tracks_qa:
    """QA figures of the reduction: a few impacts' camera views and spin fits; residuals and flags."""
    input:
        unpack(get_tracks_inputs),
        reduced=rules.reduce.output.impacts,
        code=code("tracks_qa.py"),
    output:
        impacts=report(
            "results/{dataset}/figures/tracks_impacts.png",
            caption="../report/tracks_impacts.rst",
            category="Dataset {dataset}",
            subcategory="Camera tracks",
            labels={"figure": "tracks QA", "shows": "camera views and spin fits of a few impacts"},
        ),
        summary=report(
            "results/{dataset}/figures/tracks_summary.png",
            caption="../report/tracks_summary.rst",
            category="Dataset {dataset}",
            subcategory="Camera tracks",
            labels={"figure": "tracks summary", "shows": "fit residuals and exclusions"},
        ),
    log:
        "results/{dataset}/logs/tracks_qa.log",
    script:
        "../scripts/tracks_qa.py"
