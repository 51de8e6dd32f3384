rule fit_stronge:
    """Fit eta^2 of Stronge's contact model per ball; model curves and Fig. 10 histories (Sec. V.A)."""
    input:
        impacts=rules.reconstruct.output.impacts,
        code=code("fit_stronge.py"),
    output:
        stronge="results/{dataset}/stronge.nc",
    log:
        "results/{dataset}/logs/fit_stronge.log",
    benchmark:
        "results/{dataset}/benchmarks/fit_stronge.tsv"
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
