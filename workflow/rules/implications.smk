rule implications:
    """Collide a pitched ball with a bat and fly it, or fly given launch conditions (Sec. V.B)."""
    input:
        unpack(get_scenario_fit),
        unpack(get_scenario_tables),
        code=code("implications.py"),
    output:
        scenario=f"{R}/implications/{{scenario}}.nc",
    log:
        f"{R}/implications/logs/{{scenario}}.log",
    benchmark:
        f"{R}/implications/benchmarks/{{scenario}}.tsv"
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
        scenario=f"{R}/implications/paper.nc",
        code=code("implications_compare.py"),
    output:
        csv=f"{R}/implications/paper_comparison.csv",
        md=f"{R}/implications/paper_comparison.md",
        prov=f"{R}/implications/paper_comparison.provenance.json",
    log:
        f"{R}/implications/logs/paper_comparison.log",
    conda:
        ENV
    script:
        "../scripts/implications_compare.py"
