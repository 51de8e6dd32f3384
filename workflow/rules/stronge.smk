rule fit_stronge:
    """Fit eta^2 of Stronge's contact model per ball; model curves and Fig. 10 histories (Sec. V.A)."""
    input:
        impacts=rules.reconstruct.output.impacts,
        code=code("fit_stronge.py"),
    output:
        stronge=f"{R}/{{dataset}}/stronge.nc",
    log:
        f"{R}/{{dataset}}/logs/fit_stronge.log",
    benchmark:
        f"{R}/{{dataset}}/benchmarks/fit_stronge.tsv"
    group:
        "dataset"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=dataset_mem_mb,
        runtime=20,
    params:
        stronge=config["stronge"],
    script:
        "../scripts/fit_stronge.py"
