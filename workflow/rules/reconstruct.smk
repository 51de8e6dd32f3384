rule reconstruct:
    """Reconstruct psi (Eq. angmom), D and the bracket terms of Eqs. omega and vtf per impact."""
    input:
        impacts=rules.normalize.output.impacts,
        balls=get_balls_table,
        bats=get_bats_table,
        code=code("reconstruct.py"),
    output:
        impacts=f"{R}/{{dataset}}/reconstruct.nc",
    log:
        f"{R}/{{dataset}}/logs/reconstruct.log",
    benchmark:
        f"{R}/{{dataset}}/benchmarks/reconstruct.tsv"
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
    script:
        "../scripts/reconstruct.py"
