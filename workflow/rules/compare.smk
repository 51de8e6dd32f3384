rule compare:
    """Tabulate every published number of Secs. II-V.A beside ours and the truth."""
    input:
        fit=rules.fit_ex.output.fit,
        impacts=rules.reconstruct.output.impacts,
        stronge=rules.fit_stronge.output.stronge,
        code=code("compare.py"),
    output:
        csv=f"{R}/{{dataset}}/paper_comparison.csv",
        md=f"{R}/{{dataset}}/paper_comparison.md",
        prov=f"{R}/{{dataset}}/paper_comparison.provenance.json",
    log:
        f"{R}/{{dataset}}/logs/compare.log",
    conda:
        ENV
    script:
        "../scripts/compare.py"
