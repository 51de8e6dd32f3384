rule implications:
    """Collide a pitched ball with a bat and fly it, or fly given launch conditions (Sec. V.B)."""
    input:
        unpack(get_scenario_fit),
        unpack(get_scenario_tables),
        code=code("implications.py"),
    output:
        scenario="results/implications/{scenario}.nc",
    log:
        "results/implications/logs/{scenario}.log",
    benchmark:
        "results/implications/benchmarks/{scenario}.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=scenario_mem_mb,
        runtime=20,
    params:
        scenario=get_scenario,
        air=config["implications"]["air"],
        sha256=scenario_hashes,
    script:
        "../scripts/implications.py"


rule implications_compare:
    """Compare the paper scenario's carry and exit speed with Sec. V.B's statements."""
    input:
        scenario="results/implications/paper.nc",
        code=code("implications_compare.py"),
    output:
        csv="results/implications/paper_comparison.csv",
        md="results/implications/paper_comparison.md",
        prov="results/implications/paper_comparison.provenance.json",
    log:
        "results/implications/logs/paper_comparison.log",
    conda:
        ENV
    script:
        "../scripts/implications_compare.py"
