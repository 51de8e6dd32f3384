rule fit_ex:
    """Fit e_x per bat and ball and pooled (Eq. omega), Eq. ratio, and the Figs. 3-4 slopes."""
    input:
        impacts=rules.reconstruct.output.impacts,
        code=code("fit_ex.py"),
    output:
        fit=f"{R}/{{dataset}}/fit_ex.nc",
    log:
        f"{R}/{{dataset}}/logs/fit_ex.log",
    benchmark:
        f"{R}/{{dataset}}/benchmarks/fit_ex.tsv"
    group:
        "dataset"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=dataset_mem_mb,
        runtime=10,
    params:
        mu_k_example=config["analysis"]["mu_k_example"],
    script:
        "../scripts/fit_ex.py"
