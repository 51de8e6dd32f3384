rule simulate:
    """Draw a synthetic experiment that mirrors the paper's (Sec. II, Tables I-II)."""
    input:
        balls=get_balls_table,
        bats=get_bats_table,
        code=code("simulate.py"),
    output:
        impacts=f"{R}/{{dataset}}/simulate.nc",
    log:
        f"{R}/{{dataset}}/logs/simulate.log",
    benchmark:
        f"{R}/{{dataset}}/benchmarks/simulate.tsv"
    group:
        "dataset"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=dataset_mem_mb,
        runtime=10,
    params:
        settings=get_synthetic_settings,
        files=data_files,
        sha256=data_hashes,
    script:
        "../scripts/simulate.py"


rule ingest:
    """Read a measured dataset (CSV or NetCDF, paper units), check every row, convert to SI."""
    input:
        impacts=get_measured_impacts,
        balls=get_balls_table,
        bats=get_bats_table,
        code=code("ingest.py"),
    output:
        impacts=f"{R}/{{dataset}}/ingest.nc",
    log:
        f"{R}/{{dataset}}/logs/ingest.log",
    benchmark:
        f"{R}/{{dataset}}/benchmarks/ingest.tsv"
    group:
        "dataset"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=dataset_mem_mb,
        runtime=10,
    params:
        files=data_files,
        sha256=data_hashes,
        calibration=lambda w: dataset_config(w).get("calibration", {}),
    script:
        "../scripts/ingest.py"
