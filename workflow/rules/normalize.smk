rule normalize:
    """Scale measured spin and exit speed to the reference bat speed (normalize.v_ref_mph; Sec. II)."""
    input:
        impacts=get_source,
        code=code("normalize.py"),
    output:
        impacts=f"{R}/{{dataset}}/normalize.nc",
    log:
        f"{R}/{{dataset}}/logs/normalize.log",
    benchmark:
        f"{R}/{{dataset}}/benchmarks/normalize.tsv"
    group:
        "dataset"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=dataset_mem_mb,
        runtime=10,
    params:
        v_ref_mph=config["normalize"]["v_ref_mph"],
    script:
        "../scripts/normalize.py"
