# Replicate studies (docs/studies.md): the whole chain on many replicates of a synthetic
# dataset, one job per batch of replicates, then the coverage of every uncertainty and, for a
# sweep, the design table; each figure a job of its own (plot_study_*, study_grid), drawn from its file. Not part of `rule all`: `make study` (or `snakemake
# studies`); the studies marked on_request: `make study-robustness` (`snakemake studies_on_request`).


rule study_batch:
    """Run one batch of a study's replicate experiments through the chain (in memory)."""
    input:
        balls=get_study_balls,
        bats=get_study_bats,
        code=code("study_batch.py"),
    output:
        batch=f"{R}/studies/{{study}}/batches/batch{{batch}}.nc",
    log:
        f"{R}/studies/{{study}}/logs/batch{{batch}}.log",
    benchmark:
        f"{R}/studies/{{study}}/benchmarks/batch{{batch}}.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=study_batch_mem_mb,
        runtime=study_batch_runtime,
    params:
        study=get_study_config,
        sha256=study_hashes,
    script:
        "../scripts/study_batch.py"


rule study_truth_point:
    """The design's truth of every quantity at one sweep point: the estimators on a large noise-free experiment.

    A job per point, beside the batches (a grid's points in parallel, not one after the other),
    started before them: the longest jobs first, so that the study does not wait for a truth job
    started last (the calibration study's truth takes as long as two or three batches).
    """
    input:
        balls=get_study_balls,
        bats=get_study_bats,
        code=code("study_truth.py"),
    output:
        truth=f"{R}/studies/{{study}}/truth/point{{point}}.nc",
    log:
        f"{R}/studies/{{study}}/logs/truth_point{{point}}.log",
    benchmark:
        f"{R}/studies/{{study}}/benchmarks/truth_point{{point}}.tsv"
    priority: 1
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=study_truth_mem_mb,
        runtime=study_truth_runtime,
    params:
        study=get_study_config,
        sha256=study_hashes,
    script:
        "../scripts/study_truth.py"


rule study_truth:
    """The design's truth of every quantity at every sweep point (the points' files joined)."""
    input:
        points=get_study_truth_points,
        code=code("study_truth_merge.py"),
    output:
        truth=f"{R}/studies/{{study}}/truth.nc",
    log:
        f"{R}/studies/{{study}}/logs/truth.log",
    conda:
        ENV
    threads: 1
    resources:
        runtime=10,
    script:
        "../scripts/study_truth_merge.py"


rule study_aggregate:
    """Coverage of every quantity with an uncertainty and a truth, over all batches of a study (file and table)."""
    input:
        batches=get_study_batches,
        truth=rules.study_truth.output.truth,
        code=code("study_aggregate.py"),
    output:
        coverage=f"{R}/studies/{{study}}/coverage.nc",
        csv=f"{R}/studies/{{study}}/coverage.csv",
    log:
        f"{R}/studies/{{study}}/logs/aggregate.log",
    benchmark:
        f"{R}/studies/{{study}}/benchmarks/aggregate.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=study_aggregate_mem_mb,
        runtime=10,
    params:
        study=get_study_config,
    script:
        "../scripts/study_aggregate.py"


rule plot_study_coverage:
    """A study's coverage figure, drawn from its coverage file (a job of its own: drawing apart from computing)."""
    input:
        coverage=rules.study_aggregate.output.coverage,
        code=code("plot_study_coverage.py"),
    output:
        png=report(
            f"{R}/studies/{{study}}/coverage.png",
            caption="../report/study_coverage.rst",
            category="Studies",
            subcategory="{study}",
            labels={"figure": "coverage", "shows": "coverage of every reported uncertainty"},
        ),
    log:
        f"{R}/studies/{{study}}/logs/plot_coverage.log",
    conda:
        ENV
    threads: 1
    resources:
        runtime=10,
    script:
        "../scripts/plot_study_coverage.py"


rule study_design:
    """A sweep's spread of e_x and the impacts per bat an experiment needs (file and table)."""
    input:
        coverage=rules.study_aggregate.output.coverage,
        code=code("study_design.py"),
    output:
        design=f"{R}/studies/{{study}}/design.nc",
        csv=f"{R}/studies/{{study}}/design.csv",
    log:
        f"{R}/studies/{{study}}/logs/design.log",
    conda:
        ENV
    params:
        study=get_study_config,
    script:
        "../scripts/study_design.py"


rule plot_study_design:
    """A sweep's design figure, drawn from its design file (a job of its own: drawing apart from computing)."""
    input:
        design=rules.study_design.output.design,
        code=code("plot_study_design.py"),
    output:
        png=report(
            f"{R}/studies/{{study}}/design.png",
            caption="../report/study_design.rst",
            category="Studies",
            subcategory="{study}",
            labels={"figure": "design", "shows": "spread of e_x and impacts needed"},
        ),
    log:
        f"{R}/studies/{{study}}/logs/plot_design.log",
    conda:
        ENV
    script:
        "../scripts/plot_study_design.py"


rule study_grid:
    """A grid study's coverage at a glance: quantities x grid points, statistical and combined intervals."""
    input:
        coverage=rules.study_aggregate.output.coverage,
        code=code("study_grid.py"),
    output:
        png=report(
            f"{R}/studies/{{study}}/grid.png",
            caption="../report/study_grid.rst",
            category="Studies",
            subcategory="{study}",
            labels={"figure": "grid", "shows": "95 % coverage at every grid point"},
        ),
    log:
        f"{R}/studies/{{study}}/logs/grid.log",
    conda:
        ENV
    script:
        "../scripts/study_grid.py"


rule studies:
    """Every study of the config but those on request (`make study`)."""
    input:
        study_targets() + ([f"{R}/studies/front.rst"] if STUDIES else []),


rule studies_on_request:
    """The studies marked on_request (`make study-robustness`): too long to run with the others."""
    input:
        study_targets(on_request=True),
